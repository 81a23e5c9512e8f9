//! Joining a physics cluster (`--cluster NAME --name DAEMON`): a Zenoh session of the daemon's
//! own, opened only when `--cluster` is given, so a daemon outside a cluster has no socket,
//! no thread and no cost of it.
//!
//! - [`session`]: the flags, their checks (loopback unless TLS and an allow-list), and the
//!   Zenoh configuration they make (peer mode, no multicast scouting, explicit endpoints).
//! - [`membership`]: the daemon's liveliness token, and refusing a name already alive.
//! - [`load`]: the load report each second (planes, bodies, tick budget used, CPU) and the
//!   gauge the server loop feeds it through (its one hook).
//!
//! - [`failover`]: persistent planes replicated to the other members, and restored by one
//!   of them when their daemon leaves.
//! - [`migrate`]: planes moving to and arriving from other members (`MoveTo`).
//! - [`rebalance`]: `--rebalance`, planes moved off a daemon over its tick budget.
//! - [`relay`]: remote clients, answered as local clients of this daemon, one per remote
//!   session (started by [`Cluster::serve_remote`]).
//!
//! Local clients keep iceoryx2 zero-copy: Zenoh carries only what crosses hosts.

mod error;
pub mod failover;
pub mod load;
pub mod membership;
pub mod migrate;
pub mod rebalance;
pub mod relay;
pub mod session;

use std::sync::Arc;

use crate::server::moves::migration::Migration;
use crate::server::persistence::persist::Adoptions;
pub use error::ClusterError;
pub use session::ClusterArgs;

/// A daemon's membership of its cluster: alive while this value lives (its token is
/// undeclared and its reports stop when it is dropped or the process dies).
pub struct Cluster {
    reporter: load::Reporter,
    _member: membership::Member,
    session: zenoh::Session,
    cluster: String,
    name: String,
    relay: Option<relay::Relay>,
    failover: Option<failover::Failover>,
    /// An endpoint clients of a plane that moved away connect through (the first listened).
    endpoint: String,
    arrivals: Option<migrate::Arrivals>,
    rebalancer: Option<rebalance::Rebalancer>,
}

impl Cluster {
    /// Joins the cluster `args` name, or returns `None` when no `--cluster` is given.
    /// `gauge` is what the server loop feeds (see [`load::Gauge`]).
    pub fn join(
        args: &ClusterArgs,
        gauge: Arc<load::Gauge>,
    ) -> Result<Option<Cluster>, ClusterError> {
        let Some(plan) = session::Plan::from_args(args)? else {
            return Ok(None);
        };
        let session = session::open(&plan)?;
        let joined = membership::Member::join(&session, &plan.cluster, &plan.name).and_then(|m| {
            Ok((
                m,
                load::Reporter::start(&session, &plan.cluster, &plan.name, gauge)?,
            ))
        });
        let (member, reporter) = match joined {
            Ok(parts) => parts,
            Err(e) => {
                // Closing waits on the peers: do it aside, the caller reports the error now.
                std::thread::spawn(move || {
                    use zenoh::Wait;
                    let _ = session.close().wait();
                });
                return Err(e);
            }
        };
        tracing::info!(
            cluster = plan.cluster,
            name = plan.name,
            zid = %session.zid(),
            listen = ?plan.listen,
            "joined the physics cluster"
        );
        let endpoint = plan.listen.first().cloned().unwrap_or_default();
        Ok(Some(Cluster {
            endpoint,
            arrivals: None,
            rebalancer: None,
            reporter,
            _member: member,
            session,
            cluster: plan.cluster,
            name: plan.name,
            relay: None,
            failover: None,
        }))
    }

    /// Starts replicating this daemon's persistent planes (the state folder `dir` of its
    /// domain) to the other members and taking over theirs when they leave
    /// ([`failover`]); adopted planes reach the server loop through `adopt`.
    pub fn start_failover(
        &mut self,
        dir: std::path::PathBuf,
        adopt: Arc<Adoptions>,
        domain: &str,
    ) -> Result<(), ClusterError> {
        let f = failover::Failover::start(
            &self.session,
            &self.cluster,
            &self.name,
            dir,
            adopt,
            domain,
        )?;
        self.failover = Some(f);
        Ok(())
    }

    /// Starts serving remote clients of this daemon ([`relay`]): they reach the daemon of
    /// `domain` as local clients, at most `max_sessions` at once.
    pub fn serve_remote(&mut self, domain: &str, max_sessions: usize) -> Result<(), ClusterError> {
        let relay = relay::Relay::start(
            &self.session,
            relay::RelayOptions {
                cluster: self.cluster.clone(),
                daemon: self.name.clone(),
                domain: domain.to_string(),
                max_sessions,
            },
        )?;
        self.relay = Some(relay);
        Ok(())
    }

    /// Starts taking planes that move here from other members, and returns the hook the
    /// server loop moves planes away and takes arrivals through ([`migrate`]).
    pub fn start_migration(&mut self, domain: &str) -> Result<Arc<Migration>, ClusterError> {
        let (migration, arrivals) = migrate::start(
            &self.session,
            &self.cluster,
            &self.name,
            &self.endpoint,
            domain,
        )?;
        self.arrivals = Some(arrivals);
        Ok(migration)
    }

    /// Starts `--rebalance SHARE` ([`rebalance`]): planes move through `migration`.
    pub fn start_rebalance(
        &mut self,
        share: f32,
        migration: Arc<Migration>,
        domain: &str,
    ) -> Result<(), ClusterError> {
        let r = rebalance::start(
            &self.session,
            &self.cluster,
            &self.name,
            share,
            migration,
            domain,
        )?;
        self.rebalancer = Some(r);
        Ok(())
    }

    /// The Zenoh session (for the parts of the cluster built on it).
    pub fn session(&self) -> &zenoh::Session {
        &self.session
    }

    /// Leaves the cluster: stops the reports, undeclares the token, closes the session.
    pub fn leave(self) {
        let Cluster {
            reporter,
            _member,
            session,
            relay,
            failover,
            arrivals,
            rebalancer,
            ..
        } = self;
        drop(rebalancer);
        drop(arrivals);
        drop(failover);
        if let Some(relay) = relay {
            relay.stop();
        }
        reporter.stop();
        drop(_member);
        use zenoh::Wait;
        if let Err(e) = session.close().wait() {
            tracing::debug!("closing the cluster session: {e}");
        }
    }
}

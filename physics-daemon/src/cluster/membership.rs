//! Membership: each daemon holds a liveliness token `physics/<cluster>/daemon/<name>` for as
//! long as its session lives. Zenoh withdraws the token when the session closes, when the
//! process dies (the kernel closes its links) or when its links stay silent past the lease
//! ([`shm_layout::cluster::LEASE_MS`]), so every member and client sees who is alive without
//! a protocol of ours. The daemon logs each other member's arrival and departure.
//!
//! A name already alive is refused: before declaring its token the daemon asks the cluster
//! for tokens of its name. Two daemons that start with the same name in the same instant can
//! both pass that check; the name is advisory for people, the session id stays unique.

use std::time::Duration;

use shm_layout::cluster as keys;
use zenoh::Wait;

use super::error::ClusterError;

/// How long the name check waits for answers from the members already connected.
const NAME_CHECK: Duration = Duration::from_millis(1500);

/// Waits until the links to the cluster's members stop growing (bounded by
/// [`SETTLE_MAX`]): peers route only their own declarations, so a member's token is seen
/// only once Zenoh's gossip has connected this daemon to that member directly.
fn settle(session: &zenoh::Session) {
    let started = std::time::Instant::now();
    let mut last = usize::MAX;
    let mut stable_since = started;
    while started.elapsed() < SETTLE_MAX {
        let peers = session.info().peers_zid().wait().count();
        if peers != last {
            last = peers;
            stable_since = std::time::Instant::now();
        } else if stable_since.elapsed() >= SETTLE_QUIET {
            return;
        }
        std::thread::sleep(Duration::from_millis(50));
    }
}

/// The longest wait for the links to settle.
const SETTLE_MAX: Duration = Duration::from_secs(3);
/// How long the link count must hold still to count as settled.
const SETTLE_QUIET: Duration = Duration::from_millis(500);

/// A daemon's token, and its watch on the others (each arrival and departure is logged):
/// alive while this value lives.
pub struct Member {
    _token: zenoh::liveliness::LivelinessToken,
    _watch: zenoh::pubsub::Subscriber<()>,
}

impl Member {
    /// Checks that `name` is free in `cluster`, then declares its token.
    pub fn join(
        session: &zenoh::Session,
        cluster: &str,
        name: &str,
    ) -> Result<Member, ClusterError> {
        let key = keys::daemon_key(cluster, name);
        settle(session);
        let replies = session
            .liveliness()
            .get(&key)
            .timeout(NAME_CHECK)
            .wait()
            .map_err(|e| ClusterError::Zenoh(format!("cannot ask who is alive: {e}")))?;
        while let Ok(reply) = replies.recv() {
            if reply.result().is_ok() {
                return Err(ClusterError::NameTaken {
                    cluster: cluster.to_string(),
                    name: name.to_string(),
                });
            }
        }
        let token = session
            .liveliness()
            .declare_token(&key)
            .wait()
            .map_err(|e| ClusterError::Zenoh(format!("cannot declare the token {key}: {e}")))?;
        let me = name.to_string();
        let watch = session
            .liveliness()
            .declare_subscriber(keys::daemons_key(cluster))
            .history(true)
            .callback(move |sample| {
                let other = keys::last_segment(sample.key_expr().as_str());
                if other == me {
                    return;
                }
                match sample.kind() {
                    zenoh::sample::SampleKind::Put => {
                        tracing::info!(name = other, "cluster member alive")
                    }
                    zenoh::sample::SampleKind::Delete => {
                        tracing::info!(name = other, "cluster member left")
                    }
                }
            })
            .wait()
            .map_err(|e| ClusterError::Zenoh(format!("cannot watch the members: {e}")))?;
        Ok(Member {
            _token: token,
            _watch: watch,
        })
    }
}

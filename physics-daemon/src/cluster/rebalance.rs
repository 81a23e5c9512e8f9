//! `--rebalance SHARE`: a daemon that uses more than `SHARE` of its tick budget (its own
//! load report, docs/cluster.md "Load") moves planes to the least loaded member with room,
//! through the path of `MoveTo` (`crate::server::moves`): the largest 3D plane first, never
//! one pinned to it (placed by name), never one that arrived within
//! [`crate::server::moves::migration::SETTLE`].
//!
//! Hysteresis, so planes do not ping-pong: a member has room only while it uses less than
//! half of `SHARE`; after a move the daemon waits [`COOLDOWN`] (its load report then shows
//! the new state) before it considers another; an arrived plane settles first.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use shm_layout::cluster::{self as keys, LoadReport};
use zenoh::{Session, Wait};

use super::error::ClusterError;
use crate::server::moves::migration::{Migration, RebalanceRequest};

/// How often the loads are looked at (the load report's period).
pub const PERIOD: Duration = Duration::from_secs(1);
/// After a move, how long before the next one is considered.
pub const COOLDOWN: Duration = Duration::from_secs(5);
/// `--rebalance` without a value.
pub const DEFAULT_SHARE: f32 = 0.8;

/// Checks a `--rebalance` share: within (0, 1].
pub fn check_share(share: f32) -> Result<f32, ClusterError> {
    if share.is_finite() && share > 0.0 && share <= 1.0 {
        Ok(share)
    } else {
        Err(ClusterError::Flags(format!(
            "--rebalance must be a share of the tick budget within (0, 1] (0.8: move planes \
             away above 80 %), got {share}"
        )))
    }
}

/// The rebalancing thread; stops when dropped.
pub struct Rebalancer {
    stop: Arc<AtomicBool>,
}

impl Drop for Rebalancer {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::SeqCst);
    }
}

/// Starts rebalancing daemon `me` above `share` of its budget.
pub fn start(
    session: &Session,
    cluster: &str,
    me: &str,
    share: f32,
    migration: Arc<Migration>,
    domain: &str,
) -> Result<Rebalancer, ClusterError> {
    let share = check_share(share)?;
    let stop = Arc::new(AtomicBool::new(false));
    let (s, session, cluster, me, domain) = (
        stop.clone(),
        session.clone(),
        cluster.to_string(),
        me.to_string(),
        domain.to_string(),
    );
    std::thread::Builder::new()
        .name("rebalance".into())
        .spawn(move || {
            let mut last_move: Option<Instant> = None;
            while !s.load(Ordering::SeqCst) {
                std::thread::sleep(PERIOD);
                if last_move.is_some_and(|t| t.elapsed() < COOLDOWN) {
                    continue;
                }
                let reports = loads(&session, &cluster);
                let Some(target) = choose(&reports, &me, share) else {
                    continue;
                };
                tracing::info!(
                    to = target,
                    share,
                    "over the tick budget share: moving a plane away"
                );
                migration.rebalance(RebalanceRequest { target });
                if let Err(e) = crate::wake(&domain) {
                    tracing::warn!("rebalance: cannot wake the loop: {e}");
                }
                last_move = Some(Instant::now());
            }
        })
        .map_err(|e| ClusterError::Zenoh(format!("rebalance: cannot start a thread: {e}")))?;
    Ok(Rebalancer { stop })
}

/// The latest load report of every member (a report under another name's key is ignored).
fn loads(session: &Session, cluster: &str) -> Vec<LoadReport> {
    let Ok(replies) = session.get(keys::loads_key(cluster)).timeout(PERIOD).wait() else {
        return Vec::new();
    };
    let mut reports = Vec::new();
    while let Ok(reply) = replies.recv() {
        if let Ok(sample) = reply.result() {
            let name = keys::last_segment(sample.key_expr().as_str());
            if let Some(r) = LoadReport::decode(&sample.payload().to_bytes())
                .filter(|r| r.name == name && r.budget_used.is_finite())
            {
                reports.push(r);
            }
        }
    }
    reports
}

/// Where a plane of `me` should go now: `None` unless `me` uses more than `share` of its
/// budget, has a plane, and another member uses less than half of `share` (the least
/// loaded of those).
pub fn choose(reports: &[LoadReport], me: &str, share: f32) -> Option<String> {
    let own = reports.iter().find(|r| r.name == me)?;
    if own.budget_used <= share || own.planes == 0 {
        return None;
    }
    reports
        .iter()
        .filter(|r| r.name != me && r.budget_used < share / 2.0)
        .min_by(|a, b| {
            a.budget_used
                .total_cmp(&b.budget_used)
                .then_with(|| a.name.cmp(&b.name))
        })
        .map(|r| r.name.clone())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn report(name: &str, planes: u32, budget_used: f32) -> LoadReport {
        LoadReport {
            name: name.into(),
            planes,
            bodies: 0,
            budget_used,
            cpu: 0.0,
            cores: 1,
            pid: 1,
            sequence: 1,
        }
    }

    #[test]
    fn only_an_overloaded_daemon_moves_and_only_to_a_member_with_room() {
        let r = [
            report("a", 3, 0.9),
            report("b", 1, 0.5),
            report("c", 1, 0.3),
        ];
        assert_eq!(
            choose(&r, "a", 0.8).as_deref(),
            Some("c"),
            "least loaded with room"
        );
        assert_eq!(choose(&r, "b", 0.8), None, "under its share");
        // Nobody under half the share: no room anywhere (no ping-pong between two busy).
        let r = [report("a", 3, 0.9), report("b", 1, 0.45)];
        assert_eq!(choose(&r, "a", 0.8), None);
        let r = [report("a", 0, 0.9), report("b", 0, 0.0)];
        assert_eq!(choose(&r, "a", 0.8), None, "no plane to move");
        assert!(check_share(0.0).is_err() && check_share(f32::NAN).is_err());
        assert!(check_share(1.5).is_err() && check_share(0.8).is_ok());
    }
}

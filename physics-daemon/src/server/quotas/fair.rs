//! Fair CPU shares between client processes. Every automatic tick (and every `Step`) of a
//! plane is charged to its owner's process; a process may use `cores / processes` of the
//! machine (its fair share: the processes that own planes split the cores evenly). A process
//! past its share has its planes' automatic ticks postponed until its account is back
//! within its share, so a client that asks for more than its share (64 planes at TickRate
//! 10,000) slows its own planes, not the other clients' steps.
//!
//! The account is a virtual clock: a tick that took `t` of CPU moves the process's clock by
//! `t / share`; a clock ahead of the wall clock means the process used more than its share,
//! and its ticks wait until the wall clock catches up. A clock far behind (an idle process)
//! is pulled up to `BURST` before now, so idling saves at most that much credit.

use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// Credit an idle process may save up: short bursts above the share are not postponed.
const BURST: Duration = Duration::from_millis(20);

/// The machine's cores and how many processes split them.
#[derive(Debug)]
pub struct CpuShares {
    cores: f64,
    processes: AtomicUsize,
    start: Instant,
}

impl CpuShares {
    /// Shares of `cores` (at least 1).
    pub fn new(cores: u32) -> CpuShares {
        CpuShares {
            cores: cores.max(1) as f64,
            processes: AtomicUsize::new(0),
            start: Instant::now(),
        }
    }

    /// `n` processes own planes now.
    pub fn set_processes(&self, n: usize) {
        self.processes.store(n, Ordering::Relaxed);
    }

    /// The cores one process may use.
    pub fn share(&self) -> f64 {
        self.cores / self.processes.load(Ordering::Relaxed).max(1) as f64
    }
}

impl Default for CpuShares {
    fn default() -> Self {
        CpuShares::new(crate::backend::pools::cores())
    }
}

/// One process's CPU account.
#[derive(Debug, Default)]
pub struct CpuAccount {
    /// The virtual clock, nanoseconds since `shares.start`.
    clock_ns: AtomicU64,
    shares: Arc<CpuShares>,
}

impl CpuAccount {
    /// An account of a process among `shares`.
    pub fn new(shares: Arc<CpuShares>) -> CpuAccount {
        CpuAccount {
            clock_ns: AtomicU64::new(0),
            shares,
        }
    }

    /// Charges `used` of CPU at `now`. Returns when the process's next automatic tick may
    /// run, when it is past its share (`None`: at once).
    pub fn charge(&self, used: Duration, now: Instant) -> Option<Instant> {
        note_step(used);
        let start = self.shares.start;
        let now_ns = now.saturating_duration_since(start).as_nanos() as u64;
        let floor = now_ns.saturating_sub(BURST.as_nanos() as u64);
        let cost = (used.as_nanos() as f64 / self.shares.share()) as u64;
        let mut clock = 0;
        let _ = self
            .clock_ns
            .fetch_update(Ordering::SeqCst, Ordering::SeqCst, |c| {
                clock = c.max(floor).saturating_add(cost);
                Some(clock)
            });
        (clock > now_ns).then(|| start + Duration::from_nanos(clock))
    }

    /// When the process's next automatic tick may run (`None`: now).
    pub fn ready_at(&self, now: Instant) -> Option<Instant> {
        let start = self.shares.start;
        let now_ns = now.saturating_duration_since(start).as_nanos() as u64;
        let clock = self.clock_ns.load(Ordering::SeqCst);
        (clock > now_ns).then(|| start + Duration::from_nanos(clock))
    }
}

/// Nanoseconds spent stepping planes since the daemon started.
static STEP_NANOS: AtomicU64 = AtomicU64::new(0);

/// Counts `used` as time spent stepping a plane.
pub fn note_step(used: Duration) {
    STEP_NANOS.fetch_add(used.as_nanos() as u64, Ordering::Relaxed);
}

/// Nanoseconds spent stepping planes since the daemon started ([`note_step`]).
pub fn stepped_nanos() -> u64 {
    STEP_NANOS.load(Ordering::Relaxed)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_process_over_its_share_waits_and_an_idle_one_saves_only_a_burst() {
        let shares = Arc::new(CpuShares::new(2));
        shares.set_processes(2);
        let hog = CpuAccount::new(shares.clone());
        let now = Instant::now() + Duration::from_secs(1);
        // One core of share: 10 ms of CPU within the burst is free, 50 ms is not.
        assert_eq!(hog.charge(Duration::from_millis(10), now), None);
        let wait = hog
            .charge(Duration::from_millis(50), now)
            .expect("past its share");
        let ahead = wait - now;
        assert!(
            ahead >= Duration::from_millis(39) && ahead <= Duration::from_millis(41),
            "{ahead:?}"
        );
        assert!(hog.ready_at(now).is_some());
        assert!(hog.ready_at(wait + Duration::from_millis(1)).is_none());
        // With four processes the share is half a core: CPU costs twice the wall time.
        shares.set_processes(4);
        let other = CpuAccount::new(shares);
        let later = now + Duration::from_secs(10);
        let wait = other.charge(Duration::from_millis(30), later).unwrap();
        assert_eq!(wait - later, Duration::from_millis(40));
    }
}

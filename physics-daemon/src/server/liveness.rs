//! Whether the connected clients' processes still run, without listing iceoryx2's nodes.
//!
//! Listing nodes (`Node::list`) reads every node's files in the machine-wide nodes folder,
//! every domain's, not only this daemon's: with a few hundred nodes of other deployments on
//! the machine it took about 1 ms each time, twice a second while a client was connected,
//! which was most of an idle daemon's CPU. A process that died is seen far more cheaply in
//! `/proc/<pid>/stat` (gone, or a zombie nobody waited for), so the loop lists nodes only when
//! a client's process looks dead, and otherwise once every [`FULL_CHECK`] (a client that
//! closed its node but kept its process running, or a reused pid, is found then).

use std::time::{Duration, Instant};

/// The longest the loop goes without listing nodes while clients are connected.
pub const FULL_CHECK: Duration = Duration::from_secs(5);

/// Whether process `pid` runs: its `/proc` entry exists and it is not a zombie (a client
/// killed by its parent shows as one until the parent waits for it). Without `/proc`
/// nothing can be said cheaply: false, so the caller lists nodes.
pub fn process_alive(pid: u32) -> bool {
    let Ok(stat) = std::fs::read_to_string(format!("/proc/{pid}/stat")) else {
        return false;
    };
    // "pid (comm) S ...": the state follows the last ')' (comm may hold any byte).
    match stat.rsplit_once(')') {
        Some((_, rest)) => !matches!(rest.trim_start().chars().next(), Some('Z' | 'X' | 'x')),
        None => false,
    }
}

/// When the loop must list nodes to find gone clients.
#[derive(Debug)]
pub struct Schedule {
    last_full: Instant,
}

impl Default for Schedule {
    fn default() -> Self {
        Schedule {
            last_full: Instant::now(),
        }
    }
}

impl Schedule {
    /// Whether to list nodes now: some client's process looks dead (`all_alive` false), or
    /// [`FULL_CHECK`] has passed since the last listing. Records the listing when it says yes.
    pub fn list_now(&mut self, all_alive: impl FnOnce() -> bool) -> bool {
        let now = Instant::now();
        if now.duration_since(self.last_full) < FULL_CHECK && all_alive() {
            return false;
        }
        self.last_full = now;
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn this_process_runs_and_a_waited_child_does_not() {
        assert!(process_alive(std::process::id()));
        let mut child = std::process::Command::new("true").spawn().unwrap();
        let pid = child.id();
        // Exited but not waited for: a zombie (give a loaded machine time to run it).
        let until = Instant::now() + Duration::from_secs(10);
        while process_alive(pid) && Instant::now() < until {
            std::thread::sleep(Duration::from_millis(10));
        }
        assert!(!process_alive(pid), "a zombie is not a running client");
        child.wait().unwrap();
        assert!(!process_alive(pid), "gone");
    }

    #[test]
    fn nodes_are_listed_when_a_process_looks_dead_or_a_period_passed() {
        let mut s = Schedule::default();
        assert!(!s.list_now(|| true), "all alive, within the period");
        assert!(s.list_now(|| false), "a dead-looking process");
        s.last_full = Instant::now() - FULL_CHECK;
        assert!(s.list_now(|| true), "the period passed");
        assert!(!s.list_now(|| true), "and a new one started");
    }
}

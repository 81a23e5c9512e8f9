//! Whether the connected clients' processes still run, without listing iceoryx2's nodes.
//!
//! Listing nodes (`Node::list`) reads every node's files in the machine-wide nodes folder,
//! every domain's, not only this daemon's: with a few hundred nodes of other deployments on
//! the machine it took about 1 ms each time, twice a second while a client was connected,
//! which was most of an idle daemon's CPU. A process that died is seen far more cheaply in
//! `/proc/<pid>/stat` (gone, or a zombie nobody waited for), so the loop lists nodes only when
//! a client's process looks dead, and otherwise once every [`FULL_CHECK`] (a client that
//! closed its node but kept its process running, or a reused pid, is found then).

use std::time::{Duration, Instant, SystemTime};

use crate::server::liveness::alarm::Registry;
use crate::server::liveness::pidwatch::{folder_stamp, PidWatch};

/// The longest the loop goes without listing nodes while clients are connected.
pub const FULL_CHECK: Duration = Duration::from_secs(5);
/// The longest the loop goes without listing nodes when pidfds watch every client and the
/// node folder did not change.
pub const SAFETY_NET: Duration = Duration::from_secs(30);

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
    /// The clients' processes, watched through pidfds (`pidwatch`).
    pids: PidWatch,
    /// The node folder's modification time at the last listing.
    stamp: Option<SystemTime>,
    /// The loop's alarm, once [`Schedule::ring`] set it.
    alarm: Option<Registry>,
    /// A watched process had exited at the last look (its client may not be released yet).
    exited: bool,
}

impl Default for Schedule {
    fn default() -> Self {
        Schedule {
            last_full: Instant::now(),
            pids: PidWatch::default(),
            stamp: None,
            alarm: None,
            exited: false,
        }
    }
}

impl Schedule {
    /// From now on rings `alarm` when a client's process exits.
    pub fn ring(&mut self, alarm: Registry) {
        self.alarm = Some(alarm);
    }

    /// Whether the alarm rings for every client's exit (and no exit is still to be dealt
    /// with). Only then may the loop look less often than its period. (A client that closes
    /// its node without a goodbye and keeps running is found by the next look's folder
    /// time: the node folder is not on the alarm, since any process can change it as often
    /// as it likes.)
    pub fn alarmed(&self) -> bool {
        self.alarm.is_some() && self.pids.all_alarmed() && !self.exited
    }

    /// Whether to list nodes now; records the listing when it says yes. Yes when a client's
    /// process exited (its pidfd, or `all_alive` false where pidfds cannot tell), when the
    /// domain's node folder at `folder` changed (a node came or went: a client that closed
    /// its node but kept running), or when [`FULL_CHECK`] passed (only [`SAFETY_NET`] where
    /// pidfds watch every client: a pid cannot be reused under a pidfd).
    pub fn list_now(
        &mut self,
        pids: impl IntoIterator<Item = u32>,
        folder: &str,
        all_alive: impl FnOnce() -> bool,
    ) -> bool {
        let now = Instant::now();
        self.pids.watch_with(pids, self.alarm.as_ref());
        let stamp = folder_stamp(folder);
        let exited = self.pids.any_exited();
        self.exited = exited == Some(true);
        let period = match exited {
            Some(_) => SAFETY_NET,
            None => FULL_CHECK,
        };
        let quiet = now.duration_since(self.last_full) < period
            && stamp.is_some()
            && stamp == self.stamp
            && match exited {
                Some(exited) => !exited,
                None => all_alive(),
            };
        if quiet {
            return false;
        }
        self.last_full = now;
        self.stamp = stamp;
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
    fn nodes_are_listed_when_a_process_exits_the_folder_changes_or_a_period_passed() {
        let dir = std::env::temp_dir().join(format!("liveness-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let folder = dir.to_str().unwrap().to_string();
        let own = std::process::id();
        let mut s = Schedule::default();
        assert!(
            s.list_now([own], &folder, || true),
            "first look: no stamp yet"
        );
        assert!(
            !s.list_now([own], &folder, || true),
            "all alive, nothing changed"
        );
        // A node came: the folder changed (sleep past the file system's time granularity).
        std::thread::sleep(Duration::from_millis(20));
        std::fs::write(dir.join("node"), b"").unwrap();
        assert!(s.list_now([own], &folder, || true), "the folder changed");
        assert!(!s.list_now([own], &folder, || true), "and is recorded");
        // A client process exits.
        let mut child = std::process::Command::new("sleep")
            .arg("30")
            .spawn()
            .unwrap();
        assert!(!s.list_now([own, child.id()], &folder, || true));
        child.kill().unwrap();
        child.wait().unwrap();
        assert!(
            s.list_now([own, child.id()], &folder, || true),
            "a client exited"
        );
        // The safety net with pidfds, the short period without.
        s.last_full = Instant::now() - SAFETY_NET;
        assert!(s.list_now([own], &folder, || true), "the safety net passed");
        s.last_full = Instant::now() - FULL_CHECK;
        assert!(
            !s.list_now([own], &folder, || true),
            "pidfds watch: no short period"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
}

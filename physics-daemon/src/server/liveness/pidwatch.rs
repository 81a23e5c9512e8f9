//! Which of a set of processes have exited, from Linux process file descriptors (pidfds).
//!
//! Finding a gone client or a killed process's leftover node used to take a listing of the
//! domain's nodes (every node's files read and parsed) at a fixed period, the most of what an
//! idle daemon cost. A pidfd (`pidfd_open(2)`) becomes readable once its process exits
//! (zombies included), and it names that process, never a later one that reuses the pid; one
//! `poll(2)` over all of them answers "did any exit?" for a few microseconds. So the loop and
//! the resource guard list nodes only when a watched process exited, when the node folder
//! changed, or rarely as a safety net.
//!
//! Where pidfds cannot be had (an old kernel, `EMFILE`, more than [`MAX_WATCHED`] processes),
//! [`PidWatch::any_exited`] answers `None` and the caller keeps its short listing period.

use super::alarm;
use std::collections::HashMap;
use std::os::fd::{AsRawFd, FromRawFd, OwnedFd};

/// Most processes one watch keeps a descriptor for (each is an open file of the daemon).
pub const MAX_WATCHED: usize = 256;

/// Process file descriptors of the processes being watched.
#[derive(Debug, Default)]
pub struct PidWatch {
    /// pid → its pidfd; `None` when it could not be opened (the answer is then unknown,
    /// unless the process is already gone).
    fds: HashMap<u32, Option<OwnedFd>>,
    /// A pid was gone already when it was to be watched.
    gone_at_watch: bool,
    /// More pids were asked for than [`MAX_WATCHED`].
    overflow: bool,
    /// A descriptor the alarm refused to watch (sticky: the alarm cannot be trusted after).
    unalarmed: bool,
}

impl PidWatch {
    /// Watches exactly `pids` from now on: descriptors of pids no longer listed are closed,
    /// new ones opened (a pid that no longer runs counts as exited at the next
    /// [`PidWatch::any_exited`]).
    pub fn watch(&mut self, pids: impl IntoIterator<Item = u32>) {
        self.watch_with(pids, None);
    }

    /// [`PidWatch::watch`], registering each new descriptor with `alarm` too (the loop's
    /// [`crate::server::liveness::alarm`], which then rings when that process exits).
    pub fn watch_with(
        &mut self,
        pids: impl IntoIterator<Item = u32>,
        alarm: Option<&alarm::Registry>,
    ) {
        let mut wanted: Vec<u32> = pids.into_iter().filter(|&p| p != 0).collect();
        wanted.sort_unstable();
        wanted.dedup();
        self.overflow = wanted.len() > MAX_WATCHED;
        wanted.truncate(MAX_WATCHED);
        self.fds.retain(|pid, _| wanted.binary_search(pid).is_ok());
        for pid in wanted {
            if self.fds.contains_key(&pid) {
                continue;
            }
            match pidfd_open(pid) {
                Ok(fd) => {
                    if let Some(alarm) = alarm {
                        self.unalarmed |= !alarm.add(fd.as_raw_fd());
                    }
                    self.fds.insert(pid, Some(fd));
                }
                Err(e) if e.raw_os_error() == Some(libc::ESRCH) => self.gone_at_watch = true,
                Err(_) => {
                    self.fds.insert(pid, None);
                }
            }
        }
    }

    /// Whether a watched process has exited since it was first watched: `Some(true)` yes,
    /// `Some(false)` every watched process runs, `None` when that cannot be told (a pid
    /// without a descriptor, or more pids than [`MAX_WATCHED`]). Clears the "gone when
    /// watched" mark it reports.
    pub fn any_exited(&mut self) -> Option<bool> {
        if std::mem::take(&mut self.gone_at_watch) {
            return Some(true);
        }
        let mut polled: Vec<libc::pollfd> = Vec::with_capacity(self.fds.len());
        let mut unknown = self.overflow;
        for fd in self.fds.values() {
            match fd {
                Some(fd) => polled.push(libc::pollfd {
                    fd: fd.as_raw_fd(),
                    events: libc::POLLIN,
                    revents: 0,
                }),
                None => unknown = true,
            }
        }
        if !polled.is_empty() {
            // SAFETY: `polled` is a valid array of `polled.len()` pollfd records whose
            // descriptors this watch owns for the duration of the call.
            let ready = unsafe { libc::poll(polled.as_mut_ptr(), polled.len() as libc::nfds_t, 0) };
            if ready < 0 {
                return None;
            }
            if ready > 0 {
                return Some(true);
            }
        }
        if unknown {
            None
        } else {
            Some(false)
        }
    }

    /// Whether every watched pid has a descriptor the alarm watches (so an exit rings it).
    pub fn all_alarmed(&self) -> bool {
        !self.overflow && !self.unalarmed && self.fds.values().all(Option::is_some)
    }

    /// Pids being watched with a descriptor.
    pub fn watched(&self) -> usize {
        self.fds.values().filter(|fd| fd.is_some()).count()
    }
}

/// `pidfd_open(2)`: a descriptor that refers to process `pid` (close-on-exec).
fn pidfd_open(pid: u32) -> std::io::Result<OwnedFd> {
    let Ok(pid) = libc::pid_t::try_from(pid) else {
        return Err(std::io::Error::from_raw_os_error(libc::ESRCH));
    };
    // SAFETY: the syscall takes a pid and flags and returns a new descriptor or -1.
    let fd = unsafe { libc::syscall(libc::SYS_pidfd_open, pid, 0) };
    if fd < 0 {
        return Err(std::io::Error::last_os_error());
    }
    // SAFETY: the kernel just returned this descriptor to us; nothing else owns it.
    Ok(unsafe { OwnedFd::from_raw_fd(fd as i32) })
}

/// A process's exit as something a WaitSet can wait on: its pidfd, which becomes readable
/// once the process exits (zombies included).
#[derive(Debug)]
pub struct ProcessExit {
    pidfd: OwnedFd,
    /// The same descriptor as iceoryx2 sees it (not owned: `pidfd` closes it).
    view: iceoryx2_bb_posix::file_descriptor::FileDescriptor,
}

impl ProcessExit {
    /// Watches `pid`; `None` when it is gone already or pidfds cannot be had.
    pub fn watch(pid: u32) -> Option<ProcessExit> {
        let pidfd = pidfd_open(pid).ok()?;
        let view =
            iceoryx2_bb_posix::file_descriptor::FileDescriptor::non_owning_new(pidfd.as_raw_fd())?;
        Some(ProcessExit { pidfd, view })
    }

    /// Whether the process has exited.
    pub fn exited(&self) -> bool {
        let mut fd = libc::pollfd {
            fd: self.pidfd.as_raw_fd(),
            events: libc::POLLIN,
            revents: 0,
        };
        // SAFETY: one valid pollfd record whose descriptor we own, for the call.
        let ready = unsafe { libc::poll(&mut fd, 1, 0) };
        ready > 0
    }
}

impl iceoryx2_bb_posix::file_descriptor::FileDescriptorBased for ProcessExit {
    fn file_descriptor(&self) -> &iceoryx2_bb_posix::file_descriptor::FileDescriptor {
        &self.view
    }
}

impl iceoryx2_bb_posix::file_descriptor_set::SynchronousMultiplexing for ProcessExit {}

/// Modification time of the folder at `path` (a folder's time changes when an entry is
/// added or removed), or `None` when it cannot be read.
pub fn folder_stamp(path: &str) -> Option<std::time::SystemTime> {
    std::fs::metadata(path).and_then(|m| m.modified()).ok()
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::{Duration, Instant};

    fn exited_within(watch: &mut PidWatch, limit: Duration) -> bool {
        let until = Instant::now() + limit;
        loop {
            if watch.any_exited() == Some(true) {
                return true;
            }
            if Instant::now() > until {
                return false;
            }
            std::thread::sleep(Duration::from_millis(5));
        }
    }

    #[test]
    fn a_running_child_is_seen_exiting_and_a_zombie_counts_as_exited() {
        let mut child = std::process::Command::new("sleep")
            .arg("30")
            .spawn()
            .unwrap();
        let mut watch = PidWatch::default();
        watch.watch([child.id(), std::process::id()]);
        assert_eq!(watch.watched(), 2);
        assert_eq!(watch.any_exited(), Some(false), "both run");
        child.kill().unwrap();
        // Killed, not yet waited for: a zombie, which is exited.
        assert!(exited_within(&mut watch, Duration::from_secs(10)));
        child.wait().unwrap();
        assert_eq!(watch.any_exited(), Some(true), "stays exited once reaped");
        // No longer watched: the answer is about the others only.
        watch.watch([std::process::id()]);
        assert_eq!(watch.watched(), 1);
        assert_eq!(watch.any_exited(), Some(false));
    }

    #[test]
    fn a_pid_gone_before_it_is_watched_is_reported_once() {
        let mut child = std::process::Command::new("true").spawn().unwrap();
        let pid = child.id();
        child.wait().unwrap();
        let mut watch = PidWatch::default();
        watch.watch([pid]);
        assert_eq!(watch.any_exited(), Some(true));
        assert_eq!(
            watch.any_exited(),
            Some(false),
            "reported once, nothing left watched"
        );
    }

    #[test]
    fn more_pids_than_the_cap_make_the_answer_unknown() {
        let mut watch = PidWatch::default();
        let own = std::process::id();
        // This process and pids past the kernel's `pid_max`, which no process can have:
        // only the count matters for the cap. (Pids just above our own were used before:
        // a process among them, such as another test's child, could exit between the watch
        // and the look and make the answer a true "yes".)
        let pid_max: u32 = std::fs::read_to_string("/proc/sys/kernel/pid_max")
            .ok()
            .and_then(|s| s.trim().parse().ok())
            .unwrap_or(1 << 22);
        let never = (1..=MAX_WATCHED as u32).map(|i| pid_max + i);
        watch.watch(std::iter::once(own).chain(never));
        assert_eq!(watch.watched(), 1, "this process is watched");
        // The pids that do not run count as exited, once.
        assert_eq!(watch.any_exited(), Some(true));
        // This process runs, but the pids past the cap are not watched: unknown.
        assert_eq!(watch.any_exited(), None);
        assert!(!watch.all_alarmed());
    }
}

//! What wakes the request loop to look for gone clients: one epoll descriptor, watched by
//! the loop's WaitSet, that becomes readable when a watched client process exits (its pidfd,
//! [`crate::server::liveness::pidwatch`]). With it the loop of a daemon whose clients sit idle sleeps until
//! one dies (or something else wakes it) instead of looking twice a second; where it cannot
//! be had, the loop keeps looking at its period. The domain's node folder is deliberately
//! not on it: any process of the user can make and remove nodes there as fast as it likes,
//! and each change would wake the loop (a client that closes its node without a goodbye
//! and keeps running is found by the loop's next look instead).
//!
//! Every descriptor is registered edge-triggered, so one exit wakes the loop once (a client
//! that stays a zombie does not keep it awake); [`Alarm::drain`] takes what woke it.

use std::os::fd::{AsRawFd, FromRawFd, OwnedFd, RawFd};

/// The loop's end of the alarm: the epoll descriptor the WaitSet watches.
#[derive(Debug)]
pub struct Alarm {
    epoll: OwnedFd,
    /// The same descriptor as iceoryx2 sees it (not owned: `epoll` closes it).
    view: iceoryx2_bb_posix::file_descriptor::FileDescriptor,
}

/// The registering end (the same epoll instance through a second descriptor), kept by the
/// loop's liveness schedule, which knows which processes to watch.
#[derive(Debug)]
pub struct Registry {
    epoll: OwnedFd,
}

impl Alarm {
    /// A new alarm and its registry; `None` where epoll descriptors cannot be had.
    pub fn new() -> Option<(Alarm, Registry)> {
        // SAFETY: plain syscalls; each descriptor is owned by the `OwnedFd` made from it.
        let (epoll, second) = unsafe {
            let fd = libc::epoll_create1(libc::EPOLL_CLOEXEC);
            if fd < 0 {
                return None;
            }
            let epoll = OwnedFd::from_raw_fd(fd);
            let second = libc::fcntl(fd, libc::F_DUPFD_CLOEXEC, 0);
            if second < 0 {
                return None;
            }
            (epoll, OwnedFd::from_raw_fd(second))
        };
        let view =
            iceoryx2_bb_posix::file_descriptor::FileDescriptor::non_owning_new(epoll.as_raw_fd())?;
        Some((Alarm { epoll, view }, Registry { epoll: second }))
    }

    /// Takes what is ready; true when a watched descriptor became readable (a process
    /// exited) since the last call.
    pub fn drain(&self) -> bool {
        let mut events = [libc::epoll_event { events: 0, u64: 0 }; 32];
        let mut any = false;
        loop {
            // SAFETY: `events` holds room for `events.len()` records; timeout 0.
            let n = unsafe {
                libc::epoll_wait(
                    self.epoll.as_raw_fd(),
                    events.as_mut_ptr(),
                    events.len() as i32,
                    0,
                )
            };
            if n <= 0 {
                return any;
            }
            any = true;
            if (n as usize) < events.len() {
                return true;
            }
        }
    }
}

impl iceoryx2_bb_posix::file_descriptor::FileDescriptorBased for Alarm {
    fn file_descriptor(&self) -> &iceoryx2_bb_posix::file_descriptor::FileDescriptor {
        &self.view
    }
}

impl iceoryx2_bb_posix::file_descriptor_set::SynchronousMultiplexing for Alarm {}

impl Registry {
    /// Watches `fd` (a pidfd: readable when its process exits; any pollable descriptor) until
    /// it is closed: closing a descriptor that has no duplicate removes it from the alarm.
    /// False when the system refused.
    pub fn add(&self, fd: RawFd) -> bool {
        let mut event = libc::epoll_event {
            events: (libc::EPOLLIN | libc::EPOLLET) as u32,
            u64: fd as u64,
        };
        // SAFETY: registers a descriptor the caller owns with an epoll instance we own.
        unsafe { libc::epoll_ctl(self.epoll.as_raw_fd(), libc::EPOLL_CTL_ADD, fd, &mut event) == 0 }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::{Duration, Instant};

    fn readable(alarm: &Alarm, within: Duration) -> bool {
        let mut fd = libc::pollfd {
            fd: alarm.epoll.as_raw_fd(),
            events: libc::POLLIN,
            revents: 0,
        };
        // SAFETY: one valid pollfd record whose descriptor the alarm owns, for the call.
        unsafe { libc::poll(&mut fd, 1, within.as_millis() as i32) > 0 }
    }

    #[test]
    fn an_exit_rings_once_and_any_watched_descriptor_rings() {
        let (alarm, registry) = Alarm::new().expect("epoll");
        // A process that exits: readable once, and not again while it stays a zombie.
        let mut child = std::process::Command::new("sleep")
            .arg("30")
            .spawn()
            .unwrap();
        let mut watch = super::super::pidwatch::PidWatch::default();
        watch.watch_with([child.id()], Some(&registry));
        assert!(!readable(&alarm, Duration::from_millis(100)), "it runs");
        child.kill().unwrap();
        let started = Instant::now();
        assert!(readable(&alarm, Duration::from_secs(10)), "it exited");
        assert!(started.elapsed() < Duration::from_secs(5));
        assert!(alarm.drain());
        // Still a zombie: the exit does not ring again.
        assert!(!readable(&alarm, Duration::from_millis(100)), "rung once");
        assert!(!alarm.drain());
        // Reaped (the kernel may ring once more for that), then quiet for good.
        child.wait().unwrap();
        std::thread::sleep(Duration::from_millis(50));
        alarm.drain();
        assert!(
            !readable(&alarm, Duration::from_millis(100)),
            "quiet once reaped"
        );
        // Any pollable descriptor: a folder's inotify watch, an entry made and removed.
        let dir = std::env::temp_dir().join(format!("alarm-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let folder = super::super::folder_watch::FolderWatch::new(dir.to_str().unwrap()).unwrap();
        assert!(registry.add(folder.raw_fd()));
        assert!(!readable(&alarm, Duration::from_millis(100)));
        std::fs::write(dir.join("node"), b"").unwrap();
        assert!(readable(&alarm, Duration::from_secs(5)), "an entry came");
        assert!(alarm.drain());
        assert!(folder.drain());
        std::fs::remove_file(dir.join("node")).unwrap();
        assert!(readable(&alarm, Duration::from_secs(5)), "an entry went");
        assert!(alarm.drain());
        let _ = std::fs::remove_dir_all(&dir);
    }
}

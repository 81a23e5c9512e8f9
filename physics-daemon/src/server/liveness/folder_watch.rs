//! Wake-ups when a folder's entries change (Linux inotify), so a thread that only has work
//! when something appears in a folder can sleep until it does instead of looking at a
//! period. The resource guard of an idle daemon (no other process in the domain) waits on
//! the domain's node folder this way: a new process creates its node there before it can
//! hold anything the guard caps.

use std::os::fd::{AsRawFd, FromRawFd, OwnedFd};
use std::time::Duration;

/// An inotify descriptor watching one folder for entries created, removed or moved.
#[derive(Debug)]
pub struct FolderWatch {
    fd: OwnedFd,
    /// The folder itself was removed or moved: the watch sees nothing more.
    lost: std::cell::Cell<bool>,
}

impl FolderWatch {
    /// Watches `path`; `None` when it cannot (no inotify, no such folder, the watch limit).
    pub fn new(path: &str) -> Option<FolderWatch> {
        let path = std::ffi::CString::new(path).ok()?;
        // SAFETY: plain syscalls; the descriptor is owned by the `OwnedFd` made from it.
        unsafe {
            let fd = libc::inotify_init1(libc::IN_NONBLOCK | libc::IN_CLOEXEC);
            if fd < 0 {
                return None;
            }
            let fd = OwnedFd::from_raw_fd(fd);
            let mask = libc::IN_CREATE
                | libc::IN_DELETE
                | libc::IN_MOVED_FROM
                | libc::IN_MOVED_TO
                | libc::IN_DELETE_SELF
                | libc::IN_MOVE_SELF;
            if libc::inotify_add_watch(fd.as_raw_fd(), path.as_ptr(), mask) < 0 {
                return None;
            }
            Some(FolderWatch {
                fd,
                lost: std::cell::Cell::new(false),
            })
        }
    }

    /// Reads every change queued so far; true when there was one.
    pub fn drain(&self) -> bool {
        let mut buf = [0u8; 4096];
        let mut any = false;
        loop {
            // SAFETY: reads at most `buf.len()` bytes into `buf` from a descriptor we own.
            let n = unsafe {
                libc::read(
                    self.fd.as_raw_fd(),
                    buf.as_mut_ptr() as *mut libc::c_void,
                    buf.len(),
                )
            };
            if n <= 0 {
                return any;
            }
            any = true;
            // Each record: wd (i32), mask, cookie, len (u32), then `len` bytes of name.
            let mut at = 0usize;
            while at + 16 <= n as usize {
                let word =
                    |i: usize| u32::from_ne_bytes([buf[i], buf[i + 1], buf[i + 2], buf[i + 3]]);
                let (mask, len) = (word(at + 4), word(at + 12) as usize);
                if mask & (libc::IN_IGNORED | libc::IN_DELETE_SELF | libc::IN_MOVE_SELF) != 0 {
                    self.lost.set(true);
                }
                at += 16 + len;
            }
        }
    }

    /// Whether the watch still sees the folder (not removed or moved away since).
    pub fn is_live(&self) -> bool {
        !self.lost.get()
    }

    /// The descriptor to poll (readable when a change is queued).
    pub fn raw_fd(&self) -> i32 {
        self.fd.as_raw_fd()
    }
}

/// An eventfd another thread writes to wake a [`wait`]er at once.
#[derive(Debug)]
pub struct Wake {
    fd: OwnedFd,
}

impl Wake {
    /// A new wake-up descriptor; `None` when the system has none to give.
    pub fn new() -> Option<Wake> {
        // SAFETY: a plain syscall; the descriptor is owned by the `OwnedFd` made from it.
        unsafe {
            let fd = libc::eventfd(0, libc::EFD_NONBLOCK | libc::EFD_CLOEXEC);
            (fd >= 0).then(|| Wake {
                fd: OwnedFd::from_raw_fd(fd),
            })
        }
    }

    /// Wakes the waiter (now, or at its next wait).
    pub fn wake(&self) {
        let one: u64 = 1;
        // SAFETY: writes 8 bytes from `one` to a descriptor we own.
        let _ = unsafe {
            libc::write(
                self.fd.as_raw_fd(),
                &one as *const u64 as *const libc::c_void,
                8,
            )
        };
    }
}

/// Waits up to `timeout` for `wake`, or for a change in `folder`. Returns whether the folder
/// changed (its queued changes are read).
pub fn wait(wake: &Wake, folder: Option<&FolderWatch>, timeout: Duration) -> bool {
    let polled = |fd| libc::pollfd {
        fd,
        events: libc::POLLIN,
        revents: 0,
    };
    let mut fds = [
        polled(wake.fd.as_raw_fd()),
        polled(folder.map_or(-1, FolderWatch::raw_fd)),
    ];
    let n = if folder.is_some() { 2 } else { 1 };
    let ms = timeout.as_millis().min(i32::MAX as u128) as i32;
    // SAFETY: `fds` holds `n` valid pollfd records whose descriptors live for the call.
    unsafe { libc::poll(fds.as_mut_ptr(), n, ms) };
    let mut count = [0u8; 8];
    // SAFETY: reads the eventfd's 8-byte counter into `count` (resetting it; nothing when it
    // was not written).
    let _ = unsafe {
        libc::read(
            wake.fd.as_raw_fd(),
            count.as_mut_ptr() as *mut libc::c_void,
            8,
        )
    };
    folder.is_some_and(FolderWatch::drain)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Instant;

    #[test]
    fn a_new_entry_wakes_the_waiter_and_a_quiet_folder_does_not() {
        let dir = std::env::temp_dir().join(format!("folder-watch-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let watch = FolderWatch::new(dir.to_str().unwrap()).expect("inotify on a temp folder");
        let wake = Wake::new().expect("an eventfd");
        // Nothing happens: the whole timeout passes, no change.
        let started = Instant::now();
        assert!(!wait(&wake, Some(&watch), Duration::from_millis(200)));
        assert!(started.elapsed() >= Duration::from_millis(190));
        // An entry made from another thread ends the wait early, as a change.
        let made = dir.join("node");
        let maker = {
            let made = made.clone();
            std::thread::spawn(move || {
                std::thread::sleep(Duration::from_millis(50));
                std::fs::create_dir(&made).unwrap();
            })
        };
        let started = Instant::now();
        assert!(wait(&wake, Some(&watch), Duration::from_secs(10)));
        assert!(started.elapsed() < Duration::from_secs(5));
        maker.join().unwrap();
        // A wake-up ends the wait early, without a change; the queue was read.
        wake.wake();
        let started = Instant::now();
        assert!(!wait(&wake, Some(&watch), Duration::from_secs(10)));
        assert!(started.elapsed() < Duration::from_secs(5));
        // Removing the entry is a change too.
        std::fs::remove_dir(&made).unwrap();
        assert!(wait(&wake, Some(&watch), Duration::from_secs(10)));
        let _ = std::fs::remove_dir_all(&dir);
    }
}

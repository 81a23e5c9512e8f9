//! Real daemon processes for the bench, each in a domain of its own, stopped and cleaned up
//! when dropped.

use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::sync::atomic::{AtomicU32, Ordering};
use std::time::{Duration, Instant};

use client_sdk::{Client, Error};

use super::error::{BenchError, BenchResult};

pub struct DaemonProcess {
    pub domain: String,
    child: Option<Child>,
}

/// A domain no other run uses (pid + counter), within the 32-character limit.
pub fn unique_domain(tag: &str) -> String {
    static COUNTER: AtomicU32 = AtomicU32::new(0);
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    format!("bench-{tag}-{}-{n}", std::process::id())
}

impl DaemonProcess {
    /// Starts the `physics-daemon` next to this executable and waits until it answers.
    pub fn start(tag: &str) -> BenchResult<DaemonProcess> {
        Self::start_with(tag, &[], None)
    }

    /// Starts a daemon with extra flags (quotas), its stderr appended to `log` when given,
    /// and waits (up to 10 s) until it answers. Like a daemon started on demand, it exits by
    /// itself once this process is gone (`--starter-pid`).
    pub fn start_with(
        tag: &str,
        args: &[String],
        log: Option<&Path>,
    ) -> BenchResult<DaemonProcess> {
        let domain = unique_domain(tag);
        let exe = client_sdk::daemon_executable();
        let stderr = match log {
            Some(path) => Stdio::from(
                std::fs::OpenOptions::new()
                    .create(true)
                    .append(true)
                    .open(path)
                    .map_err(BenchError::io(format!("open {}", path.display())))?,
            ),
            None => Stdio::inherit(),
        };
        let child = Command::new(&exe)
            .args(["--domain", &domain])
            .args(["--starter-pid", &std::process::id().to_string()])
            .args(args)
            .stdin(Stdio::null())
            .stderr(stderr)
            .spawn()
            .map_err(BenchError::io(format!("start {}", exe.display())))?;
        let mut daemon = DaemonProcess {
            domain,
            child: Some(child),
        };
        let deadline = Instant::now() + Duration::from_secs(10);
        loop {
            match Client::connect(&daemon.domain) {
                Ok(_) => return Ok(daemon),
                Err(Error::NoDaemon { .. }) if Instant::now() < deadline => {
                    if !daemon.is_running() {
                        return Err(BenchError::Failed(format!(
                            "the daemon of {} exited at start (flags {args:?})",
                            daemon.domain
                        )));
                    }
                    std::thread::sleep(Duration::from_millis(20));
                }
                Err(e) => return Err(e.into()),
            }
        }
    }

    pub fn pid(&self) -> u32 {
        self.child.as_ref().map_or(0, |c| c.id())
    }

    /// Whether the daemon process still runs.
    pub fn is_running(&mut self) -> bool {
        self.child
            .as_mut()
            .is_some_and(|c| matches!(c.try_wait(), Ok(None)))
    }

    pub fn connect(&self) -> BenchResult<Client> {
        Ok(Client::connect(&self.domain)?)
    }
}

impl Drop for DaemonProcess {
    /// Stops the daemon (SIGINT, SIGKILL after 3 s), then removes whatever is left in the
    /// domain.
    fn drop(&mut self) {
        if let Some(mut child) = self.child.take() {
            // SAFETY: kill(2) on our own child's pid.
            unsafe { libc::kill(child.id() as i32, libc::SIGINT) };
            let deadline = Instant::now() + Duration::from_secs(3);
            while Instant::now() < deadline && matches!(child.try_wait(), Ok(None)) {
                std::thread::sleep(Duration::from_millis(10));
            }
            let _ = child.kill();
            let _ = child.wait();
        }
        let _ = physics_daemon::cleanup_domain(&self.domain);
    }
}

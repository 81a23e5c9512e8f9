//! Real daemon processes for the bench, each in a domain of its own, stopped and cleaned up
//! when dropped.

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
        let exe = client_sdk::daemon_executable();
        let domain = unique_domain(tag);
        let child = Command::new(&exe)
            .args(["--domain", &domain])
            .env("PHYSICS_LOG", "warn")
            .stdin(Stdio::null())
            .spawn()
            .map_err(BenchError::io(format!(
                "start {} (build it with cargo build --release --workspace --bins)",
                exe.display()
            )))?;
        let mut daemon = DaemonProcess {
            domain,
            child: Some(child),
        };
        let deadline = Instant::now() + Duration::from_secs(10);
        loop {
            match Client::connect(&daemon.domain) {
                Ok(_) => return Ok(daemon),
                Err(Error::NoDaemon { detail, .. }) if Instant::now() < deadline => {
                    if let Some(Ok(Some(status))) = daemon.child.as_mut().map(|c| c.try_wait()) {
                        return Err(BenchError::Failed(format!(
                            "daemon of domain {} exited with {status} ({detail})",
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

    pub fn connect(&self) -> BenchResult<Client> {
        Ok(Client::connect(&self.domain)?)
    }
}

impl Drop for DaemonProcess {
    /// SIGINT (a clean exit), SIGKILL after 3 s, then removal of whatever is left in the domain.
    fn drop(&mut self) {
        if let Some(mut child) = self.child.take() {
            // SAFETY: kill(2) on our own child.
            unsafe { libc::kill(child.id() as i32, libc::SIGINT) };
            let deadline = Instant::now() + Duration::from_secs(3);
            while Instant::now() < deadline && matches!(child.try_wait(), Ok(None)) {
                std::thread::sleep(Duration::from_millis(5));
            }
            let _ = child.kill();
            let _ = child.wait();
        }
        let _ = physics_daemon::cleanup_domain(&self.domain);
    }
}

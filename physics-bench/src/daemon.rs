//! Real daemon processes for the bench, each in a domain of its own, stopped and cleaned up
//! when dropped.

use std::path::Path;
use std::process::Stdio;
use std::sync::atomic::{AtomicU32, Ordering};
use std::time::{Duration, Instant};

use client_sdk::{Client, DaemonChild};

use super::error::{BenchError, BenchResult};

pub struct DaemonProcess {
    pub domain: String,
    child: Option<DaemonChild>,
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
        let (child, _) = client_sdk::start_daemon_with(&domain, args, stderr)?;
        Ok(DaemonProcess {
            domain,
            child: Some(child),
        })
    }

    pub fn pid(&self) -> u32 {
        self.child.as_ref().map_or(0, DaemonChild::pid)
    }

    /// Whether the daemon process still runs.
    pub fn is_running(&mut self) -> bool {
        self.child.as_mut().is_some_and(DaemonChild::is_running)
    }

    pub fn connect(&self) -> BenchResult<Client> {
        Ok(Client::connect(&self.domain)?)
    }

    /// Connects as the Luau host does: refusals reported by the next call into their
    /// plane, so a frame's flush sends its writes without waiting for the daemon.
    pub fn connect_as_game(&self) -> BenchResult<Client> {
        let mut options = client_sdk::ConnectOptions::new(&self.domain);
        options.refusals_at_next_call = true;
        Ok(Client::connect_with(options)?)
    }
}

impl Drop for DaemonProcess {
    /// Stops the daemon (SIGINT, SIGKILL after 3 s), then removes whatever is left in the
    /// domain.
    fn drop(&mut self) {
        drop(self.child.take());
        let _ = physics_daemon::cleanup_domain(&self.domain);
    }
}

/// Nanoseconds on a CPU so far of every thread of `pid` together (`/proc/PID/task/*/
/// schedstat`: nanoseconds, where `stat`'s clock ticks are 10 ms). The daemon's threads
/// live as long as it does, so a difference of two readings is what ran in between.
pub fn daemon_cpu_ns(pid: u32) -> BenchResult<u64> {
    let dir = format!("/proc/{pid}/task");
    let entries =
        std::fs::read_dir(&dir).map_err(|e| BenchError::Failed(format!("list {dir}: {e}")))?;
    let mut sum = 0u64;
    for entry in entries.flatten() {
        // A thread may end between the listing and the read: it is simply not counted.
        let Ok(stat) = std::fs::read_to_string(entry.path().join("schedstat")) else {
            continue;
        };
        sum += stat
            .split_whitespace()
            .next()
            .and_then(|v| v.parse::<u64>().ok())
            .unwrap_or(0);
    }
    Ok(sum)
}

/// Waits until the daemon is idle (under 2 % of a core over 10 ms, or half a second at
/// most): what a step put off (the copy made after it is answered, the drop of the oldest
/// copy on the disposal thread) is then done and counted in the block that caused it.
pub fn until_idle(pid: u32) -> BenchResult<()> {
    let started = Instant::now();
    let mut last = daemon_cpu_ns(pid)?;
    while started.elapsed() < Duration::from_millis(500) {
        std::thread::sleep(Duration::from_millis(10));
        let now = daemon_cpu_ns(pid)?;
        if now.saturating_sub(last) < 200_000 {
            return Ok(());
        }
        last = now;
    }
    Ok(())
}

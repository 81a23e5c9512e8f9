//! Real daemon processes for the bench, each in a domain of its own, stopped and cleaned up
//! when dropped.

use std::sync::atomic::{AtomicU32, Ordering};

use client_sdk::{Client, DaemonChild};

use super::error::BenchResult;

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
        let domain = unique_domain(tag);
        let (child, _) = client_sdk::start_daemon(&domain)?;
        Ok(DaemonProcess {
            domain,
            child: Some(child),
        })
    }

    pub fn pid(&self) -> u32 {
        self.child.as_ref().map_or(0, |c| c.pid())
    }

    pub fn connect(&self) -> BenchResult<Client> {
        Ok(Client::connect(&self.domain)?)
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

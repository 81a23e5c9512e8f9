//! Connect to the daemon of a domain, starting one as a child process when none answers.

use std::path::PathBuf;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use crate::{client::Client, error::Error};

/// A daemon started by this process; stopped (SIGINT, then waited for) when dropped.
pub struct DaemonChild {
    child: Child,
}

impl DaemonChild {
    /// Process id of the daemon.
    pub fn pid(&self) -> u32 {
        self.child.id()
    }

    /// Whether the daemon process still runs.
    pub fn is_running(&mut self) -> bool {
        matches!(self.child.try_wait(), Ok(None))
    }
}

impl Drop for DaemonChild {
    fn drop(&mut self) {
        interrupt_child(&mut self.child);
    }
}

/// Stops a child process of ours: SIGINT (so it can say goodbye), up to 3 s to exit, then
/// SIGKILL; reaped either way.
pub fn interrupt_child(child: &mut Child) {
    // SAFETY: plain kill(2) on our own child's pid.
    unsafe { libc::kill(child.id() as libc::pid_t, libc::SIGINT) };
    let deadline = Instant::now() + Duration::from_secs(3);
    while Instant::now() < deadline {
        if let Ok(Some(_)) = child.try_wait() {
            return;
        }
        std::thread::sleep(Duration::from_millis(10));
    }
    let _ = child.kill();
    let _ = child.wait();
}

/// The daemon executable: `$PHYSICS_DAEMON_BIN`, else `physics-daemon` next to the
/// current executable (cargo puts all workspace binaries together), else from `PATH`.
pub fn daemon_executable() -> PathBuf {
    sibling_executable("physics-daemon", "PHYSICS_DAEMON_BIN")
}

/// A workspace executable: `$env_var`, else `name` next to the current executable (or one
/// folder up, where cargo puts binaries beside its test and example folders), else `name`
/// from `PATH`.
pub fn sibling_executable(name: &str, env_var: &str) -> PathBuf {
    if let Some(p) = std::env::var_os(env_var) {
        return PathBuf::from(p);
    }
    if let Ok(exe) = std::env::current_exe() {
        for dir in exe.ancestors().skip(1).take(2) {
            let candidate = dir.join(name);
            if candidate.is_file() {
                return candidate;
            }
        }
    }
    PathBuf::from(name)
}

/// A client plus the daemon it started, if it had to. Dropping it says goodbye to the
/// daemon first, then stops the daemon it started (fields drop in declaration order).
pub struct Session {
    /// The connected client.
    pub client: Client,
    /// The daemon this session started, `None` when one was already running.
    pub daemon: Option<DaemonChild>,
}

impl std::ops::Deref for Session {
    type Target = Client;
    fn deref(&self) -> &Client {
        &self.client
    }
}

/// Connects to the daemon of `domain`; when none answers, starts one and connects to it.
pub fn connect_or_start(domain: &str) -> Result<Session, Error> {
    match Client::connect(domain) {
        Ok(client) => Ok(Session {
            client,
            daemon: None,
        }),
        Err(Error::NoDaemon { .. }) => {
            let (daemon, client) = start_daemon(domain)?;
            Ok(Session {
                client,
                daemon: Some(daemon),
            })
        }
        Err(e) => Err(e),
    }
}

/// Starts a daemon for `domain` as a child process and waits (up to 10 s) until it answers.
/// Returns it with a connected client. The daemon exits by itself once this process is gone
/// and no client is left (`--starter-pid`), so a starter killed without cleanup leaves no
/// daemon behind.
pub fn start_daemon(domain: &str) -> Result<(DaemonChild, Client), Error> {
    start_daemon_with(domain, &[], Stdio::inherit())
}

/// [`start_daemon`] with extra daemon flags (quotas) and where its stderr goes.
pub fn start_daemon_with(
    domain: &str,
    args: &[String],
    stderr: Stdio,
) -> Result<(DaemonChild, Client), Error> {
    let exe = daemon_executable();
    let child = Command::new(&exe)
        .arg("--domain")
        .arg(domain)
        .arg("--starter-pid")
        .arg(std::process::id().to_string())
        .args(args)
        .stdin(Stdio::null())
        .stderr(stderr)
        .spawn()
        .map_err(|e| Error::NoDaemon {
            domain: domain.to_string(),
            detail: format!("cannot start {}: {e}", exe.display()),
        })?;
    let mut child = DaemonChild { child };
    let deadline = Instant::now() + Duration::from_secs(10);
    loop {
        match Client::connect(domain) {
            Ok(client) => return Ok((child, client)),
            Err(Error::NoDaemon { detail, .. }) if Instant::now() < deadline => {
                if let Ok(Some(status)) = child.child.try_wait() {
                    return Err(Error::NoDaemon {
                        domain: domain.to_string(),
                        detail: format!("the started daemon exited with {status} ({detail})"),
                    });
                }
                std::thread::sleep(Duration::from_millis(20));
            }
            Err(e) => return Err(e),
        }
    }
}

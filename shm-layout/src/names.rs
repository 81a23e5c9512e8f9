//! Domains and service names.
//!
//! A domain isolates one deployment: every iceoryx2 resource of the domain carries the
//! prefix [`prefix`], so tests in different domains run side by side and a test can check
//! that nothing of its domain is left behind.

use iceoryx2::config::Config;
use iceoryx2::prelude::{FileName, SemanticString, ServiceName};

use crate::ids::PlaneId;
use crate::version::LAYOUT_VERSION;

/// The domain used when neither `--domain` nor [`DOMAIN_ENV`] names one.
pub const DEFAULT_DOMAIN: &str = "physics";
/// Environment variable naming the domain when no `--domain` is given.
pub const DOMAIN_ENV: &str = "PHYSICS_DOMAIN";
/// iceoryx2 node name of the daemon.
pub const DAEMON_NODE_NAME: &str = "physics-daemon";

/// A domain name that cannot be used.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("invalid domain {domain:?}: {reason}")]
pub struct DomainError {
    /// The refused domain name.
    pub domain: String,
    /// What is wrong with it.
    pub reason: &'static str,
}

/// Checks a domain name: 1 to 32 characters of `[A-Za-z0-9_-]`.
pub fn validate_domain(domain: &str) -> Result<(), DomainError> {
    let err = |reason| {
        Err(DomainError {
            domain: domain.to_string(),
            reason,
        })
    };
    if domain.is_empty() || domain.len() > 32 {
        return err("must be 1 to 32 characters long");
    }
    if !domain
        .bytes()
        .all(|b| b.is_ascii_alphanumeric() || b == b'_' || b == b'-')
    {
        return err("may only contain letters, digits, '_' and '-'");
    }
    Ok(())
}

/// The file prefix of every shared-memory and socket resource of the domain.
pub fn prefix(domain: &str) -> String {
    format!("phys_{domain}_")
}

/// Environment variable naming the directory that holds the domain's sockets and node
/// records (it must belong to the user and be writable by nobody else).
pub const RUNTIME_DIR_ENV: &str = "PHYSICS_RUNTIME_DIR";

/// The directory of the domain's sockets and node records, one that another local user
/// cannot have created: `$PHYSICS_RUNTIME_DIR/iceoryx2/` when set; else
/// `$XDG_RUNTIME_DIR/iceoryx2/` when that names a directory of this user that nobody else may
/// write (the login manager makes `/run/user/UID` so, mode 0700); else
/// `/dev/shm/iceoryx2-UID/` (or `/tmp/iceoryx2-UID/` without a `/dev/shm`), which any user
/// could create first (the daemon then refuses to start and says so).
///
/// The fallback is memory, not disk: iceoryx2 fsyncs every service description it writes
/// (a plane's output, a client's reply event), which on a disk held the daemon's request
/// loop ~30 ms each time a client came or went.
pub fn root_path() -> String {
    if let Some(dir) = std::env::var_os(RUNTIME_DIR_ENV).filter(|d| !d.is_empty()) {
        return format!("{}/iceoryx2/", dir.to_string_lossy().trim_end_matches('/'));
    }
    // SAFETY: getuid(2) cannot fail and has no side effects.
    let uid = unsafe { libc::getuid() };
    if let Some(dir) = std::env::var_os("XDG_RUNTIME_DIR").filter(|d| !d.is_empty()) {
        if private_dir_of(std::path::Path::new(&dir), uid) {
            return format!("{}/iceoryx2/", dir.to_string_lossy().trim_end_matches('/'));
        }
    }
    if std::path::Path::new("/dev/shm").is_dir() {
        return format!("/dev/shm/iceoryx2-{uid}/");
    }
    format!("/tmp/iceoryx2-{uid}/")
}

/// Whether `dir` is a directory (not a link) of user `uid` that no other user may write.
fn private_dir_of(dir: &std::path::Path, uid: u32) -> bool {
    use std::os::unix::fs::MetadataExt;
    std::fs::symlink_metadata(dir)
        .is_ok_and(|m| m.is_dir() && m.uid() == uid && m.mode() & 0o022 == 0)
}

/// The iceoryx2 configuration of a domain.
pub fn config(domain: &str) -> Result<Config, DomainError> {
    validate_domain(domain)?;
    let unusable = || DomainError {
        domain: domain.to_string(),
        reason: "is not usable as a file name",
    };
    let mut config = Config::default();
    config.global.prefix = FileName::new(prefix(domain).as_bytes()).map_err(|_| unusable())?;
    let root = iceoryx2::prelude::Path::new(root_path().as_bytes()).map_err(|_| unusable())?;
    config.global.set_root_path(&root);
    // The domain's node records in a directory of their own: listing the domain's nodes
    // (the daemon's resource guard and liveness checks do it every period) then reads only
    // this domain's entries, not every node of every domain on the machine.
    config.global.node.directory =
        iceoryx2::prelude::Path::new(node_directory(domain).as_bytes()).map_err(|_| unusable())?;
    Ok(config)
}

/// The domain's node directory under the root path (iceoryx2's `global.node.directory`).
pub fn node_directory(domain: &str) -> String {
    format!("nodes/{}", prefix(domain))
}

fn service(name: String) -> ServiceName {
    ServiceName::new(&name).expect("service names built here are valid")
}

/// Request-response service carrying command batches.
pub fn control() -> ServiceName {
    service("physics/control".into())
}

/// Event the clients notify after sending a request; the daemon waits on it.
pub fn control_wake() -> ServiceName {
    service("physics/control/wake".into())
}

/// Event the daemon notifies when a reply for `client` is ready.
pub fn client_wake(client: u128) -> ServiceName {
    service(format!("physics/client/{client:032x}/wake"))
}

/// Publish-subscribe `[BodyState]` with a `TickHeader` user header.
pub fn plane_bodies(plane: PlaneId) -> ServiceName {
    service(format!("physics/v{LAYOUT_VERSION}/plane/{plane}/bodies"))
}

/// Publish-subscribe `[EventRecord]` with a `TickHeader` user header.
pub fn plane_events(plane: PlaneId) -> ServiceName {
    service(format!("physics/v{LAYOUT_VERSION}/plane/{plane}/events"))
}

/// Publish-subscribe `u64`: the daemon's heartbeat counter, sent a few times a second by a
/// thread of its own, so clients tell a stopped or hung daemon from a slow request.
pub fn heartbeat() -> ServiceName {
    service("physics/heartbeat".into())
}

/// Event notified after every published tick of the plane.
pub fn plane_tick(plane: PlaneId) -> ServiceName {
    service(format!("physics/plane/{plane}/tick"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn domains_are_validated() {
        assert!(validate_domain("physics").is_ok());
        assert!(validate_domain("t-12_ab").is_ok());
        assert!(validate_domain("").is_err());
        assert!(validate_domain("a/b").is_err());
        assert!(validate_domain(&"x".repeat(33)).is_err());
        let e = validate_domain("a b").unwrap_err().to_string();
        assert!(e.contains("\"a b\""), "{e}");
    }

    #[test]
    fn config_carries_the_prefix() {
        let c = config("unit").unwrap();
        assert_eq!(c.global.prefix.to_string(), "phys_unit_");
        // Each domain lists only its own nodes.
        assert!(c
            .global
            .node_dir()
            .to_string()
            .ends_with("/nodes/phys_unit_"));
        assert_ne!(
            c.global.node_dir(),
            config("other").unwrap().global.node_dir()
        );
    }
}

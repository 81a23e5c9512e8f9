//! The domain's files under /dev/shm and its per-user root directory: no file of a domain is
//! writable by another user. iceoryx2 creates its node-counter segment (`*.global_mgmt`)
//! world-writable; the daemon narrows it to its owner, and refuses to start, with a message
//! naming the file and its owner, when another user planted files of the domain (which
//! would otherwise break every node of the domain with `UnableToGenerateUniqueNodeId`).

use std::os::unix::fs::{MetadataExt, PermissionsExt};
use std::path::PathBuf;

use shm_layout::names;

use crate::DaemonError;

/// The domain's files (and the root directory) owned by another user.
pub fn foreign(domain: &str) -> Vec<(PathBuf, u32)> {
    // SAFETY: getuid(2) cannot fail and has no side effects.
    let me = unsafe { libc::getuid() };
    let mut found = Vec::new();
    let root = PathBuf::from(names::root_path());
    if let Ok(meta) = std::fs::metadata(&root) {
        if meta.uid() != me {
            found.push((root, meta.uid()));
        }
    }
    for path in domain_files(domain) {
        if let Ok(meta) = std::fs::symlink_metadata(&path) {
            if meta.uid() != me {
                found.push((path, meta.uid()));
            }
        }
    }
    found
}

/// Fails with a clear error when another user owns files of the domain or its root
/// directory: it names the file, its owner and a way out.
pub fn check_ownership(domain: &str) -> Result<(), DaemonError> {
    let Some((path, uid)) = foreign(domain).into_iter().next() else {
        return Ok(());
    };
    let root = PathBuf::from(names::root_path());
    let is_root = path == root || path.starts_with(&root) && path.is_dir();
    let (what, way_out) = if is_root {
        (
            "the root directory",
            format!(
                "have root remove it, or set {} (or XDG_RUNTIME_DIR) to a directory only you \
                 can write, e.g. `mkdir -m 700 ~/.physics && export {}=~/.physics`",
                names::RUNTIME_DIR_ENV,
                names::RUNTIME_DIR_ENV
            ),
        )
    } else {
        (
            "a file",
            "have that user or root remove it, or use another domain (--domain): /dev/shm is \
             one namespace for every user, and a domain name others cannot guess cannot be \
             taken"
                .to_string(),
        )
    };
    Err(DaemonError::ForeignFiles {
        domain: domain.to_string(),
        path: path.display().to_string(),
        uid,
        owner: user_name(uid).unwrap_or_else(|| "unknown user".to_string()),
        what,
        way_out,
    })
}

/// The name of user `uid` from /etc/passwd.
fn user_name(uid: u32) -> Option<String> {
    let passwd = std::fs::read_to_string("/etc/passwd").ok()?;
    passwd.lines().find_map(|line| {
        let mut fields = line.split(':');
        let name = fields.next()?;
        let id: u32 = fields.nth(1)?.parse().ok()?;
        (id == uid).then(|| name.to_string())
    })
}

/// Takes write access to the domain's files away from everyone but their owner.
pub fn restrict(domain: &str) {
    let root = PathBuf::from(names::root_path());
    for path in std::iter::once(root).chain(domain_files(domain)) {
        let Ok(meta) = std::fs::symlink_metadata(&path) else {
            continue;
        };
        let mode = meta.permissions().mode();
        if meta.file_type().is_symlink() || mode & 0o022 == 0 {
            continue;
        }
        let narrowed = mode & !0o077;
        if let Err(e) = std::fs::set_permissions(&path, PermissionsExt::from_mode(narrowed)) {
            tracing::warn!(path = %path.display(), "cannot restrict permissions: {e}");
        }
    }
}

/// Every file of `domain` under /dev/shm and the per-user root directory (sockets, node
/// records, service descriptions), at any depth.
pub fn domain_files(domain: &str) -> Vec<PathBuf> {
    let prefix = names::prefix(domain);
    let mut found = Vec::new();
    let shm = PathBuf::from("/dev/shm");
    let root = PathBuf::from(names::root_path());
    // A root inside /dev/shm is walked with it.
    let mut dirs = if root.starts_with(&shm) {
        vec![shm]
    } else {
        vec![shm, root]
    };
    while let Some(dir) = dirs.pop() {
        let Ok(entries) = std::fs::read_dir(&dir) else {
            continue;
        };
        for entry in entries.flatten() {
            let path = entry.path();
            if entry.file_type().is_ok_and(|t| t.is_dir()) {
                dirs.push(path);
            } else if entry.file_name().to_string_lossy().starts_with(&prefix) {
                found.push(path);
            }
        }
    }
    found
}

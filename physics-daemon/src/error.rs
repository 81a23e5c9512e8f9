//! The failures of the daemon as a whole (not of one command).

/// Failures of the daemon as a whole (not of one command).
#[derive(Debug, thiserror::Error)]
pub enum DaemonError {
    /// The domain name is not usable.
    #[error("invalid domain: {0}")]
    Domain(#[from] shm_layout::names::DomainError),
    /// Another daemon serves the domain.
    #[error("another physics daemon is already serving domain {domain:?}")]
    AlreadyRunning {
        /// The domain.
        domain: String,
    },
    /// Another user owns files of the domain (planted or left behind): no node of the
    /// domain could start safely.
    #[error(
        "another user ({owner}, uid {uid}) owns {path}, {what} of domain {domain:?}: {way_out}"
    )]
    ForeignFiles {
        /// The domain.
        domain: String,
        /// The file.
        path: String,
        /// Its owner.
        uid: u32,
        /// The owner's user name (or "unknown user").
        owner: String,
        /// "a file" or "the root directory".
        what: &'static str,
        /// What to do about it.
        way_out: String,
    },
    /// iceoryx2 failed.
    #[error("shared-memory transport: {0}")]
    Ipc(String),
}

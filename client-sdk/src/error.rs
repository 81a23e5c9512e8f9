//! The error type of every client operation.

use shm_layout::CommandError;

/// Why a client operation failed.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// No daemon answers in the domain (none runs, or one could not be started).
    #[error("no physics daemon is serving domain {domain:?} ({detail})")]
    NoDaemon {
        /// The domain that was tried.
        domain: String,
        /// What went wrong.
        detail: String,
    },
    /// The daemon this client was connected to no longer exists.
    #[error(
        "the physics daemon of domain {domain:?} is gone (process {pid} exited or was killed)"
    )]
    DaemonGone {
        /// The domain of the daemon.
        domain: String,
        /// Process id of the daemon.
        pid: u32,
    },
    /// The daemon speaks another layout version; the message names both versions.
    #[error("{0}")]
    VersionMismatch(String),
    /// The daemon refused a command.
    #[error("{0}")]
    Command(#[from] CommandError),
    /// Some commands of a flushed batch failed; the others were applied.
    #[error("{} command(s) of the batch failed; first: {}", .0.len(), .0[0])]
    Batch(Vec<CommandError>),
    /// Writes queued earlier were refused by the daemon after the call that queued them
    /// returned ([`ConnectOptions::refusals_at_next_call`](crate::client::ConnectOptions)): reported
    /// by the next call into their plane instead of being lost or ending a frame. Each
    /// message names the write and, when the host recorded it, the line that made it.
    #[error("{}", refused_text(.0))]
    Refused(Vec<CommandError>),
    /// A value was refused before anything was sent.
    #[error("invalid {field}: {message}")]
    Invalid {
        /// The field or property that was refused.
        field: String,
        /// Why it was refused.
        message: String,
    },
    /// No reply, or no new tick, came within the given time.
    #[error("timed out after {0:?}")]
    Timeout(std::time::Duration),
    /// The daemon process exists but its heartbeat stopped while a request waited: it is
    /// stopped (SIGSTOP) or hung, not merely slow.
    #[error(
        "the physics daemon of domain {domain:?} (process {pid}) is stalled: no heartbeat for \
         {silent:.1?} while a request waited (stopped or hung)"
    )]
    Stalled {
        /// The domain.
        domain: String,
        /// The daemon's process id.
        pid: u32,
        /// How long the heartbeat has been silent.
        silent: std::time::Duration,
    },
    /// The shared-memory transport failed.
    #[error("shared-memory transport: {0}")]
    Ipc(String),
    /// The daemon's reply could not be decoded or was not the one expected.
    #[error("protocol: {0}")]
    Protocol(String),
    /// The cluster transport (Zenoh) failed or was given unusable settings; the message
    /// names the setting.
    #[error("cluster: {0}")]
    Cluster(String),
}

fn refused_text(errors: &[CommandError]) -> String {
    let first = errors.first().map(|e| e.message.as_str()).unwrap_or("");
    match errors.len() {
        1 => format!("an earlier write was refused: {first}"),
        n => format!("{n} earlier writes were refused; first: {first}"),
    }
}

impl Error {
    /// A value the shared checks refused before it was sent (they name the field).
    pub(crate) fn invalid_value(e: CommandError) -> Error {
        match &e.field {
            Some(field) => Error::Invalid {
                field: field.clone(),
                message: e.detail().to_string(),
            },
            None => Error::Command(e),
        }
    }

    pub(crate) fn ipc(what: &str, e: impl core::fmt::Debug) -> Error {
        Error::Ipc(format!("{what}: {e:?}"))
    }
}

impl From<local_transport::TransportError> for Error {
    fn from(e: local_transport::TransportError) -> Error {
        use local_transport::TransportError;
        match e {
            TransportError::NoDaemon { domain, detail } => Error::NoDaemon { domain, detail },
            TransportError::InvalidDomain(message) => Error::Invalid {
                field: "domain".into(),
                message,
            },
            TransportError::Ipc(message) => Error::Ipc(message),
        }
    }
}

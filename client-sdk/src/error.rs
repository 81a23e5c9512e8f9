use shm_layout::CommandError;

#[derive(Debug, thiserror::Error)]
pub enum Error {
    #[error("no physics daemon is serving domain {domain:?} ({detail})")]
    NoDaemon { domain: String, detail: String },
    #[error(
        "the physics daemon of domain {domain:?} is gone (process {pid} exited or was killed)"
    )]
    DaemonGone { domain: String, pid: u32 },
    #[error("{0}")]
    VersionMismatch(String),
    #[error("{0}")]
    Command(#[from] CommandError),
    /// Some commands of a flushed batch failed; the others were applied.
    #[error("{} command(s) of the batch failed; first: {}", .0.len(), .0[0])]
    Batch(Vec<CommandError>),
    #[error("invalid {field}: {message}")]
    Invalid { field: String, message: String },
    #[error("timed out after {0:?}")]
    Timeout(std::time::Duration),
    #[error("shared-memory transport: {0}")]
    Ipc(String),
    #[error("protocol: {0}")]
    Protocol(String),
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

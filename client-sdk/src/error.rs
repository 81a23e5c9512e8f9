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
    /// A value the shared checks refused before it was sent. Their messages start with the
    /// field's name.
    pub(crate) fn invalid_value(e: CommandError) -> Error {
        let (field, message) = e
            .message
            .split_once(' ')
            .unwrap_or((e.message.as_str(), ""));
        Error::Invalid {
            field: field.into(),
            message: message.into(),
        }
    }

    pub(crate) fn ipc(what: &str, e: impl core::fmt::Debug) -> Error {
        Error::Ipc(format!("{what}: {e:?}"))
    }
}

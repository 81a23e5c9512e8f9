//! One error type for the bench: every failure names what was being done.

use shm_layout::CommandError;

#[derive(Debug, thiserror::Error)]
pub enum BenchError {
    #[error("client: {0}")]
    Client(#[from] client_sdk::Error),
    #[error("daemon: {0}")]
    Daemon(#[from] physics_daemon::DaemonError),
    #[error("in-process plane: {0}")]
    Plane(#[from] CommandError),
    #[error("{what}: {source}")]
    Io {
        what: String,
        source: std::io::Error,
    },
    #[error("{0}")]
    Failed(String),
}

impl BenchError {
    pub fn io(what: impl Into<String>) -> impl FnOnce(std::io::Error) -> BenchError {
        let what = what.into();
        move |source| BenchError::Io { what, source }
    }
}

pub type BenchResult<T> = Result<T, BenchError>;

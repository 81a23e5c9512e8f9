//! The physics daemon: owns every plane of a domain, steps them, publishes their body states
//! into shared memory and serves command batches from client processes.
//!
//! - [`server`]: the iceoryx2 node, the WaitSet loop and request dispatch.
//! - [`clients`]: who is connected, and noticing clients that died.
//! - [`plane`]: one rapier world with stable handles and the plane options.
//! - [`publish`]: writing a plane's tick into loaned shared-memory samples.

pub mod clients;
pub mod plane;
pub mod publish;
pub mod server;

pub use server::{cleanup_domain, run, wake, Daemon};

#[derive(Debug, thiserror::Error)]
pub enum DaemonError {
    #[error("invalid domain: {0}")]
    Domain(#[from] shm_layout::names::DomainError),
    #[error("another physics daemon is already serving domain {domain:?}")]
    AlreadyRunning { domain: String },
    #[error("shared-memory transport: {0}")]
    Ipc(String),
}

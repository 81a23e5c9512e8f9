//! The physics daemon: owns every plane of a domain, steps them, publishes their body states
//! into shared memory and serves command batches from client processes.
//!
//! - [`server`]: the iceoryx2 node, the WaitSet loop, clients, and routing by plane id.
//! - [`backend`]: the seam every plane kind implements, and the reusable [`backend::SlotTable`].
//! - [`rapier3d`]: the 3D plane kind (a rapier world with stable handles and the options).
//! - `rapier2d`: the 2D GUI plane kind (`PhysicsService.NewGUI`), behind the `gui` feature.
//! - `gpu`: the GPU path of 3D planes (`DeferGpu`, wgpu compute), behind the `gpu` feature.
//! - [`publish`]: writing a plane's tick into loaned shared-memory samples.
//! - [`cluster`]: joining a physics cluster over Zenoh (`--cluster`).

#![deny(missing_docs)]

pub mod backend;
pub mod cluster;
#[cfg(feature = "gpu")]
pub mod gpu;
pub mod kinds;
pub mod publish;
#[cfg(feature = "gui")]
pub mod rapier2d;
pub mod rapier3d;
pub mod server;

pub use server::{cleanup_domain, run, wake, Daemon};

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

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
//! - [`record`]: recording a plane to a file that replays it bit for bit.

#![deny(missing_docs)]

pub mod backend;
pub mod cluster;
mod error;
#[cfg(feature = "gpu")]
pub mod gpu;
pub mod kinds;
pub mod publish;
#[cfg(feature = "gui")]
pub mod rapier2d;
pub mod rapier3d;
pub mod record;
pub mod server;

pub use error::DaemonError;
pub use server::{cleanup_domain, run, wake, Daemon};

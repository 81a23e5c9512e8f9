//! The rapier3d backend: one 3D plane is a rapier world, the slot table that gives bodies
//! stable handles, and the plane options. No I/O here: the server hands it ops and the
//! publisher writes what it reports.
//!
//! Layers, lowest first (a file imports only files of its own layer's parts or below):
//! - the parts' state and the free functions over it: `objects/` (`objects/mod.rs`: the
//!   objects' part, the slot table's bodies with their tallies, the body pass's buffers and
//!   the pending map; parts, the body pass, forces, speed limits, maps), `joints/` (joint table,
//!   motors, articulations), `contacts/` (the event log, contact hooks and figures, thin
//!   colliders, clipped and capsule contacts), `history/` (the history part: state hash,
//!   pose mirror, publishing, the rollback ring), `queries/mod.rs` (the queries' part: the
//!   collision-group table and the bodies a query must first bring up to date),
//!   `controllers` (character controllers), `adaptive` (extra substeps);
//! - `plane`: the [`Plane`] over them, its state for snapshots and its step;
//! - the `impl Plane` files that nothing imports: `options` (creation, plane options),
//!   `backend` (op routing), `solver`, `offload`, and in the parts' folders `objects/ops.rs`,
//!   `objects/properties.rs`, `joints/ops.rs`, `contacts/events.rs`, `queries/`,
//!   `history/snapshot.rs`, `history/rewind.rs`, `controllers/ops.rs`, ...

mod adaptive;
mod backend;
mod contacts;
mod controllers;
mod history;
mod joints;
mod objects;
mod offload;
mod options;
mod plane;
mod queries;
mod solver;

#[cfg(test)]
mod ccd_tests;
#[cfg(test)]
mod stack_tests;
#[cfg(test)]
mod unstepped;

pub use history::gpu_saved::GpuSaved;
pub use objects::object::MAX_SLOTS;
pub use offload::{no_other_engine, DeferHook, SimpleBody, SimplePose};
pub use plane::Plane;

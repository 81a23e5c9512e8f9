//! The plane's history: what it publishes (`pose_mirror`: every slot's state as the last
//! step left it, and the state hash; `publish`: writing a sample), what it keeps for Rewind
//! (`rollback`) and its snapshots. `rewind.rs` and `snapshot.rs` are the plane's
//! `impl Plane` side; the others know no plane.

pub(super) mod gpu_saved;
pub(super) mod pose_mirror;
pub(super) mod publish;
mod rewind;
pub(super) mod rollback;
pub(super) mod snapshot;

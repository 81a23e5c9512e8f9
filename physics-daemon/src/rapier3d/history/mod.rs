//! The plane's history: what it publishes (`pose_mirror`: every slot's state as the last
//! step left it, and the state hash; `publish`: writing a sample), what it keeps for Rewind
//! (`rollback`) and its snapshots. [`History`] is the part's state (the hash, the mirror
//! and the ring); `rewind.rs` and `snapshot.rs` are the plane's `impl Plane` side; the
//! others know no plane.

pub(super) mod gpu_saved;
pub(super) mod pose_mirror;
pub(super) mod publish;
mod rewind;
pub(super) mod rollback;
pub(super) mod snapshot;

use crate::backend::rollback::{Duplicate, Ring};
use crate::rapier3d::history::pose_mirror::PoseMirror;

/// The plane's history part (`S`: the plane's state): the state hash and the pose mirror
/// of the last step, and the states kept for Rewind. Its fields are private to this folder
/// (`rewind.rs` and `snapshot.rs` reach them) but the hash, which the plane snapshots.
pub(crate) struct History<S> {
    /// [`StateHasher`](shm_layout::StateHasher) over every slot as the last step left it (the
    /// tick header's; snapshot state, named in the plane's `plane_state!`).
    pub(in crate::rapier3d) state_hash: u64,
    /// States of the last ticks while RollbackTicks > 0 (see `rollback`).
    rollback: Ring<S>,
    /// Every slot's state as the last step left it, for the publisher (see `pose_mirror`).
    mirror: PoseMirror,
}

impl<S: Duplicate + Send + 'static> Default for History<S> {
    fn default() -> Self {
        History {
            state_hash: 0,
            rollback: Ring::dropping_off_thread(),
            mirror: PoseMirror::default(),
        }
    }
}

impl<S: Duplicate + Send + 'static> History<S> {
    /// The state hash as the last step left it.
    pub(crate) fn hash(&self) -> u64 {
        self.state_hash
    }

    /// The pose mirror (what a sample is written from).
    pub(crate) fn mirror(&self) -> &PoseMirror {
        &self.mirror
    }

    /// The pose mirror, to update after a step.
    pub(crate) fn mirror_mut(&mut self) -> &mut PoseMirror {
        &mut self.mirror
    }

    /// An op changed slots without marking them (every body woken, the collision groups
    /// replaced, a pose from another engine): the mirror's copy of the states is stale.
    pub(crate) fn forget_poses(&mut self) {
        self.mirror.forget();
    }

    /// A step ended with the state hash `hash` (`None`: unchanged); its tick is to be kept
    /// for Rewind (off the tick's path: see `rollback`).
    pub(crate) fn stepped(&mut self, hash: Option<u64>) {
        if let Some(hash) = hash {
            self.state_hash = hash;
        }
        self.rollback.note_step();
    }

    /// Another engine stepped the plane and left the state hash `hash`.
    pub(crate) fn stepped_elsewhere(&mut self, hash: u64) {
        self.state_hash = hash;
    }
}

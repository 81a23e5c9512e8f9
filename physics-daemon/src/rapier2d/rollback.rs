//! Rollback on GUI planes (`RollbackTicks = K`, `PlaneOp::Rewind(n)`), as on 3D planes
//! (`rapier3d/history/`): with K > 0 the plane keeps its state after each of its last K
//! ticks (an in-memory copy each, counted in the owner's state bytes) and can go back n ≤ K
//! ticks; the script then re-applies corrected inputs and steps again. With K = 0 (the
//! default) nothing is kept and a step pays nothing. The ticks are kept in a
//! [`Ring`](crate::backend::rollback::Ring), right after each step, and dropped in place.

use shm_layout::{CommandError, Reply};

use super::plane::Plane;
use crate::backend::counted::CountedBytes;

/// What one kept tick is counted as per object slot (a GUI body's copy, its collider and
/// contacts: about half a 3D one's).
const BYTES_PER_SLOT: u64 = 768;

impl Plane {
    /// After a step: keeps the state of the new tick when RollbackTicks > 0.
    pub(super) fn keep_for_rollback(&mut self) {
        let k = self.rollback_ticks as usize;
        if k == 0 {
            if !self.rollback.is_empty() {
                self.rollback.clear();
            }
            return;
        }
        let copy = Box::new(self.clone_state());
        let counted = CountedBytes::new(
            &self.state_bytes,
            BYTES_PER_SLOT * self.bodies.slot_count() as u64,
        );
        self.rollback.keep(self.clock.tick, copy, counted, k);
    }

    /// Goes back `n` ticks (1 ≤ n ≤ RollbackTicks and ticks kept so far). The state of the
    /// tick gone back to stays kept (a second rewind to it works); later ones are dropped.
    pub(super) fn rewind(&mut self, n: u32) -> Result<Reply, CommandError> {
        let now = self.clock.tick;
        if let Some(copy) = self
            .rollback
            .rewind(self.rollback_ticks, n, now, "the GUI plane")?
        {
            self.adopt_copy(copy)?;
        }
        Ok(Reply::Applied {
            tick: self.clock.tick,
        })
    }
}

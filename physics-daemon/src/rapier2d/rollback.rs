//! Rollback on GUI planes (`RollbackTicks = K`, `PlaneOp::Rewind(n)`), as on 3D planes
//! (`rapier3d/rollback.rs`): with K > 0 the plane keeps its state after each of its last K
//! ticks (an in-memory copy each, counted in the owner's state bytes) and can go back n ≤ K
//! ticks; the script then re-applies corrected inputs and steps again. With K = 0 (the
//! default) nothing is kept and a step pays nothing.

use std::collections::VecDeque;

use shm_layout::{CommandError, Reply};

use super::snapshot::State;
use super::Plane;
use crate::backend::counted::CountedBytes;

/// What one kept tick is counted as per object slot (a GUI body's copy, its collider and
/// contacts: about half a 3D one's).
const BYTES_PER_SLOT: u64 = 768;

/// The kept states, oldest first.
#[derive(Default)]
pub(super) struct Ring {
    kept: VecDeque<(u64, Box<State>, CountedBytes)>,
}

impl Ring {
    /// Forgets every kept state.
    pub fn clear(&mut self) {
        self.kept.clear();
    }
}

impl Plane {
    /// After a step: keeps the state of the new tick when RollbackTicks > 0.
    pub(super) fn keep_for_rollback(&mut self) {
        let k = self.rollback_ticks as usize;
        if k == 0 {
            if !self.rollback.kept.is_empty() {
                self.rollback.clear();
            }
            return;
        }
        let copy = Box::new(self.clone_state());
        let counted = CountedBytes::new(
            &self.state_bytes,
            BYTES_PER_SLOT * self.bodies.slot_count() as u64,
        );
        self.rollback
            .kept
            .push_back((self.clock.tick, copy, counted));
        while self.rollback.kept.len() > k + 1 {
            self.rollback.kept.pop_front();
        }
    }

    /// Goes back `n` ticks (1 ≤ n ≤ RollbackTicks and ticks kept so far). The state of the
    /// tick gone back to stays kept (a second rewind to it works); later ones are dropped.
    pub(super) fn rewind(&mut self, n: u32) -> Result<Reply, CommandError> {
        let k = self.rollback_ticks;
        if k == 0 {
            return Err(CommandError::invalid_field(
                "Rewind",
                "Rewind needs RollbackTicks > 0 (set it when creating the GUI plane or before \
                 the ticks to go back over)",
            ));
        }
        if n == 0 {
            return Ok(Reply::Applied {
                tick: self.clock.tick,
            });
        }
        let at = self.clock.tick.checked_sub(n as u64).and_then(|t| {
            self.rollback
                .kept
                .iter()
                .position(|(tick, _, _)| *tick == t)
        });
        let (Some(at), true) = (at, n <= k) else {
            let oldest = self
                .rollback
                .kept
                .front()
                .map_or(self.clock.tick, |(t, _, _)| *t);
            return Err(CommandError::invalid_field(
                "Rewind",
                format!(
                    "Rewind({n}) goes further back than the plane keeps: RollbackTicks = {k}, \
                     ticks {oldest} to {} kept",
                    self.clock.tick
                ),
            ));
        };
        self.rollback.kept.truncate(at + 1);
        let copy = self.rollback.kept[at].1.duplicate();
        self.adopt_copy(copy)?;
        Ok(Reply::Applied {
            tick: self.clock.tick,
        })
    }
}

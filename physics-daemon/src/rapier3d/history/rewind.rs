//! Rollback's side of the plane: keeping its state after each tick in the ring (see
//! `rollback`) and going back to one of them (`PlaneOp::Rewind`).

use shm_layout::{CommandError, Reply};

use crate::backend::counted::CountedBytes;
use crate::rapier3d::history::rollback::BYTES_PER_SLOT;
use crate::rapier3d::plane::Plane;

impl Plane {
    /// Keeps the last step's tick if that is still to be done: before anything changes the
    /// plane, and when the worker is idle.
    pub(in crate::rapier3d) fn finish_keep(&mut self) -> Result<(), CommandError> {
        if self.history.rollback.take_pending() {
            self.keep_for_rollback()?;
        }
        Ok(())
    }

    /// Whether a stepped tick is yet to be kept.
    pub(in crate::rapier3d) fn keep_pending(&self) -> bool {
        let ring = &self.history.rollback;
        ring.pending() && (self.settings.rollback_ticks > 0 || !ring.is_empty())
    }

    /// After a step: keeps the state of the new tick when RollbackTicks > 0.
    fn keep_for_rollback(&mut self) -> Result<(), CommandError> {
        let k = self.settings.rollback_ticks as usize;
        if k == 0 {
            if !self.history.rollback.is_empty() {
                self.history.rollback.clear();
            }
            return Ok(());
        }
        let copy = Box::new(self.clone_state());
        let counted = CountedBytes::new(
            &self.state_bytes,
            BYTES_PER_SLOT * self.objects.slot_count() as u64,
        );
        self.history
            .rollback
            .keep(self.clock.tick, copy, counted, k);
        Ok(())
    }

    /// Goes back `n` ticks (1 ≤ n ≤ RollbackTicks and ticks kept so far). The state of the
    /// tick gone back to stays kept (a second rewind to it works); later ones are dropped.
    pub(in crate::rapier3d) fn rewind(&mut self, n: u32) -> Result<Reply, CommandError> {
        let k = self.settings.rollback_ticks;
        let now = self.clock.tick;
        if let Some(copy) = self.history.rollback.rewind(k, n, now, "the plane")? {
            self.adopt_copy(copy)?;
        }
        Ok(Reply::Applied {
            tick: self.clock.tick,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::backend::Backend;
    use shm_layout::{PlaneOp, PlaneProp, Pose, Shape};

    fn falling(k: u32) -> Plane {
        let mut plane = Plane::new(1, &[PlaneProp::RollbackTicks(k)]).unwrap();
        for i in 0..4 {
            plane
                .apply(PlaneOp::AddObject {
                    shape: Shape::Cube { size: [1.0; 3] },
                    pose: Pose::at([0.0, 1.0 + 1.1 * i as f32, 0.0]),
                    props: vec![],
                })
                .unwrap();
        }
        plane
    }

    /// The copy a step puts off is made by whatever comes first (the worker's idle work, the
    /// next step, an op): the kept ticks are the same either way, and a rewind finds them.
    #[test]
    fn a_deferred_keep_keeps_the_same_ticks_whoever_makes_it() {
        let dt = 1.0 / 60.0;
        let mut idle = falling(3);
        let mut busy = falling(3);
        let mut hashes = Vec::new();
        for _ in 0..5 {
            idle.step(dt).unwrap();
            assert!(idle.has_idle_work());
            idle.idle_work().unwrap();
            assert!(!idle.has_idle_work());
            busy.step(dt).unwrap();
            assert_eq!(idle.history.state_hash, busy.history.state_hash);
            hashes.push(idle.history.state_hash);
        }
        // `busy` kept its ticks at each next step; its last is kept by the rewind itself.
        assert!(busy.has_idle_work());
        for plane in [&mut idle, &mut busy] {
            assert_eq!(
                plane.apply(PlaneOp::Rewind(2)).unwrap(),
                Reply::Applied { tick: 3 }
            );
            assert_eq!(plane.history.state_hash, hashes[2]);
            plane.step(dt).unwrap();
            assert_eq!(plane.history.state_hash, hashes[3], "the same tick again");
        }
        // Nothing is kept, nor pending, with RollbackTicks = 0.
        let mut none = falling(0);
        none.step(dt).unwrap();
        assert!(!none.has_idle_work());
    }
}

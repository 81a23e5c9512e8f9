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

impl Plane {
    /// The parts of a kept tick, by name, as [`Plane::rollback_record_part`] copies them:
    /// the whole copy first, then the engine's sets and phases it holds, then the plane's
    /// object table (what the whole holds besides them is the plane's other tables).
    pub const ROLLBACK_RECORD_PARTS: [&str; 9] = [
        "whole",
        "bodies",
        "colliders",
        "narrow phase",
        "broad phase",
        "islands",
        "joints",
        "soft bodies",
        "objects",
    ];

    /// A copy of the part `name` (one of [`Plane::ROLLBACK_RECORD_PARTS`]) of what Rewind
    /// keeps of the plane's current tick, made as a kept tick makes it (`None`: no such
    /// part). What it holds is what one kept tick costs in memory for that part; what
    /// copying and dropping it takes is its share of a kept tick's CPU (`physics-bench
    /// snapshot` counts both per body).
    pub fn rollback_record_part(&self, name: &str) -> Option<Box<dyn std::any::Any + Send>> {
        let w = &self.world;
        Some(match name {
            "whole" => Box::new(self.clone_state()),
            "bodies" => Box::new(w.bodies.clone()),
            "colliders" => Box::new(w.colliders.clone()),
            "narrow phase" => Box::new(w.narrow_phase.clone()),
            "broad phase" => Box::new(w.broad_phase.clone()),
            "islands" => Box::new(w.islands.clone()),
            "joints" => Box::new((w.impulse_joints.clone(), w.multibody_joints.clone())),
            "soft bodies" => Box::new(w.soft_bodies.clone()),
            "objects" => Box::new(self.objects.table().clone()),
            _ => return None,
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

    /// Every part of a kept tick is copied by name (an unknown name gives none), and the
    /// whole copy is what a rewind becomes: a plane that takes it steps on as the plane it
    /// was copied from does.
    #[test]
    fn the_parts_of_a_kept_tick_are_copied_by_name() {
        let dt = 1.0 / 60.0;
        let mut plane = falling(3);
        for _ in 0..5 {
            plane.step(dt).unwrap();
        }
        for name in Plane::ROLLBACK_RECORD_PARTS {
            assert!(plane.rollback_record_part(name).is_some(), "{name}");
        }
        assert!(plane.rollback_record_part("contacts").is_none());
        let whole = plane.rollback_record_part("whole").unwrap();
        let state = whole
            .downcast::<crate::rapier3d::plane::State>()
            .expect("the whole copy is the plane's state");
        let mut copy = falling(3);
        copy.adopt_copy(*state).unwrap();
        assert_eq!(copy.history.state_hash, plane.history.state_hash);
        for tick in 0..10 {
            plane.step(dt).unwrap();
            copy.step(dt).unwrap();
            assert_eq!(
                copy.history.state_hash, plane.history.state_hash,
                "tick {tick}"
            );
        }
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

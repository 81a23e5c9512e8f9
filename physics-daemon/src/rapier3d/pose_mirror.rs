//! The plane's published states in slot order, as the last step left them: a compact array
//! of [`BodyState`] (64 bytes a slot, the sample's own layout) that the step's pass over
//! every slot (the state hash's) writes on its way, so that publishing copies it in one
//! sequential streaming copy instead of gathering each body from rapier's 464-byte
//! `RigidBody` (three or four scattered cache lines a body).
//!
//! The copy is valid while nothing changed the plane since it was written: every op marks
//! the plane's [`Dirty`] list, whose running count of marks the mirror remembers. When the
//! count moved (an op, a restore, a rewind, a plane-wide setting) or the slot count changed,
//! the publisher reads rapier as before until the next step that rehashes rewrites the
//! mirror.

use std::mem::MaybeUninit;

use rapier3d::prelude::RigidBodySet;
use shm_layout::{BodyState, StateHasher};

use super::{publish, Body};
use crate::backend::{SlotFilter, SlotTable};

/// Every slot's published state as of the last rehashing step.
#[derive(Debug, Default)]
pub(super) struct PoseMirror {
    states: Vec<BodyState>,
    /// [`Dirty::marks`] when `states` was written; `None`: never, or given up.
    marks: Option<u64>,
}

impl PoseMirror {
    /// Rewrites every slot's state from rapier and returns their [`StateHasher`] hash (the
    /// tick header's), computed on the way.
    pub(super) fn write_and_hash(
        &mut self,
        slots: &SlotTable<Body>,
        bodies: &RigidBodySet,
        marks: u64,
    ) -> u64 {
        let mut h = StateHasher::new();
        self.states.clear();
        self.states.extend((0..slots.slot_count()).map(|i| {
            let state = publish::body_state(slots, bodies, i);
            h.add(&state);
            state
        }));
        self.marks = Some(marks);
        h.finish()
    }

    /// Gives the copy up until the next rehashing step (bodies moved without an op: another
    /// engine's poses written back).
    pub(super) fn forget(&mut self) {
        self.marks = None;
    }

    /// The states, when they are still every slot's current ones.
    pub(super) fn current(&self, marks: u64, slot_count: usize) -> Option<&[BodyState]> {
        (self.marks == Some(marks) && self.states.len() == slot_count).then_some(&self.states[..])
    }
}

/// Copies the slots `filter` wants of `states[first..]` into `out` (`out[k]` is slot
/// `first + k`): one streaming copy when it wants them all.
pub(super) fn copy_run(
    states: &[BodyState],
    first: usize,
    out: &mut [MaybeUninit<BodyState>],
    filter: SlotFilter<'_>,
) {
    let src = &states[first..first + out.len()];
    match filter {
        SlotFilter::All => {
            // SAFETY: `src` and `out` have the same length and element layout
            // (`MaybeUninit<T>` is layout-compatible with `T`), and cannot overlap (one is
            // the plane's own heap array, the other a shared-memory sample).
            unsafe {
                std::ptr::copy_nonoverlapping(
                    src.as_ptr(),
                    out.as_mut_ptr().cast::<BodyState>(),
                    src.len(),
                )
            }
        }
        filter => {
            for (k, (dst, state)) in out.iter_mut().zip(src).enumerate() {
                if filter.wants(first + k) {
                    dst.write(*state);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rapier3d::Plane;
    use shm_layout::{ObjectProp, PlaneProp, Pose, Shape};

    fn sample(plane: &Plane) -> Vec<BodyState> {
        let mut out = vec![MaybeUninit::<BodyState>::uninit(); plane.slot_count()];
        plane.write_sample(&mut out, SlotFilter::All);
        // SAFETY: SlotFilter::All writes every element.
        out.into_iter()
            .map(|s| unsafe { s.assume_init() })
            .collect()
    }

    fn expected(plane: &Plane) -> Vec<BodyState> {
        (0..plane.slot_count())
            .map(|i| plane.body_state(i))
            .collect()
    }

    /// The mirror serves the sample right after a step, and any change between a step and
    /// a publish (an op, a plane-wide setting, a new object) falls back to rapier's own
    /// bodies: the sample always equals every slot's current state.
    #[test]
    fn a_sample_from_the_mirror_is_always_current() {
        let mut plane = Plane::new(1, &[PlaneProp::TickRate(0.0)]).unwrap();
        let ball = Shape::Sphere { radius: 0.5 };
        let handles: Vec<_> = (0..20)
            .map(|i| {
                plane
                    .add_object(&ball, Pose::at([i as f32 * 2.0, 5.0, 0.0]), &[])
                    .unwrap()
            })
            .collect();
        assert!(
            plane
                .mirror
                .current(plane.bodies.marks_made(), 20)
                .is_none(),
            "not before a step"
        );
        plane.step(1.0 / 60.0).unwrap();
        assert!(
            plane
                .mirror
                .current(plane.bodies.marks_made(), 20)
                .is_some(),
            "written by the step"
        );
        assert_eq!(sample(&plane), expected(&plane));
        // The step's hash is the mirror's.
        assert_eq!(plane.header().state_hash, plane.state_hash());

        plane
            .set_object(handles[3], ObjectProp::Pose(Pose::at([0.0, 50.0, 0.0])))
            .unwrap();
        assert!(
            plane
                .mirror
                .current(plane.bodies.marks_made(), 20)
                .is_none(),
            "an op since"
        );
        let now = sample(&plane);
        assert_eq!(now, expected(&plane));
        assert_eq!(now[3].position, [0.0, 50.0, 0.0]);

        plane.step(1.0 / 60.0).unwrap();
        assert_eq!(sample(&plane), expected(&plane));
        plane.set(PlaneProp::Gravity([0.0, 0.0, 0.0])).unwrap();
        assert!(
            plane
                .mirror
                .current(plane.bodies.marks_made(), 20)
                .is_none(),
            "a plane-wide set"
        );
        assert_eq!(sample(&plane), expected(&plane));

        plane.step(1.0 / 60.0).unwrap();
        plane
            .add_object(&ball, Pose::at([0.0, 9.0, 9.0]), &[])
            .unwrap();
        assert!(
            plane
                .mirror
                .current(plane.bodies.marks_made(), 21)
                .is_none(),
            "a new slot"
        );
        assert_eq!(sample(&plane), expected(&plane));
    }
}

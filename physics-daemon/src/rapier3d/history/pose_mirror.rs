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
//!
//! A step after which the mirror is still valid (no op since it was written) does not
//! rewrite it whole: the plane lists the slots the step can have moved (the bodies awake
//! before or after it, and the controllers), the mirror adds every slot it holds as alive,
//! not anchored and not asleep, and reads only those states from rapier; of every other
//! slot it reads the sleeping bit alone (rapier puts bodies to sleep and wakes them outside
//! its awake set). The hash, one FNV chain over every slot, goes on from the running hash
//! kept before each slot at the first slot whose state changed. A mostly settled plane then
//! reads whole states in proportion to its awake bodies and one bit for each other body;
//! the hash stays bit for bit the chain over every slot (debug builds check the mirror and
//! the hash against a full rewrite after every such step).
//!
//! [`Dirty`]: crate::backend::Dirty

use std::mem::MaybeUninit;

use rapier3d::prelude::RigidBodySet;
use shm_layout::{BodyState, StateHasher, FLAG_ALIVE, FLAG_ANCHORED, FLAG_SLEEPING};

use crate::backend::{SlotFilter, SlotTable};
use crate::rapier3d::objects::object::{body_state, Object};

/// Every slot's published state as of the last rehashing step.
#[derive(Debug, Default)]
pub(crate) struct PoseMirror {
    states: Vec<BodyState>,
    /// `chain[i]`: the running [`StateHasher`] hash before slot `i` (as long as `states`).
    chain: Vec<u64>,
    /// The hash of every slot of `states`.
    hash: u64,
    /// [`Dirty::marks`] when `states` was written; `None`: never, or given up.
    ///
    /// [`Dirty::marks`]: crate::backend::Dirty::marks
    marks: Option<u64>,
    /// Slots the step running now can have changed (filled by the plane before
    /// [`PoseMirror::rehash`]; repeats allowed).
    pub(crate) moved: Vec<u32>,
    /// Slots of `states` alive, not anchored and not asleep: rapier can put such a body to
    /// sleep (its published flags change) in a step that does not list it as awake, so
    /// every rehash reads them too. Rebuilt when any slot's flags change.
    unsettled: Vec<u32>,
}

/// Whether two states are the same bits (`==` on floats would take -0.0 for 0.0 and never
/// a NaN for itself; the hash sees bits).
fn same_bits(a: &BodyState, b: &BodyState) -> bool {
    let words = |s: &BodyState| {
        let f = |x: &f32| x.to_bits();
        let mut w = [0u32; 16];
        for (k, v) in s
            .position
            .iter()
            .map(f)
            .chain([s.flags])
            .chain(s.rotation.iter().map(f))
            .chain(s.linear_velocity.iter().map(f))
            .chain([s.generation])
            .chain(s.angular_velocity.iter().map(f))
            .chain([s._reserved])
            .enumerate()
        {
            w[k] = v;
        }
        w
    };
    words(a) == words(b)
}

impl PoseMirror {
    /// Rewrites every slot's state from rapier and returns their [`StateHasher`] hash (the
    /// tick header's), computed on the way.
    pub(crate) fn write_and_hash(
        &mut self,
        slots: &SlotTable<Object>,
        bodies: &RigidBodySet,
        marks: u64,
    ) -> u64 {
        let mut h = StateHasher::new();
        self.states.clear();
        self.chain.clear();
        for i in 0..slots.slot_count() {
            let state = body_state(slots, bodies, i);
            self.chain.push(h.finish());
            h.add(&state);
            self.states.push(state);
        }
        self.marks = Some(marks);
        self.hash = h.finish();
        self.find_unsettled();
        self.hash
    }

    fn find_unsettled(&mut self) {
        self.unsettled.clear();
        self.unsettled.extend(
            self.states
                .iter()
                .enumerate()
                .filter(|(_, s)| {
                    s.flags & FLAG_ALIVE != 0 && s.flags & (FLAG_ANCHORED | FLAG_SLEEPING) == 0
                })
                .map(|(i, _)| i as u32),
        );
    }

    /// After a step: the [`StateHasher`] hash of every slot's state, with the mirror
    /// rewritten. When the mirror is still valid (no mark since it was written, as many
    /// slots), only the slots in [`PoseMirror::moved`] are read from rapier and the hash
    /// goes on from the first of them whose state changed; otherwise every slot is
    /// rewritten ([`PoseMirror::write_and_hash`]).
    pub(crate) fn rehash(
        &mut self,
        slots: &SlotTable<Object>,
        bodies: &RigidBodySet,
        marks: u64,
    ) -> u64 {
        let n = slots.slot_count();
        if self.marks != Some(marks) || self.states.len() != n || self.chain.len() != n {
            return self.write_and_hash(slots, bodies, marks);
        }
        let (mut first, mut flags_changed) = (n, false);
        for &slot in self.moved.iter().chain(&self.unsettled) {
            let i = slot as usize;
            let Some(old) = self.states.get_mut(i) else {
                continue;
            };
            let now = body_state(slots, bodies, i);
            if !same_bits(&now, old) {
                flags_changed |= now.flags != old.flags;
                *old = now;
                first = first.min(i);
            }
        }
        // Rapier also puts bodies to sleep and wakes them outside the awake set (a sleeping
        // island's members, bodies a torn joint wakes): the sleeping bit of every slot is
        // read (one cache line a body, not the state's three or four).
        for (i, old) in self.states.iter_mut().enumerate() {
            if old.flags & FLAG_ALIVE == 0 {
                continue;
            }
            let asleep = slots
                .at(i)
                .and_then(|b| bodies.get(b.handle))
                .is_some_and(|b| b.is_sleeping());
            if asleep != (old.flags & FLAG_SLEEPING != 0) {
                *old = body_state(slots, bodies, i);
                flags_changed = true;
                first = first.min(i);
            }
        }
        if flags_changed {
            self.find_unsettled();
        }
        if first < n {
            let mut h = StateHasher::resume(self.chain[first]);
            for (state, before) in self.states[first..].iter().zip(&mut self.chain[first..]) {
                *before = h.finish();
                h.add(state);
            }
            self.hash = h.finish();
        }
        #[cfg(debug_assertions)]
        self.check(slots, bodies);
        self.hash
    }

    /// Debug builds: the mirror and its hash equal a full rewrite (a slot the plane failed
    /// to list as moved would show here).
    #[cfg(debug_assertions)]
    fn check(&self, slots: &SlotTable<Object>, bodies: &RigidBodySet) {
        let mut h = StateHasher::new();
        for (i, state) in self.states.iter().enumerate() {
            let now = body_state(slots, bodies, i);
            assert!(
                same_bits(&now, state),
                "pose mirror: slot {i} changed in a step without being listed as moved"
            );
            h.add(&now);
        }
        assert_eq!(h.finish(), self.hash, "pose mirror: the resumed hash");
    }

    /// Gives the copy up until the next rehashing step (bodies moved without an op: another
    /// engine's poses written back).
    pub(crate) fn forget(&mut self) {
        self.marks = None;
    }

    /// The states, when they are still every slot's current ones.
    pub(crate) fn current(&self, marks: u64, slot_count: usize) -> Option<&[BodyState]> {
        (self.marks == Some(marks) && self.states.len() == slot_count).then_some(&self.states[..])
    }
}

/// Copies the slots `filter` wants of `states[first..]` into `out` (`out[k]` is slot
/// `first + k`): one streaming copy when it wants them all.
pub(crate) fn copy_run(
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
                .history
                .mirror
                .current(plane.objects.marks_made(), 20)
                .is_none(),
            "not before a step"
        );
        plane.step(1.0 / 60.0).unwrap();
        assert!(
            plane
                .history
                .mirror
                .current(plane.objects.marks_made(), 20)
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
                .history
                .mirror
                .current(plane.objects.marks_made(), 20)
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
                .history
                .mirror
                .current(plane.objects.marks_made(), 20)
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
                .history
                .mirror
                .current(plane.objects.marks_made(), 21)
                .is_none(),
            "a new slot"
        );
        assert_eq!(sample(&plane), expected(&plane));
    }
}

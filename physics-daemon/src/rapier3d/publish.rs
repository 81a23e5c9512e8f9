//! Writing the plane's body states into a published sample. A large plane with a pool of its
//! own (Threads > 1) writes its sample in chunks on that pool, each chunk a sequential run of
//! slots; a small one, or one without a pool, writes it in one pass.

use std::mem::MaybeUninit;

use rapier3d::prelude::*;
use rayon::prelude::*;
use shm_layout::{BodyState, FLAG_ALIVE, FLAG_ANCHORED, FLAG_SLEEPING};

use super::{Body, Plane};
use crate::backend::{SlotFilter, SlotTable};

/// Slots below which a sample is written on the calling thread (the hand-off costs more).
const PARALLEL_FROM: usize = 8_192;
/// Slots per chunk handed to one pool thread.
const CHUNK: usize = 2_048;

/// The published state of slot `i` (dead slots carry only their generation).
pub(super) fn body_state(slots: &SlotTable<Body>, bodies: &RigidBodySet, i: usize) -> BodyState {
    let generation = slots.generation(i);
    let Some((body, extra)) = slots
        .at(i)
        .and_then(|b| Some((bodies.get(b.handle)?, b.flags)))
    else {
        return BodyState {
            generation,
            ..BodyState::default()
        };
    };
    let pose = body.position();
    let mut flags = FLAG_ALIVE | extra;
    if body.is_sleeping() {
        flags |= FLAG_SLEEPING;
    }
    if body.is_fixed() {
        flags |= FLAG_ANCHORED;
    }
    BodyState {
        position: pose.translation.into(),
        flags,
        rotation: pose.rotation.into(),
        linear_velocity: body.linvel().into(),
        generation,
        angular_velocity: body.angvel().into(),
        _reserved: 0,
    }
}

fn write_run(
    slots: &SlotTable<Body>,
    bodies: &RigidBodySet,
    first: usize,
    out: &mut [MaybeUninit<BodyState>],
    filter: SlotFilter<'_>,
) {
    for (k, dst) in out.iter_mut().enumerate() {
        let i = first + k;
        if filter.wants(i) {
            dst.write(body_state(slots, bodies, i));
        }
    }
}

impl Plane {
    /// [`crate::backend::Backend::write_states`] of this plane.
    pub(super) fn write_sample(&self, out: &mut [MaybeUninit<BodyState>], filter: SlotFilter<'_>) {
        if let Some(states) = self.mirror.current(self.bodies.marks_made(), out.len()) {
            // The last step's own copy, in slot order: a streaming copy.
            return match self.world.physics_pipeline.thread_pool() {
                Some(pool) if out.len() >= PARALLEL_FROM => pool.install(|| {
                    out.par_chunks_mut(CHUNK)
                        .enumerate()
                        .for_each(|(c, chunk)| {
                            super::pose_mirror::copy_run(states, c * CHUNK, chunk, filter)
                        })
                }),
                _ => super::pose_mirror::copy_run(states, 0, out, filter),
            };
        }
        let (slots, bodies) = (&self.bodies, &self.world.bodies);
        match self.world.physics_pipeline.thread_pool() {
            Some(pool) if out.len() >= PARALLEL_FROM => pool.install(|| {
                out.par_chunks_mut(CHUNK)
                    .enumerate()
                    .for_each(|(c, chunk)| write_run(slots, bodies, c * CHUNK, chunk, filter))
            }),
            _ => write_run(slots, bodies, 0, out, filter),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use shm_layout::{PlaneProp, Pose, Shape};

    /// Writing a sample walks the slot table once per slot (the write's cost is timed by
    /// `cargo bench -p physics-daemon --bench publish`): an entry must stay one short record,
    /// not the part's settings inline (276 bytes), or every publish reads ten times the memory.
    #[test]
    fn a_slot_table_entry_stays_small() {
        let entry = std::mem::size_of::<Option<Body>>() + std::mem::size_of::<u32>();
        assert!(entry <= 32, "slot table entry of {entry} bytes");
    }

    #[test]
    fn a_sample_written_on_the_pool_matches_the_slots() {
        let mut plane = Plane::new(1, &[PlaneProp::Threads(2), PlaneProp::TickRate(0.0)]).unwrap();
        let ball = Shape::Sphere { radius: 0.25 };
        let n = PARALLEL_FROM + CHUNK / 2 + 3;
        for i in 0..n {
            let (x, z) = ((i % 100) as f32, (i / 100) as f32);
            plane.add_object(&ball, Pose::at([x, 5.0, z]), &[]).unwrap();
        }
        plane.step(1.0 / 60.0).unwrap();
        let mut out = vec![MaybeUninit::<BodyState>::uninit(); plane.slot_count()];
        plane.write_sample(&mut out, SlotFilter::All);
        for (i, written) in out.iter().enumerate() {
            // SAFETY: SlotFilter::All writes every element.
            let written = unsafe { written.assume_init() };
            assert_eq!(written, plane.body_state(i), "slot {i}");
        }
        assert!(
            plane.body_state(n - 1).position[1] < 5.0,
            "the last ball fell"
        );
    }
}

//! Writing the plane's body states into a published sample. A large plane with a pool of its
//! own (Threads > 1) writes its sample in chunks on that pool, each chunk a sequential run of
//! slots; a small one, or one without a pool, writes it in one pass.

use std::mem::MaybeUninit;

use rapier3d::prelude::*;
use rayon::prelude::*;
use shm_layout::BodyState;

use crate::backend::{SlotFilter, SlotTable};
use crate::rapier3d::history::pose_mirror::{copy_run, PoseMirror};
use crate::rapier3d::objects::object::{body_state, Object};

/// Slots below which a sample is written on the calling thread (the hand-off costs more).
const PARALLEL_FROM: usize = 8_192;
/// Slots per chunk handed to one pool thread.
const CHUNK: usize = 2_048;

fn write_run(
    slots: &SlotTable<Object>,
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

/// [`crate::backend::Backend::write_states`] of a plane: from `mirror` when it holds the
/// last step's states, else read from `slots` and `world`.
pub(crate) fn write_sample(
    mirror: &PoseMirror,
    slots: &SlotTable<Object>,
    world: &PhysicsWorld,
    out: &mut [MaybeUninit<BodyState>],
    filter: SlotFilter<'_>,
) {
    if let Some(states) = mirror.current(slots.marks_made(), out.len()) {
        // The last step's own copy, in slot order: a streaming copy.
        return match world.physics_pipeline.thread_pool() {
            Some(pool) if out.len() >= PARALLEL_FROM => pool.install(|| {
                out.par_chunks_mut(CHUNK)
                    .enumerate()
                    .for_each(|(c, chunk)| copy_run(states, c * CHUNK, chunk, filter))
            }),
            _ => copy_run(states, 0, out, filter),
        };
    }
    let bodies = &world.bodies;
    match world.physics_pipeline.thread_pool() {
        Some(pool) if out.len() >= PARALLEL_FROM => pool.install(|| {
            out.par_chunks_mut(CHUNK)
                .enumerate()
                .for_each(|(c, chunk)| write_run(slots, bodies, c * CHUNK, chunk, filter))
        }),
        _ => write_run(slots, bodies, 0, out, filter),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rapier3d::plane::Plane;
    use shm_layout::{PlaneProp, Pose, Shape};

    /// Writing a sample walks the slot table once per slot (the write's cost is timed by
    /// `cargo bench -p physics-daemon --bench publish`): an entry must stay one short record,
    /// not the part's settings inline (276 bytes), or every publish reads ten times the memory.
    #[test]
    fn a_slot_table_entry_stays_small() {
        let entry = std::mem::size_of::<Option<Object>>() + std::mem::size_of::<u32>();
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

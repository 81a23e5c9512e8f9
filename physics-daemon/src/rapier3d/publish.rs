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
        #[cfg(feature = "gpu")]
        if self.gpu.is_some() {
            // The GPU path's poses live in its read-back, not in rapier's bodies.
            for (i, dst) in out.iter_mut().enumerate() {
                if filter.wants(i) {
                    dst.write(self.body_state(i));
                }
            }
            return;
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

    /// Not a check: prints what writing a sample of 10,000 awake bodies costs, into four
    /// rotating buffers like a publisher's recycled samples, and the sizes that decide it
    /// (`cargo test --release -p physics-daemon --lib sample_write_cost -- --ignored
    /// --nocapture`).
    #[test]
    #[ignore]
    fn sample_write_cost() {
        let props = [PlaneProp::TickRate(0.0), PlaneProp::Gravity([0.0; 3])];
        let mut plane = Plane::new(1, &props).unwrap();
        let cube = Shape::Cube { size: [1.0; 3] };
        for i in 0..10_000 {
            let at = [i % 22, (i / 22) % 22, i / 484].map(|k| k as f32 * 3.0);
            let v = [
                (i % 7) as f32 - 3.0,
                (i % 5) as f32 - 2.0,
                (i % 3) as f32 - 1.0,
            ];
            let velocity = [shm_layout::ObjectProp::Velocity(v)];
            plane.add_object(&cube, Pose::at(at), &velocity).unwrap();
        }
        plane.step(1.0 / 60.0).unwrap();
        let mut bufs: Vec<Vec<MaybeUninit<BodyState>>> = (0..4)
            .map(|_| vec![MaybeUninit::uninit(); plane.slot_count()])
            .collect();
        let mut times = Vec::new();
        for k in 0..400 {
            if k % 20 == 0 {
                plane.step(1.0 / 60.0).unwrap();
            }
            let started = std::time::Instant::now();
            plane.write_sample(&mut bufs[k % 4], SlotFilter::All);
            times.push(started.elapsed().as_secs_f64() * 1e6);
            std::hint::black_box(&bufs[k % 4]);
        }
        times.sort_by(f64::total_cmp);
        eprintln!(
            "write_sample, 10,000 awake bodies: median {:.1} µs, p10 {:.1} µs; slot table entry \
             {} B, RigidBody {} B",
            times[200],
            times[40],
            std::mem::size_of::<Option<Body>>() + 4,
            std::mem::size_of::<RigidBody>(),
        );
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

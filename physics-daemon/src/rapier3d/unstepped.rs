//! Tests: a plane that is written but never stepped (manual, or disabled) keeps its
//! per-write bookkeeping bounded. Every property write marks its body for the publisher
//! and for the next query; only a step, a publish or a query emptied those lists, so a
//! paused plane's lists grew by one entry a write for as long as the client wrote.

use shm_layout::{Handle, ObjectOp, ObjectProp, PlaneOp, PlaneProp, Pose, Shape};

use super::Plane;
use crate::backend::marks::FOLD_MIN;
use crate::backend::Backend;

const CUBES: usize = 10;
const WRITES: usize = 200_000;

fn manual_plane_with_cubes() -> (Plane, Vec<Handle>) {
    let mut plane = Plane::new(1, &[PlaneProp::TickRate(0.0)]).unwrap();
    let cubes = (0..CUBES)
        .map(|i| {
            plane
                .add_object(
                    &Shape::Cube { size: [1.0; 3] },
                    Pose::at([i as f32 * 2.0, 0.5, 0.0]),
                    &[],
                )
                .unwrap()
        })
        .collect();
    (plane, cubes)
}

#[test]
fn writes_to_a_plane_that_never_steps_keep_its_marks_bounded() {
    let (mut plane, cubes) = manual_plane_with_cubes();
    for i in 0..WRITES {
        let op = PlaneOp::Object {
            handle: cubes[i % CUBES],
            op: ObjectOp::Set(ObjectProp::Velocity([0.0, (i % 7) as f32, 0.0])),
        };
        Backend::apply(&mut plane, op).unwrap();
        // 200,000 writes to 10 cubes: at most FOLD_MIN entries each list, not 200,000.
        assert!(plane.queries.stale_count() <= FOLD_MIN, "write {i}");
        assert!(plane.objects.since_step().len() <= FOLD_MIN, "write {i}");
    }
    // What the lists are for still holds: the publisher is told every written slot.
    let mut slots = Vec::new();
    Backend::drain_dirty(&mut plane, &mut slots);
    slots.sort_unstable();
    slots.dedup();
    let mut written: Vec<u32> = cubes.iter().map(|h| h.slot).collect();
    written.sort_unstable();
    assert_eq!(slots, written);
    // And the next step sees every write (the last velocity of each cube): one tick of
    // free fall later, vy = written + g·dt (damping and solver error well under 0.05).
    let dt = 1.0 / 60.0;
    let g = plane.settings.gravity[1];
    assert!(plane.step(dt).unwrap());
    for (k, h) in cubes.iter().enumerate() {
        let last = ((WRITES - CUBES + k) % 7) as f32;
        let v = plane.body_state(h.slot as usize).linear_velocity;
        assert!(
            (v[1] - (last + g * dt)).abs() < 0.05,
            "cube {k}: vy {} after writing {last} (g {g})",
            v[1]
        );
    }
}

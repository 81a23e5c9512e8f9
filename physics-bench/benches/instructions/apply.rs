//! Applying per command: a frame's velocity writes applied to an awake plane's objects, as
//! the plane's worker applies a decoded batch.

use std::hint::black_box;

use gungraun::{library_benchmark, library_benchmark_group};
use physics_daemon::backend::Backend;
use physics_scenes::{free_bodies, LocalPlane};
use shm_layout::{ObjectOp, ObjectProp, PlaneOp, PlaneProp};

use crate::common::{plane, run};

/// A plane of `n` free bodies and one velocity write for each.
fn writes(n: usize) -> (LocalPlane, Vec<PlaneOp>) {
    let mut plane = plane(&[PlaneProp::Gravity([0.0; 3])]);
    let handles = free_bodies(&mut plane, n).expect("free bodies");
    run(&mut plane, 2);
    let ops = handles
        .iter()
        .enumerate()
        .map(|(i, &handle)| PlaneOp::Object {
            handle,
            op: ObjectOp::Set(ObjectProp::Velocity([i as f32 * 0.01, 0.5, -1.0])),
        })
        .collect();
    (plane, ops)
}

#[library_benchmark]
#[bench::n10(args = (10), setup = writes)]
#[bench::n1000(args = (1000), setup = writes)]
fn set_velocity((mut plane, ops): (LocalPlane, Vec<PlaneOp>)) -> LocalPlane {
    for op in ops {
        black_box(plane.apply(op).expect("applied"));
    }
    plane
}

library_benchmark_group!(name = apply_group; benchmarks = set_velocity);

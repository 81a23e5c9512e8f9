//! A controller tick: controllers walking a path on a floor, the plane's step with them.
//! The slope between the two sizes is a controller's cost per tick.

use std::hint::black_box;

use gungraun::{library_benchmark, library_benchmark_group};
use physics_scenes::{floor, LocalPlane};
use shm_layout::{ControllerOp, Pose, Reply};

use crate::common::{plane, run, DT};

/// `n` controllers 6 units apart on a floor, each walking a 30 × 30 square, a few ticks in
/// (standing on the floor, walking).
fn walking(n: usize) -> LocalPlane {
    let mut plane = plane(&[]);
    floor(&mut plane, 400.0, &[]).expect("floor");
    let side = (n as f64).sqrt().ceil() as usize;
    for i in 0..n {
        let at = [
            (i % side) as f32 * 6.0 - 150.0,
            2.6,
            (i / side) as f32 * 6.0 - 150.0,
        ];
        let reply = plane
            .controller_op(ControllerOp::Create {
                pose: Pose::at(at),
                size: [2.0, 5.0, 2.0],
                controlled: false,
                props: vec![],
            })
            .expect("controller");
        let Reply::Object { handle, .. } = reply else {
            panic!("a controller's reply names its object: {reply:?}");
        };
        let waypoints = vec![
            [at[0] + 30.0, 0.0, at[2]],
            [at[0] + 30.0, 0.0, at[2] + 30.0],
            [at[0], 0.0, at[2] + 30.0],
            at,
        ];
        plane
            .controller_op(ControllerOp::SetPath { handle, waypoints })
            .expect("path");
    }
    run(&mut plane, 10);
    plane
}

#[library_benchmark]
#[bench::n10(args = (10), setup = walking)]
#[bench::n100(args = (100), setup = walking)]
fn tick(mut plane: LocalPlane) -> LocalPlane {
    black_box(plane.step(DT).expect("step"));
    plane
}

library_benchmark_group!(name = controllers_group; benchmarks = tick);

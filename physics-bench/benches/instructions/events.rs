//! An event record per contact: cubes set down on a floor, their first step (every cube's
//! contact with the floor begins), with ReportContacts on and, for the difference, off.
//! What the events add per contact is the slope of `reporting` less that of `silent`.

use std::hint::black_box;

use gungraun::{library_benchmark, library_benchmark_group};
use physics_scenes::{floor, LocalPlane};
use shm_layout::{ObjectProp, Pose, Shape};

use crate::common::{plane, DT};

/// `n` unit cubes 2 apart resting on a floor, not yet stepped.
fn set_down(n: usize, report: bool) -> LocalPlane {
    let mut plane = plane(&[]);
    floor(&mut plane, 2.0 * n as f32 + 4.0, &[]).expect("floor");
    let side = (n as f64).sqrt().ceil() as usize;
    for i in 0..n {
        let (x, z) = ((i % side) as f32 * 2.0, (i / side) as f32 * 2.0);
        plane
            .add_object(
                &Shape::Cube { size: [1.0; 3] },
                Pose::at([x - side as f32, 0.5, z - side as f32]),
                &[ObjectProp::ReportContacts(report)],
            )
            .expect("cube");
    }
    plane
}

fn reporting_cubes(n: usize) -> LocalPlane {
    set_down(n, true)
}

fn silent_cubes(n: usize) -> LocalPlane {
    set_down(n, false)
}

#[library_benchmark]
#[bench::n20(args = (20), setup = reporting_cubes)]
#[bench::n80(args = (80), setup = reporting_cubes)]
fn reporting(mut plane: LocalPlane) -> LocalPlane {
    black_box(plane.step(DT).expect("step"));
    assert!(!plane.events().is_empty(), "the landings are reported");
    plane
}

#[library_benchmark]
#[bench::n20(args = (20), setup = silent_cubes)]
#[bench::n80(args = (80), setup = silent_cubes)]
fn silent(mut plane: LocalPlane) -> LocalPlane {
    black_box(plane.step(DT).expect("step"));
    plane
}

library_benchmark_group!(name = events_group; benchmarks = reporting, silent);

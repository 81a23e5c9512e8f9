//! A step per body: a settled pile (everything asleep), an awake pile (every body resting
//! on another) and free bodies (awake, no contacts).

use std::hint::black_box;

use gungraun::{library_benchmark, library_benchmark_group};
use physics_scenes::LocalPlane;

use crate::common::{awake_pile, free, settled_pile, DT};

#[library_benchmark]
#[bench::n100(args = (100), setup = settled_pile)]
#[bench::n400(args = (400), setup = settled_pile)]
fn settled(mut plane: LocalPlane) -> LocalPlane {
    black_box(plane.step(DT).expect("step"));
    plane
}

#[library_benchmark]
#[bench::n50(args = (50), setup = awake_pile)]
#[bench::n200(args = (200), setup = awake_pile)]
fn awake(mut plane: LocalPlane) -> LocalPlane {
    black_box(plane.step(DT).expect("step"));
    plane
}

#[library_benchmark]
#[bench::n100(args = (100), setup = free)]
#[bench::n400(args = (400), setup = free)]
fn free_bodies(mut plane: LocalPlane) -> LocalPlane {
    black_box(plane.step(DT).expect("step"));
    plane
}

library_benchmark_group!(name = step_group; benchmarks = settled, awake, free_bodies);

//! A snapshot and a rollback tick per body: Snapshot of an awake pile, and a step of it with
//! RollbackTicks = 8 including the tick's keeping (which the daemon does right after the
//! tick, off its path, but on the plane's thread all the same).

use std::hint::black_box;

use gungraun::{library_benchmark, library_benchmark_group};
use physics_daemon::backend::Backend;
use physics_scenes::{pile, LocalPlane};
use shm_layout::PlaneProp;

use crate::common::{awake_pile, plane, DT};

/// An awake pile of `n` with RollbackTicks = 8 and eight ticks kept already.
fn rolling(n: usize) -> LocalPlane {
    let mut plane = plane(&[PlaneProp::NeverSleep(true), PlaneProp::RollbackTicks(8)]);
    pile(&mut plane, n).expect("pile");
    for _ in 0..30 {
        plane.step(DT).expect("step");
        plane.idle_work().expect("keep");
    }
    plane
}

#[library_benchmark]
#[bench::n50(args = (50), setup = awake_pile)]
#[bench::n200(args = (200), setup = awake_pile)]
fn snapshot(plane: LocalPlane) -> (LocalPlane, Vec<u8>) {
    let bytes = black_box(plane.snapshot().expect("snapshot"));
    (plane, bytes)
}

#[library_benchmark]
#[bench::n50(args = (50), setup = rolling)]
#[bench::n200(args = (200), setup = rolling)]
fn rollback_tick(mut plane: LocalPlane) -> LocalPlane {
    black_box(plane.step(DT).expect("step"));
    plane.idle_work().expect("keep");
    plane
}

library_benchmark_group!(name = history_group; benchmarks = snapshot, rollback_tick);

//! What every benchmark's setup shares: one rayon thread that is the main thread, and the
//! scenes.

use physics_scenes::{free_bodies, pile, LocalPlane};
use shm_layout::PlaneProp;

/// The step every benchmark takes (60 Hz).
pub const DT: f32 = 1.0 / 60.0;

/// Makes rayon's global pool one thread, the calling one: a plane with Threads = 1 runs
/// rapier's parallel parts on the global pool, and Callgrind counts only the thread that
/// runs the benchmark function.
pub fn one_thread() {
    // An error means the pool exists already (an earlier setup in this process made it).
    let _ = rapier3d::rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .use_current_thread()
        .build_global();
}

/// A manual plane (TickRate 0: it ticks when stepped) with `props` after that.
pub fn plane(props: &[PlaneProp]) -> LocalPlane {
    one_thread();
    let mut all = vec![PlaneProp::TickRate(0.0)];
    all.extend_from_slice(props);
    LocalPlane::new(1, &all).expect("a manual plane")
}

/// Steps `plane` `ticks` times.
pub fn run(plane: &mut LocalPlane, ticks: usize) {
    for _ in 0..ticks {
        plane.step(DT).expect("step");
    }
}

/// `n` unit cubes in columns of five on a floor, stepped until they sleep.
pub fn settled_pile(n: usize) -> LocalPlane {
    let mut plane = plane(&[]);
    pile(&mut plane, n).expect("pile");
    run(&mut plane, 240);
    assert_eq!(
        plane.awake_count(),
        0,
        "the pile of {n} settles in 240 ticks"
    );
    plane
}

/// `n` unit cubes in columns of five on a floor, NeverSleep: every body awake, resting on
/// another.
pub fn awake_pile(n: usize) -> LocalPlane {
    let mut plane = plane(&[PlaneProp::NeverSleep(true)]);
    pile(&mut plane, n).expect("pile");
    run(&mut plane, 30);
    plane
}

/// `n` cubes flying apart without gravity: every body awake, no contacts.
pub fn free(n: usize) -> LocalPlane {
    let mut plane = plane(&[PlaneProp::Gravity([0.0; 3])]);
    free_bodies(&mut plane, n).expect("free bodies");
    run(&mut plane, 2);
    plane
}

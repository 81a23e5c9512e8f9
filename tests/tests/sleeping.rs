//! `Sleeping` (read-only, from the published flags) and `Wake()`: a box resting on a floor
//! falls asleep, reads asleep both from shared memory and from the daemon's info, and a wake
//! makes it simulate again; a wake of a stale handle is an error naming the handle.

use client_sdk::{Error, ErrorKind, PlaneOptions, Pose, Shape};
use integration_tests::Scene;

const DT: f32 = 1.0 / 60.0;

#[test]
fn a_resting_box_falls_asleep_and_wakes_on_request() {
    let scene = Scene::new("sleep", PlaneOptions::default());
    scene.floor();
    let b = scene
        .plane
        .add(
            Shape::Cube { size: [1.0; 3] },
            Pose::at([0.0, 0.5, 0.0]),
            &[],
        )
        .unwrap();
    assert!(!b.is_sleeping().unwrap(), "a new body is awake");
    // Rapier puts a body to sleep after 0.5 s below its thresholds: allow 6 s of sim time.
    let mut ticks = 0;
    while !b.is_sleeping().unwrap() {
        scene.plane.step(DT).unwrap();
        ticks += 1;
        assert!(ticks < 360, "the box never fell asleep");
    }
    assert!(b.info().unwrap().sleeping, "the daemon agrees");
    let at_rest = b.position().unwrap();
    assert!((at_rest[1] - 0.5).abs() < 0.05, "{at_rest:?}");

    b.wake().unwrap();
    scene.client.flush().unwrap();
    assert!(!b.info().unwrap().sleeping, "awake right after the wake");
    scene.plane.step(DT).unwrap();
    assert!(
        !b.is_sleeping().unwrap(),
        "the next tick publishes it awake"
    );
    // It stays put: waking adds no motion.
    let p = b.position().unwrap();
    assert!((p[1] - at_rest[1]).abs() < 1e-3, "{p:?} vs {at_rest:?}");

    // A destroyed object cannot be woken.
    b.destroy();
    scene.client.flush().unwrap();
    match b.wake() {
        Err(Error::Command(e)) => assert_eq!(e.kind, ErrorKind::StaleHandle, "{e}"),
        other => panic!("wake of a destroyed object: {other:?}"),
    }
}

//! Controllers on a plane with a pool (Threads = 2) through a real daemon: ticked side by
//! side, they give bit for bit the states of Threads = 1 on every tick (controllers
//! walking into each other, two pushing the same crate, walkers on their own, paths that
//! finish), and the ones that meet still collide as in slot order.

use client_sdk::{Controller, Object, ObjectProp, PlaneOptions, Pose, Shape};
use integration_tests::{quat, Scene};
use shm_layout::EVENT_PATH_FINISHED;

const DT: f32 = 1.0 / 60.0;
const TICKS: u32 = 150;
/// The default character: capsule radius 1, total height 5.
const SIZE: [f32; 3] = [2.0, 5.0, 2.0];
const HALF: f32 = 2.5;
const SKIN: f32 = 0.01;

/// What a run leaves to check: every tick's state hash, the gaps of the pairs walking into
/// each other after the last tick, the path-finished events and the crate's position.
struct Run {
    hashes: Vec<u64>,
    gaps: Vec<f32>,
    finished: usize,
    crate_z: f32,
}

fn character(s: &Scene, at: [f32; 3]) -> Controller {
    s.plane
        .new_controller(
            Pose {
                position: at,
                rotation: quat([0.0, 1.0, 0.0], std::f32::consts::PI),
            },
            SIZE,
            false,
            &[],
        )
        .expect("new controller")
}

/// The scene on a plane of `threads`: 6 pairs walking into each other along Z, 2
/// controllers pushing one light crate, 8 walkers on paths of their own, far apart.
fn run(threads: u32) -> Run {
    let s = Scene::new(
        &format!("kcc-threads-{threads}"),
        PlaneOptions {
            threads: Some(threads),
            ..PlaneOptions::default()
        },
    );
    s.floor();
    s.plane.subscribe_events().unwrap();
    let mut pairs = Vec::new();
    for i in 0..6 {
        let x = -60.0 + i as f32 * 8.0;
        let a = character(&s, [x, HALF + SKIN, -40.0]);
        let b = character(&s, [x, HALF + SKIN, -30.0]);
        a.set_move_vector(0.0, 1.0).unwrap();
        b.set_move_vector(0.0, -1.0).unwrap();
        pairs.push((a, b));
    }
    let light: Object = s
        .plane
        .add(
            Shape::Cube { size: [2.0; 3] },
            Pose::at([20.0, 1.0, 6.0]),
            &[ObjectProp::Density(0.1)],
        )
        .unwrap();
    let mut pushers = Vec::new();
    for x in [19.0, 21.0] {
        let c = character(&s, [x, HALF + SKIN, 0.0]);
        c.set_move_vector(0.0, 1.0).unwrap();
        pushers.push(c);
    }
    let mut walkers = Vec::new();
    for i in 0..8 {
        let (x, z) = (-60.0 + i as f32 * 12.0, 40.0);
        let c = character(&s, [x, HALF + SKIN, z]);
        let waypoints = [
            [x + 6.0, 0.0, z],
            [x + 6.0, 0.0, z + 6.0],
            [x, 0.0, z + 6.0],
        ];
        assert_eq!(c.compute_path(&waypoints).unwrap(), 3);
        walkers.push(c);
    }
    let mut hashes = Vec::new();
    let mut finished = 0;
    for _ in 0..TICKS {
        s.plane.step(DT).unwrap();
        hashes.push(s.plane.state_hash().unwrap());
        finished += s
            .plane
            .events()
            .unwrap()
            .records
            .iter()
            .filter(|r| r.kind == EVENT_PATH_FINISHED)
            .count();
    }
    let gaps = pairs
        .iter()
        .map(|(a, b)| b.object().position().unwrap()[2] - a.object().position().unwrap()[2])
        .collect();
    Run {
        hashes,
        gaps,
        finished,
        crate_z: light.position().unwrap()[2],
    }
}

#[test]
fn threads_2_ticks_controllers_as_threads_1_does() {
    let one = run(1);
    let two = run(2);
    // The scene moves: the hash changes from tick to tick.
    let distinct: std::collections::HashSet<_> = one.hashes.iter().collect();
    assert!(
        distinct.len() > TICKS as usize / 2,
        "only {} distinct hashes",
        distinct.len()
    );
    let first = one.hashes.iter().zip(&two.hashes).position(|(a, b)| a != b);
    assert_eq!(first, None, "Threads = 2 diverged from Threads = 1 at tick");
    for r in [&one, &two] {
        // Radius-1 capsules that walked into each other stop against each other: 2
        // between centres, not overlapping (less 0.05), nor farther than one tick's
        // walk (16 × 1/60) from touching, or they would not be blocked.
        for gap in &r.gaps {
            assert!(
                *gap > 2.0 - 0.05 && *gap < 2.0 + 16.0 * DT,
                "pair stopped {gap} apart"
            );
        }
        // Each walker finishes its 3-waypoint path (18 units at WalkSpeed 16) once.
        assert_eq!(r.finished, 8, "paths finished");
        // The crate (mass 0.8) was pushed from z = 6 by the two walking at it.
        assert!(r.crate_z > 10.0, "crate pushed: z {}", r.crate_z);
    }
}

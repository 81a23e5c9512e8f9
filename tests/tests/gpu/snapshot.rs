//! Snapshots of DeferGpu planes through a real daemon, on whatever Vulkan adapter the
//! machine has (Mesa's lavapipe in CI, as `tests/tests/gpu/main.rs`): a pile of boxes and balls
//! falling into an anchored container on the GPU path, snapshot at tick 20, 40 ticks of a
//! command log; Restore on the same plane and FromSnapshot as a new plane (on the GPU
//! again) replay the same hashes on every tick, bit for bit on the same adapter, and a
//! ball's poses match the first run's exactly.

use client_sdk::{Object, ObjectProp, PlaneOptions, Pose, Shape};
use integration_tests::{no_damping, Scene};

const DT: f32 = 1.0 / 60.0;

fn log(objects: &[Object], t: u32) {
    if t == 5 {
        objects[3]
            .set(ObjectProp::Velocity([2.0, 6.0, -1.0]))
            .unwrap();
    }
    if t == 17 {
        objects[8].apply_impulse([0.0, 3.0, 4.0]).unwrap();
    }
}

/// Steps 40 ticks of the log: each tick's hash, and a ball's last position.
fn replay(plane: &client_sdk::Plane, objects: &[Object]) -> (Vec<u64>, [f32; 3]) {
    let hashes = (1..=40)
        .map(|t| {
            log(objects, t);
            plane.step(DT).unwrap();
            plane.state_hash().unwrap()
        })
        .collect();
    (hashes, objects[0].position().unwrap())
}

#[test]
fn a_defer_gpu_plane_snapshots_and_restores_bit_for_bit() {
    let scene = Scene::new(
        "gpu-snap",
        PlaneOptions {
            defer_gpu: Some(true),
            ..no_damping()
        },
    );
    physics_scenes::container(&mut &scene.plane, 8.0, 6.0).unwrap();
    let objects: Vec<Object> = (0..24)
        .map(|i| {
            let at = [
                (i % 4) as f32 * 1.3 - 2.0,
                2.0 + (i / 4) as f32 * 1.2,
                ((i * 7) % 5) as f32 * 0.9 - 1.8,
            ];
            let shape = match i % 2 {
                0 => Shape::Sphere { radius: 0.5 },
                _ => Shape::Cube { size: [0.9; 3] },
            };
            scene.plane.add(shape, Pose::at(at), &[]).unwrap()
        })
        .collect();
    scene.run(DT, 20);
    let snapshot = scene.plane.take_snapshot().unwrap();
    assert_eq!(snapshot.tick(), 20);
    assert_eq!(snapshot.state_hash(), scene.plane.state_hash().unwrap());
    let (reference, end) = replay(&scene.plane, &objects);
    assert!(reference.windows(2).all(|w| w[0] != w[1]), "the pile moves");
    assert!(
        end[1] < 1.5,
        "the first ball fell into the container: {end:?}"
    );

    // Restore on the same plane: still on the GPU, the same hashes and the same ball.
    assert_eq!(scene.plane.restore(&snapshot).unwrap(), 20);
    assert!(scene.plane.info().unwrap().settings.defer_gpu);
    assert_eq!(scene.plane.state_hash().unwrap(), snapshot.state_hash());
    let (again, end_again) = replay(&scene.plane, &objects);
    assert_eq!(again, reference, "replay after Restore");
    assert_eq!(end_again, end);

    // A new plane from it (through bytes, as a file carries it): on the GPU, the same.
    let carried = client_sdk::PlaneSnapshot::from_bytes(snapshot.bytes().to_vec()).unwrap();
    let copy = scene.client.plane_from_snapshot(&carried, &[]).unwrap();
    assert!(copy.info().unwrap().settings.defer_gpu);
    let copies: Vec<Object> = objects
        .iter()
        .map(|o| Object::from_handle(&copy, o.handle()))
        .collect();
    let (from_snapshot, end_copy) = replay(&copy, &copies);
    assert_eq!(from_snapshot, reference, "replay after FromSnapshot");
    assert_eq!(end_copy, end);
}

//! Recording and replay of the other plane kinds through a real daemon: a GUI plane (a
//! pile of squares with impulses between ticks) and a DeferGpu plane (a pile falling into a
//! container on the GPU path, on whatever Vulkan adapter the machine has: lavapipe in CI).
//! Each recording replays, on a new client, with every tick's state hash equal, and the
//! replayed bodies end bit for bit where the recorded ones did.

use std::sync::Arc;

use client_sdk::{
    first_difference, load_recording, Advanced, GuiPlaneOptions, GuiShape, Object, PlaneOptions,
    Pose, Replay, Shape,
};
use integration_tests::{no_damping, Scene, TestDaemon};

const DT: f32 = 1.0 / 60.0;

fn file(tag: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("record-kinds-{}-{tag}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir.join("run.physrec")
}

/// Replays `path` to its end on a new client of `daemon`: the ticks it checked, and the
/// replayed plane's body states at its last tick.
fn replay_all(daemon: &TestDaemon, path: &std::path::Path) -> (u64, Vec<client_sdk::BodyState>) {
    let client = daemon.client();
    let recording = Arc::new(load_recording(path).unwrap());
    let mut replay = Replay::start(&client, recording).unwrap();
    let mut ticks = 0;
    loop {
        match replay.advance().unwrap() {
            Advanced::Tick(_) => ticks += 1,
            Advanced::End => break,
            Advanced::Diverged(d) => panic!("{d}"),
        }
    }
    let states = replay.plane().snapshot().unwrap().bodies().to_vec();
    (ticks, states)
}

#[test]
fn a_gui_plane_recording_replays_bit_for_bit() {
    let daemon = TestDaemon::start("record-gui");
    let client = daemon.client();
    let plane = client
        .create_gui_plane(&GuiPlaneOptions {
            bounds: Some(([0.0, 0.0], [400.0, 300.0])),
            tick_rate: Some(0.0),
            ..Default::default()
        })
        .unwrap();
    let path = file("gui");
    plane.plane().start_recording(Some(&path)).unwrap();
    let mut objects = Vec::new();
    for t in 0..90u32 {
        if t % 10 == 0 {
            let at = [40.0 + 27.0 * (t / 10) as f32, 200.0 - 3.0 * t as f32];
            objects.push(plane.add(GuiShape::Square, [30.0, 30.0], at, &[]).unwrap());
        }
        if t % 7 == 3 {
            let o = &objects[t as usize % objects.len()];
            o.apply_impulse([150.0, -400.0]).unwrap();
        }
        plane.step(DT).unwrap();
    }
    let info = plane
        .plane()
        .stop_recording()
        .unwrap()
        .expect("it recorded");
    assert_eq!(info.ticks, 90);
    let recorded = plane.plane().snapshot().unwrap().bodies().to_vec();
    let (ticks, replayed) = replay_all(&daemon, &path);
    assert_eq!(ticks, 90);
    assert_eq!(first_difference(&recorded, &replayed), None);
}

#[test]
fn a_defer_gpu_plane_recording_replays_bit_for_bit() {
    let scene = Scene::new(
        "record-gpu",
        PlaneOptions {
            defer_gpu: Some(true),
            ..no_damping()
        },
    );
    physics_scenes::container(&mut &scene.plane, 8.0, 6.0).unwrap();
    let path = file("gpu");
    scene.plane.start_recording(Some(&path)).unwrap();
    let mut objects: Vec<Object> = Vec::new();
    for t in 0..60u32 {
        if t < 24 {
            let at = [
                (t % 4) as f32 * 1.3 - 2.0,
                2.0 + (t / 4) as f32 * 1.2,
                ((t * 7) % 5) as f32 * 0.9 - 1.8,
            ];
            let shape = match t % 2 {
                0 => Shape::Sphere { radius: 0.5 },
                _ => Shape::Cube { size: [0.9; 3] },
            };
            objects.push(scene.plane.add(shape, Pose::at(at), &[]).unwrap());
        }
        if t == 30 {
            objects[5].apply_impulse([0.0, 3.0, 4.0]).unwrap();
        }
        scene.plane.step(DT).unwrap();
    }
    let info = scene.plane.stop_recording().unwrap().expect("it recorded");
    assert_eq!(info.ticks, 60);
    let recorded = scene.plane.snapshot().unwrap().bodies().to_vec();
    let (ticks, replayed) = replay_all(&scene.daemon, &path);
    assert_eq!(ticks, 60);
    assert_eq!(first_difference(&recorded, &replayed), None);
}

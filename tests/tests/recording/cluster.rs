//! A recording of a plane that moves to another daemon of its cluster: recording on `a`,
//! stepped, moved to `b` (`Plane::move_to`) and stepped on there. The file on `a` ends
//! with the move (its end entry says so) and replays with every tick's hash equal, the
//! write sent with the move included; a recording started on `b` through the moved
//! plane's handle replays too, on either daemon.

use crate::common::{file_hashes, replay_to_end, RemoveOnDrop, TempDir};
use std::path::Path;
use std::sync::Arc;
use std::time::Duration;

use client_sdk::{load_recording, Object, ObjectProp, Plane, PlaneOptions, Pose, Recording, Shape};
use integration_tests::cluster::{endpoint, free_port, member, unique_cluster};
use integration_tests::{eventually, TestDaemon};

const DT: f32 = 1.0 / 60.0;

/// Two members of one cluster, `a` and `b`.
struct Pair {
    a: TestDaemon,
    b: TestDaemon,
}

fn pair(tag: &str) -> Pair {
    let cluster = unique_cluster(tag);
    let (pa, pb) = (free_port(), free_port());
    let a = member(&cluster, "a", pa, &[], &[]);
    let b = member(&cluster, "b", pb, &[pa], &[]);
    let view = client_sdk::cluster::Cluster::connect(&cluster, &[&endpoint(pa)]).unwrap();
    eventually(Duration::from_secs(10), || {
        (view.daemons().ok()?.len() == 2).then_some(())
    })
    .expect("both members joined");
    Pair { a, b }
}

/// A pile of cubes on a floor with a ball thrown into it and a paddle beside it.
fn game(plane: &Plane) -> (Vec<Object>, Object) {
    physics_scenes::floor(&mut &*plane, 60.0, &[]).unwrap();
    let cubes = physics_scenes::pyramid(&mut &*plane, 4, 0.0).unwrap();
    physics_scenes::ball(
        &mut &*plane,
        [-10.0, 1.0, 0.0],
        &[ObjectProp::Velocity([14.0, 4.0, 0.2])],
    )
    .unwrap();
    let paddle = plane
        .add(
            Shape::Cube {
                size: [1.0, 1.5, 0.4],
            },
            Pose::at([0.0, 1.2, 2.0]),
            &[ObjectProp::GravityScale(0.0)],
        )
        .unwrap();
    (cubes, paddle)
}

/// Ticks `from..=to`: the paddle's velocity every tick, an impulse every 10; (tick, hash)
/// of each step.
fn play(plane: &Plane, cubes: &[Object], paddle: &Object, from: u32, to: u32) -> Vec<(u64, u64)> {
    (from..=to)
        .map(|t| {
            paddle
                .set_velocity([0.0, 0.0, -3.0 * (t as f32 * 0.08).sin()])
                .unwrap();
            if t % 10 == 3 {
                cubes[t as usize % cubes.len()]
                    .apply_impulse([0.0, 3.0, -1.0])
                    .unwrap();
            }
            let tick = plane.step(DT).unwrap();
            (tick, plane.state_hash().unwrap())
        })
        .collect()
}

/// The recording at `path` once its end entry is written.
fn finished(path: &Path) -> Recording {
    eventually(Duration::from_secs(5), || {
        load_recording(path).ok().filter(|r| r.end.is_some())
    })
    .unwrap_or_else(|| {
        panic!(
            "{} has no end entry: {:?}",
            path.display(),
            load_recording(path).map(|r| r.events.len())
        )
    })
}

#[test]
fn a_recording_of_a_plane_that_moves_to_another_daemon_ends_there_goes_on_there_and_replays() {
    let pair = pair("rec-move");
    let dir = TempDir::new("rec-move");
    let owner = pair.a.client();
    let plane = owner.create_plane(&PlaneOptions::manual()).unwrap();
    let (cubes, paddle) = game(&plane);
    plane.step(DT).unwrap();
    let on_a = dir.join("on-a.physrec");
    plane.start_recording(Some(&on_a)).unwrap();
    let live_a = play(&plane, &cubes, &paddle, 1, 40);
    // A write queued right before the move goes with the move's request: applied on a,
    // before the cut, so it is in a's recording.
    paddle.set_velocity([0.0, 2.0, 0.0]).unwrap();
    plane.move_to("b").unwrap();
    assert_eq!(plane.daemon().as_deref(), Some("b"));
    let first_on_b = plane.step(DT).unwrap();
    assert_eq!(first_on_b, 42, "tick 41 on a, 42 on b");
    let hash_on_b = plane.state_hash().unwrap();
    let live_b = play(&plane, &cubes, &paddle, 42, 70);

    // The file on a ends with the move.
    let recording_a = Arc::new(finished(&on_a));
    let end = recording_a.end.clone().unwrap();
    assert!(
        end.contains("moved") && end.contains('b'),
        "end entry: {end:?}"
    );
    assert_eq!(recording_a.start.daemon, "a");
    assert_eq!(recording_a.tick_count(), 40);
    assert_eq!(file_hashes(&recording_a), live_a);
    // The recording goes on on b, in a file of b's own (its recordings folder), from the
    // state the plane arrived in: ticks 42..=71 (the first on b included) replay too.
    let info = plane
        .stop_recording()
        .unwrap()
        .expect("b records the plane on");
    let _remove_b = RemoveOnDrop(info.path.clone().into());
    assert_eq!(info.ticks, 30);
    let arrived = Arc::new(load_recording(&info.path).unwrap());
    assert_eq!(arrived.start.daemon, "b");
    assert_eq!(arrived.first_tick(), 41, "it starts where a's ends");
    assert_eq!(arrived.end.as_deref(), Some("stopped"));
    let mut on_b = vec![(first_on_b, hash_on_b)];
    on_b.extend(live_b.iter().copied());
    assert_eq!(file_hashes(&arrived), on_b);
    assert_eq!(replay_to_end(&pair.a.client(), &arrived).0, on_b);

    // It replays on a, and the replayed plane steps on to what b computed after the move
    // (the write sent with the move is in the file).
    let (replayed, replay) = replay_to_end(&pair.a.client(), &recording_a);
    assert_eq!(replayed, live_a);
    assert_eq!(replay.plane().step(DT).unwrap(), 42);
    assert_eq!(
        replay.plane().state_hash().unwrap(),
        hash_on_b,
        "the replay, stepped once more, agrees with b's first tick"
    );

    // A recording started on b through the moved plane's handle: the client reaches b
    // through a's relay, so the path it asks for is dropped (a remote client names no file
    // on the daemon's host) and b names the file in its recordings folder.
    let asked = dir.join("on-b.physrec");
    let on_b = plane.start_recording(Some(&asked)).unwrap();
    assert!(!asked.exists(), "a remote client's path is not written");
    assert_ne!(on_b, asked);
    let _remove = RemoveOnDrop(on_b.clone());
    let live_b2 = play(&plane, &cubes, &paddle, 71, 100);
    let info = plane.stop_recording().unwrap().expect("recording on b");
    assert_eq!(info.ticks, 30);
    let recording_b = Arc::new(load_recording(&on_b).unwrap());
    assert_eq!(recording_b.start.daemon, "b");
    assert_eq!(recording_b.end.as_deref(), Some("stopped"));
    assert_eq!(recording_b.first_tick(), live_b.last().unwrap().0);
    assert_eq!(file_hashes(&recording_b), live_b2);
    for (what, client) in [("b", pair.b.client()), ("a", pair.a.client())] {
        let (replayed, _replay) = replay_to_end(&client, &recording_b);
        assert_eq!(replayed, live_b2, "b's recording replayed on {what}");
    }
}

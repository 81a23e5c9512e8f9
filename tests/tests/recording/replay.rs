//! Recording planes and replaying the files through real daemons: a scenario game (a pile,
//! a thrown ball, a paddle written every tick, a joint chain, a ray every tick, objects
//! added and removed, Gravity changed) recorded on a manual plane replays with every tick's
//! hash equal and ends in the same bodies bit for bit, on a new client and on another
//! daemon; so does a plane ticking by itself with writes landing between its ticks, every
//! plane of a daemon started with `--record DIR`, and a recording with rewinds and restores
//! in it. Periodic keyframes let a replay seek forwards and back. A damaged file is refused
//! naming the byte offset of the entry; a rewritten tick hash stops the replay at that tick
//! naming the batch before it; bad recording requests are refused by name.

use crate::common::{file_hashes, replay_to_end, TempDir};
use integration_tests::recording_file::{entries, forge_tick_hash, tick_entry};
use std::collections::BTreeSet;
use std::path::Path;
use std::sync::Arc;
use std::time::{Duration, Instant};

use client_sdk::{
    first_difference, load_recording, Advanced, BodyState, Client, Error, ErrorKind, Joint,
    JointKind, JointProp, Object, ObjectProp, Plane, PlaneOptions, PlaneProp, Pose, Recording,
    Replay, Shape,
};
use integration_tests::{eventually, TestDaemon};
use shm_layout::recording::{EntryTag, Event, KeyframeWhy, ENTRY_OVERHEAD};

const DT: f32 = 1.0 / 60.0;
/// Ticks the scenario game is recorded for.
const GAME_TICKS: u32 = 240;

/// The scenario game's handles.
struct Game {
    plane: Plane,
    /// The pyramid's ten cubes, row by row from the bottom.
    cubes: Vec<Object>,
    /// A floating box pushed back and forth by a Velocity write every tick.
    paddle: Object,
    /// The joints of the chain, from the world down.
    links: Vec<Joint>,
    /// Objects added while playing.
    added: Vec<Object>,
}

/// On a floor: a base-4 pyramid of unit cubes, a ball thrown into it, a weightless paddle
/// beside it and a chain of four balls on ball joints hung from the world.
fn build_game(plane: Plane) -> Game {
    physics_scenes::floor(&mut &plane, 60.0, &[]).unwrap();
    let cubes = physics_scenes::pyramid(&mut &plane, 4, 0.0).unwrap();
    physics_scenes::ball(
        &mut &plane,
        [-10.0, 1.0, 0.0],
        &[
            ObjectProp::Velocity([14.0, 4.0, 0.2]),
            ObjectProp::Bounciness(0.4),
        ],
    )
    .unwrap();
    let paddle = plane
        .add(
            Shape::Cube {
                size: [1.0, 1.5, 0.4],
            },
            Pose::at([0.0, 1.2, 2.0]),
            &[ObjectProp::GravityScale(0.0), ObjectProp::Weight(20.0)],
        )
        .unwrap();
    let mut links = Vec::new();
    let mut prev: Option<Object> = None;
    let mut anchor = [-4.0, 6.0, -3.0];
    for i in 0..4 {
        let at = [-4.0 + 0.5 * (i + 1) as f32, 6.0, -3.0];
        let link = plane
            .add(Shape::Sphere { radius: 0.2 }, Pose::at(at), &[])
            .unwrap();
        let joint = plane
            .joint(
                JointKind::Ball,
                &link,
                prev.as_ref(),
                &[
                    JointProp::AnchorA([anchor[0] - at[0], anchor[1] - at[1], 0.0]),
                    JointProp::AnchorB(if prev.is_some() { [0.0; 3] } else { anchor }),
                ],
            )
            .unwrap();
        links.push(joint);
        prev = Some(link);
        anchor = at;
    }
    Game {
        plane,
        cubes,
        paddle,
        links,
        added: Vec::new(),
    }
}

/// What the game sends before the step of its tick `t` (counted from 1): the paddle's
/// velocity and a ray down through the pile every tick, impulses every 25 ticks, a ball
/// thrown at 30, three boxes dropped at 60, a cube and a box removed at 90, Gravity changed
/// at 120 and 180, the chain's last joint removed at 150.
fn play(game: &mut Game, t: u32) {
    let plane = game.plane.clone();
    game.paddle
        .set_velocity([0.0, 0.0, -3.0 * (t as f32 * 0.08).sin()])
        .unwrap();
    game.paddle.set_angular_velocity([0.0; 3]).unwrap();
    if t % 25 == 5 {
        // Cubes 0..9: cube 9 (the top) is removed at 90.
        let cube = &game.cubes[(t / 25) as usize % 9];
        cube.apply_impulse([0.0, 3.0, -2.0]).unwrap();
    }
    match t {
        30 => {
            let ball = plane
                .add(
                    Shape::Sphere { radius: 0.4 },
                    Pose::at([10.0, 2.0, 0.3]),
                    &[ObjectProp::Velocity([-15.0, 3.0, 0.5])],
                )
                .unwrap();
            game.added.push(ball);
        }
        60 => {
            for i in 0..3 {
                let o = plane
                    .add(
                        Shape::Cube {
                            size: [0.6, 0.6, 0.6],
                        },
                        Pose::at([-1.0 + i as f32, 6.0 + 0.7 * i as f32, -1.0]),
                        &[],
                    )
                    .unwrap();
                game.added.push(o);
            }
        }
        90 => {
            game.cubes[9].destroy();
            game.added[2].destroy();
        }
        120 => plane.set(PlaneProp::Gravity([0.0, -20.0, 0.0])).unwrap(),
        150 => game.links[3].destroy().unwrap(),
        180 => plane.set(PlaneProp::Gravity([1.0, -50.0, 0.0])).unwrap(),
        _ => {}
    }
    // A hitscan down through the pile, as a game's gun would.
    plane
        .raycast([0.3, 10.0, 0.1], [0.0, -20.0, 0.0], None)
        .unwrap();
}

/// Plays ticks `from..=to` of the game, stepping after each; returns (tick, state hash) of
/// every step as the plane published it.
fn play_ticks(game: &mut Game, from: u32, to: u32) -> Vec<(u64, u64)> {
    (from..=to)
        .map(|t| {
            play(game, t);
            let tick = game.plane.step(DT).unwrap();
            (tick, game.plane.state_hash().unwrap())
        })
        .collect()
}

/// A recorded game: the game, the live (tick, hash) of every step recorded, the plane's
/// final bodies and the recording.
type Recorded = (Game, Vec<(u64, u64)>, Vec<BodyState>, Arc<Recording>);

/// The game on a new manual plane of `client`, recorded into `path` from tick `warm_up`
/// for `ticks` ticks.
fn record_game(client: &Client, path: &Path, warm_up: u32, ticks: u32) -> Recorded {
    let mut game = build_game(client.create_plane(&PlaneOptions::manual()).unwrap());
    for _ in 0..warm_up {
        game.plane.step(DT).unwrap();
    }
    assert_eq!(game.plane.start_recording(Some(path)).unwrap(), path);
    let live = play_ticks(&mut game, 1, ticks);
    let info = game
        .plane
        .stop_recording()
        .unwrap()
        .expect("the plane was recording");
    assert_eq!(Path::new(&info.path), path);
    assert_eq!(info.ticks, ticks as u64, "RecordingInfo.ticks");
    assert_eq!(
        info.bytes,
        std::fs::metadata(path).unwrap().len(),
        "RecordingInfo.bytes is the file's size once stopped"
    );
    let bodies = game.plane.snapshot().unwrap().bodies().to_vec();
    let recording = Arc::new(load_recording(path).unwrap());
    (game, live, bodies, recording)
}

/// Panics naming the first field whose bits differ between `a` and `b`.
fn assert_same_bodies(a: &[BodyState], b: &[BodyState], what: &str) {
    if let Some(d) = first_difference(a, b) {
        panic!("{what}: {d}");
    }
}

/// The message `load_recording` refuses `bytes` with (written to `path` first).
fn refusal(path: &Path, bytes: &[u8]) -> String {
    std::fs::write(path, bytes).unwrap();
    match load_recording(path) {
        Ok(r) => panic!(
            "{} was read ({} events) instead of refused",
            path.display(),
            r.events.len()
        ),
        Err(e) => e.to_string(),
    }
}

#[test]
fn a_scenario_game_recorded_on_a_manual_plane_replays_with_every_hash_equal() {
    let daemon = TestDaemon::start("rec-game");
    let other = TestDaemon::start("rec-game-other");
    let dir = TempDir::new("rec-game");
    let path = dir.join("game.physrec");
    let client = daemon.client();
    // Recording starts at tick 10: the ball is in flight, the chain swinging.
    let (_game, live, bodies, recording) = record_game(&client, &path, 10, GAME_TICKS);
    assert_eq!(recording.first_tick(), 10);
    assert_eq!(recording.last_tick(), 10 + GAME_TICKS as u64);
    assert_eq!(recording.tick_count(), GAME_TICKS as u64);
    assert!(recording.end.is_some(), "a stopped recording has its end");
    assert_eq!(
        file_hashes(&recording),
        live,
        "the file holds every tick's hash as the plane published it"
    );
    let distinct: BTreeSet<u64> = live.iter().map(|&(_, h)| h).collect();
    assert_eq!(distinct.len(), live.len(), "the game moves on every tick");
    // A batch before every tick (the paddle and the ray), with the ray among its ops.
    let batches: Vec<&Event> = recording
        .events
        .iter()
        .filter(|e| matches!(e, Event::Batch { .. }))
        .collect();
    assert_eq!(batches.len(), GAME_TICKS as usize, "one batch per tick");
    let ops = recording.ops(batches[0]).unwrap();
    assert!(
        ops.iter()
            .any(|op| matches!(op, client_sdk::PlaneOp::Query(_))),
        "the ray is recorded: {ops:?}"
    );
    for (what, client) in [
        ("a new client of the recording daemon", daemon.client()),
        ("a client of another daemon", other.client()),
    ] {
        let (replayed, replay) = replay_to_end(&client, &recording);
        assert_eq!(
            replayed.len(),
            GAME_TICKS as usize,
            "{what}: ticks replayed"
        );
        assert_eq!(replayed, live, "{what}: the replayed hashes");
        let again = replay.plane().snapshot().unwrap().bodies().to_vec();
        assert_same_bodies(&bodies, &again, what);
        assert_eq!(replay.ops_at(10 + 100).len(), ops_before(&recording, 110));
    }
}

/// How many ops the recording applied at `tick`.
fn ops_before(recording: &Recording, tick: u64) -> usize {
    recording
        .events
        .iter()
        .filter_map(|e| match e {
            Event::Batch { tick: t, count, .. } if *t == tick => Some(*count as usize),
            _ => None,
        })
        .sum()
}

/// A recording started right after objects were added, before the plane steps again: its
/// start keyframe holds bodies that have not moved yet (the thrown ball with its velocity),
/// and the replay restores it and steps on with every hash equal.
#[test]
fn a_recording_started_right_after_adds_replays_with_every_hash_equal() {
    let daemon = TestDaemon::start("rec-fresh");
    let dir = TempDir::new("rec-fresh");
    let path = dir.join("fresh.physrec");
    let client = daemon.client();
    // Recording starts at tick 0, with the whole game just added.
    let (_game, live, bodies, recording) = record_game(&client, &path, 0, 60);
    assert_eq!(file_hashes(&recording), live);
    let (replayed, replay) = replay_to_end(&daemon.client(), &recording);
    assert_eq!(replayed, live);
    let again = replay.plane().snapshot().unwrap().bodies().to_vec();
    assert_same_bodies(&bodies, &again, "a recording started before the first step");
}

#[test]
fn a_plane_ticking_by_itself_with_writes_between_its_ticks_replays() {
    let daemon = TestDaemon::start("rec-ticking");
    let dir = TempDir::new("rec-ticking");
    let client = daemon.client();
    let plane = client
        .create_plane(&PlaneOptions {
            tick_rate: Some(60.0),
            ..Default::default()
        })
        .unwrap();
    physics_scenes::floor(&mut &plane, 60.0, &[]).unwrap();
    let cubes = physics_scenes::pyramid(&mut &plane, 4, 0.0).unwrap();
    let paddle = plane
        .add(
            Shape::Cube {
                size: [1.0, 1.5, 0.4],
            },
            Pose::at([0.0, 1.2, 2.0]),
            &[ObjectProp::GravityScale(0.0)],
        )
        .unwrap();
    client.flush().unwrap();
    let path = dir.join("ticking.physrec");
    plane.start_recording(Some(&path)).unwrap();
    let started = Instant::now();
    let mut added = Vec::new();
    let mut writes = 0u32;
    // About a second, and at least 40 rounds of writes (a loaded machine takes longer).
    while started.elapsed() < Duration::from_secs(1)
        || (writes < 40 && started.elapsed() < Duration::from_secs(5))
    {
        writes += 1;
        let i = writes;
        paddle
            .set_velocity([0.0, 0.0, -3.0 * (i as f32 * 0.1).sin()])
            .unwrap();
        if i.is_multiple_of(7) {
            cubes[(i / 7) as usize % cubes.len()]
                .apply_impulse([0.5, 4.0, 0.0])
                .unwrap();
        }
        match i {
            10 => added.push(
                plane
                    .add(
                        Shape::Sphere { radius: 0.4 },
                        Pose::at([-6.0, 1.0, 0.0]),
                        &[ObjectProp::Velocity([12.0, 2.0, 0.0])],
                    )
                    .unwrap(),
            ),
            25 => plane.set(PlaneProp::Gravity([0.0, -30.0, 0.0])).unwrap(),
            35 => added[0].destroy(),
            _ => {}
        }
        client.flush().unwrap();
        std::thread::sleep(Duration::from_millis(7));
    }
    let info = plane.stop_recording().unwrap().expect("it was recording");
    let recording = Arc::new(load_recording(&path).unwrap());
    assert_eq!(info.ticks, recording.tick_count());
    // 60 ticks in the second; at least a third of them on a loaded machine.
    assert!(
        info.ticks >= 20,
        "{} ticks recorded in a second at TickRate 60",
        info.ticks
    );
    assert!(writes >= 40, "{writes} rounds of writes in a second");
    let batch_ticks: BTreeSet<u64> = recording
        .events
        .iter()
        .filter_map(|e| match e {
            Event::Batch { tick, .. } => Some(*tick),
            _ => None,
        })
        .collect();
    println!(
        "{} ticks recorded in {:?}, {writes} rounds of writes, batches at {} ticks",
        info.ticks,
        started.elapsed(),
        batch_ticks.len()
    );
    assert!(
        batch_ticks.len() >= 15,
        "the writes landed between many ticks: {batch_ticks:?}"
    );
    let recorded = file_hashes(&recording);
    let (replayed, _replay) = replay_to_end(&daemon.client(), &recording);
    assert_eq!(replayed.len(), info.ticks as usize);
    assert_eq!(replayed, recorded);
}

#[test]
fn a_daemon_started_with_record_writes_a_file_per_plane_that_replays() {
    let dir = TempDir::new("rec-dir");
    let folder = dir.path().to_str().unwrap().to_string();
    let daemon = TestDaemon::start_with("rec-dir", &["--record", &folder], &[]);
    let other = TestDaemon::start("rec-dir-replay");
    // A plane destroyed by its owner.
    let client = daemon.client();
    let mut first = build_game(client.create_plane(&PlaneOptions::manual()).unwrap());
    let first_live = play_ticks(&mut first, 1, 40);
    let first_id = first.plane.id();
    // Recording is on already: asking again is refused.
    assert!(first
        .plane
        .start_recording(Some(&dir.join("again.physrec")))
        .is_err());
    first.plane.destroy().unwrap();
    // A plane whose client goes away.
    let (second_id, second_live) = {
        let client = daemon.client();
        let mut second = build_game(client.create_plane(&PlaneOptions::manual()).unwrap());
        let live = play_ticks(&mut second, 1, 30);
        (second.plane.id(), live)
    };
    let files = eventually(Duration::from_secs(10), || {
        let mut found = Vec::new();
        for entry in std::fs::read_dir(dir.path()).ok()? {
            let path = entry.ok()?.path();
            let recording = load_recording(&path).ok()?;
            recording.end.as_ref()?;
            found.push((path, recording));
        }
        (found.len() == 2).then_some(found)
    })
    .unwrap_or_else(|| {
        let names: Vec<_> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        panic!("not two finished recordings in {folder}: {names:?}")
    });
    for (id, live) in [(first_id, first_live), (second_id, second_live)] {
        let (path, recording) = files
            .iter()
            .find(|(_, r)| r.start.plane == id)
            .unwrap_or_else(|| panic!("no recording of plane {id}"));
        let name = path.file_name().unwrap().to_str().unwrap();
        let ms = name
            .strip_prefix(&format!("plane-{id}-"))
            .and_then(|n| n.strip_suffix(".physrec"))
            .unwrap_or_else(|| panic!("{name} is not plane-<id>-<unix ms>.physrec"));
        // Named when the file is made, just before the start entry is written.
        let named_ms: u64 = ms.parse().unwrap();
        let started = recording.start.started_unix_ms;
        assert!(
            named_ms <= started && started - named_ms < 1000,
            "{name}: started at {started} ms"
        );
        // Recorded from its creation: the objects come in the batches.
        assert_eq!(recording.first_tick(), 0);
        assert_eq!(file_hashes(recording), live, "plane {id}");
        let (replayed, _replay) = replay_to_end(&other.client(), &Arc::new(recording.clone()));
        assert_eq!(replayed, live, "plane {id} replayed on another daemon");
    }
}

#[test]
fn periodic_keyframes_let_a_replay_seek_forwards_and_back() {
    let daemon = TestDaemon::start_with("rec-keys", &["--record-keyframe-every", "50"], &[]);
    let dir = TempDir::new("rec-keys");
    let path = dir.join("keys.physrec");
    let client = daemon.client();
    // Recording starts at tick 10: the keyframes are every 50 ticks from there.
    let k0 = 10u64;
    let (_game, live, bodies, recording) = record_game(&client, &path, k0 as u32, 300);
    assert_eq!(recording.start.keyframe_every, 50);
    let periodic: Vec<(u64, u64)> = recording
        .events
        .iter()
        .filter_map(|e| match e {
            Event::Keyframe {
                why: KeyframeWhy::Periodic,
                tick,
                state_hash,
                ..
            } => Some((*tick, *state_hash)),
            _ => None,
        })
        .collect();
    let ticks: Vec<u64> = periodic.iter().map(|&(t, _)| t).collect();
    let every_50: Vec<u64> = (1..=6).map(|k| k0 + 50 * k).collect();
    assert_eq!(ticks, every_50);
    let hash_at = |tick: u64| live[(tick - k0) as usize - 1].1;
    for (tick, hash) in periodic {
        assert_eq!(hash, hash_at(tick), "the keyframe of tick {tick}");
    }
    // From the start to 200, against a seek that enters at the keyframe of 200.
    let mut from_start = Replay::start(&daemon.client(), recording.clone()).unwrap();
    assert_eq!(
        from_start.run(Some(k0 + 200)).unwrap(),
        Advanced::Tick(k0 + 200)
    );
    let mut seeking = Replay::start(&daemon.client(), recording.clone()).unwrap();
    assert_eq!(seeking.seek(k0 + 200).unwrap(), Advanced::Tick(k0 + 200));
    assert_eq!(seeking.tick(), k0 + 200);
    let hash = seeking.plane().state_hash().unwrap();
    assert_eq!(hash, from_start.plane().state_hash().unwrap());
    assert_eq!(hash, hash_at(k0 + 200));
    assert_same_bodies(
        from_start.plane().snapshot().unwrap().bodies(),
        seeking.plane().snapshot().unwrap().bodies(),
        "a seek to 200 against a replay from the start",
    );
    // Forwards past a keyframe, then back before the one it came from.
    assert_eq!(seeking.seek(k0 + 250).unwrap(), Advanced::Tick(k0 + 250));
    assert_eq!(seeking.plane().state_hash().unwrap(), hash_at(k0 + 250));
    assert_eq!(seeking.seek(k0 + 60).unwrap(), Advanced::Tick(k0 + 60));
    assert_eq!(seeking.tick(), k0 + 60);
    assert_eq!(seeking.plane().state_hash().unwrap(), hash_at(k0 + 60));
    // And on from there to the end, every hash checked.
    assert_eq!(seeking.run(None).unwrap(), Advanced::End);
    assert_eq!(seeking.tick(), k0 + 300);
    assert_same_bodies(
        &bodies,
        seeking.plane().snapshot().unwrap().bodies(),
        "the end after seeking back",
    );
}

#[test]
fn a_damaged_file_is_refused_naming_the_entry_and_one_without_its_end_replays() {
    let daemon = TestDaemon::start("rec-damage");
    let dir = TempDir::new("rec-damage");
    let path = dir.join("good.physrec");
    let client = daemon.client();
    let (_game, live, _bodies, recording) = record_game(&client, &path, 5, 60);
    let good = recording.bytes.clone();
    let bad_path = dir.join("bad.physrec");

    // A byte of an op inside a batch entry in the middle.
    let batch = recording
        .events
        .iter()
        .filter_map(|e| match e {
            Event::Batch { offset, range, .. } => Some((*offset, range.clone())),
            _ => None,
        })
        .nth(30)
        .expect("a 31st batch");
    let (batch_at, ops) = batch;
    let mut bad = good.clone();
    bad[ops.start + ops.len() / 2] ^= 0x08;
    let e = refusal(&bad_path, &bad);
    assert!(e.contains("byte offset"), "{e}");
    assert!(
        e.contains(&format!("batch entry at byte offset {batch_at} ")),
        "{e}"
    );

    // A byte inside the start keyframe's snapshot.
    let Event::Keyframe { range, .. } = &recording.events[0] else {
        panic!("the first event is the start keyframe")
    };
    // Tag, length and the keyframe's why byte come before the snapshot.
    let keyframe_at = range.start - 6;
    let mut bad = good.clone();
    bad[range.start + range.len() / 2] ^= 0x01;
    let e = refusal(&bad_path, &bad);
    assert!(
        e.contains(&format!("keyframe entry at byte offset {keyframe_at} ")),
        "{e}"
    );

    // Cut short inside a tick entry and inside a batch entry.
    let tick_at = tick_entry(&good, 5 + 40);
    let e = refusal(&bad_path, &good[..tick_at + 10]);
    assert!(
        e.contains(&format!("inside the entry at byte offset {tick_at} (")),
        "{e}"
    );
    let e = refusal(&bad_path, &good[..batch_at + ENTRY_OVERHEAD + 2]);
    assert!(
        e.contains(&format!("inside the entry at byte offset {batch_at} (")),
        "{e}"
    );

    // Without its end entry (a daemon killed while recording): it reads and replays.
    let all = entries(&good);
    let &(end_at, tag, _) = all.last().unwrap();
    assert_eq!(tag, EntryTag::End as u8, "the last entry is the end");
    let cut = dir.join("no-end.physrec");
    std::fs::write(&cut, &good[..end_at]).unwrap();
    let without_end = Arc::new(load_recording(&cut).unwrap());
    assert_eq!(without_end.end, None);
    assert_eq!(without_end.tick_count(), 60);
    let (replayed, _replay) = replay_to_end(&daemon.client(), &without_end);
    assert_eq!(replayed, live);
}

#[test]
fn a_rewritten_tick_hash_stops_the_replay_at_that_tick_naming_the_batch_before_it() {
    let daemon = TestDaemon::start("rec-diverge");
    let dir = TempDir::new("rec-diverge");
    let path = dir.join("game.physrec");
    let client = daemon.client();
    let k0 = 5u64;
    let (_game, live, _bodies, recording) = record_game(&client, &path, k0 as u32, 60);
    let tick = k0 + 40;
    let good = &recording.bytes;
    let hash = recording
        .events
        .iter()
        .find_map(|e| match e {
            Event::Tick {
                tick: t,
                state_hash,
                ..
            } if *t == tick => Some(*state_hash),
            _ => None,
        })
        .unwrap();
    assert_eq!(hash, live[(tick - k0) as usize - 1].1);
    // The batch applied after the tick before.
    let batch_at = recording
        .events
        .iter()
        .find_map(|e| match e {
            Event::Batch {
                tick: t, offset, ..
            } if *t == tick - 1 => Some(*offset),
            _ => None,
        })
        .expect("a batch before the tick");
    let (bytes, forged) = forge_tick_hash(good, tick);
    let patched = Arc::new(Recording::parse(bytes).expect("a well-formed file"));

    let mut replay = Replay::start(&daemon.client(), patched.clone()).unwrap();
    let mut agreed = 0;
    let divergence = loop {
        match replay.advance().unwrap() {
            Advanced::Tick(t) => {
                agreed += 1;
                assert_eq!(t, k0 + agreed);
            }
            Advanced::Diverged(d) => break d,
            Advanced::End => panic!("the replay ran to the end past a forged hash"),
        }
    };
    assert_eq!(
        agreed,
        tick - k0 - 1,
        "every tick before the forged one agrees"
    );
    assert_eq!(divergence.tick, tick);
    assert_eq!(divergence.recorded, forged);
    assert_eq!(
        divergence.replayed, hash,
        "the replay computes what the plane did"
    );
    assert_eq!(replay.tick(), tick, "the replay stays at the tick");
    let text = divergence.to_string();
    assert!(
        text.contains(&format!("diverged at tick {tick}:")),
        "{text}"
    );
    assert!(
        text.contains(&format!(
            "applied at tick {} (entry at byte offset {batch_at})",
            tick - 1
        )),
        "{text}"
    );
    // run() stops at the same place.
    let mut again = Replay::start(&daemon.client(), patched).unwrap();
    match again.run(None).unwrap() {
        Advanced::Diverged(d) => assert_eq!(d, divergence),
        other => panic!("run() gave {other:?}"),
    }
}

#[test]
fn rewinds_and_restores_while_recording_replay_through_their_jump_keyframes() {
    let daemon = TestDaemon::start("rec-jump");
    let dir = TempDir::new("rec-jump");
    let path = dir.join("jumps.physrec");
    let client = daemon.client();
    let mut game = build_game(
        client
            .create_plane(&PlaneOptions {
                rollback_ticks: Some(8),
                ..PlaneOptions::manual()
            })
            .unwrap(),
    );
    for _ in 0..5 {
        game.plane.step(DT).unwrap();
    }
    game.plane.start_recording(Some(&path)).unwrap();
    let mut live = play_ticks(&mut game, 1, 20);
    // Back 3 ticks (25 to 22), then on with other writes.
    assert_eq!(game.plane.rewind(3).unwrap(), 22);
    live.extend(play_ticks(&mut game, 21, 40));
    let snapshot = game.plane.take_snapshot().unwrap();
    live.extend(play_ticks(&mut game, 41, 50));
    // Back to the snapshot (tick 42), and on again.
    assert_eq!(game.plane.restore(&snapshot).unwrap(), snapshot.tick());
    live.extend(play_ticks(&mut game, 51, 65));
    let info = game.plane.stop_recording().unwrap().unwrap();
    let bodies = game.plane.snapshot().unwrap().bodies().to_vec();
    let recording = Arc::new(load_recording(&path).unwrap());
    let jumps: Vec<u64> = recording
        .events
        .iter()
        .filter_map(|e| match e {
            Event::Keyframe {
                why: KeyframeWhy::Jump,
                tick,
                ..
            } => Some(*tick),
            _ => None,
        })
        .collect();
    assert_eq!(jumps, vec![22, snapshot.tick()]);
    assert_eq!(info.ticks, 65);
    assert_eq!(recording.tick_count(), 65);
    assert_eq!(file_hashes(&recording), live);
    let (replayed, replay) = replay_to_end(&daemon.client(), &recording);
    assert_eq!(replayed, live);
    assert_same_bodies(
        &bodies,
        replay.plane().snapshot().unwrap().bodies(),
        "the end of a replay through jumps",
    );
}

#[test]
fn bad_recording_requests_are_refused_by_name_and_the_daemon_serves_on() {
    let daemon = TestDaemon::start("rec-bad");
    let dir = TempDir::new("rec-bad");
    let client = daemon.client();
    let plane = client
        .create_plane(&PlaneOptions {
            shared: Some(true),
            ..PlaneOptions::manual()
        })
        .unwrap();
    let ball = physics_scenes::ball(&mut &plane, [0.0, 5.0, 0.0], &[]).unwrap();
    // Not recording: stopping says so.
    assert_eq!(plane.stop_recording().unwrap(), None);

    let path = dir.join("once.physrec");
    plane.start_recording(Some(&path)).unwrap();
    // Twice.
    let twice = dir.join("twice.physrec");
    let e = plane.start_recording(Some(&twice)).unwrap_err().to_string();
    assert!(e.contains("already"), "{e}");
    assert!(!twice.exists(), "a refused start creates no file");
    plane.step(DT).unwrap();
    let info = plane.stop_recording().unwrap().unwrap();
    assert_eq!(info.ticks, 1);

    // A file that exists: refused naming it, and left as it was.
    let e = plane.start_recording(Some(&path)).unwrap_err().to_string();
    assert!(e.contains(path.to_str().unwrap()), "{e}");
    assert_eq!(std::fs::metadata(&path).unwrap().len(), info.bytes);
    assert_eq!(load_recording(&path).unwrap().tick_count(), 1);
    // A folder that exists.
    let e = plane
        .start_recording(Some(dir.path()))
        .unwrap_err()
        .to_string();
    assert!(e.contains(dir.path().to_str().unwrap()), "{e}");
    // A folder that does not exist.
    let missing = dir.join("no-such-folder").join("x.physrec");
    let e = plane
        .start_recording(Some(&missing))
        .unwrap_err()
        .to_string();
    assert!(e.contains("no-such-folder"), "{e}");
    assert!(!missing.exists());

    // Another client of the shared plane: only the owner records.
    let other = daemon.client();
    let theirs = other.attach_plane(plane.id()).unwrap();
    for result in [
        theirs
            .start_recording(Some(&dir.join("theirs.physrec")))
            .map(|_| ()),
        theirs.stop_recording().map(|_| ()),
    ] {
        match result {
            Err(Error::Command(c)) => assert_eq!(c.kind, ErrorKind::NotOwner, "{}", c.message),
            got => panic!("expected NotOwner, got {got:?}"),
        }
    }
    assert!(!dir.join("theirs.physrec").exists());

    // The plane and the daemon serve on, and the plane records again.
    assert_eq!(plane.step(DT).unwrap(), 2);
    assert!(ball.position().unwrap()[1] < 5.0);
    let again = dir.join("again.physrec");
    plane.start_recording(Some(&again)).unwrap();
    let live: Vec<(u64, u64)> = (0..5)
        .map(|_| {
            let t = plane.step(DT).unwrap();
            (t, plane.state_hash().unwrap())
        })
        .collect();
    assert_eq!(plane.stop_recording().unwrap().unwrap().ticks, 5);
    let recording = Arc::new(load_recording(&again).unwrap());
    let (replayed, _replay) = replay_to_end(&daemon.client(), &recording);
    assert_eq!(replayed, live);

    // No path: the daemon names a file under the temporary folder.
    let named = plane.start_recording(None).unwrap();
    assert!(
        named.starts_with(std::env::temp_dir().join("physics-recordings")),
        "{}",
        named.display()
    );
    plane.step(DT).unwrap();
    let info = plane.stop_recording().unwrap().unwrap();
    assert_eq!(Path::new(&info.path), named);
    assert_eq!(load_recording(&named).unwrap().tick_count(), 1);
    std::fs::remove_file(&named).unwrap();
}

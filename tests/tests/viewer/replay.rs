//! `physics-view --replay FILE` in a real browser: three balls falling onto a floor are
//! recorded (120 ticks of 1/60 s, a ray cast at tick 30), the viewer plays the file into a
//! plane of its own and the test drives its timeline through the HTTP API. Headless
//! Chromium loads the page at two ticks: the page reports each tick, shows every body at the
//! pose a replay in the test reaches at that tick, and its two frames differ where the
//! balls moved and nowhere else (a grid of the canvas's pixels the page writes into the
//! DOM); the two screenshots differ. Play then pause moves the tick forward, a step moves
//! it by one, the ray of tick 30 is drawn at tick 30, contacts are those of the tick, a
//! forged tick hash stops playback with the divergence's message on the page, a damaged
//! file makes the viewer exit naming the byte offset, and with no daemon running the viewer
//! starts one and stops it when it exits.
//!
//! Chromium is required: without it the browser tests fail and say how to install it.

use crate::browser::{chromium, chromium_run, http, view_attributes, viewer_bin, TempDir, Viewer};
use integration_tests::recording_file::{forge_tick_hash, tick_entry};
use std::collections::HashMap;
use std::path::Path;
use std::process::{Command, Stdio};
use std::sync::Arc;
use std::time::Duration;

use client_sdk::{
    load_recording, Advanced, Client, Object, ObjectProp, Plane, PlaneOptions, Pose, Recording,
    Replay, Shape,
};
use integration_tests::{eventually, unique_domain, TestDaemon};
use serde_json::{json, Value};

const DT: f32 = 1.0 / 60.0;
/// Ticks recorded.
const TICKS: u64 = 120;
/// The tick after whose step the recorded ray is cast.
const RAY_TICK: u64 = 30;
/// The recorded ray.
const RAY: ([f32; 3], [f32; 3]) = ([0.0, 12.0, 2.0], [0.0, -12.0, 0.0]);
/// Poses travel f32 → JSON → JS double → JSON, and the two replays step the same ops with
/// the same dt (their hashes are checked equal to the recording's): 1e-4 is ample.
const POSE_TOLERANCE: f64 = 1e-4;

/// Loads the page until it shows the replay at `tick` and has rendered that tick (its
/// pixel grid written); returns #view's attributes.
fn load_tick(profile: &Path, url: &str, tick: u64) -> HashMap<String, String> {
    let mut last = HashMap::new();
    for _ in 0..4 {
        let dom = chromium_run(profile, &["--dump-dom".to_string()], url);
        let attrs = view_attributes(&dom);
        let want = tick.to_string();
        if attrs.get("data-replay-tick") == Some(&want)
            && attrs.get("data-frame-tick") == Some(&want)
            && attrs.contains_key("data-grid")
        {
            return attrs;
        }
        last = attrs;
    }
    last.remove("data-grid");
    panic!("the page never showed tick {tick} of the replay: #view = {last:?}");
}

/// A floor and three balls of radius 1 (no bounce) on a new manual plane of `client`,
/// recorded into `path` for [`TICKS`] ticks of 1/60 s with a ray cast after tick
/// [`RAY_TICK`]. Returns the recorded plane and the recording.
fn record_balls(client: &Client, path: &Path) -> (Plane, Arc<Recording>) {
    let plane = client.create_plane(&PlaneOptions::manual()).unwrap();
    plane
        .add(
            Shape::Cube {
                size: [8.0, 1.0, 8.0],
            },
            Pose::at([0.0, -0.5, 0.0]),
            &[ObjectProp::Anchored(true)],
        )
        .unwrap();
    for (x, y) in [(-3.0, 6.0), (0.0, 8.0), (3.0, 10.0)] {
        plane
            .add(
                Shape::Sphere { radius: 1.0 },
                Pose::at([x, y, 0.0]),
                &[ObjectProp::Bounciness(0.0)],
            )
            .unwrap();
    }
    assert_eq!(plane.start_recording(Some(path)).unwrap(), path);
    for tick in 1..=TICKS {
        plane.step(DT).unwrap();
        if tick == RAY_TICK {
            plane.raycast(RAY.0, RAY.1, None).unwrap();
        }
    }
    let info = plane.stop_recording().unwrap().expect("the plane recorded");
    let recording = load_recording(path).unwrap();
    assert_eq!(info.ticks, recording.tick_count());
    assert_eq!(recording.last_tick(), TICKS);
    // The recording enters at the state the first step made (or before it).
    assert!(recording.first_tick() <= 1, "{}", recording.first_tick());
    (plane, Arc::new(recording))
}

/// Every body of a plane (slot → position, rotation) as a replay in the test reaches `tick`.
type Poses = HashMap<u64, ([f64; 3], [f64; 4])>;

fn poses_at(replay: &mut Replay, tick: u64) -> Poses {
    match replay.seek(tick).unwrap() {
        Advanced::Tick(t) => assert_eq!(t, tick),
        other => panic!("seek({tick}): {other:?}"),
    }
    let snap = replay.plane().snapshot().unwrap();
    assert_eq!(snap.tick(), tick);
    snap.bodies()
        .iter()
        .enumerate()
        .filter(|(_, b)| b.is_alive())
        .map(|(slot, b)| {
            (
                slot as u64,
                (b.position.map(|v| v as f64), b.rotation.map(|v| v as f64)),
            )
        })
        .collect()
}

/// The bodies the page (or the API) shows equal `want`, slot by slot, within
/// [`POSE_TOLERANCE`].
fn assert_poses(shown: &Value, want: &Poses, what: &str) {
    let shown = shown.as_array().expect("bodies");
    assert_eq!(shown.len(), want.len(), "{what}: {shown:?}");
    for b in shown {
        let slot = b["slot"].as_u64().unwrap();
        let (p, q) = want
            .get(&slot)
            .unwrap_or_else(|| panic!("{what}: slot {slot} is not in the replay"));
        let num = |v: &Value| v.as_f64().expect("a number");
        for i in 0..3 {
            let got = num(&b["position"][i]);
            assert!(
                (got - p[i]).abs() <= POSE_TOLERANCE,
                "{what}: slot {slot} position {} vs {p:?}",
                b["position"]
            );
        }
        for i in 0..4 {
            let got = num(&b["rotation"][i]);
            assert!(
                (got - q[i]).abs() <= POSE_TOLERANCE,
                "{what}: slot {slot} rotation {} vs {q:?}",
                b["rotation"]
            );
        }
    }
}

/// The page's pixel grid: (width, height, RGB per cell).
fn grid(attrs: &HashMap<String, String>) -> (usize, usize, Vec<[u8; 3]>) {
    let g = &attrs["data-grid"];
    let (size, hex) = g.split_once(':').expect("WxH:hex");
    let (w, h) = size.split_once('x').expect("WxH");
    let (w, h): (usize, usize) = (w.parse().unwrap(), h.parse().unwrap());
    assert_eq!(hex.len(), w * h * 6, "grid of {w}x{h}");
    let byte = |i: usize| u8::from_str_radix(&hex[i..i + 2], 16).unwrap();
    let cells = (0..w * h)
        .map(|c| [byte(c * 6), byte(c * 6 + 2), byte(c * 6 + 4)])
        .collect();
    (w, h, cells)
}

/// The bodies' screen discs the page wrote: slot → (x, y, r) in grid cells.
fn screen(attrs: &HashMap<String, String>, w: usize, h: usize) -> HashMap<u64, [f64; 3]> {
    let v: Value = serde_json::from_str(&attrs["data-screen"]).unwrap();
    v.as_array()
        .unwrap()
        .iter()
        .map(|b| {
            let f = |k: &str| b[k].as_f64().unwrap();
            (
                b["slot"].as_u64().unwrap(),
                [f("x") * w as f64, f("y") * h as f64, f("r") * h as f64],
            )
        })
        .collect()
}

/// The ball slots of [`record_balls`] (the floor is slot 0).
const BALLS: [u64; 3] = [1, 2, 3];

/// The timeline seeks to two ticks; at each the page says so and shows every body where
/// a replay in the test has it; the two frames differ where the balls were and are, and
/// nowhere else; the screenshots differ. The ray of tick 30 is drawn at tick 30, the
/// contacts of the last tick are the balls' contacts with the floor.
#[test]
fn the_page_shows_the_replay_at_the_tick_its_timeline_is_at() {
    chromium();
    let daemon = TestDaemon::start("vr-shows");
    let client = daemon.client();
    let dir = TempDir::new("vr-shows");
    let file = dir.join("balls.physrec");
    let (_recorded, recording) = record_balls(&client, &file);
    let (a, b) = (10u64, 90u64);
    let mut mine = Replay::start(&client, recording.clone()).unwrap();
    let (want_a, want_b) = (poses_at(&mut mine, a), poses_at(&mut mine, b));
    // The balls moved between the two ticks by more than their diameter.
    for slot in BALLS {
        let (pa, pb) = (want_a[&slot].0, want_b[&slot].0);
        assert!(pa[1] - pb[1] > 2.0, "ball {slot}: {pa:?} → {pb:?}");
    }
    poses_at(&mut mine, TICKS);
    let mut contacts_at_end = Vec::new();
    for slot in BALLS {
        let handle = client_sdk::Handle {
            slot: slot as u32,
            generation: mine.plane().snapshot().unwrap().bodies()[slot as usize].generation,
        };
        contacts_at_end.extend(
            Object::from_handle(mine.plane(), handle)
                .contacts()
                .unwrap(),
        );
    }
    mine.into_plane().destroy().unwrap();

    let viewer = Viewer::replay(&daemon.domain, &file, &[]);
    let state = viewer.get("/api/replay");
    let first = recording.first_tick();
    assert_eq!(state["first"], first, "{state}");
    assert_eq!(state["last"], TICKS, "{state}");
    assert_eq!(
        state["tick"], first,
        "the replay starts paused at its first tick: {state}"
    );
    assert_eq!(state["playing"], false, "{state}");
    assert_eq!(state["diverged"], Value::Null, "{state}");
    let plane = state["plane"].as_u64().expect("the replay's plane");
    let info = viewer.get("/api/info");
    assert_eq!(info["replay"]["plane"], plane, "{info}");
    assert_eq!(
        info["daemon_pid"],
        daemon.pid(),
        "the running daemon is used: {info}"
    );

    let profile = dir.join("profile");
    let url = format!("{}/", viewer.base);
    let mut shots = Vec::new();
    let mut frames = Vec::new();
    for (tick, want) in [(a, &want_a), (b, &want_b)] {
        let r = viewer.ok(json!({"action": "seek", "tick": tick}));
        assert_eq!(r["tick"], tick, "{r}");
        let attrs = load_tick(&profile, &url, tick);
        // The replay plane is the one shown (no ?plane= in the URL).
        assert_eq!(attrs["data-plane"], plane.to_string());
        assert_eq!(attrs["data-tick"], tick.to_string());
        assert_eq!(attrs["data-replay-first"], first.to_string());
        assert_eq!(attrs["data-replay-last"], TICKS.to_string());
        assert_eq!(attrs["data-replay-playing"], "false");
        assert_eq!(attrs["data-replay-diverged"], "");
        assert_eq!(attrs["data-replay-rays"], "[]", "no ray at tick {tick}");
        assert_eq!(attrs["data-meshes"], "4", "{attrs:?}");
        let shown: Value = serde_json::from_str(&attrs["data-bodies"]).unwrap();
        assert_poses(&shown, want, &format!("the page at tick {tick}"));
        let png = dir.join(format!("tick-{tick}.png"));
        chromium_run(&profile, &[format!("--screenshot={}", png.display())], &url);
        let bytes = std::fs::read(&png).unwrap_or_else(|e| panic!("no screenshot {png:?}: {e}"));
        assert!(bytes.starts_with(b"\x89PNG\r\n\x1a\n"), "not a PNG");
        shots.push(bytes);
        frames.push(attrs);
    }
    assert_ne!(
        shots[0], shots[1],
        "the screenshots at ticks {a} and {b} are the same"
    );
    // A link to a tick: `/?tick=T` jumps the replay there as the page opens.
    let linked = 50u64;
    let attrs = load_tick(&profile, &format!("{}/?tick={linked}", viewer.base), linked);
    assert_eq!(attrs["data-tick"], linked.to_string());
    assert_eq!(viewer.get("/api/replay")["tick"], linked);

    // Where the two frames differ: the cells of the balls' discs at either tick, and only
    // those (the camera keeps its framing; the floor and the background are the same).
    let (w, h, ga) = grid(&frames[0]);
    let (_, _, gb) = grid(&frames[1]);
    let (sa, sb) = (screen(&frames[0], w, h), screen(&frames[1], w, h));
    let differs = |c: usize| (0..3).any(|k| ga[c][k].abs_diff(gb[c][k]) > 24);
    let near = |x: f64, y: f64, margin: f64| {
        BALLS.iter().any(|s| {
            [sa[s], sb[s]]
                .iter()
                .any(|d| (x - d[0]).hypot(y - d[1]) <= d[2] + margin)
        })
    };
    let mut changed = 0;
    for c in 0..w * h {
        let (x, y) = ((c % w) as f64 + 0.5, (c / w) as f64 + 0.5);
        if differs(c) {
            changed += 1;
            assert!(
                near(x, y, 1.5),
                "cell ({x}, {y}) changed away from every ball: {:?} vs {:?}; balls {sa:?} {sb:?}",
                ga[c],
                gb[c]
            );
        }
    }
    for slot in BALLS {
        for (disc, other) in [(sa[&slot], sb[&slot]), (sb[&slot], sa[&slot])] {
            assert!(
                disc[2] >= 1.0,
                "ball {slot} is under a cell wide on screen: {disc:?}"
            );
            // A ball's centre cell changed, unless the ball covers it at the other tick too.
            if (disc[0] - other[0]).hypot(disc[1] - other[1]) > disc[2] + other[2] + 1.0 {
                let c = (disc[1] as usize).min(h - 1) * w + (disc[0] as usize).min(w - 1);
                assert!(
                    differs(c),
                    "ball {slot}'s cell at {disc:?} did not change: {:?} vs {:?}",
                    ga[c],
                    gb[c]
                );
            }
        }
    }
    assert!(changed > 0);
    eprintln!(
        "{changed} of {} cells changed between ticks {a} and {b}",
        w * h
    );

    // The ray cast after tick 30's step is drawn at tick 30.
    viewer.ok(json!({"action": "seek", "tick": RAY_TICK}));
    let attrs = load_tick(&profile, &url, RAY_TICK);
    let rays: Value = serde_json::from_str(&attrs["data-replay-rays"]).unwrap();
    let rays = rays.as_array().expect("rays");
    assert_eq!(rays.len(), 1, "{rays:?}");
    assert_eq!(rays[0]["kind"], "Raycast", "{rays:?}");
    let to = [0, 1, 2].map(|i| RAY.0[i] + RAY.1[i]);
    for i in 0..3 {
        assert_eq!(
            rays[0]["from"][i].as_f64(),
            Some(RAY.0[i] as f64),
            "{rays:?}"
        );
        assert_eq!(rays[0]["to"][i].as_f64(), Some(to[i] as f64), "{rays:?}");
    }

    // The contacts of the last tick: each ball's with the floor, as the test's replay has
    // them.
    viewer.ok(json!({"action": "seek", "tick": TICKS}));
    let snap = viewer.get(&format!("/api/plane/{plane}"));
    assert_eq!(snap["tick"], TICKS);
    let contacts = snap["contacts"].as_array().unwrap();
    assert_eq!(contacts.len(), contacts_at_end.len(), "{contacts:?}");
    assert_eq!(
        contacts.len(),
        3,
        "every ball rests on the floor: {contacts:?}"
    );
    for c in contacts {
        let y = c["position"][1].as_f64().unwrap();
        let hit = contacts_at_end.iter().any(|m| {
            (0..3)
                .all(|i| (c["position"][i].as_f64().unwrap() - m.position[i] as f64).abs() <= 1e-4)
        });
        assert!(
            hit,
            "{c} is not a contact of the replay: {contacts_at_end:?}"
        );
        assert!(y.abs() < 0.05, "a contact off the floor's top: {c}");
    }
}

/// Play then pause moves the tick forward and holds it; a step moves it by exactly one;
/// playing stops at the end; out-of-range and malformed requests are refused; the replay
/// plane refuses the plane controls (its timeline drives it).
#[test]
fn play_pause_step_and_the_end_of_the_recording() {
    let daemon = TestDaemon::start("vr-play");
    let client = daemon.client();
    let dir = TempDir::new("vr-play");
    let file = dir.join("balls.physrec");
    let (_recorded, recording) = record_balls(&client, &file);
    let first = recording.first_tick();
    let mut mine = Replay::start(&client, recording).unwrap();
    let viewer = Viewer::replay(&daemon.domain, &file, &["--allow-control"]);
    let plane = viewer.get("/api/replay")["plane"].as_u64().unwrap();

    assert_eq!(viewer.ok(json!({"action": "seek", "tick": 10}))["tick"], 10);
    let r = viewer.ok(json!({"action": "play", "speed": 4}));
    assert_eq!(r["playing"], true, "{r}");
    assert_eq!(r["speed"], 4.0, "{r}");
    eventually(Duration::from_secs(20), || {
        (viewer.get("/api/replay")["tick"].as_u64().unwrap() > 10).then_some(())
    })
    .expect("playing never moved the tick");
    let r = viewer.ok(json!({"action": "pause"}));
    assert_eq!(r["playing"], false, "{r}");
    let paused = r["tick"].as_u64().unwrap();
    assert!(paused > 10, "{r}");
    std::thread::sleep(Duration::from_millis(300));
    assert_eq!(
        viewer.get("/api/replay")["tick"],
        paused,
        "a paused replay moved"
    );
    let r = viewer.ok(json!({"action": "step"}));
    assert_eq!(r["tick"], paused + 1, "{r}");
    assert_eq!(r["playing"], false, "{r}");
    let r = viewer.ok(json!({"action": "step"}));
    assert_eq!(r["tick"], paused + 2, "{r}");
    // The plane shows the tick the timeline is at, with the bodies of that tick.
    let want = poses_at(&mut mine, paused + 2);
    let snap = viewer.get(&format!("/api/plane/{plane}"));
    assert_eq!(snap["tick"], paused + 2);
    assert_eq!(snap["replay"]["tick"], paused + 2);
    assert_poses(&snap["bodies"], &want, "after two steps");

    // Played to the end, it stops there; a step at the end stays.
    viewer.ok(json!({"action": "play", "speed": 4}));
    let end = eventually(Duration::from_secs(30), || {
        let r = viewer.get("/api/replay");
        (r["playing"] == false).then_some(r)
    })
    .expect("playing never reached the end");
    assert_eq!(end["tick"], TICKS, "{end}");
    assert_eq!(end["at_end"], true, "{end}");
    let r = viewer.ok(json!({"action": "step"}));
    assert_eq!(r["tick"], TICKS, "{r}");

    let (status, r) = viewer.act(json!({"action": "seek", "tick": 500}));
    assert_eq!(status, 409, "{r}");
    assert!(
        r["error"]
            .as_str()
            .unwrap()
            .contains(&format!("ticks {first} to {TICKS}")),
        "{r}"
    );
    for bad in [
        json!({"action": "fly"}),
        json!({"action": "seek"}),
        json!({"action": "play", "speed": 100}),
        json!({"action": "play", "speed": -1}),
    ] {
        let (status, r) = viewer.act(bad.clone());
        assert_eq!(status, 400, "{bad}: {r}");
    }
    let (status, text) = http(
        &viewer.base,
        "POST",
        &format!("/api/plane/{plane}/step"),
        "",
    );
    assert_eq!(status, 409, "{text}");
    assert!(text.contains("timeline"), "{text}");
    assert_eq!(viewer.get("/api/replay")["tick"], TICKS);
}

/// A recording whose tick 40 carries another state hash (a well-formed entry): playing
/// stops at tick 40, the page shows the divergence's message, play and step are refused
/// until a seek goes back before it.
#[test]
fn a_divergence_stops_playback_and_the_page_shows_it() {
    chromium();
    let daemon = TestDaemon::start("vr-diverge");
    let client = daemon.client();
    let dir = TempDir::new("vr-diverge");
    let file = dir.join("balls.physrec");
    let (_recorded, recording) = record_balls(&client, &file);
    let tick = 40u64;
    let good = &recording.bytes;
    let (bytes, forged_hash) = forge_tick_hash(good, tick);
    let forged = dir.join("forged.physrec");
    std::fs::write(&forged, &bytes).unwrap();

    let viewer = Viewer::replay(&daemon.domain, &forged, &[]);
    let state = viewer.get("/api/replay");
    assert_eq!(state["tick"], recording.first_tick(), "{state}");
    assert_eq!(state["diverged"], Value::Null, "{state}");
    viewer.ok(json!({"action": "play", "speed": 4}));
    let stopped = eventually(Duration::from_secs(30), || {
        let r = viewer.get("/api/replay");
        (r["playing"] == false).then_some(r)
    })
    .expect("playing never stopped");
    assert_eq!(stopped["tick"], tick, "{stopped}");
    let message = stopped["diverged"]
        .as_str()
        .expect("a divergence")
        .to_string();
    assert!(message.contains("diverged at tick 40"), "{message}");
    assert!(
        message.contains(&format!("the recording has {forged_hash:016x}")),
        "{message}"
    );

    let profile = dir.join("profile");
    let attrs = load_tick(&profile, &format!("{}/", viewer.base), tick);
    assert_eq!(attrs["data-replay-diverged"], message);
    assert_eq!(attrs["data-replay-playing"], "false");

    for action in ["play", "step"] {
        let (status, r) = viewer.act(json!({ "action": action }));
        assert_eq!(status, 409, "{action}: {r}");
        assert!(
            r["error"]
                .as_str()
                .unwrap()
                .contains("seek to a tick before 40"),
            "{r}"
        );
    }
    let r = viewer.ok(json!({"action": "seek", "tick": 30}));
    assert_eq!(r["tick"], 30, "{r}");
    assert_eq!(r["diverged"], Value::Null, "{r}");
    let r = viewer.ok(json!({"action": "step"}));
    assert_eq!(r["tick"], 31, "{r}");
}

/// A damaged file (a flipped byte, a cut end) or a missing one: the viewer exits non-zero
/// before it listens, naming the byte offset of the damage.
#[test]
fn a_damaged_recording_is_refused_naming_the_byte_offset() {
    let daemon = TestDaemon::start("vr-damaged");
    let client = daemon.client();
    let dir = TempDir::new("vr-damaged");
    let file = dir.join("balls.physrec");
    let (_recorded, recording) = record_balls(&client, &file);
    let good = recording.bytes.clone();
    let at = tick_entry(&good, 60);
    let mut flipped = good.clone();
    flipped[at + 7] ^= 0x40;
    let cut = good[..good.len() - 9].to_vec();
    for (name, bytes, offset) in [("flipped", flipped, Some(at)), ("cut", cut, None)] {
        let path = dir.join(format!("{name}.physrec"));
        std::fs::write(&path, &bytes).unwrap();
        let out = Command::new(viewer_bin())
            .args(["--domain", &daemon.domain, "--port", "0", "--replay"])
            .arg(&path)
            .stdin(Stdio::null())
            .output()
            .expect("run physics-view");
        let stderr = String::from_utf8_lossy(&out.stderr);
        let stdout = String::from_utf8_lossy(&out.stdout);
        assert!(
            !out.status.success(),
            "{name}: exited {} ({stderr})",
            out.status
        );
        assert!(stderr.contains("byte offset"), "{name}: {stderr}");
        if let Some(offset) = offset {
            assert!(
                stderr.contains(&format!("byte offset {offset}")),
                "{name}: {stderr}"
            );
        }
        assert!(
            stderr.contains(&path.display().to_string()),
            "{name}: {stderr}"
        );
        assert!(!stdout.contains("http://"), "{name}: it listened: {stdout}");
    }
    let out = Command::new(viewer_bin())
        .args(["--domain", &daemon.domain, "--port", "0", "--replay"])
        .arg(dir.join("missing.physrec"))
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(
        String::from_utf8_lossy(&out.stderr).contains("cannot read recording"),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// With no daemon in the domain, `--replay` starts one (as physics-lua does), replays
/// there, and stops it when the viewer exits. `--help` documents `--replay`.
#[test]
fn a_replay_starts_a_daemon_when_none_runs_and_stops_it() {
    let recorder = TestDaemon::start("vr-rec");
    let client = recorder.client();
    let dir = TempDir::new("vr-own");
    let file = dir.join("balls.physrec");
    let (_recorded, recording) = record_balls(&client, &file);
    let mut mine = Replay::start(&client, recording).unwrap();
    let want = poses_at(&mut mine, 60);

    let domain = unique_domain("vr-own");
    let viewer = Viewer::replay(&domain, &file, &[]);
    let info = viewer.get("/api/info");
    assert_eq!(info["connected"], true, "{info}");
    let pid = info["daemon_pid"].as_u64().unwrap();
    assert!(pid != 0 && pid != recorder.pid() as u64, "{info}");
    let said = viewer.stderr.lock().unwrap().join("\n");
    assert!(said.contains(&format!("pid {pid}")), "{said}");
    let r = viewer.ok(json!({"action": "seek", "tick": 60}));
    let snap = viewer.get(&format!("/api/plane/{}", r["plane"]));
    assert_poses(&snap["bodies"], &want, "on the started daemon at tick 60");
    drop(viewer);
    eventually(Duration::from_secs(10), || {
        (!Path::new(&format!("/proc/{pid}")).exists()).then_some(())
    })
    .expect("the daemon the viewer started outlived it");

    let out = Command::new(viewer_bin()).arg("--help").output().unwrap();
    let help = String::from_utf8_lossy(&out.stdout);
    assert!(help.contains("--replay <FILE>"), "{help}");
}

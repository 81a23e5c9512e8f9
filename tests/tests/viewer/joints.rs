//! Joints in `physics-view`, in a real browser: a chain of balls held by ball joints (the
//! first to the world) swings on a manual plane. The page draws each joint as a line from
//! A's anchor to B's and reports it in data- attributes of `#view`: `data-joints` (joints
//! drawn), `data-joints-broken`, `data-joint-lines` (each line's ends). The test checks the
//! count against the plane's joints and each line's ends against the anchors placed by the
//! poses shared memory holds (and, independently, that a ball joint's two ends meet), for a
//! live plane (with a broken joint drawn as such and a destroyed one absent) and for the
//! replay of a recording of the chain (`physics-view --replay FILE`) at two ticks.
//!
//! Chromium is required: without it the test fails and says how to install it.

use crate::browser::{chromium, chromium_run, view_attributes, TempDir, Viewer};
use std::collections::HashMap;
use std::path::Path;

use client_sdk::{
    load_recording, Advanced, Client, JointKind, JointProp, Object, ObjectProp, Plane,
    PlaneOptions, Pose, Replay, Shape,
};
use integration_tests::TestDaemon;
use serde_json::{json, Value};

const DT: f32 = 1.0 / 60.0;
/// Balls of the chain, so joints: the first ball to the world, then each to the one before.
const CHAIN: usize = 6;
/// Ends travel f32 → JSON → JS double → JSON; the test places the anchors in f64 from the
/// same f32 poses: 1e-4 is ample for coordinates of about 10.
const END_TOLERANCE: f64 = 1e-4;
/// How far apart a ball joint's two ends may be drawn: the solver holds them together to
/// well under a millimetre on this light chain (the daemon's own figure, `error`, is
/// checked too); a rotation applied wrongly puts them up to a ball spacing (1) apart.
const MEET_TOLERANCE: f64 = 0.02;

/// Loads `url` until the page has drawn plane `plane` at `tick`; returns #view's attributes.
fn load(profile: &Path, url: &str, plane: u32, tick: u64) -> HashMap<String, String> {
    let mut last = HashMap::new();
    for _ in 0..4 {
        let attrs = view_attributes(&chromium_run(profile, &["--dump-dom".to_string()], url));
        if attrs.get("data-ready").map(String::as_str) == Some("1")
            && attrs.get("data-plane") == Some(&plane.to_string())
            && attrs.get("data-tick") == Some(&tick.to_string())
            && attrs.contains_key("data-joints")
        {
            return attrs;
        }
        last = attrs;
    }
    last.remove("data-grid");
    panic!("the page never drew plane {plane} at tick {tick}: #view = {last:?}");
}

/// The chain: [`CHAIN`] balls 1 apart along +x at height 8, each held at its −x side: the
/// first to the world point (0, 8, 0), each other to the +x side of the ball before. It
/// starts straight and swings down under gravity. Returns the balls.
fn chain(plane: &Plane) -> Vec<Object> {
    let balls: Vec<Object> = (0..CHAIN)
        .map(|i| {
            plane
                .add(
                    Shape::Sphere { radius: 0.3 },
                    Pose::at([0.5 + i as f32, 8.0, 0.0]),
                    &[ObjectProp::Weight(1.0)],
                )
                .unwrap()
        })
        .collect();
    for (i, ball) in balls.iter().enumerate() {
        let (other, anchor_b) = if i == 0 {
            (None, [0.0, 8.0, 0.0])
        } else {
            (Some(&balls[i - 1]), [0.5, 0.0, 0.0])
        };
        plane
            .joint(
                JointKind::Ball,
                ball,
                other,
                &[
                    JointProp::AnchorA([-0.5, 0.0, 0.0]),
                    JointProp::AnchorB(anchor_b),
                ],
            )
            .unwrap();
    }
    balls
}

/// `q · v` for a unit quaternion `[x, y, z, w]`, in f64.
fn rotate(q: [f32; 4], v: [f32; 3]) -> [f64; 3] {
    let q = q.map(f64::from);
    let v = v.map(f64::from);
    let (u, s) = ([q[0], q[1], q[2]], q[3]);
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let uv = [
        u[1] * v[2] - u[2] * v[1],
        u[2] * v[0] - u[0] * v[2],
        u[0] * v[1] - u[1] * v[0],
    ];
    let (d, uu) = (dot(u, v), dot(u, u));
    [0, 1, 2].map(|k| 2.0 * d * u[k] + (s * s - uu) * v[k] + 2.0 * s * uv[k])
}

/// Joint slot → (from, to, broken).
type Lines = HashMap<u64, ([f64; 3], [f64; 3], bool)>;

/// What the page must draw for `plane` now (the anchors of the plane's joints as listed,
/// placed by the poses of its snapshot), and the snapshot's tick.
fn expected(plane: &Plane) -> (Lines, u64) {
    let snap = plane.snapshot().unwrap();
    let bodies = snap.bodies();
    let place = |h: client_sdk::Handle, local: [f32; 3]| {
        let b = &bodies[h.slot as usize];
        assert!(b.is_alive() && b.generation == h.generation, "{h:?}");
        let r = rotate(b.rotation, local);
        [0, 1, 2].map(|k| b.position[k] as f64 + r[k])
    };
    let lines = plane
        .joints()
        .unwrap()
        .into_iter()
        .map(|j| {
            let from = place(j.a, j.settings.anchor_a);
            let to = match j.b {
                Some(b) => place(b, j.settings.anchor_b),
                None => j.settings.anchor_b.map(f64::from),
            };
            (j.handle.slot as u64, (from, to, j.broken))
        })
        .collect();
    (lines, snap.tick())
}

fn vec3(v: &Value) -> [f64; 3] {
    [0, 1, 2].map(|i| v[i].as_f64().expect("a number"))
}

fn distance(a: [f64; 3], b: [f64; 3]) -> f64 {
    (0..3).map(|k| (a[k] - b[k]).powi(2)).sum::<f64>().sqrt()
}

/// The page's joint lines equal `want` (each slot once, ends within [`END_TOLERANCE`]);
/// every unbroken joint's ends meet. Returns the lines shown.
fn assert_lines(
    attrs: &HashMap<String, String>,
    want: &Lines,
    what: &str,
) -> HashMap<u64, ([f64; 3], [f64; 3])> {
    let shown: Value = serde_json::from_str(&attrs["data-joint-lines"]).unwrap();
    let shown = shown.as_array().expect("lines");
    assert_eq!(
        attrs["data-joints"],
        want.len().to_string(),
        "{what}: {shown:?}"
    );
    assert_eq!(shown.len(), want.len(), "{what}");
    let broken = want.values().filter(|w| w.2).count();
    assert_eq!(attrs["data-joints-broken"], broken.to_string(), "{what}");
    let mut out = HashMap::new();
    for l in shown {
        let slot = l["slot"].as_u64().unwrap();
        let (from, to, is_broken) = want
            .get(&slot)
            .unwrap_or_else(|| panic!("{what}: joint {slot} is not the plane's"));
        let (f, t) = (vec3(&l["from"]), vec3(&l["to"]));
        assert!(
            distance(f, *from) <= END_TOLERANCE && distance(t, *to) <= END_TOLERANCE,
            "{what}: joint {slot} drawn {f:?} → {t:?}, its anchors are {from:?} → {to:?}"
        );
        assert_eq!(l["broken"], *is_broken, "{what}: joint {slot}");
        if !is_broken {
            assert!(
                distance(f, t) <= MEET_TOLERANCE,
                "{what}: ball joint {slot}'s ends do not meet: {f:?} → {t:?}"
            );
        }
        assert!(out.insert(slot, (f, t)).is_none(), "{what}: {slot} twice");
    }
    out
}

/// How far the chain's balls turned from where they started (radians, the largest): the
/// anchors' placement is only tested by a chain that turned.
fn largest_turn(plane: &Plane) -> f64 {
    let snap = plane.snapshot().unwrap();
    snap.bodies()
        .iter()
        .filter(|b| b.is_alive())
        .map(|b| 2.0 * (b.rotation[3].abs().min(1.0) as f64).acos())
        .fold(0.0, f64::max)
}

/// A live plane: the chain's six joints drawn anchor to anchor, a seventh joint broken (its
/// BreakForce far under the ball's weight) drawn as broken, an eighth destroyed and absent.
#[test]
fn the_page_draws_a_live_planes_joints_between_their_anchors() {
    chromium();
    let daemon = TestDaemon::start("vj-live");
    let client: Client = daemon.client();
    let dir = TempDir::new("vj-live");
    let plane = client.create_plane(&PlaneOptions::manual()).unwrap();
    let balls = chain(&plane);
    let loose = plane
        .add(
            Shape::Sphere { radius: 0.3 },
            Pose::at([-4.0, 8.0, 0.0]),
            &[ObjectProp::Weight(1.0)],
        )
        .unwrap();
    let breaks = plane
        .joint(
            JointKind::Ball,
            &loose,
            None,
            &[
                JointProp::AnchorB([-4.0, 9.0, 0.0]),
                JointProp::AnchorA([0.0, 1.0, 0.0]),
                JointProp::BreakForce(1e-3),
            ],
        )
        .unwrap();
    let gone = plane
        .joint(JointKind::Ball, &balls[CHAIN - 1], Some(&loose), &[])
        .unwrap();
    gone.destroy().unwrap();
    for _ in 0..30 {
        plane.step(DT).unwrap();
    }
    assert!(breaks.is_broken().unwrap(), "{:?}", breaks.info().unwrap());
    let turn = largest_turn(&plane);
    assert!(turn > 0.1, "the chain barely turned: {turn} rad");
    let (want, tick) = expected(&plane);
    assert_eq!(want.len(), CHAIN + 1);
    // Nothing was added after the destroy: its slot is still free, and not listed.
    assert!(!want.contains_key(&(gone.handle().slot as u64)));
    for j in plane.joints().unwrap() {
        if !j.broken {
            assert!(j.error < MEET_TOLERANCE as f32, "{j:?}");
        }
    }

    let viewer = Viewer::start::<&str>(&daemon.domain, &[]);
    // The JSON the page draws from: every joint's line.
    let api = viewer.get(&format!("/api/plane/{}", plane.id()));
    assert_eq!(api["joint_count"], CHAIN + 1, "{}", api["joints"]);
    assert_eq!(api["joints"].as_array().unwrap().len(), CHAIN + 1);

    let profile = dir.join("profile");
    let url = format!("{}/?plane={}", viewer.base, plane.id());
    let attrs = load(&profile, &url, plane.id(), tick);
    assert_eq!(attrs["data-kind"], "Rapier3d");
    let shown = assert_lines(&attrs, &want, "the live page");
    // The world joint's far end is its world point.
    let world = shown
        .values()
        .find(|(_, t)| distance(*t, [0.0, 8.0, 0.0]) < 1e-6)
        .expect("the chain's world joint");
    assert!(distance(world.0, [0.0, 8.0, 0.0]) <= MEET_TOLERANCE);
    eprintln!(
        "live: {} joints drawn ({} broken), balls turned up to {turn:.3} rad",
        attrs["data-joints"], attrs["data-joints-broken"]
    );
}

/// A recording of the chain (60 ticks) replayed by `physics-view --replay`: at two ticks
/// the page draws the chain's joints where a replay in the test has the anchors, and they
/// moved between the two.
#[test]
fn the_page_draws_a_replayed_planes_joints_at_each_tick() {
    chromium();
    let daemon = TestDaemon::start("vj-replay");
    let client = daemon.client();
    let dir = TempDir::new("vj-replay");
    let file = dir.join("chain.physrec");
    let plane = client.create_plane(&PlaneOptions::manual()).unwrap();
    chain(&plane);
    assert_eq!(plane.start_recording(Some(&file)).unwrap(), file);
    for _ in 0..60 {
        plane.step(DT).unwrap();
    }
    plane.stop_recording().unwrap().expect("the plane recorded");
    let recording = std::sync::Arc::new(load_recording(&file).unwrap());
    let last = recording.last_tick();
    assert!(recording.first_tick() <= 1, "{}", recording.first_tick());
    let (a, b) = (20u64, last);

    // What the page must show at each tick: a replay of the test's own.
    let mut mine = Replay::start(&client, recording.clone()).unwrap();
    let mut wants = Vec::new();
    for tick in [a, b] {
        match mine.seek(tick).unwrap() {
            Advanced::Tick(t) => assert_eq!(t, tick),
            other => panic!("seek({tick}): {other:?}"),
        }
        let (want, at) = expected(mine.plane());
        assert_eq!(at, tick);
        assert_eq!(want.len(), CHAIN);
        wants.push(want);
    }
    assert!(largest_turn(mine.plane()) > 0.1);
    mine.into_plane().destroy().unwrap();

    let viewer = Viewer::replay(&daemon.domain, &file, &[]);
    let state = viewer.get("/api/replay");
    let id = state["plane"].as_u64().expect("the replay's plane") as u32;
    let profile = dir.join("profile");
    let url = format!("{}/", viewer.base);
    let mut drawn = Vec::new();
    for (tick, want) in [a, b].into_iter().zip(&wants) {
        let r = viewer.ok(json!({"action": "seek", "tick": tick}));
        assert_eq!(r["tick"], tick, "{r}");
        let attrs = load(&profile, &url, id, tick);
        assert_eq!(attrs["data-replay-tick"], tick.to_string());
        drawn.push(assert_lines(
            &attrs,
            want,
            &format!("the replay at tick {tick}"),
        ));
    }
    // The lines follow the chain: the last ball's joint moved by more than a ball's size.
    let moved = drawn[0]
        .iter()
        .map(|(slot, (f, _))| distance(*f, drawn[1][slot].0))
        .fold(0.0, f64::max);
    assert!(
        moved > 0.6,
        "the joints hardly moved between ticks {a} and {b}: {moved}"
    );
    eprintln!("replay: {CHAIN} joints drawn at ticks {a} and {b}, moved up to {moved:.3}");
}

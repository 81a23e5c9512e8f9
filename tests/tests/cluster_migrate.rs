//! Migration of a plane between two daemons of a cluster on one machine (`Plane::move_to`,
//! `plane:MoveTo`): each daemon in a domain of its own on a loopback port the OS handed out.
//! A plane of falling balls stepped on `a`, read by a local reader on `a` and by a remote
//! reader, moves to `b` mid-fall: the tick counter goes on (30 on a, 31 on b), every tick
//! has the `StateHash` an unmoved twin plane computes, the free fall still matches the
//! closed form, a write sent to `a` after the cut is applied once on `b`, and both readers
//! keep reading. The refusals are named.

use std::time::{Duration, Instant};

use client_sdk::{Client, ErrorKind, Object, Plane, PlaneKind, PlaneOptions, Pose, Shape};
use integration_tests::cluster::{endpoint, free_port, member, unique_cluster};
use integration_tests::{eventually, TestDaemon};

const DT: f32 = 1.0 / 60.0;
const G: f32 = 10.0;
const BALLS: usize = 10;
const H0: f32 = 1000.0;

/// Two members, `a` and `b`, both seen through a's endpoint.
struct Pair {
    cluster: String,
    a_port: u16,
    a: TestDaemon,
    _b: TestDaemon,
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
    Pair {
        cluster,
        a_port: pa,
        a,
        _b: b,
    }
}

impl Pair {
    /// A remote client of daemon `daemon` through a's endpoint.
    fn remote(&self, daemon: &str) -> Client {
        integration_tests::cluster::remote_client(&self.cluster, self.a_port, daemon)
    }
}

fn falling_plane(client: &Client) -> (Plane, Vec<Object>) {
    let plane = client
        .create_plane(&PlaneOptions {
            tick_rate: Some(0.0),
            gravity: Some([0.0, -G, 0.0]),
            shared: Some(true),
            ..integration_tests::no_damping()
        })
        .unwrap();
    let balls = (0..BALLS)
        .map(|i| {
            plane
                .add(
                    Shape::Sphere { radius: 0.5 },
                    Pose::at([i as f32 * 2.0, H0, 0.0]),
                    &[],
                )
                .unwrap()
        })
        .collect();
    (plane, balls)
}

/// Where semi-implicit Euler over 4 substeps a tick (h = dt/4, m = 4n substeps, as rapier
/// integrates) puts a ball dropped at rest from `H0` after `ticks` ticks.
fn free_fall(ticks: u64) -> f32 {
    let (h, m) = (DT / 4.0, 4.0 * ticks as f32);
    H0 - G * h * h * m * (m + 1.0) / 2.0
}

/// Waits until `plane` shows tick `tick` (a reader that may have to switch over first).
fn read_tick(plane: &Plane, tick: u64) -> u64 {
    let deadline = Instant::now() + Duration::from_secs(10);
    loop {
        let now = plane.snapshot().unwrap();
        if now.tick() >= tick {
            assert_eq!(now.tick(), tick, "the reader skipped to a later tick");
            return now.header().state_hash;
        }
        assert!(
            Instant::now() < deadline,
            "the reader stays at tick {}",
            now.tick()
        );
        let _ = plane.wait_tick(Duration::from_millis(500));
    }
}

#[test]
fn a_plane_moves_mid_fall_and_its_readers_writers_and_hashes_carry_on() {
    let pair = pair("mv-fall");
    let owner = pair.a.client();
    let (plane, balls) = falling_plane(&owner);
    let (twin, twin_balls) = falling_plane(&owner);
    assert_eq!(
        plane.daemon(),
        None,
        "a local client names no cluster daemon"
    );

    // Readers: a local client of a, and a remote client of a through the cluster.
    let local = pair.a.client();
    let local_plane = local.attach_plane(plane.id()).unwrap();
    let remote = pair.remote("a");
    let remote_plane = remote.attach_plane(plane.id()).unwrap();

    for tick in 1..=30u64 {
        assert_eq!(plane.step(DT).unwrap(), tick);
        assert_eq!(twin.step(DT).unwrap(), tick);
        let hash = plane.state_hash().unwrap();
        assert_eq!(
            hash,
            twin.state_hash().unwrap(),
            "twins agree at tick {tick}"
        );
        assert_eq!(read_tick(&local_plane, tick), hash);
        assert_eq!(read_tick(&remote_plane, tick), hash);
    }
    let last_on_a = Instant::now();
    // A write queued by the owner right before the move goes with the move's request: it
    // is applied on a, before the cut, and travels in the snapshot.
    balls[2].set_velocity([0.0, 3.0, 0.0]).unwrap();
    twin_balls[2].set_velocity([0.0, 3.0, 0.0]).unwrap();
    twin.client().flush().unwrap();
    let moving = Instant::now();
    plane.move_to("b").unwrap();
    let move_took = moving.elapsed();
    assert_eq!(
        plane.daemon().as_deref(),
        Some("b"),
        "the plane names its new daemon"
    );
    assert_eq!(plane.snapshot().unwrap().tick(), 30, "the same tick on b");
    assert_eq!(
        plane.state_hash().unwrap(),
        twin.state_hash().unwrap(),
        "b publishes exactly the state a left"
    );

    // A write sent to a after the cut: refused there (not applied), sent again to b.
    let pushed = Object::from_handle(&local_plane, balls[1].handle());
    pushed.apply_impulse([0.0, 20.0, 0.0]).unwrap();
    local.flush().unwrap();
    twin_balls[1].apply_impulse([0.0, 20.0, 0.0]).unwrap();
    twin.client().flush().unwrap();
    assert_eq!(
        local_plane.daemon().as_deref(),
        Some("b"),
        "the writer switched over"
    );

    assert_eq!(plane.step(DT).unwrap(), 31, "tick 30 on a, 31 on b");
    let pause = last_on_a.elapsed();
    assert_eq!(twin.step(DT).unwrap(), 31);
    println!(
        "move of {BALLS} balls: MoveTo {:.2} ms; last tick on a to first tick on b {:.2} ms",
        move_took.as_secs_f64() * 1e3,
        pause.as_secs_f64() * 1e3
    );
    assert!(pause < Duration::from_secs(2), "pause {pause:?}");

    for tick in 31..=60u64 {
        if tick > 31 {
            assert_eq!(plane.step(DT).unwrap(), tick);
            assert_eq!(twin.step(DT).unwrap(), tick);
        }
        let hash = plane.state_hash().unwrap();
        assert_eq!(
            hash,
            twin.state_hash().unwrap(),
            "the moved plane computes what its unmoved twin does at tick {tick} (the write \
             after the cut applied exactly once)"
        );
        assert_eq!(
            read_tick(&local_plane, tick),
            hash,
            "local reader, tick {tick}"
        );
        assert_eq!(
            read_tick(&remote_plane, tick),
            hash,
            "remote reader, tick {tick}"
        );
    }
    assert_eq!(remote_plane.daemon().as_deref(), Some("b"));
    // Free fall through the move: ball 0 was never touched.
    let y = balls[0].position().unwrap()[1];
    assert!(
        (y - free_fall(60)).abs() < 1e-3,
        "ball 0 at {y}, free fall says {}",
        free_fall(60)
    );
    // The owner still owns it on b (it may write and destroy), the reader does not.
    balls[3].set_velocity([1.0, 0.0, 0.0]).unwrap();
    owner.flush().unwrap();
    let e = local_plane.destroy().unwrap_err();
    assert!(e.to_string().contains("only its owner"), "{e}");
    plane.destroy().unwrap();
}

#[test]
fn moves_that_cannot_happen_are_refused_by_name() {
    let pair = pair("mv-refuse");
    let owner = pair.a.client();
    let (plane, _) = falling_plane(&owner);
    plane.step(DT).unwrap();

    let e = plane.move_to("nowhere").unwrap_err();
    assert!(
        e.to_string()
            .contains("no live daemon is named \"nowhere\""),
        "{e}"
    );
    let e = plane.move_to("b/*").unwrap_err();
    assert!(e.to_string().contains("MoveTo"), "{e}");
    // To itself: nothing happens.
    plane.move_to("a").unwrap();
    assert_eq!(plane.step(DT).unwrap(), 2);
    // Only the owner moves a plane.
    let other = pair.a.client();
    let theirs = other.attach_plane(plane.id()).unwrap();
    let e = theirs.move_to("b").unwrap_err();
    match &e {
        client_sdk::Error::Command(c) => assert_eq!(c.kind, ErrorKind::NotOwner, "{e}"),
        other => panic!("expected NotOwner, got {other}"),
    }
    // A GUI plane does not move.
    let gui = owner
        .create_plane(&PlaneOptions {
            kind: Some(PlaneKind::Gui2d),
            ..Default::default()
        })
        .unwrap();
    let e = gui.move_to("b").unwrap_err();
    assert!(e.to_string().contains("cannot move"), "{e}");
    // Refused moves leave the plane where it was.
    assert_eq!(plane.step(DT).unwrap(), 3);

    // Outside a cluster run.
    let lone = TestDaemon::start("mv-lone");
    let client = lone.client();
    let (alone, _) = falling_plane(&client);
    let e = alone.move_to("b").unwrap_err();
    assert!(e.to_string().contains("--cluster"), "{e}");
}

#[test]
fn a_luau_script_moves_its_plane_and_its_parts_keep_falling() {
    let pair = pair("mv-lua");
    let script = std::env::temp_dir().join(format!(
        "{}.luau",
        integration_tests::unique_domain("mv-lua")
    ));
    std::fs::write(
        &script,
        r#"
local Physics = import("PhysicsService")
local Renderable = import("Renderable")
local P = import("Primitives")
local V, CF = P.Vector.new, P.CFrame.new
local plane = Physics.New({ TickRate = 0, Gravity = V(0, -10, 0), LinearDamping = 0, AngularDamping = 0 })
assert(plane.Daemon == "a", "placed on a: " .. tostring(plane.Daemon))
local part = Renderable.BasePart("Sphere")
part.Size = V(1, 1, 1)
part.CFrame = CF(V(0, 100, 0))
local ball = plane:Add(part)
for _ = 1, 30 do
    plane:Step(1 / 60)
end
plane:MoveTo("b")
assert(plane.Daemon == "b", "moved: " .. tostring(plane.Daemon))
for _ = 1, 30 do
    plane:Step(1 / 60)
end
local y = ball.CFrame.Position.Y
local h, m = 1 / 240, 240
local expect = 100 - 10 * h * h * m * (m + 1) / 2
assert(math.abs(y - expect) < 1e-3, string.format("y %.5f, expected %.5f", y, expect))
local ok, err = pcall(function()
    plane:MoveTo(7)
end)
assert(not ok and string.find(tostring(err), "must be a string", 1, true), tostring(err))
ok, err = pcall(function()
    plane:MoveTo("nowhere")
end)
assert(not ok and string.find(tostring(err), "nowhere", 1, true), tostring(err))
print("MOVED OK")
"#,
    )
    .unwrap();
    let out = integration_tests::cluster::cluster_lua(&pair.cluster, pair.a_port, "a", &script)
        .output()
        .unwrap();
    let text =
        String::from_utf8_lossy(&out.stdout).to_string() + &String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success() && text.contains("MOVED OK"), "{text}");
    let _ = std::fs::remove_file(script);
}

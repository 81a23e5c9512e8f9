//! Remote clients of a physics cluster on one machine: two daemons, each in a domain of its
//! own (as if on two hosts) on a loopback port of its own. A client that reaches the cluster
//! through one member's endpoint uses a plane on the other daemon with the same SDK calls
//! as a local client: it creates, writes, steps and reads; every tick it reads is bit for
//! bit what a local reader of that daemon reads (same `StateHash`, same slots); errors,
//! ownership and events come back as they do locally; its planes are released when it says
//! goodbye and when its process is killed; a Luau script runs remotely with `--cluster`.

use std::time::Duration;

use client_sdk::cluster::ClusterOptions;
use client_sdk::remote::RemoteOptions;
use client_sdk::{Client, Contact, ErrorKind, ObjectProp, PlaneOptions, Pose, Shape};
use integration_tests::cluster::{endpoint, free_port, member, unique_cluster};
use integration_tests::{eventually, unique_domain, TestDaemon};

/// Two members: `east` (the endpoint clients use) and `west` (where their planes live).
struct Two {
    cluster: String,
    east_port: u16,
    _east: TestDaemon,
    west: TestDaemon,
}

fn two(tag: &str) -> Two {
    two_with(tag, &[])
}

/// [`two`] with `west_args` added to west's command line.
fn two_with(tag: &str, west_args: &[&str]) -> Two {
    let cluster = unique_cluster(tag);
    let (pe, pw) = (free_port(), free_port());
    let east = member(&cluster, "east", pe, &[], &[]);
    let west = member(&cluster, "west", pw, &[pe], west_args);
    let two = Two {
        cluster,
        east_port: pe,
        _east: east,
        west,
    };
    // Both members visible through east's endpoint before anyone connects.
    let view = client_sdk::cluster::Cluster::connect(&two.cluster, &[&endpoint(pe)]).unwrap();
    eventually(Duration::from_secs(10), || {
        (view.daemons().ok()?.len() == 2).then_some(())
    })
    .expect("both members joined");
    two
}

impl Two {
    fn options(&self, daemon: Option<&str>) -> RemoteOptions {
        RemoteOptions {
            cluster: ClusterOptions {
                cluster: self.cluster.clone(),
                endpoints: vec![endpoint(self.east_port)],
                ..Default::default()
            },
            daemon: daemon.map(str::to_string),
        }
    }

    fn remote(&self) -> Client {
        Client::connect_cluster(&self.options(Some("west"))).expect("remote client of west")
    }
}

const DT: f32 = 1.0 / 60.0;
const G: f32 = 10.0;

#[test]
fn a_remote_client_reads_every_tick_bit_for_bit_as_a_local_reader() {
    let two = two("rc-bits");
    let remote = two.remote();
    assert_eq!(remote.cluster_daemon(), Some("west"));
    let plane = remote
        .create_plane(&PlaneOptions {
            tick_rate: Some(0.0),
            gravity: Some([0.0, -G, 0.0]),
            ..integration_tests::no_damping()
        })
        .unwrap();
    let floor = plane
        .add(
            Shape::Cube {
                size: [100.0, 1.0, 100.0],
            },
            Pose::at([0.0, -0.5, 0.0]),
            &[ObjectProp::Anchored(true)],
        )
        .unwrap();
    let h = 5.0f32;
    let balls: Vec<_> = (0..20)
        .map(|i| {
            plane
                .add(
                    Shape::Sphere { radius: 0.5 },
                    Pose::at([i as f32 * 1.5 - 15.0, 0.5 + h + i as f32 * 0.1, 0.0]),
                    &[],
                )
                .unwrap()
        })
        .collect();
    // A local reader on west's own host.
    let local = two.west.client();
    let local_plane = local.attach_plane(plane.id()).unwrap();
    for tick in 1..=90u64 {
        assert_eq!(plane.step(DT).unwrap(), tick);
        let r = plane.snapshot().unwrap();
        assert_eq!(
            r.tick(),
            tick,
            "the remote reader has the tick its step returned"
        );
        let l = eventually(Duration::from_secs(5), || {
            let s = local_plane.snapshot().ok()?;
            (s.tick() == tick).then_some(s)
        })
        .expect("the local reader sees the tick");
        assert_eq!(r.header().state_hash, l.header().state_hash, "tick {tick}");
        assert_eq!(
            shm_layout::StateHasher::of(r.bodies()),
            r.header().state_hash,
            "the rebuilt slots hash to the daemon's StateHash at tick {tick}"
        );
        assert_eq!(r.bodies(), l.bodies(), "tick {tick}");
        if tick == 30 {
            // Semi-implicit Euler over 4 substeps a tick (h = dt/4, m = 4n substeps), as
            // rapier integrates: y = y0 - g h² m(m+1)/2, still in the air at 30 ticks.
            let (hs, m) = (DT / 4.0, 4.0 * tick as f32);
            let y = balls[0].position().unwrap()[1];
            let expect = 0.5 + h - G * hs * hs * m * (m + 1.0) / 2.0;
            assert!(
                (y - expect).abs() < 1e-3,
                "ball 0 at {y}, free fall says {expect}"
            );
        }
    }
    // At rest on the floor after 1.5 s (the highest fell 6.9 units: ~1.2 s at g = 10).
    for b in &balls {
        let y = b.position().unwrap()[1];
        assert!((y - 0.5).abs() < 0.02, "resting on the floor: {y}");
    }
    assert_eq!(
        floor.position().unwrap(),
        [0.0, -0.5, 0.0],
        "the anchored floor stays"
    );
}

#[test]
fn errors_ownership_and_events_come_back_as_they_do_locally() {
    let two = two("rc-errors");
    let remote = two.remote();
    let plane = remote
        .create_plane(&PlaneOptions {
            tick_rate: Some(0.0),
            gravity: Some([0.0, -G, 0.0]),
            ..integration_tests::no_damping()
        })
        .unwrap();
    // Bad input is refused by name, as for a local client.
    let ball = plane
        .add(
            Shape::Sphere { radius: 0.5 },
            Pose::at([0.0, 3.0, 0.0]),
            &[ObjectProp::ReportContacts(true)],
        )
        .unwrap();
    let e = plane
        .add(Shape::Sphere { radius: f32::NAN }, Pose::at([0.0; 3]), &[])
        .unwrap_err()
        .to_string();
    assert!(e.contains("NaN") || e.contains("radius"), "{e}");
    // A local client of west may read the remote client's plane but not change it.
    let local = two.west.client();
    let theirs = local.attach_plane(plane.id()).unwrap();
    let refused = theirs
        .add(
            Shape::Sphere { radius: 0.5 },
            Pose::at([3.0, 3.0, 0.0]),
            &[],
        )
        .and_then(|_| local.flush())
        .unwrap_err();
    match refused {
        client_sdk::Error::Command(e) => assert_eq!(e.kind, ErrorKind::NotOwner, "{e:?}"),
        other => assert!(
            other.to_string().contains("belongs to another client"),
            "{other}"
        ),
    }
    // Events travel: the ball lands on an anchored floor.
    plane
        .add(
            Shape::Cube {
                size: [20.0, 1.0, 20.0],
            },
            Pose::at([0.0, -0.5, 0.0]),
            &[ObjectProp::Anchored(true)],
        )
        .unwrap();
    plane.subscribe_events().unwrap();
    let mut started = Vec::new();
    for _ in 0..90 {
        plane.step(DT).unwrap();
        // Events of a step reach the remote reader within a moment of its reply.
        let events = eventually(Duration::from_millis(200), || {
            let e = plane.events().ok()?;
            (!e.records.is_empty()).then_some(e)
        });
        if let Some(events) = events {
            assert_eq!(events.lost, 0);
            started.extend(
                events
                    .records
                    .iter()
                    .filter_map(Contact::from_record)
                    .filter(|c| matches!(c, Contact::Started { .. })),
            );
        }
    }
    assert_eq!(started.len(), 1, "one landing: {started:?}");
    let Contact::Started { a, b, .. } = started[0] else {
        unreachable!()
    };
    assert!(a == ball.handle() || b == ball.handle());
    // A stale handle is refused by name.
    ball.destroy();
    let e = ball
        .set_velocity([1.0, 0.0, 0.0])
        .and_then(|_| remote.flush());
    assert!(e.is_err(), "a write to a destroyed ball is refused");
}

/// Planes west reports holding (its load report, refreshed each second).
fn west_planes(two: &Two) -> u32 {
    client_sdk::cluster::Cluster::connect(&two.cluster, &[&endpoint(two.east_port)])
        .and_then(|c| c.daemons())
        .ok()
        .and_then(|d| d.into_iter().find(|d| d.name == "west"))
        .and_then(|d| d.load)
        .map_or(u32::MAX, |l| l.planes)
}

#[test]
fn a_remote_clients_planes_are_released_when_it_leaves_or_dies() {
    let two = two("rc-leave");
    let before = eventually(Duration::from_secs(5), || {
        Some(west_planes(&two)).filter(|n| *n != u32::MAX)
    })
    .expect("west reports its load");
    {
        let remote = two.remote();
        remote.create_plane(&PlaneOptions::default()).unwrap();
        eventually(Duration::from_secs(5), || {
            (west_planes(&two) == before + 1).then_some(())
        })
        .expect("west reports the remote client's plane");
    }
    eventually(Duration::from_secs(5), || {
        (west_planes(&two) == before).then_some(())
    })
    .expect("Goodbye released the plane");

    // A remote client process killed without a word: its token ends, the relay says
    // goodbye for it.
    let script = std::env::temp_dir().join(format!("{}.luau", unique_domain("rc-kill")));
    std::fs::write(
        &script,
        "local plane = import(\"PhysicsService\").New({})\nHeart:Connect(function() local _ = plane end)\n",
    )
    .unwrap();
    let mut child =
        integration_tests::cluster::cluster_lua(&two.cluster, two.east_port, "west", &script)
            .spawn()
            .unwrap();
    eventually(Duration::from_secs(20), || {
        (west_planes(&two) == before + 1).then_some(())
    })
    .expect("the script's plane exists on west");
    child.kill().unwrap();
    let _ = child.wait();
    eventually(Duration::from_secs(10), || {
        (west_planes(&two) == before).then_some(())
    })
    .expect("the killed client's plane was released");
    let _ = std::fs::remove_file(script);
}

#[test]
fn a_luau_script_runs_against_a_remote_daemon() {
    let two = two("rc-lua");
    let script = std::env::temp_dir().join(format!("{}.luau", unique_domain("rc-lua")));
    std::fs::write(
        &script,
        r#"
local Physics = import("PhysicsService")
local Renderable = import("Renderable")
local P = import("Primitives")
local V, CF = P.Vector.new, P.CFrame.new
local plane = Physics.New({ TickRate = 0, Gravity = V(0, -10, 0), LinearDamping = 0, AngularDamping = 0 })
local part = Renderable.BasePart("Sphere")
part.Size = V(1, 1, 1)
part.CFrame = CF(V(0, 100, 0))
local ball = plane:Add(part)
for _ = 1, 60 do
    plane:Step(1 / 60)
end
local y = ball.CFrame.Position.Y
-- 60 ticks of 4 substeps of semi-implicit Euler: y0 - g h^2 m (m + 1) / 2.
local h, m = 1 / 240, 240
local expect = 100 - 10 * h * h * m * (m + 1) / 2
assert(math.abs(y - expect) < 1e-3, string.format("y %.5f, expected %.5f", y, expect))
print(string.format("REMOTE OK %.4f", y))
"#,
    )
    .unwrap();
    let out = integration_tests::physics_lua(
        "unused-domain",
        script.to_str().unwrap(),
        &[
            "--cluster",
            &two.cluster,
            "--connect",
            &endpoint(two.east_port),
        ],
    )
    .output()
    .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        out.status.success() && stdout.contains("REMOTE OK"),
        "stdout: {stdout}\nstderr: {stderr}"
    );
    let _ = std::fs::remove_file(script);
}

#[test]
fn each_remote_client_is_its_own_owner_for_quotas() {
    // One client per process and ten objects per owner: remote clients all reach west
    // through its relay (one process), yet each is a client and an owner of its own.
    let two = two_with(
        "rc-quota",
        &[
            "--max-clients-per-process",
            "1",
            "--max-objects-per-client",
            "10",
        ],
    );
    let (a, b) = (two.remote(), two.remote());
    let fill = |c: &Client| {
        let plane = c
            .create_plane(&PlaneOptions {
                tick_rate: Some(0.0),
                ..Default::default()
            })
            .unwrap();
        for i in 0..10 {
            plane
                .add(
                    Shape::Sphere { radius: 0.5 },
                    Pose::at([i as f32 * 2.0, 0.0, 0.0]),
                    &[],
                )
                .unwrap();
        }
        c.flush().unwrap();
        plane
    };
    let pa = fill(&a);
    let e = pa
        .add(
            Shape::Sphere { radius: 0.5 },
            Pose::at([0.0, 5.0, 0.0]),
            &[],
        )
        .and_then(|_| a.flush())
        .unwrap_err()
        .to_string();
    assert!(e.contains("max-objects-per-client"), "{e}");
    // b's quota is untouched by a's.
    fill(&b);
}

#[test]
fn a_session_and_a_plane_stream_within_the_relays_bounds() {
    use physics_daemon::cluster::relay::{MAX_SESSIONS_PER_PLANE, MAX_WATCHES_PER_SESSION};
    let two = two("rc-bounds");
    let remote = two.remote();
    let manual = || PlaneOptions {
        tick_rate: Some(0.0),
        ..Default::default()
    };
    let mut planes: Vec<_> = (0..MAX_WATCHES_PER_SESSION)
        .map(|_| remote.create_plane(&manual()).unwrap())
        .collect();
    let e = remote.create_plane(&manual()).unwrap_err().to_string();
    assert!(e.contains("streams 16 planes"), "{e}");
    // Destroying one frees its place.
    planes.pop().unwrap().destroy().unwrap();
    planes.push(
        eventually(Duration::from_secs(5), || {
            remote.create_plane(&manual()).ok()
        })
        .unwrap(),
    );

    // One plane streams to at most MAX_SESSIONS_PER_PLANE sessions (this one and 15
    // readers); local readers keep the rest of its reader places.
    let target = planes.last().unwrap();
    let readers: Vec<Client> = (1..MAX_SESSIONS_PER_PLANE).map(|_| two.remote()).collect();
    let attached: Vec<_> = readers
        .iter()
        .map(|c| c.attach_plane(target.id()).unwrap())
        .collect();
    let extra = two.remote();
    let e = extra.attach_plane(target.id()).unwrap_err().to_string();
    assert!(e.contains("16 remote sessions"), "{e}");
    let local = two.west.client();
    local
        .attach_plane(target.id())
        .expect("a local reader still gets in");
    drop(attached);
    drop(readers);
    // The readers' sessions ended: their places came back.
    eventually(Duration::from_secs(10), || {
        extra.attach_plane(target.id()).ok()
    })
    .expect("a place freed when the sessions left");
}

#[test]
fn an_unknown_daemon_or_a_forged_session_is_refused_by_name() {
    let two = two("rc-bad");
    let e = Client::connect_cluster(&two.options(Some("nobody")))
        .expect_err("no daemon named nobody")
        .to_string();
    assert!(e.contains("nobody"), "{e}");
    // A request under a key that is no session key is refused without a session.
    let view =
        client_sdk::cluster::Cluster::connect(&two.cluster, &[&endpoint(two.east_port)]).unwrap();
    use zenoh::Wait;
    let replies = view
        .session()
        .get(shm_layout::remote::request_key(
            &two.cluster,
            "west",
            "NOT-HEX",
        ))
        .payload(vec![1u8, 2, 3])
        .timeout(Duration::from_secs(5))
        .wait()
        .unwrap();
    let reply = replies.recv().expect("an answer");
    let err = reply.result().expect_err("refused");
    let text = err.payload().try_to_string().unwrap().into_owned();
    assert!(text.contains("NOT-HEX") && text.contains("hex"), "{text}");
    // The daemon keeps serving remote clients.
    let remote = two.remote();
    remote.create_plane(&PlaneOptions::default()).unwrap();
}

#[test]
fn the_cluster_bench_finds_remote_reads_exact_and_settled_frames_small() {
    let bench = client_sdk::daemon_executable().with_file_name("physics-bench");
    assert!(bench.is_file(), "build the workspace's binaries first");
    let out = std::env::temp_dir().join(unique_domain("rc-bench"));
    let output = std::process::Command::new(bench)
        .args(["cluster", "--bodies", "300", "--seconds", "1", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&output.stdout).to_string()
        + &String::from_utf8_lossy(&output.stderr);
    assert!(output.status.success(), "{text}");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("cluster.json")).unwrap()).unwrap();
    assert_eq!(json["goals"][0]["met"], true, "{text}");
    let cases = json["cases"].as_array().unwrap();
    let bytes = |awake: bool| {
        cases
            .iter()
            .find(|c| c["awake"] == awake)
            .and_then(|c| c["frame_bytes"].as_f64())
            .unwrap()
    };
    // Awake: every slot each tick (~57 bytes a body); settled: the header and what woke.
    assert!(bytes(true) > 300.0 * 40.0, "{text}");
    assert!(bytes(false) < bytes(true) / 10.0, "{text}");
    for c in cases {
        assert!(c["remote"]["ticks"].as_u64().unwrap() >= 30, "{text}");
    }
    // The failover case ran: the survivor resumed the plane from a replicated snapshot.
    assert!(
        json["failover"]["resumed_tick"].as_u64().unwrap() > 0,
        "{text}"
    );
    // The migration row ran: the plane stopped at a tick on one daemon and ticked on the
    // other after a pause.
    assert!(
        json["migrations"][0]["tick"].as_u64().unwrap() > 0,
        "{text}"
    );
    assert!(
        json["migrations"][0]["pause_ms"].as_f64().unwrap() > 0.0,
        "{text}"
    );
    let _ = std::fs::remove_dir_all(out);
}

#[test]
fn placement_puts_a_scripts_planes_on_the_daemon_it_names() {
    let two = two("rc-place");
    let script = std::env::temp_dir().join(format!("{}.luau", unique_domain("rc-place")));
    std::fs::write(
        &script,
        r#"
local Physics = import("PhysicsService")
local Renderable = import("Renderable")
local P = import("Primitives")
local V, CF = P.Vector.new, P.CFrame.new
local here = Physics.New({ TickRate = 0 })
assert(here.Daemon == "east", "own daemon: " .. tostring(here.Daemon))
local there = Physics.New({ Placement = "west", TickRate = 0, Gravity = V(0, -10, 0), LinearDamping = 0, AngularDamping = 0 })
assert(there.Daemon == "west", "placed: " .. tostring(there.Daemon))
local part = Renderable.BasePart("Sphere")
part.Size = V(1, 1, 1)
part.CFrame = CF(V(0, 100, 0))
local ball = there:Add(part)
for _ = 1, 60 do
    there:Step(1 / 60)
end
local y = ball.CFrame.Position.Y
local h, m = 1 / 240, 240
local expect = 100 - 10 * h * h * m * (m + 1) / 2
assert(math.abs(y - expect) < 1e-3, string.format("y %.5f, expected %.5f", y, expect))
assert(Physics.New({ Placement = "west" }).Daemon == "west", "a second plane on west")
assert(Physics.New({ Placement = "local" }).Daemon == "east", "local is the script's daemon")
local auto = Physics.New({ Placement = "auto" }).Daemon
assert(auto == "east" or auto == "west", "auto: " .. tostring(auto))
local ok, err = pcall(function()
    return Physics.New({ Placement = "nobody" })
end)
assert(not ok and string.find(tostring(err), "nobody", 1, true), tostring(err))
print("PLACED OK")
"#,
    )
    .unwrap();
    let out = integration_tests::cluster::cluster_lua(&two.cluster, two.east_port, "east", &script)
        .output()
        .unwrap();
    let text =
        String::from_utf8_lossy(&out.stdout).to_string() + &String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success() && text.contains("PLACED OK"), "{text}");

    // Outside a cluster run, a placement elsewhere is refused naming what it needs.
    std::fs::write(
        &script,
        "local ok, err = pcall(function() return import(\"PhysicsService\").New({ Placement = \"west\" }) end)\n\
         assert(not ok and string.find(tostring(err), \"--cluster\", 1, true), tostring(err))\n\
         assert(import(\"PhysicsService\").New({ Placement = \"local\" }).Daemon == nil)\n\
         print(\"LOCAL OK\")\n",
    )
    .unwrap();
    let out = integration_tests::physics_lua(&two.west.domain, script.to_str().unwrap(), &[])
        .output()
        .unwrap();
    let text =
        String::from_utf8_lossy(&out.stdout).to_string() + &String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success() && text.contains("LOCAL OK"), "{text}");
    let _ = std::fs::remove_file(script);
}

#[test]
fn a_remote_client_learns_its_daemon_died_instead_of_hanging() {
    let mut two = two("rc-dies");
    let remote = two.remote();
    let plane = remote
        .create_plane(&PlaneOptions {
            tick_rate: Some(0.0),
            ..Default::default()
        })
        .unwrap();
    plane.step(DT).unwrap();
    assert_eq!(remote.watch_daemon(), client_sdk::DaemonHealth::Live);
    two.west.kill9();
    let started = std::time::Instant::now();
    let e = plane.step(DT).unwrap_err();
    let took = started.elapsed();
    // The killed daemon's links close at once: its token ends (gone) or the query finds no
    // relay (no answer); either way an error naming it, well within the request timeout.
    assert!(
        took < Duration::from_secs(10),
        "the step failed after {took:?}"
    );
    let text = e.to_string();
    assert!(
        matches!(e, client_sdk::Error::DaemonGone { .. }) || text.contains("west"),
        "{text}"
    );
    eventually(Duration::from_secs(5), || {
        (remote.watch_daemon() == client_sdk::DaemonHealth::Gone).then_some(())
    })
    .expect("the client's watch reports the daemon gone");
}

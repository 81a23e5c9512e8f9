//! Failover seen from the clients: a remote client (Rust, and a `--cluster` Luau script) of
//! a persistent plane on `west` keeps using the same plane values after west is SIGKILLed:
//! its next call finds the member that took the plane over (`east`), the plane goes on there
//! from the replicated snapshot, and the client is told the ticks lost
//! (`Plane::take_recovered`, `plane.Recovered`) instead of getting `DaemonGone`.

use std::io::{BufRead, BufReader};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use client_sdk::{Client, Object, Plane, PlaneName, PlaneOptions, PlaneProp, Pose, Shape};
use integration_tests::cluster::{endpoint, free_port, member, unique_cluster};
use integration_tests::{eventually, unique_domain, TestDaemon};
use zenoh::Wait;

const DT: f32 = 1.0 / 60.0;
const G: f32 = 10.0;
const Y0: f32 = 1000.0;

/// Height after `n` ticks of free fall from `Y0` at rest (4 substeps a tick, semi-implicit
/// Euler, as rapier integrates).
fn fallen(n: u64) -> f32 {
    let (h, m) = (DT / 4.0, 4.0 * n as f32);
    Y0 - G * h * h * m * (m + 1.0) / 2.0
}

/// East and west with state folders of their own; a session of the test's own that sees
/// what west replicates of plane `arena` (the replica's size, the newest tick record).
struct Pair {
    cluster: String,
    east_port: u16,
    _east: TestDaemon,
    west: TestDaemon,
    replicated: Arc<AtomicU64>,
    recorded: Arc<AtomicU64>,
    _subs: Vec<zenoh::pubsub::Subscriber<()>>,
    _view: client_sdk::cluster::Cluster,
    // Last: the daemons go before their state folders.
    _state: StateDir,
}

/// The state folders, removed when dropped.
struct StateDir(std::path::PathBuf);

impl Drop for StateDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

fn pair(tag: &str) -> Pair {
    let cluster = unique_cluster(tag);
    let state = std::env::temp_dir().join(unique_domain(&format!("{tag}-state")));
    let (pe, pw) = (free_port(), free_port());
    // A snapshot period long enough that the saved snapshot (tick 30) is the newest one.
    let flags = |who: &str| {
        [
            "--state-dir".to_string(),
            state.join(who).display().to_string(),
            "--snapshot-every".into(),
            "30".into(),
        ]
    };
    let (fe, fw) = (flags("east"), flags("west"));
    let east = member(
        &cluster,
        "east",
        pe,
        &[],
        &fe.each_ref().map(String::as_str),
    );
    let west = member(
        &cluster,
        "west",
        pw,
        &[pe],
        &fw.each_ref().map(String::as_str),
    );
    let view = client_sdk::cluster::Cluster::connect(&cluster, &[&endpoint(pe)]).unwrap();
    eventually(Duration::from_secs(10), || {
        (view.daemons().ok()?.len() == 2).then_some(())
    })
    .expect("both members joined");
    let replicated = Arc::new(AtomicU64::new(0));
    let recorded = Arc::new(AtomicU64::new(0));
    let (r1, r2) = (replicated.clone(), recorded.clone());
    let replicas = view
        .session()
        .declare_subscriber(format!("physics/{cluster}/replica/west/arena"))
        .callback(move |s| r1.store(s.payload().len() as u64, Ordering::SeqCst))
        .wait()
        .unwrap();
    let ticks = view
        .session()
        .declare_subscriber(format!("physics/{cluster}/replica-tick/west/arena"))
        .callback(move |s| {
            let b = s.payload().to_bytes();
            r2.store(
                u64::from_le_bytes(b[..8].try_into().unwrap()),
                Ordering::SeqCst,
            )
        })
        .wait()
        .unwrap();
    Pair {
        cluster,
        east_port: pe,
        _east: east,
        west,
        replicated,
        recorded,
        _subs: vec![replicas, ticks],
        _view: view,
        _state: StateDir(state),
    }
}

impl Pair {
    /// Waits until the plane file and the tick record of tick `tick` reached the cluster.
    fn replicated_up_to(&self, tick: u64) {
        eventually(Duration::from_secs(10), || {
            (self.replicated.load(Ordering::SeqCst) > 0
                && self.recorded.load(Ordering::SeqCst) == tick)
                .then_some(())
        })
        .expect("west's plane file and tick record were replicated");
        // East got the same puts (a scan period of margin for its callback).
        std::thread::sleep(Duration::from_millis(200));
    }
}

/// The persistent plane "arena" on `client`'s daemon with a ball falling from `Y0`, stepped
/// to tick 30 and saved there.
fn saved_arena(client: &Client) -> (Plane, Object) {
    let plane = client
        .create_plane(
            &PlaneOptions {
                tick_rate: Some(0.0),
                gravity: Some([0.0, -G, 0.0]),
                ..integration_tests::no_damping()
            }
            .with(PlaneProp::Name(PlaneName::new("arena").unwrap()))
            .with(PlaneProp::Persistent(true)),
        )
        .unwrap();
    let ball = plane
        .add(Shape::Sphere { radius: 0.5 }, Pose::at([0.0, Y0, 0.0]), &[])
        .unwrap();
    for _ in 0..30 {
        plane.step(DT).unwrap();
    }
    assert_eq!(plane.save().unwrap(), 30);
    (plane, ball)
}

#[test]
fn a_remote_client_keeps_stepping_its_plane_on_the_member_that_took_it_over() {
    let mut pair = pair("fs-rust");
    let remote = integration_tests::cluster::remote_client(&pair.cluster, pair.east_port, "west");
    let (plane, ball) = saved_arena(&remote);
    for _ in 0..10 {
        plane.step(DT).unwrap();
    }
    pair.replicated_up_to(40);
    assert_eq!(plane.daemon().as_deref(), Some("west"));
    assert_eq!(plane.take_recovered(), None);

    pair.west.kill9();
    let killed = Instant::now();
    // The next step finds the plane on east, resumed from the tick-30 snapshot.
    let tick = plane
        .step(DT)
        .expect("the step goes on on the member that took over");
    let took = killed.elapsed();
    eprintln!("failover switch-over: first step on east {took:?} after west was killed");
    assert_eq!(
        tick, 31,
        "resumed at the replicated snapshot's tick 30, then stepped"
    );
    assert_eq!(plane.daemon().as_deref(), Some("east"));
    assert_eq!(
        plane.take_recovered(),
        Some(10),
        "the ticks west ran past the snapshot"
    );
    assert_eq!(plane.take_recovered(), None, "told once");
    // The same Object value reads the ball where free fall puts it at tick 31.
    let y = ball.position().unwrap()[1];
    assert!(
        (y - fallen(31)).abs() < 1e-2,
        "ball at {y}, free fall says {}",
        fallen(31)
    );
    // Writes and steps go on there; the client owns the plane on east.
    ball.set_velocity([0.0, 0.0, 0.0]).unwrap();
    assert_eq!(plane.step(DT).unwrap(), 32);
    assert!(took < Duration::from_secs(10));
}

/// The daemon that takes a plane over counts the lost ticks from the replicated tick record,
/// which follows the old daemon by up to a few hundred milliseconds. Ticks the client itself
/// saw past the snapshot were lost all the same: `Recovered` never tells fewer.
#[test]
fn recovered_counts_every_tick_the_client_saw_past_the_snapshot() {
    let mut pair = pair("fs-seen");
    let remote = integration_tests::cluster::remote_client(&pair.cluster, pair.east_port, "west");
    let (plane, _ball) = saved_arena(&remote);
    for _ in 0..5 {
        plane.step(DT).unwrap();
    }
    pair.replicated_up_to(35);
    // Ten more ticks, read by this client, then west dies before its next tick record
    // (written every 100 ms) can reach the cluster.
    for _ in 0..10 {
        plane.step(DT).unwrap();
    }
    pair.west.kill9();
    let tick = plane
        .step(DT)
        .expect("the step goes on on the member that took over");
    assert_eq!(tick, 31, "resumed at the snapshot's tick 30, then stepped");
    assert_eq!(
        plane.take_recovered(),
        Some(15),
        "ticks 31 to 45 were seen by this client and are gone"
    );
}

#[test]
fn a_cluster_luau_script_hears_recovered_and_goes_on() {
    let mut pair = pair("fs-lua");
    let script = std::env::temp_dir().join(format!("{}.luau", unique_domain("fs-lua")));
    std::fs::write(
        &script,
        r#"
local Physics = import("PhysicsService")
local Renderable = import("Renderable")
local P = import("Primitives")
local V, CF = P.Vector.new, P.CFrame.new
local plane = Physics.New({ Name = "arena", Persistent = true, TickRate = 0, Gravity = V(0, -10, 0), LinearDamping = 0, AngularDamping = 0 })
assert(plane.Daemon == "west", "placed on west: " .. tostring(plane.Daemon))
local heard = {}
plane.Recovered:Connect(function(lost)
    table.insert(heard, lost)
end)
local part = Renderable.BasePart("Sphere")
part.Size = V(1, 1, 1)
part.CFrame = CF(V(0, 1000, 0))
local ball = plane:Add(part)
for _ = 1, 30 do
    plane:Step(1 / 60)
end
assert(plane:Save() == 30)
for _ = 1, 10 do
    plane:Step(1 / 60)
end
print("READY")
wait(2)
local tick = plane:Step(1 / 60)
assert(plane.Daemon == "east", "switched: " .. tostring(plane.Daemon))
wait()
wait()
assert(#heard == 1 and heard[1] == 10, "Recovered heard " .. #heard .. " times: " .. tostring(heard[1]))
local h, m = 1 / 240, 4 * 31
local expect = 1000 - 10 * h * h * m * (m + 1) / 2
local y = ball.CFrame.Position.Y
assert(math.abs(y - expect) < 1e-2, string.format("y %.4f, expected %.4f (tick %s)", y, expect, tostring(tick)))
print("SWITCHED OK")
"#,
    )
    .unwrap();
    let mut child =
        integration_tests::cluster::cluster_lua(&pair.cluster, pair.east_port, "west", &script)
            .spawn()
            .unwrap();
    let mut lines = BufReader::new(child.stdout.take().unwrap()).lines();
    let ready = lines.by_ref().map_while(Result::ok).any(|l| l == "READY");
    assert!(ready, "the script got ready");
    pair.replicated_up_to(40);
    pair.west.kill9();
    let rest: Vec<String> = lines.map_while(Result::ok).collect();
    let out = child.wait_with_output().unwrap();
    let text = rest.join("\n") + &String::from_utf8_lossy(&out.stderr);
    assert!(
        out.status.success() && text.contains("SWITCHED OK"),
        "{text}"
    );
    let _ = std::fs::remove_file(script);
}

//! `physics-bench cluster`: what a remote reader pays beside a local one. Two daemons form a
//! cluster on loopback (each in a domain of its own, as if on two hosts); a plane ticking at
//! 60 Hz lives on `west`; one reader reads it through the cluster (Zenoh, `east`'s endpoint,
//! west's relay) and one through west's shared memory, at the same time. For 1k and 10k
//! bodies, settled (asleep on a floor) and awake (every body moving), it reports delivery
//! latency (tick end → the reader has the tick, CLOCK_MONOTONIC on one host), p50 and p99,
//! the bytes of a tick's frame on the wire, and whether every tick both readers saw had the
//! same `StateHash`. Then the failover of a persistent plane: its daemon SIGKILLed, the time
//! until a survivor serves it and ticks again, and the ticks lost. And the migration of a
//! plane (`MoveTo`) of 1k and 10k bodies: the pause from its last tick on the old daemon to
//! its first on the new one.

use std::path::PathBuf;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use client_sdk::cluster::{Cluster, ClusterOptions};
use client_sdk::remote::RemoteOptions;
use client_sdk::{Client, ObjectProp, PlaneOptions, PlaneProp, Pose, Shape};
use zenoh::Wait;

use super::daemon::DaemonProcess;
use super::error::{BenchError, BenchResult};
use super::report::{self, num, Goal, Table};
use super::stats::percentile;

/// Options of the `cluster` subcommand.
#[derive(Debug, Clone, clap::Args)]
pub struct ClusterArgs {
    /// Body counts (comma-separated).
    #[arg(long, value_delimiter = ',', default_value = "1000,10000")]
    pub bodies: Vec<usize>,
    /// Seconds each case is read.
    #[arg(long, default_value_t = 4.0)]
    pub seconds: f64,
    /// Folder receiving cluster.json and cluster.md.
    #[arg(long, default_value = "bench-out")]
    pub out: PathBuf,
}

/// One reader's figures in one case.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Reader {
    pub ticks: usize,
    pub p50_ms: Option<f64>,
    pub p99_ms: Option<f64>,
}

/// Failover of a persistent plane: its daemon SIGKILLed, the survivor serving it.
#[derive(Debug, Clone, serde::Serialize)]
pub struct FailoverCase {
    pub bodies: usize,
    /// The newest tick read on the plane's first daemon before the kill.
    pub tick_before: u64,
    /// The tick the survivor resumed at, and the ticks it reports lost.
    pub resumed_tick: u64,
    pub lost_ticks: u64,
    /// SIGKILL to the plane opened on the survivor, and to its first new tick read there.
    pub open_ms: f64,
    pub first_tick_ms: f64,
}

/// Migration of a 60 Hz plane between two daemons (`MoveTo`).
#[derive(Debug, Clone, serde::Serialize)]
pub struct MigrationCase {
    pub bodies: usize,
    /// The tick the plane stopped at on the old daemon.
    pub tick: u64,
    /// From the end of that tick to the end of the next, on the new daemon (tick ends,
    /// CLOCK_MONOTONIC on one host; see [`migration`]). One period (16.7 ms) of it is the
    /// 60 Hz cadence itself.
    pub pause_ms: f64,
    /// The owner's `MoveTo` call: the hand-over and the owner's switch-over (connecting to
    /// the new daemon).
    pub call_ms: f64,
}

/// One case: a body count and a state.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Case {
    pub bodies: usize,
    pub awake: bool,
    pub local: Reader,
    pub remote: Reader,
    /// Mean bytes of a tick's frame on the wire (payload).
    pub frame_bytes: f64,
    /// Ticks both readers saw, and how many of them had different hashes.
    pub compared: usize,
    pub differed: usize,
}

#[derive(Debug, Clone, serde::Serialize)]
pub struct ClusterReport {
    pub seconds: f64,
    pub cases: Vec<Case>,
    pub failover: Option<FailoverCase>,
    pub migrations: Vec<MigrationCase>,
    pub goals: Vec<Goal>,
}

/// What a reader saw: each new tick's (tick, hash, latency ms).
type Seen = Vec<(u64, u64, f64)>;

fn free_port() -> BenchResult<u16> {
    std::net::TcpListener::bind("127.0.0.1:0")
        .and_then(|l| l.local_addr())
        .map(|a| a.port())
        .map_err(BenchError::io("find a free loopback port"))
}

fn member(
    cluster: &str,
    name: &str,
    listen: u16,
    connect: Option<u16>,
    extra: &[String],
) -> BenchResult<DaemonProcess> {
    let mut args: Vec<String> = extra.to_vec();
    args.extend([
        "--cluster".to_string(),
        cluster.to_string(),
        "--name".into(),
        name.into(),
        "--listen".into(),
        format!("tcp/127.0.0.1:{listen}"),
    ]);
    if let Some(port) = connect {
        args.push("--connect".into());
        args.push(format!("tcp/127.0.0.1:{port}"));
    }
    DaemonProcess::start_with(&format!("cl-{name}"), &args, None)
}

/// Builds the case's scene on `client`'s plane (60 Hz) and returns the plane's id.
fn scene(client: &Client, n: usize, awake: bool) -> BenchResult<(client_sdk::Plane, u32)> {
    let mut options = PlaneOptions::default().with(PlaneProp::TickRate(60.0));
    if awake {
        options = options
            .with(PlaneProp::Gravity([0.0; 3]))
            .with(PlaneProp::NeverSleep(true))
            .with(PlaneProp::LinearDamping(0.0));
    }
    let plane = client.create_plane(&options)?;
    let side = (n as f64).sqrt().ceil() as usize;
    if !awake {
        let floor = plane.add(
            Shape::Cube {
                size: [side as f32 * 2.0 + 10.0, 1.0, side as f32 * 2.0 + 10.0],
            },
            Pose::at([0.0, -0.5, 0.0]),
            &[],
        )?;
        floor.set_anchored(true)?;
    }
    for k in 0..n {
        let (i, j) = (k / side, k % side);
        let at = [
            (i as f32 - side as f32 / 2.0) * 2.0,
            0.5,
            (j as f32 - side as f32 / 2.0) * 2.0,
        ];
        let props = if awake {
            // Apart and drifting apart: every slot changes every tick, nothing collides.
            vec![ObjectProp::Velocity([at[0] * 0.01, 0.3, at[2] * 0.01])]
        } else {
            Vec::new()
        };
        plane.add(Shape::Cube { size: [1.0; 3] }, Pose::at(at), &props)?;
    }
    client.flush()?;
    let id = plane.id();
    Ok((plane, id))
}

/// Reads plane `id` for `seconds` through the client `connect` makes on this thread: each
/// new tick's (tick, hash, latency ms).
fn read(
    connect: impl FnOnce() -> Result<Client, client_sdk::Error>,
    id: u32,
    seconds: f64,
) -> BenchResult<Seen> {
    let client = connect()?;
    let plane = client.attach_plane(id)?;
    let mut seen = Vec::new();
    let until = Instant::now() + Duration::from_secs_f64(seconds);
    let mut last = 0;
    while Instant::now() < until {
        plane.wait_tick(Duration::from_secs(1))?;
        let s = plane.snapshot()?;
        let now = shm_layout::monotonic_ns();
        let h = s.header();
        if h.tick > last {
            last = h.tick;
            seen.push((
                h.tick,
                h.state_hash,
                now.saturating_sub(h.tick_end_ns) as f64 / 1e6,
            ));
        }
    }
    Ok(seen)
}

/// A persistent plane of `n` awake bodies at 60 Hz on `west` (state folder, snapshots every
/// 0.5 s, replicated to `east`); after 2 s west is SIGKILLed; east opens the plane and reads
/// its first new tick.
fn failover(n: usize) -> BenchResult<FailoverCase> {
    let cluster = super::daemon::unique_domain("fo").replace('.', "-");
    let state = std::env::temp_dir().join(super::daemon::unique_domain("fo-state"));
    let flags = |who: &str| {
        vec![
            "--state-dir".to_string(),
            state.join(who).display().to_string(),
            "--snapshot-every".into(),
            "0.5".into(),
        ]
    };
    let (pe, pw) = (free_port()?, free_port()?);
    let east = member(&cluster, "east", pe, None, &flags("east"))?;
    let west = member(&cluster, "west", pw, Some(pe), &flags("west"))?;
    let view = Cluster::connect(&cluster, &[&format!("tcp/127.0.0.1:{pe}")])?;
    let deadline = Instant::now() + Duration::from_secs(10);
    while view.daemons()?.len() < 2 {
        if Instant::now() > deadline {
            return Err(BenchError::Failed(
                "the failover members did not meet in 10 s".into(),
            ));
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    let owner = west.connect()?;
    let options = PlaneOptions::default()
        .with(PlaneProp::TickRate(60.0))
        .with(PlaneProp::Gravity([0.0; 3]))
        .with(PlaneProp::NeverSleep(true))
        .with(PlaneProp::Name(client_sdk::PlaneName::new("arena")?))
        .with(PlaneProp::Persistent(true));
    let plane = owner.create_plane(&options)?;
    let side = (n as f64).sqrt().ceil() as usize;
    for k in 0..n {
        let at = [(k / side) as f32 * 2.0, 0.0, (k % side) as f32 * 2.0];
        plane.add(
            Shape::Sphere { radius: 0.5 },
            Pose::at(at),
            &[ObjectProp::Velocity([0.0, 0.5, 0.0])],
        )?;
    }
    owner.flush()?;
    std::thread::sleep(Duration::from_secs(2));
    let tick_before = plane.snapshot()?.tick();
    // SAFETY: kill(2) on the pid of a daemon this process started.
    unsafe { libc::kill(west.pid() as libc::pid_t, libc::SIGKILL) };
    let killed = Instant::now();
    let survivor = east.connect()?;
    let opened = loop {
        match survivor.open_named("arena") {
            Ok(o) => break o,
            Err(_) if killed.elapsed() < Duration::from_secs(20) => {
                std::thread::sleep(Duration::from_millis(5))
            }
            Err(e) => return Err(e.into()),
        }
    };
    let open_ms = killed.elapsed().as_secs_f64() * 1e3;
    let resumed_tick = opened.plane.snapshot()?.tick();
    opened.plane.wait_tick(Duration::from_secs(5))?;
    let first_tick_ms = killed.elapsed().as_secs_f64() * 1e3;
    let case = FailoverCase {
        bodies: n,
        tick_before,
        resumed_tick,
        lost_ticks: opened.recovered.unwrap_or(0),
        open_ms,
        first_tick_ms,
    };
    drop((opened, survivor, plane, owner, view));
    drop((east, west));
    let _ = std::fs::remove_dir_all(&state);
    Ok(case)
}

/// A plane of `n` awake bodies at 60 Hz on `a`, moved to `b` after a second. The pause is
/// read from tick ends: the last tick on `a` (read just before the move, carried forward by
/// the period to the tick the move stopped at) and the first on `b` (the tick read after the
/// move, carried back by the period to the first).
fn migration(n: usize) -> BenchResult<MigrationCase> {
    let cluster = super::daemon::unique_domain("mv").replace('.', "-");
    let (pa, pb) = (free_port()?, free_port()?);
    let a = member(&cluster, "a", pa, None, &[])?;
    let _b = member(&cluster, "b", pb, Some(pa), &[])?;
    let view = Cluster::connect(&cluster, &[&format!("tcp/127.0.0.1:{pa}")])?;
    let deadline = Instant::now() + Duration::from_secs(10);
    while view.daemons()?.len() < 2 {
        if Instant::now() > deadline {
            return Err(BenchError::Failed(
                "the migration members did not meet in 10 s".into(),
            ));
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    let owner = a.connect()?;
    let options = PlaneOptions::default()
        .with(PlaneProp::TickRate(60.0))
        .with(PlaneProp::Gravity([0.0; 3]))
        .with(PlaneProp::NeverSleep(true));
    let plane = owner.create_plane(&options)?;
    let side = (n as f64).sqrt().ceil() as usize;
    for k in 0..n {
        let at = [(k / side) as f32 * 2.0, 0.0, (k % side) as f32 * 2.0];
        plane.add(
            Shape::Sphere { radius: 0.5 },
            Pose::at(at),
            &[ObjectProp::Velocity([0.0, 0.5, 0.0])],
        )?;
    }
    owner.flush()?;
    std::thread::sleep(Duration::from_secs(1));
    let period_ns = 1e9 / 60.0;
    plane.wait_tick(Duration::from_secs(2))?;
    let before = *plane.snapshot()?.header();
    let started = Instant::now();
    let tick = plane.move_to_at("b")?;
    let call_ms = started.elapsed().as_secs_f64() * 1e3;
    plane.wait_tick(Duration::from_secs(5))?;
    let after = *plane.snapshot()?.header();
    if after.tick <= tick || before.tick > tick {
        return Err(BenchError::Failed(format!(
            "migration: ticks {} before, stopped at {tick}, {} after",
            before.tick, after.tick
        )));
    }
    let last_on_a = before.tick_end_ns as f64 + (tick - before.tick) as f64 * period_ns;
    let first_on_b = after.tick_end_ns as f64 - (after.tick - tick - 1) as f64 * period_ns;
    let case = MigrationCase {
        bodies: n,
        tick,
        pause_ms: (first_on_b - last_on_a) / 1e6,
        call_ms,
    };
    drop((plane, owner, view));
    Ok(case)
}

fn figures(seen: &[(u64, u64, f64)]) -> Reader {
    let ms: Vec<f64> = seen.iter().map(|s| s.2).collect();
    Reader {
        ticks: seen.len(),
        p50_ms: percentile(&ms, 0.5),
        p99_ms: percentile(&ms, 0.99),
    }
}

pub fn run(args: &ClusterArgs) -> BenchResult<()> {
    let cluster = super::daemon::unique_domain("cl").replace('.', "-");
    let (pe, pw) = (free_port()?, free_port()?);
    let _east = member(&cluster, "east", pe, None, &[])?;
    let west = member(&cluster, "west", pw, Some(pe), &[])?;
    let endpoint = format!("tcp/127.0.0.1:{pe}");
    let remote = RemoteOptions {
        cluster: ClusterOptions {
            cluster: cluster.clone(),
            endpoints: vec![endpoint.clone()],
            ..Default::default()
        },
        daemon: Some("west".into()),
    };
    // Wait until both members see each other.
    let view = Cluster::connect(&cluster, &[&endpoint])?;
    let deadline = Instant::now() + Duration::from_secs(10);
    while view.daemons()?.len() < 2 {
        if Instant::now() > deadline {
            return Err(BenchError::Failed(
                "the two members did not meet in 10 s".into(),
            ));
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    let owner = Client::connect_cluster(&remote)?;
    let mut cases = Vec::new();
    for &n in &args.bodies {
        for awake in [false, true] {
            eprintln!(
                "cluster: {n} bodies, {}",
                if awake { "awake" } else { "settled" }
            );
            let (plane, id) = scene(&owner, n, awake)?;
            if !awake {
                // Let the pile fall asleep.
                std::thread::sleep(Duration::from_secs(3));
            }
            let bytes = Arc::new(AtomicU64::new(0));
            let frames = Arc::new(AtomicU64::new(0));
            let (b, f) = (bytes.clone(), frames.clone());
            let counter = view
                .session()
                .declare_subscriber(format!("physics/{cluster}/relay/west/bodies/*/{id}"))
                .callback(move |s| {
                    b.fetch_add(s.payload().len() as u64, Ordering::Relaxed);
                    f.fetch_add(1, Ordering::Relaxed);
                })
                .wait()
                .map_err(|e| BenchError::Failed(format!("count frames: {e}")))?;
            let (r, seconds) = (remote.clone(), args.seconds);
            let remote_reader = std::thread::spawn(move || {
                read(|| Client::connect_cluster(&r), id, seconds).map_err(|e| e.to_string())
            });
            let domain = west.domain.clone();
            let local_reader = std::thread::spawn(move || {
                read(|| Client::connect(&domain), id, seconds).map_err(|e| e.to_string())
            });
            let join = |h: std::thread::JoinHandle<Result<Seen, String>>| {
                h.join()
                    .map_err(|_| BenchError::Failed("a reader panicked".into()))?
                    .map_err(BenchError::Failed)
            };
            let (rs, ls) = (join(remote_reader)?, join(local_reader)?);
            drop(counter);
            // Skip each reader's first tick: its keyframe or its first sample.
            let local: std::collections::HashMap<u64, u64> =
                ls.iter().skip(1).map(|s| (s.0, s.1)).collect();
            let compared: Vec<_> = rs
                .iter()
                .skip(1)
                .filter(|s| local.contains_key(&s.0))
                .collect();
            let differed = compared.iter().filter(|s| local[&s.0] != s.1).count();
            let f = frames.load(Ordering::Relaxed).max(1);
            cases.push(Case {
                bodies: n,
                awake,
                local: figures(&ls[1.min(ls.len())..]),
                remote: figures(&rs[1.min(rs.len())..]),
                frame_bytes: bytes.load(Ordering::Relaxed) as f64 / f as f64,
                compared: compared.len(),
                differed,
            });
            plane.destroy()?;
        }
    }
    let n = args.bodies.first().copied().unwrap_or(1000);
    eprintln!("cluster: failover of a persistent plane of {n} bodies");
    let fo = failover(n)?;
    let mut migrations = Vec::new();
    for &n in &args.bodies {
        eprintln!("cluster: migration of a plane of {n} bodies");
        migrations.push(migration(n)?);
    }
    let differed: usize = cases.iter().map(|c| c.differed).sum();
    let compared: usize = cases.iter().map(|c| c.compared).sum();
    let mut goals = vec![Goal::new(
        "every tick both readers saw has the same StateHash (remote reads are exact)",
        format!("{differed} of {compared} differ"),
        Some(differed == 0 && compared > 0),
    )];
    goals.push(Goal::new(
        format!(
            "failover: SIGKILL of a persistent plane's daemon ({} bodies, 60 Hz) to its first \
             tick on the survivor ≤ 2 s",
            fo.bodies
        ),
        format!(
            "{:.0} ms (opened after {:.0} ms); resumed at tick {}, Recovered reports {} ticks \
             lost; tick {} was read before the kill, so at least {} were (the tick record \
             lags up to ~200 ms)",
            fo.first_tick_ms,
            fo.open_ms,
            fo.resumed_tick,
            fo.lost_ticks,
            fo.tick_before,
            fo.tick_before.saturating_sub(fo.resumed_tick)
        ),
        Some(fo.first_tick_ms <= 2000.0),
    ));
    for m in &migrations {
        // 100 ms at 1k bodies: six ticks at 60 Hz, a hitch a player sees once but short of
        // what a game's networking treats as a stall; the hand-over is a snapshot of the
        // plane (~100 bytes a body) over loopback and its restore.
        let judged = (m.bodies <= 1000).then_some(m.pause_ms <= 100.0);
        goals.push(Goal::new(
            format!(
                "migration: MoveTo of a 60 Hz plane of {} bodies, last tick on the old daemon \
                 to the first on the new one{}",
                m.bodies,
                if m.bodies <= 1000 {
                    " ≤ 100 ms"
                } else {
                    " (reported, not judged)"
                }
            ),
            format!(
                "{:.1} ms (one 16.7 ms period of it is the cadence); the owner's MoveTo call \
                 {:.1} ms; stopped at tick {}",
                m.pause_ms, m.call_ms, m.tick
            ),
            judged,
        ));
    }
    for c in &cases {
        let ratio = match (c.remote.p50_ms, c.local.p50_ms) {
            (Some(r), Some(l)) if l > 0.0 => Some(r / l),
            _ => None,
        };
        goals.push(Goal::new(
            format!(
                "remote p50 / local p50, {} bodies {} (reported, not judged)",
                c.bodies,
                if c.awake { "awake" } else { "settled" }
            ),
            ratio.map_or("-".into(), |r| format!("{r:.1}")),
            None,
        ));
    }
    let report = ClusterReport {
        seconds: args.seconds,
        cases,
        failover: Some(fo),
        migrations,
        goals,
    };
    let md = markdown(&report);
    let (json, md_path) = report::write(&args.out, "cluster", &report, &md)?;
    report::print(&md_path);
    println!("wrote {} and {}", json.display(), md_path.display());
    Ok(())
}

fn markdown(r: &ClusterReport) -> String {
    let mut t = Table::new(&[
        "bodies",
        "state",
        "local ticks",
        "local p50 (ms)",
        "local p99 (ms)",
        "remote ticks",
        "remote p50 (ms)",
        "remote p99 (ms)",
        "frame bytes",
        "same hash",
    ]);
    for c in &r.cases {
        t.row(&[
            c.bodies.to_string(),
            if c.awake { "awake" } else { "settled" }.into(),
            c.local.ticks.to_string(),
            num(c.local.p50_ms),
            num(c.local.p99_ms),
            c.remote.ticks.to_string(),
            num(c.remote.p50_ms),
            num(c.remote.p99_ms),
            format!("{:.0}", c.frame_bytes),
            format!("{} of {}", c.compared - c.differed, c.compared),
        ]);
    }
    format!(
        "# Cluster: remote readers beside local ones\n\nA plane at 60 Hz on daemon `west`; one \
         reader through the cluster (Zenoh on loopback via `east`, west's relay), one through \
         west's shared memory, both reading for {} s. Latency: the tick's end (daemon) to the \
         reader holding it (CLOCK_MONOTONIC, one host). Frame bytes: the mean payload of a \
         tick's frame (changed slots only). Failover: a persistent plane on a second pair of \
         members (state folders, snapshots every 0.5 s), its daemon SIGKILLed after 2 s. \
         Migration: a 60 Hz plane moved between two members with MoveTo; the pause from \
         tick ends.\n\n{}",
        r.seconds,
        t.finish(),
    )
}

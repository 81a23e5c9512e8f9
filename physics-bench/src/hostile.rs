//! `physics-bench hostile [--out DIR]`: hostile clients at scale against real daemons, one
//! verdict row per attack: reply amplification, a heavy query beside another client's
//! steps, the quota race of many connections, controller paths, a plane slower than 1 Hz,
//! `Threads` against cores, the cost of an empty plane against what the memory budget
//! counts, processes coming and going beside another client's steps, and a process past
//! its CPU share beside another client. Writes DIR/hostile.json
//! and DIR/hostile.md. The suite's `tests/tests/hostile_scale.rs` runs the same attacks at
//! debug-build sizes.

use std::io::{BufRead, Write};
use std::path::PathBuf;
use std::sync::{Arc, Barrier};
use std::time::{Duration, Instant};

use client_sdk::{Client, PlaneOptions, Pose, Ray, Shape};
use physics_daemon::server::quota::PLANE_BYTES;
use shm_layout::codec::{decode_response, encode_request};
use shm_layout::query::MAX_RAY_WORK;
use shm_layout::{
    Command, CommandResult, ControllerOp, Handle, PlaneId, PlaneOp, QueryFilter, QueryOp, Reply,
    Request, Response,
};

use super::daemon::DaemonProcess;
use super::error::{BenchError, BenchResult};
use super::procfs;
use super::report::{self, Goal};
use super::stats::percentile;

/// Options of the `hostile` subcommand.
#[derive(Debug, Clone, clap::Args)]
pub struct HostileArgs {
    /// Folder receiving hostile.json and hostile.md.
    #[arg(long, default_value = "bench-out")]
    pub out: PathBuf,
    /// Internal: be the CPU hog of the fairness row on the daemon of this domain.
    #[arg(long, hide = true)]
    pub hog: Option<String>,
    /// Internal: be a visiting client of the come-and-go row (connect to the daemon of this
    /// domain, make a plane, leave).
    #[arg(long, hide = true)]
    pub visit: Option<String>,
}

/// The report: one goal per attack.
#[derive(Debug, Clone, serde::Serialize)]
pub struct HostileReport {
    pub goals: Vec<Goal>,
}

fn send(client: &Client, commands: Vec<Command>) -> BenchResult<(Vec<CommandResult>, usize)> {
    let request = encode_request(&Request { commands });
    let bytes = client.raw_request(&request)?;
    match decode_response(&bytes).map_err(|e| BenchError::Failed(e.to_string()))? {
        Response::Results(r) => Ok((r, bytes.len())),
        Response::Rejected(e) => Err(BenchError::Failed(format!("rejected: {e}"))),
    }
}

fn add_cubes(plane: PlaneId, n: usize, at: impl Fn(usize) -> [f32; 3]) -> Vec<Command> {
    (0..n)
        .map(|i| {
            Command::plane(
                plane,
                PlaneOp::AddObject {
                    shape: Shape::Cube { size: [0.5; 3] },
                    pose: Pose::at(at(i)),
                    props: vec![],
                },
            )
        })
        .collect()
}

fn grid(i: usize) -> [f32; 3] {
    [(i % 20) as f32, (i / 400) as f32, ((i / 20) % 20) as f32]
}

fn ms(d: f64) -> String {
    format!("{:.2} ms", d * 1e3)
}

/// Step latencies (seconds) of `plane`, `n` steps with a short pause between.
fn steps(plane: &client_sdk::Plane, n: usize) -> BenchResult<Vec<f64>> {
    let mut out = Vec::with_capacity(n);
    for _ in 0..n {
        let t = Instant::now();
        plane.step(1.0 / 60.0)?;
        out.push(t.elapsed().as_secs_f64());
        std::thread::sleep(Duration::from_millis(2));
    }
    Ok(out)
}

/// A victim: a daemon of its own (named by `tag`), a manual plane of 100 cubes on it, and
/// `n` steps timed alone.
fn victim(tag: &str, n: usize) -> BenchResult<(DaemonProcess, client_sdk::Plane, Vec<f64>)> {
    let daemon = DaemonProcess::start(tag)?;
    let client = Client::connect(&daemon.domain)?;
    let plane = client.create_plane(&PlaneOptions::manual())?;
    send(&client, add_cubes(plane.id(), 100, grid))?;
    let alone = steps(&plane, n)?;
    Ok((daemon, plane, alone))
}

/// 1. A request of overlap queries over 10,000 objects: reply bytes against request bytes.
fn amplification() -> BenchResult<Goal> {
    let daemon = DaemonProcess::start("hostile-reply")?;
    let client = Client::connect(&daemon.domain)?;
    let plane = client.create_plane(&PlaneOptions::manual())?;
    send(&client, add_cubes(plane.id(), 10_000, grid))?;
    let query = QueryOp::BoundsInRadius {
        position: [10.0; 3],
        radius: 1_000.0,
        filter: QueryFilter::default(),
    };
    let commands: Vec<Command> = (0..1_000)
        .map(|_| Command::plane(plane.id(), PlaneOp::Query(query.clone())))
        .collect();
    let request = encode_request(&Request {
        commands: commands.clone(),
    })
    .len();
    let (_, reply) = send(&client, commands)?;
    let limit = physics_daemon::server::Limits::DEFAULT.reply_bytes;
    Ok(Goal::new(
        format!("1,000 × GetPartBoundsInRadius over 10,000 objects: reply ≤ --max-reply-bytes ({} MiB) + refusals", limit >> 20),
        format!(
            "request {} KB, reply {:.1} MB ({:.0}×)",
            request / 1000,
            reply as f64 / 1e6,
            reply as f64 / request as f64
        ),
        Some(reply <= limit + 1_000 * 256),
    ))
}

/// 2. Heavy raycasts on one client's plane beside another client's steps.
fn stall() -> BenchResult<Goal> {
    let (daemon, mine, alone) = victim("hostile-stall", 200)?;
    let domain = daemon.domain.clone();
    let stop = Arc::new(std::sync::atomic::AtomicBool::new(false));
    let ready = Arc::new(Barrier::new(2));
    let attacker = {
        let (stop, ready) = (stop.clone(), ready.clone());
        std::thread::spawn(move || -> BenchResult<Vec<f64>> {
            let client = Client::connect(&domain)?;
            let plane = client.create_plane(&PlaneOptions::manual())?;
            let (added, _) = send(
                &client,
                add_cubes(plane.id(), 1_000, |i| [i as f32, 0.0, 0.0]),
            )?;
            let list: Vec<Handle> = added
                .iter()
                .filter_map(|r| match r {
                    Ok(Reply::Object { handle, .. }) => Some(*handle),
                    _ => None,
                })
                .collect();
            let ray = Ray {
                origin: [-1.0, 0.0, 0.0],
                direction: [2_000.0, 0.0, 0.0],
            };
            let op = QueryOp::Raycast {
                rays: vec![ray; MAX_RAY_WORK / (1 + list.len())],
                filter: QueryFilter {
                    list,
                    ..QueryFilter::default()
                },
            };
            ready.wait();
            let mut took = Vec::new();
            while !stop.load(std::sync::atomic::Ordering::Relaxed) || took.is_empty() {
                let t = Instant::now();
                send(
                    &client,
                    vec![Command::plane(plane.id(), PlaneOp::Query(op.clone()))],
                )?;
                took.push(t.elapsed().as_secs_f64());
            }
            Ok(took)
        })
    };
    ready.wait();
    std::thread::sleep(Duration::from_millis(20));
    let during = steps(&mine, 200)?;
    stop.store(true, std::sync::atomic::Ordering::Relaxed);
    let took = attacker
        .join()
        .map_err(|_| BenchError::Failed("the attacker panicked".into()))??;
    let (a99, d99) = (
        percentile(&alone, 0.99).unwrap_or(0.0),
        percentile(&during, 0.99).unwrap_or(0.0),
    );
    let query = took.iter().copied().fold(f64::INFINITY, f64::min);
    Ok(Goal::new(
        "Step p99 beside another client's maximal raycast requests ≤ 2× alone",
        format!(
            "alone {}, beside {} (one query request {})",
            ms(a99),
            ms(d99),
            ms(query)
        ),
        Some(d99 <= 2.0 * a99.max(0.5e-3)),
    ))
}

/// 3. Eight connections of one process add a whole quota each at once.
fn quota_race() -> BenchResult<Goal> {
    const QUOTA: usize = 20_000;
    let daemon = DaemonProcess::start_with(
        "hostile-race",
        &["--max-objects-per-client".into(), QUOTA.to_string()],
        None,
    )?;
    let ready = Arc::new(Barrier::new(8));
    let done = Arc::new(Barrier::new(8));
    let threads: Vec<_> = (0..8)
        .map(|_| {
            let (domain, ready, done) = (daemon.domain.clone(), ready.clone(), done.clone());
            std::thread::spawn(move || -> BenchResult<usize> {
                let client = Client::connect(&domain)?;
                let plane = client.create_plane(&PlaneOptions::manual())?;
                let mut commands = vec![Command::plane(plane.id(), PlaneOp::Step { dt: 0.01 })];
                commands.extend(add_cubes(plane.id(), QUOTA, grid));
                ready.wait();
                let (r, _) = send(&client, commands)?;
                done.wait();
                Ok(r.iter().skip(1).filter(|r| r.is_ok()).count())
            })
        })
        .collect();
    let mut accepted = 0;
    for t in threads {
        accepted += t
            .join()
            .map_err(|_| BenchError::Failed("a connection panicked".into()))??;
    }
    Ok(Goal::new(
        format!("8 connections of one process, {QUOTA} objects each at once: accepted = the quota ({QUOTA})"),
        accepted.to_string(),
        Some(accepted == QUOTA),
    ))
}

/// 4. Controllers with full paths until the state quota refuses.
fn paths() -> BenchResult<Goal> {
    let daemon = DaemonProcess::start("hostile-paths")?;
    let client = Client::connect(&daemon.domain)?;
    let plane = client.create_plane(&PlaneOptions::manual())?;
    let points = shm_layout::controller_op::MAX_WAYPOINTS;
    let path: Vec<[f32; 3]> = (0..points).map(|i| [i as f32 * 0.01, 0.0, 9.0]).collect();
    let before = procfs::rss_bytes(daemon.pid())?;
    let mut accepted = 0;
    for i in 0..200 {
        let c = plane.new_controller(
            Pose::at([i as f32 * 3.0, 0.0, 0.0]),
            [2.0, 5.0, 2.0],
            false,
            &[],
        )?;
        let op = ControllerOp::SetPath {
            handle: c.handle(),
            waypoints: path.clone(),
        };
        let (r, _) = send(
            &client,
            vec![Command::plane(plane.id(), PlaneOp::Controller(op))],
        )?;
        if r[0].is_err() {
            break;
        }
        accepted += 1;
    }
    let grown = procfs::rss_bytes(daemon.pid())?.saturating_sub(before);
    let quota = physics_daemon::server::Limits::DEFAULT.state_bytes_per_client;
    Ok(Goal::new(
        format!(
            "200 controllers × {points}-point paths: refused past --max-state-bytes-per-client ({} MiB)",
            quota >> 20
        ),
        format!("{accepted} paths accepted, daemon RSS +{} MiB", grown >> 20),
        Some((accepted as u64) * 12 * points as u64 <= quota),
    ))
}

/// 5. A plane at TickRate 0.5 ticks.
fn slow_plane() -> BenchResult<Goal> {
    let daemon = DaemonProcess::start("hostile-slow")?;
    let client = Client::connect(&daemon.domain)?;
    let plane = client.create_plane(&PlaneOptions {
        tick_rate: Some(0.5),
        ..PlaneOptions::default()
    })?;
    let tick = plane.wait_tick(Duration::from_secs(5)).unwrap_or(0);
    Ok(Goal::new(
        "TickRate 0.5 ticks within one period (+1 s)",
        format!("tick {tick} after the first period"),
        Some(tick >= 1),
    ))
}

/// 6. 64 planes asking for Threads = 64.
fn threads() -> BenchResult<Goal> {
    let daemon = DaemonProcess::start("hostile-threads")?;
    let client = Client::connect(&daemon.domain)?;
    let threads_of =
        |pid: u32| std::fs::read_dir(format!("/proc/{pid}/task")).map_or(0, |d| d.count());
    let before = threads_of(daemon.pid());
    let mut planes = Vec::new();
    for _ in 0..64 {
        let plane = client.create_plane(&PlaneOptions {
            threads: Some(64),
            ..PlaneOptions::manual()
        })?;
        plane.step(0.01)?;
        planes.push(plane);
    }
    let after = threads_of(daemon.pid());
    let cores = physics_daemon::backend::pools::cores() as usize;
    let read_back = planes[0].info()?.settings.threads;
    Ok(Goal::new(
        format!("64 planes × Threads 64: threads ≤ 64 workers + {cores} cores; Threads reads back what is used"),
        format!("+{} threads, Threads reads {read_back}", after - before),
        Some(after - before <= 64 + cores && read_back as usize == 64.min(cores)),
    ))
}

/// 9. An empty plane's measured cost against what the memory budget counts.
fn empty_planes() -> BenchResult<Goal> {
    let daemon = DaemonProcess::start("hostile-memory")?;
    let client = Client::connect(&daemon.domain)?;
    let _first = client.create_plane(&PlaneOptions::manual())?;
    let before = procfs::rss_bytes(daemon.pid())?;
    let planes: Vec<_> = (0..32)
        .map(|_| client.create_plane(&PlaneOptions::manual()))
        .collect::<Result<_, _>>()?;
    std::thread::sleep(Duration::from_millis(200));
    let per_plane = (procfs::rss_bytes(daemon.pid())?.saturating_sub(before)) / planes.len() as u64;
    Ok(Goal::new(
        format!(
            "an empty plane costs ≤ what --max-memory-mb counts for it ({} MiB)",
            PLANE_BYTES >> 20
        ),
        format!("{:.1} MiB", per_plane as f64 / (1 << 20) as f64),
        Some(per_plane <= PLANE_BYTES),
    ))
}

/// 10. Processes that connect, make a plane and leave, one after another, beside a Step.
///
/// Each client that left used to hold the request loop ~130 ms while the daemon swept its
/// reply connection, then ~30 ms while iceoryx2 fsynced service descriptions on a disk.
fn come_and_go() -> BenchResult<Goal> {
    let (daemon, mine, alone) = victim("hostile-churn", 300)?;
    let domain = daemon.domain.clone();
    let exe = std::env::current_exe().map_err(BenchError::io("find physics-bench"))?;
    let visitors = std::thread::spawn(move || -> BenchResult<()> {
        for _ in 0..10 {
            let out = std::process::Command::new(&exe)
                .args(["hostile", "--visit", &domain])
                .output()
                .map_err(BenchError::io("run a visiting client"))?;
            if !out.status.success() {
                return Err(BenchError::Failed(format!(
                    "a visiting client failed: {}",
                    String::from_utf8_lossy(&out.stderr)
                )));
            }
        }
        Ok(())
    });
    // Step while they come and go, and until the daemon's next looks (twice a second while
    // busy) have closed what they left.
    let mut during = Vec::new();
    let mut gone: Option<Instant> = None;
    while gone.is_none_or(|g| g.elapsed() < Duration::from_millis(1500)) {
        let t = Instant::now();
        mine.step(1.0 / 60.0)?;
        during.push(t.elapsed().as_secs_f64());
        if gone.is_none() && visitors.is_finished() {
            gone = Some(Instant::now());
        }
    }
    visitors
        .join()
        .map_err(|_| BenchError::Failed("the visiting clients' thread panicked".into()))??;
    let a99 = percentile(&alone, 0.99).unwrap_or(0.0);
    let worst = during.iter().copied().fold(0.0, f64::max);
    Ok(Goal::new(
        "another client's worst Step while 10 processes connect, make a plane and leave ≤ one \
         60 Hz frame (16.7 ms)",
        format!(
            "worst {} of {} steps (p99 alone {})",
            ms(worst),
            during.len(),
            ms(a99)
        ),
        Some(worst <= 1.0 / 60.0),
    ))
}

/// 11. A process ticking 64 planes at 10,000 Hz beside another client's steps.
fn fairness() -> BenchResult<Goal> {
    let (daemon, mine, alone) = victim("hostile-cpu", 300)?;
    let exe = std::env::current_exe().map_err(BenchError::io("find physics-bench"))?;
    let mut hog = std::process::Command::new(exe)
        .args(["hostile", "--hog", &daemon.domain])
        .stdin(std::process::Stdio::piped())
        .stdout(std::process::Stdio::piped())
        .spawn()
        .map_err(BenchError::io("start the CPU hog"))?;
    let mut line = String::new();
    let stdout = hog.stdout.take().expect("piped");
    std::io::BufReader::new(stdout)
        .read_line(&mut line)
        .map_err(BenchError::io("read the hog"))?;
    std::thread::sleep(Duration::from_millis(500));
    let during = steps(&mine, 300)?;
    let _ = hog.kill();
    let _ = hog.wait();
    let (a50, d50) = (
        percentile(&alone, 0.5).unwrap_or(0.0),
        percentile(&during, 0.5).unwrap_or(0.0),
    );
    let (a99, d99) = (
        percentile(&alone, 0.99).unwrap_or(0.0),
        percentile(&during, 0.99).unwrap_or(0.0),
    );
    Ok(Goal::new(
        "Step beside a process ticking 64 planes at 10,000 Hz: p50 ≤ 2× alone (p99 shown; \
         2 shared cores)",
        format!(
            "p50 {} → {}, p99 {} → {}",
            ms(a50),
            ms(d50),
            ms(a99),
            ms(d99)
        ),
        Some(d50 <= 2.0 * a50.max(0.5e-3)),
    ))
}

/// The hog of [`fairness`]: 64 planes at TickRate 10,000 with 50 balls each, until its
/// stdin closes.
fn hog(domain: &str) -> BenchResult<()> {
    let client = Client::connect(domain)?;
    let mut planes = Vec::new();
    for _ in 0..64 {
        let plane = client.create_plane(&PlaneOptions {
            tick_rate: Some(10_000.0),
            never_sleep: Some(true),
            ..PlaneOptions::default()
        })?;
        send(
            &client,
            (0..50)
                .map(|i| {
                    Command::plane(
                        plane.id(),
                        PlaneOp::AddObject {
                            shape: Shape::Sphere { radius: 0.5 },
                            pose: Pose::at([(i % 10) as f32 * 1.5, 1.0 + (i / 10) as f32, 0.0]),
                            props: vec![],
                        },
                    )
                })
                .collect(),
        )?;
        planes.push(plane);
    }
    println!("ready");
    std::io::stdout().flush().map_err(BenchError::io("write"))?;
    let mut line = String::new();
    let _ = std::io::stdin().read_line(&mut line);
    Ok(())
}

/// One attack: measures and judges it.
type Row = fn() -> BenchResult<Goal>;

pub fn run(args: &HostileArgs) -> BenchResult<()> {
    if let Some(domain) = &args.hog {
        return hog(domain);
    }
    if let Some(domain) = &args.visit {
        let client = Client::connect(domain)?;
        client.create_plane(&PlaneOptions::manual())?;
        return Ok(());
    }
    let rows: [(&str, Row); 9] = [
        ("reply amplification", amplification),
        ("queries beside steps", stall),
        ("quota race", quota_race),
        ("controller paths", paths),
        ("TickRate below 1", slow_plane),
        ("Threads", threads),
        ("empty planes", empty_planes),
        ("clients coming and going", come_and_go),
        ("CPU shares", fairness),
    ];
    let mut goals = Vec::new();
    for (name, row) in rows {
        eprintln!("hostile: {name}");
        goals.push(row().unwrap_or_else(|e| Goal::new(name, format!("failed: {e}"), Some(false))));
    }
    let markdown = "# Hostile clients at scale\n\nOne real daemon per attack (release build \
                    when run from target/release). Shared planes and the Luau sandbox are \
                    covered by the suite (`tests/tests/hostile_scale.rs`, \
                    `tests/lua/sandbox_assets.luau`); one goal per attack.\n";
    let report = HostileReport { goals };
    let (json, md) = report::write(&args.out, "hostile", &report, markdown)?;
    println!("{}\n{}", json.display(), md.display());
    if report.goals.iter().any(|g| g.met == Some(false)) {
        return Err(BenchError::Failed("some hostile goals were not met".into()));
    }
    Ok(())
}

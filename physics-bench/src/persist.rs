//! `physics-bench persist`: what persistence costs a plane's tick. Two daemons side by side,
//! one started with `--state-dir` and a short `--snapshot-every`, one without; each holds an
//! awake pile of N bodies (persistent and named on the first); steps alternate between them
//! for a few seconds of wall time, client-observed. The periodic write snapshots the plane on
//! its worker (the plane's own encoder) and hands the bytes to the writer thread, which does
//! the disk work (write, fsync, rename, fsync of the directory) off the tick: the median
//! tick should not move, and the slowest ticks show the encode.

use std::path::PathBuf;
use std::time::{Duration, Instant};

use client_sdk::{Client, Plane, PlaneName, PlaneOptions, PlaneProp, Pose, Shape};

use super::daemon::DaemonProcess;
use super::error::{BenchError, BenchResult};
use super::report::{self, num, Goal, Table};

/// Options of the `persist` subcommand.
#[derive(Debug, Clone, clap::Args)]
pub struct PersistArgs {
    /// Bodies of the awake pile.
    #[arg(long, default_value_t = 1_000)]
    pub bodies: usize,
    /// `--snapshot-every` of the persistent daemon, in seconds.
    #[arg(long, default_value_t = 0.5)]
    pub every: f64,
    /// Seconds of alternating steps.
    #[arg(long, default_value_t = 6.0)]
    pub seconds: f64,
    /// Folder receiving persist.json and persist.md.
    #[arg(long, default_value = "bench-out")]
    pub out: PathBuf,
}

/// One side's tick times (client-observed `Step`, ms).
#[derive(Debug, Clone, serde::Serialize)]
pub struct Side {
    pub persistent: bool,
    pub ticks: usize,
    pub median_ms: f64,
    pub p99_ms: f64,
    pub max_ms: f64,
}

#[derive(Debug, Clone, serde::Serialize)]
pub struct PersistReport {
    pub bodies: usize,
    pub every_s: f64,
    /// The plane's file size.
    pub file_bytes: u64,
    pub sides: Vec<Side>,
    pub goals: Vec<Goal>,
}

const DT: f32 = 1.0 / 60.0;

fn pile(client: &Client, n: usize, name: Option<&str>) -> BenchResult<Plane> {
    let mut options = PlaneOptions::manual().with(PlaneProp::NeverSleep(true));
    if let Some(name) = name {
        let name = PlaneName::new(name)?;
        options = options
            .with(PlaneProp::Name(name))
            .with(PlaneProp::Persistent(true));
    }
    let plane = client.create_plane(&options)?;
    let side = (n as f64).sqrt().ceil() as usize;
    let floor = plane.add(
        Shape::Cube {
            size: [side as f32 * 1.5 + 10.0, 1.0, side as f32 * 1.5 + 10.0],
        },
        Pose::at([0.0, -0.5, 0.0]),
        &[],
    )?;
    floor.set_anchored(true)?;
    for k in 0..n {
        let (i, j) = (k / side, k % side);
        let at = [
            (i as f32 - side as f32 / 2.0) * 1.2,
            1.0 + (k % 3) as f32 * 1.1,
            (j as f32 - side as f32 / 2.0) * 1.2,
        ];
        plane.add(Shape::Cube { size: [1.0; 3] }, Pose::at(at), &[])?;
    }
    for _ in 0..10 {
        plane.step(DT)?;
    }
    Ok(plane)
}

fn side(persistent: bool, mut ms: Vec<f64>) -> Side {
    ms.sort_by(f64::total_cmp);
    let at = |q: f64| ms[((ms.len() - 1) as f64 * q).round() as usize];
    Side {
        persistent,
        ticks: ms.len(),
        median_ms: at(0.5),
        p99_ms: at(0.99),
        max_ms: at(1.0),
    }
}

pub fn run(args: &PersistArgs) -> BenchResult<()> {
    let state = std::env::temp_dir().join(super::daemon::unique_domain("persist-state"));
    std::fs::create_dir_all(&state).map_err(BenchError::io("create the state directory"))?;
    let persistent = DaemonProcess::start_with(
        "persist-on",
        &[
            "--state-dir".to_string(),
            state.display().to_string(),
            "--snapshot-every".to_string(),
            args.every.to_string(),
        ],
        None,
    )?;
    let plain = DaemonProcess::start("persist-off")?;
    let (a, b) = (persistent.connect()?, plain.connect()?);
    eprintln!(
        "persist: {} awake bodies, written every {} s",
        args.bodies, args.every
    );
    let on = pile(&a, args.bodies, Some("bench"))?;
    let off = pile(&b, args.bodies, None)?;
    let (mut on_ms, mut off_ms) = (Vec::new(), Vec::new());
    let until = Instant::now() + Duration::from_secs_f64(args.seconds);
    while Instant::now() < until {
        let t = Instant::now();
        on.step(DT)?;
        on_ms.push(t.elapsed().as_secs_f64() * 1e3);
        let t = Instant::now();
        off.step(DT)?;
        off_ms.push(t.elapsed().as_secs_f64() * 1e3);
    }
    let file = state.join(&persistent.domain).join("bench.physnap");
    let file_bytes = std::fs::metadata(&file).map(|m| m.len()).unwrap_or(0);
    drop((on, off, a, b));
    drop((persistent, plain));
    let _ = std::fs::remove_dir_all(&state);
    let sides = vec![side(true, on_ms), side(false, off_ms)];
    let ratio = sides[0].median_ms / sides[1].median_ms;
    let goals = vec![Goal::new(
        format!(
            "a persistent plane's median tick ≤ 1.10 × a plain one's ({} awake bodies, written every {} s)",
            args.bodies, args.every
        ),
        format!("{ratio:.2}"),
        Some(ratio <= 1.10),
    )];
    let report = PersistReport {
        bodies: args.bodies,
        every_s: args.every,
        file_bytes,
        sides,
        goals,
    };
    let md = markdown(&report);
    let (json, md_path) = report::write(&args.out, "persist", &report, &md)?;
    report::print(&md_path);
    println!("wrote {} and {}", json.display(), md_path.display());
    Ok(())
}

fn markdown(r: &PersistReport) -> String {
    let mut t = Table::new(&["plane", "ticks", "median (ms)", "p99 (ms)", "max (ms)"]);
    for s in &r.sides {
        t.row(&[
            if s.persistent { "persistent" } else { "plain" }.into(),
            s.ticks.to_string(),
            num(Some(s.median_ms)),
            num(Some(s.p99_ms)),
            num(Some(s.max_ms)),
        ]);
    }
    format!(
        "# Persistence\n\n{} awake bodies, the persistent plane written every {} s ({} KiB a \
         file); client-observed Step times, the two planes stepped alternately.\n\n{}",
        r.bodies,
        r.every_s,
        r.file_bytes / 1024,
        t.finish(),
    )
}

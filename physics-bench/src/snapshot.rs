//! `physics-bench snapshot`: what plane snapshots cost through a real daemon. Snapshot and
//! Restore time and size for piles of N bodies, settled and awake; `Rewind(8)` plus 8
//! re-simulated ticks of an awake plane against 8 ordinary ticks; and what keeping
//! `RollbackTicks = 8` costs an awake plane's tick, measured side by side with a plane
//! that keeps nothing.

use std::path::PathBuf;
use std::time::Instant;

use client_sdk::{Client, Plane, PlaneOptions, PlaneProp, Pose, Shape};

use super::daemon::DaemonProcess;
use super::error::BenchResult;
use super::report::{self, mib, num, Goal, Table};

/// Options of the `snapshot` subcommand.
#[derive(Debug, Clone, clap::Args)]
pub struct SnapshotArgs {
    /// Body counts of the piles measured.
    #[arg(long, value_delimiter = ',', default_values_t = [1_000usize, 10_000])]
    pub bodies: Vec<usize>,
    /// Bodies of the awake plane the rewind and the rollback cost are measured on.
    #[arg(long, default_value_t = 1_000)]
    pub rewind_bodies: usize,
    /// Bodies of the awake plane the cost of keeping 8 ticks is measured on.
    #[arg(long, default_value_t = 10_000)]
    pub keep_bodies: usize,
    /// Repetitions of each timing (the median is reported).
    #[arg(long, default_value_t = 5)]
    pub repeats: usize,
    /// Folder receiving snapshot.json and snapshot.md.
    #[arg(long, default_value = "bench-out")]
    pub out: PathBuf,
    /// Instead of timing: snapshot, run a command log, restore and replay it, and name the
    /// first field that differs if the replay diverges (`snapshot-validate.json` / `.md`).
    #[arg(long)]
    pub validate: bool,
    /// Bodies of the validated plane.
    #[arg(long, default_value_t = 1_000)]
    pub validate_bodies: usize,
    /// Ticks of the validated log.
    #[arg(long, default_value_t = 60)]
    pub validate_ticks: u32,
    /// Flips one bit of the replay's input at this tick (to see the report name it).
    #[arg(long)]
    pub inject_tick: Option<u32>,
}

/// One pile's figures.
#[derive(Debug, Clone, serde::Serialize)]
pub struct PileRow {
    pub bodies: usize,
    pub awake: bool,
    pub bytes: usize,
    pub snapshot_ms: f64,
    pub restore_ms: f64,
    pub step_ms: f64,
}

#[derive(Debug, Clone, serde::Serialize)]
pub struct SnapshotReport {
    pub piles: Vec<PileRow>,
    /// `Rewind(8)` + 8 ticks against 8 ordinary ticks (client-observed).
    pub rewind_ratio: f64,
    /// A tick keeping 8 against a tick keeping nothing (client-observed, side by side).
    pub keep_ratio: f64,
    /// The same with each plane stepped back to back (the copies' CPU cost).
    pub keep_ratio_back_to_back: f64,
    pub goals: Vec<Goal>,
}

const DT: f32 = 1.0 / 60.0;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// A manual plane with a pile of `n` unit boxes over a floor (awake: NeverSleep, still
/// falling; settled: two seconds of ticks and sleeping allowed).
fn pile(client: &Client, n: usize, awake: bool, extra: &[PlaneProp]) -> BenchResult<Plane> {
    let mut options = PlaneOptions::manual().with(PlaneProp::NeverSleep(awake));
    for p in extra {
        options = options.with(*p);
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
    let settle = if awake { 10 } else { 120 };
    for _ in 0..settle {
        plane.step(DT)?;
    }
    Ok(plane)
}

fn timed<T>(f: impl FnOnce() -> BenchResult<T>) -> BenchResult<(T, f64)> {
    let started = Instant::now();
    let v = f()?;
    Ok((v, started.elapsed().as_secs_f64() * 1e3))
}

fn pile_row(client: &Client, n: usize, awake: bool, repeats: usize) -> BenchResult<PileRow> {
    let plane = pile(client, n, awake, &[])?;
    let (mut snap_ms, mut restore_ms, mut step_ms) = (Vec::new(), Vec::new(), Vec::new());
    let mut bytes = 0;
    for _ in 0..repeats {
        let (snapshot, t) = timed(|| Ok(plane.take_snapshot()?))?;
        snap_ms.push(t);
        bytes = snapshot.len();
        let (_, t) = timed(|| Ok(plane.step(DT)?))?;
        step_ms.push(t);
        let (_, t) = timed(|| Ok(plane.restore(&snapshot)?))?;
        restore_ms.push(t);
    }
    plane.destroy()?;
    Ok(PileRow {
        bodies: n,
        awake,
        bytes,
        snapshot_ms: median(snap_ms),
        restore_ms: median(restore_ms),
        step_ms: median(step_ms),
    })
}

/// `Rewind(8)` + 8 ticks against 8 ordinary ticks on an awake plane keeping 8.
fn rewind_ratio(client: &Client, n: usize, repeats: usize) -> BenchResult<f64> {
    let plane = pile(client, n, true, &[PlaneProp::RollbackTicks(8)])?;
    let (mut plain, mut again) = (Vec::new(), Vec::new());
    for _ in 0..repeats {
        let (_, t) = timed(|| {
            for _ in 0..8 {
                plane.step(DT)?;
            }
            Ok(())
        })?;
        plain.push(t);
        let (_, t) = timed(|| {
            plane.rewind(8)?;
            for _ in 0..8 {
                plane.step(DT)?;
            }
            Ok(())
        })?;
        again.push(t);
    }
    plane.destroy()?;
    Ok(median(again) / median(plain))
}

/// A tick of an awake plane keeping 8 ticks against one keeping none: at a game's cadence
/// (alternated, each step followed by a 20 ms pause, so a worker has the rest of its
/// period for the copy it puts off, as a plane ticking at 60 Hz does: the tick's latency),
/// and back to back (each step waits for the copy the last one put off: the CPU the copies
/// cost).
fn keep_ratio(client: &Client, n: usize, repeats: usize) -> BenchResult<(f64, f64)> {
    let keeping = pile(client, n, true, &[PlaneProp::RollbackTicks(8)])?;
    let plain = pile(client, n, true, &[])?;
    let (mut k, mut p) = (Vec::new(), Vec::new());
    let pause = std::time::Duration::from_millis(20);
    for _ in 0..repeats.max(3) * 4 {
        k.push(timed(|| Ok(keeping.step(DT)?))?.1);
        std::thread::sleep(pause);
        p.push(timed(|| Ok(plain.step(DT)?))?.1);
        std::thread::sleep(pause);
    }
    let (mut ks, mut ps) = (Vec::new(), Vec::new());
    for _ in 0..repeats.max(3) {
        for _ in 0..4 {
            ks.push(timed(|| Ok(keeping.step(DT)?))?.1);
        }
        for _ in 0..4 {
            ps.push(timed(|| Ok(plain.step(DT)?))?.1);
        }
    }
    keeping.destroy()?;
    plain.destroy()?;
    Ok((median(k) / median(p), median(ks) / median(ps)))
}

pub fn run(args: &SnapshotArgs) -> BenchResult<()> {
    if args.validate {
        return super::validate::run(
            args.validate_bodies,
            args.validate_ticks,
            args.inject_tick,
            &args.out,
        );
    }
    // Snapshots of large planes pass the default 8 MiB reply limit, and 8 kept ticks of
    // 10,000 bodies the default 64 MiB of state bytes.
    let daemon = DaemonProcess::start_with(
        "snapshot",
        &[
            "--max-reply-bytes".to_string(),
            (256u64 << 20).to_string(),
            // Ticks kept for Rewind count as state bytes (1.5 KB a body each).
            "--max-state-bytes-per-client".to_string(),
            (1u64 << 30).to_string(),
        ],
        None,
    )?;
    let client = daemon.connect()?;
    let mut piles = Vec::new();
    for &n in &args.bodies {
        for awake in [false, true] {
            eprintln!("snapshot: {n} bodies, awake {awake}");
            piles.push(pile_row(&client, n, awake, args.repeats)?);
        }
    }
    eprintln!("snapshot: rewind ({} bodies)", args.rewind_bodies);
    let rewind_ratio = rewind_ratio(&client, args.rewind_bodies, args.repeats)?;
    eprintln!("snapshot: keeping 8 ticks ({} bodies)", args.keep_bodies);
    let (keep_ratio, keep_ratio_back_to_back) =
        keep_ratio(&client, args.keep_bodies, args.repeats)?;
    let goals = vec![
        Goal::new(
            format!(
                "Rewind(8) + 8 ticks ≤ 1.2 × 8 ticks ({} awake bodies)",
                args.rewind_bodies
            ),
            format!("{rewind_ratio:.2}"),
            Some(rewind_ratio <= 1.2),
        ),
        Goal::new(
            format!(
                "keeping RollbackTicks = 8 costs ≤ 10 % of a tick's latency at 20 ms a tick \
                 ({} awake bodies)",
                args.keep_bodies
            ),
            format!("{:+.0} %", (keep_ratio - 1.0) * 100.0),
            Some(keep_ratio <= 1.10),
        ),
        Goal::new(
            format!(
                "keeping RollbackTicks = 8 costs ≤ 10 % of a tick's CPU (steps back to back, \
                 {} awake bodies)",
                args.keep_bodies
            ),
            format!("{:+.0} %", (keep_ratio_back_to_back - 1.0) * 100.0),
            Some(keep_ratio_back_to_back <= 1.10),
        ),
    ];
    let report = SnapshotReport {
        piles,
        rewind_ratio,
        keep_ratio,
        keep_ratio_back_to_back,
        goals,
    };
    let md = markdown(&report);
    let (json, md_path) = report::write(&args.out, "snapshot", &report, &md)?;
    report::print(&md_path);
    println!("wrote {} and {}", json.display(), md_path.display());
    if report.goals.iter().any(|g| g.met == Some(false)) {
        eprintln!("snapshot: a goal was not met");
    }
    Ok(())
}

fn markdown(r: &SnapshotReport) -> String {
    let mut t = Table::new(&[
        "bodies",
        "state",
        "snapshot size (MiB)",
        "Snapshot (ms)",
        "Restore (ms)",
        "one tick (ms)",
    ]);
    for p in &r.piles {
        t.row(&[
            p.bodies.to_string(),
            if p.awake { "awake" } else { "settled" }.into(),
            mib(p.bytes as f64),
            num(Some(p.snapshot_ms)),
            num(Some(p.restore_ms)),
            num(Some(p.step_ms)),
        ]);
    }
    format!(
        "# Plane snapshots\n\nClient-observed times through a daemon (medians).\n\n{}",
        t.finish(),
    )
}

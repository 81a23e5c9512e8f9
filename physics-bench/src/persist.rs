//! `physics-bench persist`: what persistence costs a plane's tick. Two daemons side by side,
//! one started with `--state-dir` and a short `--snapshot-every`, one without; each holds an
//! awake pile of N bodies (persistent and named on the first); the two planes are stepped in
//! interleaved blocks (ABBA) for a few seconds of wall time, client-observed. The periodic
//! write snapshots the plane on its worker (the plane's own encoder) and hands the bytes to
//! the writer thread, which does the disk work (write, fsync, rename, fsync of the
//! directory) off the tick: the median tick should not move, and the slowest ticks show the
//! encode. Judged by [`Estimator::WallMinOfBlocks`] on each block's median tick; each
//! block's CPU time per tick of this process and the stepped daemon reported beside.

use std::path::PathBuf;
use std::time::Instant;

use client_sdk::{Client, Plane, PlaneName, PlaneOptions, PlaneProp, Pose, Shape};

use super::daemon::DaemonProcess;
use super::error::{BenchError, BenchResult};
use super::estimator::{self, Block, CpuClock, Estimator, JudgedGoal, Order, Pair};
use super::report::{self, num, Table};

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
    /// Blocks of each plane (they alternate ABBA): short blocks, so that both planes see
    /// the same stretches of a shared machine.
    #[arg(long, default_value_t = 30)]
    pub blocks: usize,
    /// Folder receiving persist.json and persist.md.
    #[arg(long, default_value = "bench-out")]
    pub out: PathBuf,
}

/// One side's tick times (client-observed `Step`, ms), all blocks together.
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
    /// What judges `ratio`: [`Estimator::WallMinOfBlocks`] on the blocks' median ticks.
    pub estimator: Estimator,
    /// Persistent over plain: the minima of the blocks' median ticks.
    pub ratio: f64,
    /// The same of the medians of the blocks' median ticks.
    pub ratio_median_of_blocks: f64,
    /// The same of all ticks together.
    pub ratio_pooled: f64,
    /// CPU per tick of this process and the stepped daemon, persistent over plain (medians
    /// of blocks).
    pub cpu_ratio: f64,
    pub ticks_per_block: usize,
    /// The blocks (per tick: the block's median wall, its CPU, µs): A = persistent, B =
    /// plain.
    pub blocks: Pair,
    pub goals: Vec<JudgedGoal>,
    /// Every estimator's name and meaning.
    pub estimators: std::collections::BTreeMap<&'static str, &'static str>,
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
    let at = |q: f64| {
        ms.get(((ms.len().max(1) - 1) as f64 * q).round() as usize)
            .copied()
            .unwrap_or(f64::NAN)
    };
    Side {
        persistent,
        ticks: ms.len(),
        median_ms: at(0.5),
        p99_ms: at(0.99),
        max_ms: at(1.0),
    }
}

/// Steps `plane` `ticks` times; returns the block (its median tick's wall and the CPU per
/// tick of `clock`'s processes, µs) and appends each tick's wall (ms) to `all`.
fn block(plane: &Plane, ticks: usize, clock: &CpuClock, all: &mut Vec<f64>) -> BenchResult<Block> {
    let cpu0 = clock.read()?;
    let mut ms = Vec::with_capacity(ticks);
    for _ in 0..ticks {
        let t = Instant::now();
        plane.step(DT)?;
        ms.push(t.elapsed().as_secs_f64() * 1e3);
    }
    let cpu = clock.read()?.used_since(&cpu0);
    let median =
        crate::stats::median(&ms).ok_or_else(|| BenchError::Failed("a block of no tick".into()))?;
    all.extend(&ms);
    Ok(Block {
        wall_us: median * 1e3,
        cpu_us: cpu as f64 / 1e3 / ticks as f64,
    })
}

pub fn run(args: &PersistArgs) -> BenchResult<()> {
    if args.blocks == 0 || args.seconds.is_nan() || args.seconds <= 0.0 {
        return Err(BenchError::Failed(format!(
            "persist needs --blocks ≥ 1 and --seconds > 0 (got {}, {})",
            args.blocks, args.seconds
        )));
    }
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
    // Ticks per block: the seconds asked shared among the blocks, at the tick time of a few
    // warm-up steps of each.
    let started = Instant::now();
    for _ in 0..5 {
        on.step(DT)?;
        off.step(DT)?;
    }
    let tick_s = started.elapsed().as_secs_f64() / 10.0;
    let ticks =
        ((args.seconds / (2.0 * args.blocks as f64 * tick_s.max(1e-6))) as usize).clamp(5, 2_000);
    let (on_clock, off_clock) = (
        CpuClock::new(&[persistent.pid()]),
        CpuClock::new(&[plain.pid()]),
    );
    let (mut on_ms, mut off_ms) = (Vec::new(), Vec::new());
    let pair = estimator::interleaved(
        args.blocks,
        Order::Abba,
        || block(&on, ticks, &on_clock, &mut on_ms),
        || block(&off, ticks, &off_clock, &mut off_ms),
    )?;
    let file = state.join(&persistent.domain).join("bench.physnap");
    let file_bytes = std::fs::metadata(&file).map(|m| m.len()).unwrap_or(0);
    drop((on, off, a, b));
    drop((persistent, plain));
    let _ = std::fs::remove_dir_all(&state);
    let sides = vec![side(true, on_ms), side(false, off_ms)];
    let r = pair.ratios();
    let ratio = r.wall_min;
    let ratio_pooled = sides[0].median_ms / sides[1].median_ms;
    let goals = vec![JudgedGoal::new(
        Estimator::WallMinOfBlocks,
        format!(
            "a persistent plane's median tick ≤ 1.10 × a plain one's ({} awake bodies, written every {} s)",
            args.bodies, args.every
        ),
        format!(
            "{ratio:.2} (medians of blocks {:.2}, all ticks {ratio_pooled:.2}; CPU per tick {:.2}×)",
            r.wall_median, r.cpu_median
        ),
        Some(ratio <= 1.10),
    )];
    let report = PersistReport {
        bodies: args.bodies,
        every_s: args.every,
        file_bytes,
        sides,
        estimator: Estimator::WallMinOfBlocks,
        ratio,
        ratio_median_of_blocks: r.wall_median,
        ratio_pooled,
        cpu_ratio: r.cpu_median,
        ticks_per_block: ticks,
        blocks: pair,
        goals,
        estimators: estimator::glossary(),
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
    let mut blocks = Table::new(&[
        "plane",
        "block median ticks min / median (ms)",
        "CPU per tick, median of blocks (ms)",
        "estimator",
    ]);
    for (name, side) in [("persistent", &r.blocks.a), ("plain", &r.blocks.b)] {
        blocks.row(&[
            name.into(),
            format!(
                "{:.3} / {:.3}",
                side.wall_us.min / 1e3,
                side.wall_us.median / 1e3
            ),
            format!("{:.3}", side.cpu_us.median / 1e3),
            r.estimator.name().into(),
        ]);
    }
    format!(
        "# Persistence\n\n{} awake bodies, the persistent plane written every {} s ({} KiB a \
         file); client-observed Step times, the two planes stepped in {} blocks each of {} \
         ticks, ABBA. Persistent over plain: {:.3} ({}: minima of the blocks' median ticks), \
         {:.3} (medians of blocks), {:.3} (all ticks).\n\n{}\n{}",
        r.bodies,
        r.every_s,
        r.file_bytes / 1024,
        r.blocks.a.blocks.len(),
        r.ticks_per_block,
        r.ratio,
        r.estimator.name(),
        r.ratio_median_of_blocks,
        r.ratio_pooled,
        t.finish(),
        blocks.finish(),
    )
}

//! `physics-bench snapshot`: what plane snapshots cost through a real daemon. Snapshot and
//! Restore time and size for piles of N bodies, settled and awake; `Rewind(8)` plus 8
//! re-simulated ticks of an awake plane against 8 ordinary ticks; what keeping
//! `RollbackTicks = 8` costs an awake plane's tick, measured side by side with a plane
//! that keeps nothing (its CPU by the `cpu-median-of-blocks` estimator: see
//! [`keep_cpu`]); and what one kept tick holds per awake, sleeping and anchored body (heap
//! bytes counted in process: see [`record_rows`]); and what recording a plane costs its
//! tick's CPU and how many bytes a tick adds to the file (see [`super::recording_cost`]).

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::path::PathBuf;
use std::sync::atomic::{AtomicI64, Ordering};
use std::time::Instant;

use client_sdk::{Client, Plane, PlaneOptions, PlaneProp, Pose, Shape};

use super::daemon::{daemon_cpu_ns, until_idle, DaemonProcess};
use super::error::BenchResult;
use super::estimator::{self, Estimator};
use super::recording_cost::{self, RecordingCost};
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
    /// Pairs of blocks of the rollback CPU row (a block of the plane keeping 8, then one of
    /// the plane keeping none).
    #[arg(long, default_value_t = 12)]
    pub cpu_blocks: usize,
    /// Steps in each block of the rollback CPU row.
    #[arg(long, default_value_t = 8)]
    pub block_steps: usize,
    /// Bodies of each kind (awake, sleeping, anchored) whose kept-tick bytes are counted.
    #[arg(long, default_value_t = 1_000)]
    pub record_bodies: usize,
    /// Bodies of the awake piles the cost of recording is measured on.
    #[arg(long, default_value_t = 1_000)]
    pub recording_bodies: usize,
    /// Velocity writes a tick (each on its own body) on the piles of the recording row.
    #[arg(long, default_value_t = 100)]
    pub recording_writes: usize,
    /// Ticks both piles of the recording row make (with the writes) before any is measured.
    #[arg(long, default_value_t = 300)]
    pub recording_settle_ticks: usize,
    /// Blocks of each plane (recording, plain) of the recording row, ABBA.
    #[arg(long, default_value_t = 48)]
    pub recording_blocks: usize,
    /// Ticks in each block of the recording row.
    #[arg(long, default_value_t = 40)]
    pub recording_block_ticks: usize,
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
    /// The same with each plane stepped back to back (client-observed wall time).
    pub keep_ratio_back_to_back: f64,
    /// The daemon's CPU per step keeping 8 against keeping none: median of the blocks'
    /// figures of each plane, one over the other (`cpu-median-of-blocks`, the goal's).
    pub keep_cpu_ratio_median: f64,
    /// The same from the cheapest block of each plane.
    pub keep_cpu_ratio_min: f64,
    /// The blocks, in the order run.
    pub keep_cpu_blocks: Vec<CpuBlock>,
    /// Heap bytes of one kept tick per body, by kind of body and part of the copy.
    pub record: Vec<RecordRow>,
    /// What recording a plane costs its tick's CPU, and the bytes a tick adds to the file.
    pub recording: RecordingCost,
    pub goals: Vec<SnapshotGoal>,
    /// Every estimator's name and meaning.
    pub estimators: std::collections::BTreeMap<&'static str, &'static str>,
}

/// A goal row: the goal, what was measured, the verdict, and the estimator that judged it
/// on the rows judged by a named one (see [`crate::estimator`]).
#[derive(Debug, Clone, serde::Serialize)]
pub struct SnapshotGoal {
    #[serde(flatten)]
    pub goal: Goal,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub estimator: Option<Estimator>,
}

impl From<Goal> for SnapshotGoal {
    fn from(goal: Goal) -> SnapshotGoal {
        SnapshotGoal {
            goal,
            estimator: None,
        }
    }
}

impl From<estimator::JudgedGoal> for SnapshotGoal {
    fn from(g: estimator::JudgedGoal) -> SnapshotGoal {
        SnapshotGoal {
            goal: Goal::new(g.goal, g.value, g.met),
            estimator: Some(g.estimator),
        }
    }
}

/// One block of the rollback CPU row: `steps` steps of one plane.
#[derive(Debug, Clone, serde::Serialize)]
pub struct CpuBlock {
    /// RollbackTicks of the plane stepped (8 or 0).
    pub rollback_ticks: u32,
    pub steps: usize,
    /// The daemon's CPU (every thread: the step, the copy made after it, the drop of the
    /// oldest copy) per step, in milliseconds.
    pub cpu_ms_per_step: f64,
    /// Client-observed wall time per step, in milliseconds.
    pub wall_ms_per_step: f64,
}

/// What one kept tick holds per body of a kind (counted in process on a plane of the
/// daemon's code: the heap bytes its copy allocates, less those of the same plane without
/// those bodies, over their number).
#[derive(Debug, Clone, serde::Serialize)]
pub struct RecordRow {
    /// "awake", "sleeping", "anchored" (boxes resting apart on a floor) or "awake pile".
    pub kind: String,
    /// The part of the copy (`physics_daemon::rapier3d::Plane::ROLLBACK_RECORD_PARTS`):
    /// "whole", or one of the engine's sets and phases.
    pub part: String,
    pub bodies: usize,
    pub bytes_per_body: f64,
    /// Copying and dropping that part once, per body, in microseconds (median of 5).
    pub copy_drop_us_per_body: f64,
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

/// The `cpu-median-of-blocks` estimator's result: see [`keep_cpu`].
struct KeepCpu {
    median: f64,
    min: f64,
    blocks: Vec<CpuBlock>,
}

/// The CPU that keeping `RollbackTicks = 8` costs an awake plane's tick, by the
/// `cpu-median-of-blocks` estimator: two awake planes of `n` bodies, one keeping 8 ticks
/// and one keeping none, stepped in alternating blocks of `steps` steps (`pairs` blocks
/// each, the keeping plane first in even pairs and second in odd ones, so a drift of the
/// machine's load falls on both); each block's figure is the daemon's CPU (every thread)
/// per step, read before the block and after it once the daemon is idle again. The ratio
/// is taken of the medians of the two planes' blocks (and of their minimums: the least
/// disturbed block of each). CPU time, not wall time: another process on the machine
/// delays a step but does not add to its CPU.
fn keep_cpu(
    client: &Client,
    pid: u32,
    n: usize,
    pairs: usize,
    steps: usize,
) -> BenchResult<KeepCpu> {
    let keeping = pile(client, n, true, &[PlaneProp::RollbackTicks(8)])?;
    let plain = pile(client, n, true, &[])?;
    let (pairs, steps) = (pairs.max(3), steps.max(1));
    let mut blocks = Vec::with_capacity(pairs * 2);
    let block = |plane: &Plane, k: u32| -> BenchResult<CpuBlock> {
        until_idle(pid)?;
        let cpu = daemon_cpu_ns(pid)?;
        let started = Instant::now();
        for _ in 0..steps {
            plane.step(DT)?;
        }
        let wall = started.elapsed().as_secs_f64() * 1e3;
        until_idle(pid)?;
        let cpu = daemon_cpu_ns(pid)?.saturating_sub(cpu) as f64 / 1e6;
        Ok(CpuBlock {
            rollback_ticks: k,
            steps,
            cpu_ms_per_step: cpu / steps as f64,
            wall_ms_per_step: wall / steps as f64,
        })
    };
    // One block each first: the keeping plane fills its ring, both warm up.
    block(&keeping, 8)?;
    block(&plain, 0)?;
    for i in 0..pairs {
        if i % 2 == 0 {
            blocks.push(block(&keeping, 8)?);
            blocks.push(block(&plain, 0)?);
        } else {
            blocks.push(block(&plain, 0)?);
            blocks.push(block(&keeping, 8)?);
        }
    }
    keeping.destroy()?;
    plain.destroy()?;
    let of = |k: u32| -> Vec<f64> {
        blocks
            .iter()
            .filter(|b| b.rollback_ticks == k)
            .map(|b| b.cpu_ms_per_step)
            .collect()
    };
    let (k, p) = (of(8), of(0));
    let min = |v: &[f64]| v.iter().copied().fold(f64::INFINITY, f64::min);
    Ok(KeepCpu {
        median: median(k.clone()) / median(p.clone()),
        min: min(&k) / min(&p),
        blocks,
    })
}

/// The global allocator of the bench: the system's, counting what one thread allocates
/// while it asks to (see [`heap_bytes_of`]); other threads and other times pay one
/// thread-local read an allocation.
struct Counting;

static COUNTED: AtomicI64 = AtomicI64::new(0);

thread_local! {
    static COUNTING: Cell<bool> = const { Cell::new(false) };
}

fn counting() -> bool {
    COUNTING.try_with(Cell::get).unwrap_or(false)
}

// SAFETY: every call is passed on to the system allocator unchanged; the count is a side
// effect that allocates nothing.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        if counting() {
            COUNTED.fetch_add(layout.size() as i64, Ordering::Relaxed);
        }
        // SAFETY: the caller's contract, passed on.
        unsafe { System.alloc(layout) }
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        if counting() {
            COUNTED.fetch_add(layout.size() as i64, Ordering::Relaxed);
        }
        // SAFETY: the caller's contract, passed on.
        unsafe { System.alloc_zeroed(layout) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        if counting() {
            COUNTED.fetch_sub(layout.size() as i64, Ordering::Relaxed);
        }
        // SAFETY: the caller's contract, passed on.
        unsafe { System.dealloc(ptr, layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        if counting() {
            COUNTED.fetch_add(new_size as i64 - layout.size() as i64, Ordering::Relaxed);
        }
        // SAFETY: the caller's contract, passed on.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

/// What `f` returns and the heap bytes this thread allocated (less those it freed) while
/// it ran.
fn heap_bytes_of<T>(f: impl FnOnce() -> T) -> (T, i64) {
    let before = COUNTED.load(Ordering::Relaxed);
    COUNTING.with(|c| c.set(true));
    let v = f();
    COUNTING.with(|c| c.set(false));
    (v, COUNTED.load(Ordering::Relaxed) - before)
}

/// The kinds of body whose kept-tick bytes are counted: boxes resting apart on a floor
/// (one contact each) kept awake, the same let to fall asleep, and anchored; and the
/// awake pile of the CPU row (boxes on boxes: several contacts each).
const RECORD_KINDS: [&str; 4] = ["awake", "sleeping", "anchored", "awake pile"];

/// An in-process plane of the daemon's code keeping 8 ticks: a floor and `n` unit boxes of
/// `kind` (see [`RECORD_KINDS`]), 10 ticks in ("awake pile": 60, "sleeping": until every
/// body sleeps).
fn local_plane(n: usize, kind: &str) -> BenchResult<physics_daemon::rapier3d::Plane> {
    use physics_daemon::backend::Backend;
    use shm_layout::{ObjectProp, PlaneOp};
    let failed = |e: shm_layout::CommandError| super::error::BenchError::Failed(e.to_string());
    let awake = kind.starts_with("awake");
    let mut plane = physics_daemon::rapier3d::Plane::new(
        1,
        &[PlaneProp::NeverSleep(awake), PlaneProp::RollbackTicks(8)],
    )
    .map_err(failed)?;
    let side = (n as f64).sqrt().ceil().max(1.0) as usize;
    let extent = side as f32 * 2.5 + 10.0;
    let mut add = |at: [f32; 3], size: [f32; 3], props: Vec<ObjectProp>| {
        plane
            .apply(PlaneOp::AddObject {
                shape: Shape::Cube { size },
                pose: Pose::at(at),
                props,
            })
            .map(|_| ())
            .map_err(failed)
    };
    let anchored = || vec![ObjectProp::Anchored(true)];
    add([0.0, -0.5, 0.0], [extent, 1.0, extent], anchored())?;
    let half = side as f32 / 2.0;
    for k in 0..n {
        let (i, j) = ((k / side) as f32 - half, (k % side) as f32 - half);
        match kind {
            "awake pile" => add(
                [i * 1.2, 1.0 + (k % 3) as f32 * 1.1, j * 1.2],
                [1.0; 3],
                vec![],
            )?,
            "anchored" => add([i * 2.5, 0.5, j * 2.5], [1.0; 3], anchored())?,
            _ => add([i * 2.5, 0.5, j * 2.5], [1.0; 3], vec![])?,
        }
    }
    // A second in, the pile has landed (its boxes touch the floor and each other).
    let first = if kind == "awake pile" { 60 } else { 10 };
    let mut ticks = 0;
    while ticks < first || (kind == "sleeping" && plane.awake_count() > 0 && ticks < 1200) {
        plane.step(DT).map_err(failed)?;
        ticks += 1;
    }
    if kind == "sleeping" && plane.awake_count() > 0 {
        return Err(super::error::BenchError::Failed(format!(
            "{n} boxes on a floor did not fall asleep in {ticks} ticks ({} awake)",
            plane.awake_count()
        )));
    }
    Ok(plane)
}

/// Heap bytes of each part of one kept tick of `plane`, and what copying and dropping it
/// takes (microseconds, median of 5), by part.
fn record_of(plane: &physics_daemon::rapier3d::Plane) -> Vec<(&'static str, i64, f64)> {
    physics_daemon::rapier3d::Plane::ROLLBACK_RECORD_PARTS
        .iter()
        .map(|part| {
            let (copy, bytes) = heap_bytes_of(|| plane.rollback_record_part(part));
            drop(copy);
            let times = (0..5)
                .map(|_| {
                    let started = Instant::now();
                    drop(plane.rollback_record_part(part));
                    started.elapsed().as_secs_f64() * 1e6
                })
                .collect();
            (*part, bytes, median(times))
        })
        .collect()
}

/// Heap bytes of one kept tick per body of each of [`RECORD_KINDS`]: each a plane of `n`
/// such bodies over a floor against the same floor alone (what the floor, the plane and
/// its engine hold whatever their bodies is taken off), per part of the copy.
fn record_rows(n: usize) -> BenchResult<Vec<RecordRow>> {
    let n = n.max(1);
    let empty = record_of(&local_plane(0, "awake")?);
    let mut rows = Vec::new();
    for kind in RECORD_KINDS {
        let plane = local_plane(n, kind)?;
        for ((part, bytes, us), (_, base, _)) in record_of(&plane).into_iter().zip(&empty) {
            rows.push(RecordRow {
                kind: kind.to_string(),
                part: part.to_string(),
                bodies: n,
                bytes_per_body: (bytes - base) as f64 / n as f64,
                copy_drop_us_per_body: us / n as f64,
            });
        }
    }
    Ok(rows)
}

/// The goals on what a kept tick holds: at most 100 bytes an awake body (the pose and
/// velocities rollback needs are about 64), nothing for a sleeping or anchored one.
fn record_goals(rows: &[RecordRow], n: usize) -> Vec<Goal> {
    let whole = |kind: &str| {
        rows.iter()
            .find(|r| r.kind == kind && r.part == "whole")
            .map_or(f64::NAN, |r| r.bytes_per_body)
    };
    let awake = whole("awake");
    let mut goals = vec![Goal::new(
        format!(
            "rollback record ≤ 100 B per awake body (heap bytes of one kept tick, {n} awake \
             boxes resting apart on a floor, less the floor alone)"
        ),
        format!("{awake:.0} B"),
        Some(awake <= 100.0),
    )];
    for kind in ["sleeping", "anchored"] {
        let bytes = whole(kind);
        goals.push(Goal::new(
            format!("rollback record 0 B per {kind} body (as above, {n} {kind} bodies)"),
            format!("{bytes:.0} B"),
            // Under a byte a body: what the plane holds whatever its bodies, rounded.
            Some(bytes.abs() < 1.0),
        ));
    }
    goals
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
    eprintln!(
        "snapshot: keeping 8 ticks, CPU in blocks ({} bodies)",
        args.keep_bodies
    );
    let cpu = keep_cpu(
        &client,
        daemon.pid(),
        args.keep_bodies,
        args.cpu_blocks,
        args.block_steps,
    )?;
    eprintln!(
        "snapshot: recording, CPU in blocks ({} bodies, {} writes a tick)",
        args.recording_bodies, args.recording_writes
    );
    let recording = recording_cost::measure(
        &client,
        daemon.pid(),
        recording_cost::Sizes {
            bodies: args.recording_bodies,
            writes: args.recording_writes,
            settle_ticks: args.recording_settle_ticks,
            blocks: args.recording_blocks,
            ticks_per_block: args.recording_block_ticks,
        },
        &std::env::temp_dir().join(format!(
            "{}.physrec",
            super::daemon::unique_domain("recording")
        )),
    )?;
    eprintln!(
        "snapshot: kept-tick bytes per body ({} bodies of each kind)",
        args.record_bodies
    );
    let record = record_rows(args.record_bodies)?;
    let mut goals = vec![
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
                "keeping RollbackTicks = 8 costs ≤ 10 % of a tick's CPU (cpu-median-of-blocks: \
                 {} pairs of {}-step blocks alternated, daemon CPU per step; {} awake bodies)",
                args.cpu_blocks, args.block_steps, args.keep_bodies
            ),
            format!(
                "{:+.0} % (min of blocks {:+.0} %)",
                (cpu.median - 1.0) * 100.0,
                (cpu.min - 1.0) * 100.0
            ),
            Some(cpu.median <= 1.10),
        ),
    ];
    goals.extend(record_goals(&record, args.record_bodies));
    let mut goals: Vec<SnapshotGoal> = goals.into_iter().map(SnapshotGoal::from).collect();
    goals.push(recording_cost::goal(&recording).into());
    let report = SnapshotReport {
        piles,
        rewind_ratio,
        keep_ratio,
        keep_ratio_back_to_back,
        keep_cpu_ratio_median: cpu.median,
        keep_cpu_ratio_min: cpu.min,
        keep_cpu_blocks: cpu.blocks,
        record,
        recording,
        goals,
        estimators: estimator::glossary(),
    };
    let md = markdown(&report);
    let (json, md_path) = report::write(&args.out, "snapshot", &report, &md)?;
    report::print(&md_path);
    println!("wrote {} and {}", json.display(), md_path.display());
    if report.goals.iter().any(|g| g.goal.met == Some(false)) {
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
    let mut blocks = Table::new(&[
        "RollbackTicks",
        "blocks",
        "CPU per step, median (ms)",
        "CPU per step, min (ms)",
        "wall per step, median (ms)",
    ]);
    for k in [8u32, 0] {
        let of = |f: fn(&CpuBlock) -> f64| -> Vec<f64> {
            r.keep_cpu_blocks
                .iter()
                .filter(|b| b.rollback_ticks == k)
                .map(f)
                .collect()
        };
        let cpu = of(|b| b.cpu_ms_per_step);
        if cpu.is_empty() {
            continue;
        }
        let min = cpu.iter().copied().fold(f64::INFINITY, f64::min);
        blocks.row(&[
            k.to_string(),
            cpu.len().to_string(),
            num(Some(median(cpu))),
            num(Some(min)),
            num(Some(median(of(|b| b.wall_ms_per_step)))),
        ]);
    }
    let mut record = Table::new(&[
        "body",
        "part of the kept tick",
        "bytes per body",
        "copy + drop (µs per body)",
    ]);
    for row in &r.record {
        record.row(&[
            row.kind.clone(),
            row.part.clone(),
            format!("{:.0}", row.bytes_per_body),
            format!("{:.3}", row.copy_drop_us_per_body),
        ]);
    }
    format!(
        "# Plane snapshots\n\nClient-observed times through a daemon (medians).\n\n{}\n\
         ## What keeping RollbackTicks = 8 costs a tick's CPU\n\nEstimator \
         `cpu-median-of-blocks`: an awake plane keeping 8 ticks and one keeping none, \
         stepped in alternating blocks; a block's figure is the daemon's CPU (every thread, \
         from /proc/PID/task/*/schedstat) per step, read once the daemon is idle again after \
         the block (the copy a step puts off and the drop of the oldest one are counted). \
         Ratio of the medians: {:.3}; of the minimums: {:.3}.\n\n{}\n\
         ## What one kept tick holds\n\nHeap bytes a kept tick's copy allocates per body \
         (counted in process by the bench's allocator on a plane of the daemon's code: {} \
         bodies of the kind over a floor, less the floor alone), whole and by part of the \
         engine's world (the whole holds the plane's own tables besides), and what copying \
         and dropping it once takes per body (medians of 5).\n\n{}\n{}",
        t.finish(),
        r.keep_cpu_ratio_median,
        r.keep_cpu_ratio_min,
        blocks.finish(),
        r.record.first().map_or(0, |row| row.bodies),
        record.finish(),
        recording_cost::markdown(&r.recording),
    )
}

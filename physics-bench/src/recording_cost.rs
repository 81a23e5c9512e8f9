//! `physics-bench snapshot`'s recording rows: what recording a plane costs its tick's CPU,
//! and how many bytes a tick adds to the file.
//!
//! Two awake piles of N unit boxes on one daemon, alike in everything but that one records
//! (`Plane::start_recording` into a temporary file, once, before the first block, so its
//! periodic keyframes fall where they would in a long recording); each tick the client
//! writes the Velocity of W of the boxes (the same values on both planes) and steps. Both
//! make a few hundred such ticks first (the pile lands and the writes stir it: its tick's
//! cost grows, then holds); the two planes stay alike tick for tick. The planes are then
//! stepped in interleaved blocks (ABBA, [`estimator::interleaved`]); a block's
//! figure is the daemon's CPU (every thread, the recording's writer thread included) per
//! tick, read before the block and after it once the daemon is idle again, so the
//! keyframes the writer encodes off the tick are counted in the block that asked for them.
//! Judged by [`Estimator::CpuMedianOfBlocks`]: the recording plane's median block over the
//! plain plane's (the minimum and the pooled ratio, every block's CPU over every block's
//! ticks, reported beside). A cross-check reads each plane's own threads while their ticks
//! alternate one by one ([`ThreadsCheck`]), and what the recording's writer thread takes a
//! tick.
//!
//! Then the recording is stopped and its file read back (`client_sdk::load_recording`): its
//! bytes by kind of entry ([`RecordingBytes`]), per tick with and without the keyframes.

use std::path::Path;
use std::time::Instant;

use client_sdk::{Client, Object, Plane, PlaneOptions, PlaneProp, Pose, Shape};
use shm_layout::recording::{Event, KeyframeWhy, ENTRY_OVERHEAD};

use super::error::{BenchError, BenchResult};
use super::estimator::{self, Block, CpuClock, Estimator, Order, Pair};
use super::report::Table;

const DT: f32 = 1.0 / 60.0;

/// Bytes of a tick entry (tick u64, dt f32, state hash u64, and the entry's framing).
pub const TICK_ENTRY_BYTES: usize = 20 + ENTRY_OVERHEAD;

/// What the recording row measured.
#[derive(Debug, Clone, serde::Serialize)]
pub struct RecordingCost {
    pub bodies: usize,
    /// Velocity writes a tick, each on its own body.
    pub writes_per_tick: usize,
    /// Ticks both planes made (with the writes) before the recording started.
    pub settle_ticks: usize,
    /// Ticks in each block.
    pub ticks_per_block: usize,
    /// What judges `cpu_ratio`.
    pub estimator: Estimator,
    /// The daemon's CPU per tick, the recording plane's over the plain plane's: medians of
    /// the blocks (the goal's figure).
    pub cpu_ratio: f64,
    /// The same of the cheapest block of each plane.
    pub cpu_ratio_min: f64,
    /// Every block's CPU over every block's ticks, recording over plain (a keyframe that
    /// fell in a block counts here, where the median may leave it out).
    pub cpu_ratio_pooled: f64,
    /// Client-observed wall time per tick, recording over plain (medians of blocks).
    pub wall_ratio: f64,
    /// The blocks (µs per tick: wall, the daemon's CPU): A = recording, B = plain.
    pub blocks: Pair,
    /// The cross-check: the planes' own threads, their ticks alternated one by one.
    pub threads: ThreadsCheck,
    /// What the file holds.
    pub bytes: RecordingBytes,
}

/// A stopped recording's bytes, by kind of entry (each entry's framing, tag, length and
/// checksum, `ENTRY_OVERHEAD` bytes, counted with it).
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize)]
pub struct RecordingBytes {
    /// Ticks the daemon reports recorded (`RecordingInfo::ticks`).
    pub ticks: u64,
    /// Bytes the daemon reports written (`RecordingInfo::bytes`).
    pub bytes: u64,
    /// The file's size.
    pub file_bytes: u64,
    /// Ticks between periodic keyframes (the recording's start entry).
    pub keyframe_every: u32,
    /// Keyframe entries (the start one included) and their bytes.
    pub keyframes: usize,
    pub keyframe_bytes: u64,
    /// Batch entries (the ops applied between two ticks), their ops and bytes.
    pub batches: usize,
    pub ops: u64,
    pub batch_bytes: u64,
    /// Tick entries and their bytes (`TICK_ENTRY_BYTES` each).
    pub tick_entries: usize,
    pub tick_bytes: u64,
    /// The rest: the preamble, the start entry and the end entry.
    pub other_bytes: u64,
    /// (batches + ticks) / ticks: what the file grows by a tick between keyframes.
    pub per_tick_without_keyframes: f64,
    /// The same plus a periodic keyframe's mean size over `keyframe_every`: what a long
    /// recording grows by a tick.
    pub per_tick_with_keyframes: f64,
    /// The whole file over its ticks (the start keyframe included: a short recording's).
    pub file_per_tick: f64,
    /// Batch bytes per op applied (its share of the batch entry's framing included).
    pub per_op: f64,
    /// A keyframe's mean size (periodic ones, or the start one if there is none).
    pub keyframe_mean_bytes: f64,
}

impl RecordingBytes {
    /// The bytes of `file` (whose length is `file_bytes`), as the daemon reported them
    /// (`ticks`, `bytes`) and read back from the file.
    pub fn of(
        recording: &client_sdk::Recording,
        ticks: u64,
        bytes: u64,
        file_bytes: u64,
    ) -> RecordingBytes {
        let mut r = RecordingBytes {
            ticks,
            bytes,
            file_bytes,
            keyframe_every: recording.start.keyframe_every,
            ..RecordingBytes::default()
        };
        let (mut periodic, mut periodic_bytes, mut start_bytes) = (0u64, 0u64, 0u64);
        for event in &recording.events {
            match event {
                Event::Keyframe { why, range, .. } => {
                    // The why byte, the snapshot, the framing.
                    let entry = (range.len() + 1 + ENTRY_OVERHEAD) as u64;
                    r.keyframes += 1;
                    r.keyframe_bytes += entry;
                    if *why == KeyframeWhy::Start {
                        start_bytes = entry;
                    } else {
                        periodic += 1;
                        periodic_bytes += entry;
                    }
                }
                Event::Batch {
                    count,
                    range,
                    offset,
                    ..
                } => {
                    // From the entry's first byte to the end of its checksum.
                    r.batches += 1;
                    r.ops += u64::from(*count);
                    r.batch_bytes += (range.end + 8).saturating_sub(*offset) as u64;
                }
                Event::Tick { .. } => {
                    r.tick_entries += 1;
                    r.tick_bytes += TICK_ENTRY_BYTES as u64;
                }
            }
        }
        let total = recording.bytes.len() as u64;
        r.other_bytes = total.saturating_sub(r.keyframe_bytes + r.batch_bytes + r.tick_bytes);
        let per = |b: f64, n: f64| if n > 0.0 { b / n } else { f64::NAN };
        let recorded = r.tick_entries as f64;
        r.keyframe_mean_bytes = if periodic > 0 {
            periodic_bytes as f64 / periodic as f64
        } else {
            start_bytes as f64
        };
        r.per_tick_without_keyframes = per((r.batch_bytes + r.tick_bytes) as f64, recorded);
        r.per_tick_with_keyframes = r.per_tick_without_keyframes
            + per(r.keyframe_mean_bytes, f64::from(r.keyframe_every.max(1)));
        r.file_per_tick = per(total as f64, recorded);
        r.per_op = per(r.batch_bytes as f64, r.ops as f64);
        r
    }
}

/// A manual awake plane (NeverSleep) with a pile of `n` unit boxes over a floor, as the
/// other rows of the bench build it, 10 ticks in; returns `writes` of its boxes spread
/// evenly through the pile.
fn pile(client: &Client, n: usize, writes: usize) -> BenchResult<(Plane, Vec<Object>)> {
    let plane = client.create_plane(&PlaneOptions::manual().with(PlaneProp::NeverSleep(true)))?;
    let side = (n as f64).sqrt().ceil().max(1.0) as usize;
    let floor = plane.add(
        Shape::Cube {
            size: [side as f32 * 1.5 + 10.0, 1.0, side as f32 * 1.5 + 10.0],
        },
        Pose::at([0.0, -0.5, 0.0]),
        &[],
    )?;
    floor.set_anchored(true)?;
    let mut boxes = Vec::with_capacity(n);
    for k in 0..n {
        let (i, j) = (k / side, k % side);
        let at = [
            (i as f32 - side as f32 / 2.0) * 1.2,
            1.0 + (k % 3) as f32 * 1.1,
            (j as f32 - side as f32 / 2.0) * 1.2,
        ];
        boxes.push(plane.add(Shape::Cube { size: [1.0; 3] }, Pose::at(at), &[])?);
    }
    for _ in 0..10 {
        plane.step(DT)?;
    }
    let writes = writes.min(n);
    let written = (0..writes)
        .map(|w| boxes[w * n / writes.max(1)].clone())
        .collect();
    Ok((plane, written))
}

/// One tick of a plane of the row: a Velocity write on each of `written` (a slow circle,
/// its phase by tick and body, so no two writes are alike), sent with the step.
fn tick(plane: &Plane, written: &[Object], t: u64) -> BenchResult<()> {
    for (k, object) in written.iter().enumerate() {
        let phase = t as f32 * 0.05 + k as f32;
        object.set_velocity([2.0 * phase.cos(), 0.0, 2.0 * phase.sin()])?;
    }
    plane.step(DT)?;
    Ok(())
}

/// The plane's row arguments.
#[derive(Debug, Clone, Copy)]
pub struct Sizes {
    pub bodies: usize,
    pub writes: usize,
    /// Ticks (with the writes) both piles make before anything is measured.
    pub settle_ticks: usize,
    /// Blocks of each plane.
    pub blocks: usize,
    pub ticks_per_block: usize,
}

/// Stretches of the cross-check in which the two planes' ticks alternate (see
/// [`ThreadsCheck`]).
const CHECK_STRETCHES: usize = 8;

/// CPU nanoseconds so far of the threads of `pid` named `names` (`/proc/PID/task/*/comm`),
/// by name (a name two threads share sums both).
fn named_threads_ns(pid: u32, names: &[String]) -> BenchResult<Vec<u64>> {
    let dir = format!("/proc/{pid}/task");
    let entries = std::fs::read_dir(&dir).map_err(BenchError::io(format!("list {dir}")))?;
    let mut out = vec![0u64; names.len()];
    for entry in entries.flatten() {
        // A thread may end between the listing and the reads: it is simply not counted.
        let Ok(comm) = std::fs::read_to_string(entry.path().join("comm")) else {
            continue;
        };
        let Some(k) = names.iter().position(|n| n == comm.trim_end()) else {
            continue;
        };
        let Ok(stat) = std::fs::read_to_string(entry.path().join("schedstat")) else {
            continue;
        };
        out[k] += stat
            .split_whitespace()
            .next()
            .and_then(|v| v.parse::<u64>().ok())
            .unwrap_or(0);
    }
    Ok(out)
}

/// The cross-check of the goal's figure: the two planes' ticks alternated one by one (A B
/// B A ..., B A A B ... in every other stretch) in stretches, so whatever else the machine
/// runs falls on both alike; each
/// plane's CPU read from its own threads (its worker, `plane-ID`, and for the recording
/// plane the recording's writer, `record-ID`), which leaves out the daemon's request
/// thread (the same work for both).
#[derive(Debug, Clone, serde::Serialize)]
pub struct ThreadsCheck {
    /// Ticks of each plane in each stretch.
    pub ticks_per_stretch: usize,
    /// Per stretch: (the recording plane's worker + writer) over the plain plane's worker.
    pub ratios: Vec<f64>,
    /// Their median.
    pub ratio_median: f64,
    /// All stretches pooled.
    pub ratio_pooled: f64,
    /// Per tick, all stretches pooled, µs: the recording plane's worker, its writer, the
    /// plain plane's worker.
    pub recording_worker_us: f64,
    pub writer_us: f64,
    pub plain_worker_us: f64,
}

/// Measures the row on the daemon `pid` that `client` is connected to, recording into a
/// new file at `file` (removed after).
pub fn measure(client: &Client, pid: u32, sizes: Sizes, file: &Path) -> BenchResult<RecordingCost> {
    let Sizes {
        bodies,
        writes,
        settle_ticks,
        blocks,
        ticks_per_block,
    } = sizes;
    if blocks == 0 || ticks_per_block == 0 {
        return Err(BenchError::Failed(
            "the recording row needs --recording-blocks ≥ 1 and --recording-block-ticks ≥ 1".into(),
        ));
    }
    let (recording, on) = pile(client, bodies, writes)?;
    let (plain, off) = pile(client, bodies, writes)?;
    // Both planes' ticks, counted alike so that they write the same values (the two
    // planes stay alike tick for tick: the same scene, the same ops).
    let (mut t_on, mut t_off) = (0u64, 0u64);
    // The pile lands and the writes stir it: its tick's cost grows for a few hundred
    // ticks, then holds.
    for _ in 0..settle_ticks {
        tick(&recording, &on, t_on)?;
        tick(&plain, &off, t_off)?;
        t_on += 1;
        t_off += 1;
    }
    let _ = std::fs::remove_file(file);
    recording.start_recording(Some(file))?;
    let result = blocks_and_check(
        pid,
        (&recording, &on, &mut t_on),
        (&plain, &off, &mut t_off),
        blocks,
        ticks_per_block,
    );
    let stopped = recording.stop_recording();
    let _ = recording.destroy();
    let _ = plain.destroy();
    let stopped = stopped.map_err(BenchError::from).and_then(|info| {
        info.ok_or_else(|| {
            BenchError::Failed("the recording plane was not recording when stopped".into())
        })
    });
    let (pair, check, info) = match (result, stopped) {
        (Ok((pair, check)), Ok(info)) => (pair, check, info),
        (Err(e), _) | (_, Err(e)) => {
            // No file is left behind by a row that failed.
            let _ = std::fs::remove_file(file);
            return Err(e);
        }
    };
    let file_bytes = std::fs::metadata(file).map(|m| m.len()).unwrap_or(0);
    let read = client_sdk::load_recording(file);
    let _ = std::fs::remove_file(file);
    let bytes = RecordingBytes::of(&read?, info.ticks, info.bytes, file_bytes);
    let pooled = |side: &estimator::Side| {
        side.blocks.iter().map(|b| b.cpu_us).sum::<f64>() / side.blocks.len().max(1) as f64
    };
    let r = pair.ratios();
    Ok(RecordingCost {
        bodies,
        writes_per_tick: writes.min(bodies),
        settle_ticks,
        ticks_per_block,
        estimator: Estimator::CpuMedianOfBlocks,
        cpu_ratio: r.cpu_median,
        cpu_ratio_min: r.cpu_min,
        cpu_ratio_pooled: pooled(&pair.a) / pooled(&pair.b),
        wall_ratio: r.wall_median,
        blocks: pair,
        threads: check,
        bytes,
    })
}

type Side<'a> = (&'a Plane, &'a [Object], &'a mut u64);

/// The ABBA blocks of the recording plane (`a`) and the plain one (`b`), then the
/// [`ThreadsCheck`].
fn blocks_and_check(
    pid: u32,
    a: Side<'_>,
    b: Side<'_>,
    blocks: usize,
    ticks_per_block: usize,
) -> BenchResult<(Pair, ThreadsCheck)> {
    let (a_plane, a_written, t_on) = a;
    let (b_plane, b_written, t_off) = b;
    let clock = CpuClock::daemons_only(&[pid]);
    let block = |plane: &Plane, written: &[Object], t: &mut u64| -> BenchResult<Block> {
        super::daemon::until_idle(pid)?;
        let cpu0 = clock.read()?;
        let started = Instant::now();
        for _ in 0..ticks_per_block {
            tick(plane, written, *t)?;
            *t += 1;
        }
        let wall = started.elapsed();
        super::daemon::until_idle(pid)?;
        let cpu = clock.read()?.used_since(&cpu0);
        Ok(Block {
            wall_us: wall.as_secs_f64() * 1e6 / ticks_per_block as f64,
            cpu_us: cpu as f64 / 1e3 / ticks_per_block as f64,
        })
    };
    // A block each first: both warm up, the recording's writer starts.
    block(a_plane, a_written, t_on)?;
    block(b_plane, b_written, t_off)?;
    let pair = estimator::interleaved(
        blocks,
        Order::Abba,
        || block(a_plane, a_written, t_on),
        || block(b_plane, b_written, t_off),
    )?;
    let names = [
        format!("plane-{}", a_plane.id()),
        format!("record-{}", a_plane.id()),
        format!("plane-{}", b_plane.id()),
    ];
    let mut ratios = Vec::with_capacity(CHECK_STRETCHES);
    let mut total = [0u64; 3];
    for stretch in 0..CHECK_STRETCHES {
        super::daemon::until_idle(pid)?;
        let before = named_threads_ns(pid, &names)?;
        // The first tick after the daemon idled finds its caches cold: each plane takes it
        // in every other stretch (A B B A ..., then B A A B ...).
        let a_first = stretch % 2 == 0;
        for i in 0..2 * ticks_per_block {
            if Order::Abba.is_a(i) == a_first {
                tick(a_plane, a_written, *t_on)?;
                *t_on += 1;
            } else {
                tick(b_plane, b_written, *t_off)?;
                *t_off += 1;
            }
        }
        super::daemon::until_idle(pid)?;
        let after = named_threads_ns(pid, &names)?;
        let used: Vec<u64> = after
            .iter()
            .zip(&before)
            .map(|(x, y)| x.saturating_sub(*y))
            .collect();
        for (t, u) in total.iter_mut().zip(&used) {
            *t += u;
        }
        ratios.push((used[0] + used[1]) as f64 / used[2] as f64);
    }
    let ticks = (CHECK_STRETCHES * ticks_per_block) as f64;
    let check = ThreadsCheck {
        ticks_per_stretch: ticks_per_block,
        ratio_median: crate::stats::median(&ratios).unwrap_or(f64::NAN),
        ratios,
        ratio_pooled: (total[0] + total[1]) as f64 / total[2] as f64,
        recording_worker_us: total[0] as f64 / 1e3 / ticks,
        writer_us: total[1] as f64 / 1e3 / ticks,
        plain_worker_us: total[2] as f64 / 1e3 / ticks,
    };
    Ok((pair, check))
}

/// The goal: recording adds at most 5 % to a tick's CPU.
pub fn goal(r: &RecordingCost) -> estimator::JudgedGoal {
    estimator::JudgedGoal::new(
        r.estimator,
        format!(
            "recording adds <= 5 % to a tick's CPU ({} bodies, {} writes a frame; the daemon's \
             CPU per tick, {} blocks of {} ticks a plane, ABBA)",
            group(r.bodies),
            r.writes_per_tick,
            r.blocks.a.blocks.len(),
            r.ticks_per_block
        ),
        format!(
            "{:+.1} % (min of blocks {:+.1} %, pooled {:+.1} %; the planes' own threads, \
             ticks alternated: {:+.1} %)",
            (r.cpu_ratio - 1.0) * 100.0,
            (r.cpu_ratio_min - 1.0) * 100.0,
            (r.cpu_ratio_pooled - 1.0) * 100.0,
            (r.threads.ratio_median - 1.0) * 100.0
        ),
        Some(r.cpu_ratio <= 1.05),
    )
}

/// 1000 as "1,000".
fn group(n: usize) -> String {
    let digits = n.to_string();
    let mut out = String::new();
    for (i, c) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i).is_multiple_of(3) {
            out.push(',');
        }
        out.push(c);
    }
    out
}

/// The row's section of the page.
pub fn markdown(r: &RecordingCost) -> String {
    let mut cpu = Table::new(&[
        "plane",
        "blocks",
        "daemon CPU per tick, median (ms)",
        "min (ms)",
        "wall per tick, median (ms)",
    ]);
    for (name, side) in [("recording", &r.blocks.a), ("plain", &r.blocks.b)] {
        cpu.row(&[
            name.into(),
            side.blocks.len().to_string(),
            format!("{:.3}", side.cpu_us.median / 1e3),
            format!("{:.3}", side.cpu_us.min / 1e3),
            format!("{:.3}", side.wall_us.median / 1e3),
        ]);
    }
    let c = &r.threads;
    let mut threads = Table::new(&["thread", "CPU per tick (ms)"]);
    for (name, us) in [
        ("the recording plane's worker", c.recording_worker_us),
        ("its recording's writer", c.writer_us),
        ("the plain plane's worker", c.plain_worker_us),
    ] {
        threads.row(&[name.into(), format!("{:.4}", us / 1e3)]);
    }
    let b = &r.bytes;
    let per_tick = |v: u64| v as f64 / b.tick_entries.max(1) as f64;
    let mut bytes = Table::new(&["entries", "count", "bytes", "bytes per tick"]);
    bytes.row(&[
        "batches (the ops applied between two ticks)".into(),
        format!("{} ({} ops)", b.batches, b.ops),
        b.batch_bytes.to_string(),
        format!("{:.1}", per_tick(b.batch_bytes)),
    ]);
    bytes.row(&[
        format!("ticks (tick, dt, state hash: {TICK_ENTRY_BYTES} bytes each)"),
        b.tick_entries.to_string(),
        b.tick_bytes.to_string(),
        format!("{:.1}", per_tick(b.tick_bytes)),
    ]);
    bytes.row(&[
        format!(
            "keyframes (the start one, then one every {} ticks)",
            b.keyframe_every
        ),
        b.keyframes.to_string(),
        b.keyframe_bytes.to_string(),
        format!("{:.1}", per_tick(b.keyframe_bytes)),
    ]);
    bytes.row(&[
        "preamble, start and end entries".into(),
        "3".into(),
        b.other_bytes.to_string(),
        format!("{:.1}", per_tick(b.other_bytes)),
    ]);
    bytes.row(&[
        "the file".into(),
        String::new(),
        b.file_bytes.to_string(),
        format!("{:.1}", b.file_per_tick),
    ]);
    format!(
        "## What recording costs\n\nEstimator `{}`: two awake piles of {} boxes on one \
         daemon, one recording (started once, before the first block, into a file on the \
         daemon's machine), the other not; each tick the client writes the Velocity of {} \
         boxes of each (the same values) and steps; {} such ticks of each first. Blocks of \
         {} ticks, ABBA; a block's \
         figure is the daemon's CPU (every thread, the recording's writer included, from \
         /proc/PID/task/*/schedstat) per tick, read once the daemon is idle again after the \
         block. Recording over plain: {:.3} (medians of blocks), {:.3} (minimums), {:.3} \
         (every block pooled); wall per tick {:.3}.\n\n{}\n\
         A cross-check from the planes' own threads: {} stretches in which the two planes' \
         ticks alternate one by one (ABBA, BAAB in every other stretch), {} ticks of each a \
         stretch, the recording plane's \
         worker and writer over the plain plane's worker (the daemon's request thread, the \
         same for both, left out): {:.3} (median of the stretches), {:.3} (pooled).\n\n{}\n\
         What a tick adds to the file: the batch of ops applied before it (each op \
         postcard-encoded, {:.1} bytes an op with its share of the entry's framing), a tick \
         entry with its state hash ({TICK_ENTRY_BYTES} bytes: tick, dt, hash and \
         {ENTRY_OVERHEAD} bytes of framing), and every {} ticks a keyframe (a snapshot of \
         the plane, {:.0} bytes on average): {:.0} bytes a tick without the keyframes, \
         {:.0} with them (their mean size over {} ticks). The recording held {} ticks \
         ({} reported by the daemon) in {} bytes ({} reported written; {:.0} a tick, its \
         start keyframe included).\n\n{}",
        r.estimator.name(),
        r.bodies,
        r.writes_per_tick,
        r.settle_ticks,
        r.ticks_per_block,
        r.cpu_ratio,
        r.cpu_ratio_min,
        r.cpu_ratio_pooled,
        r.wall_ratio,
        cpu.finish(),
        c.ratios.len(),
        c.ticks_per_stretch,
        c.ratio_median,
        c.ratio_pooled,
        threads.finish(),
        b.per_op,
        b.keyframe_every,
        b.keyframe_mean_bytes,
        b.per_tick_without_keyframes,
        b.per_tick_with_keyframes,
        b.keyframe_every,
        b.tick_entries,
        b.ticks,
        b.file_bytes,
        b.bytes,
        b.file_per_tick,
        bytes.finish(),
    )
}

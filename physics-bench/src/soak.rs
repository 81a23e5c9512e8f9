//! `physics-bench soak`: planes ticking at 60 Hz for minutes while a client writes every
//! frame; the daemon's memory and the domain's shared memory at the start and the end of
//! the window, and their growth against a stated bound.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::PathBuf;
use std::time::{Duration, Instant};

use client_sdk::{Client, Error, Object, Plane, PlaneOptions, Pose, Shape};

use super::daemon::DaemonProcess;
use super::error::BenchResult;
use super::procfs;
use super::report::{self, goals_table, mib, num, Goal};

/// Options of the `soak` subcommand.
#[derive(Debug, Clone, clap::Args)]
pub struct SoakArgs {
    /// How long to run, in minutes (fractions allowed: 0.5 is 30 s).
    #[arg(long, default_value_t = 10.0)]
    pub minutes: f64,
    /// Planes, each ticking at 60 Hz.
    #[arg(long, default_value_t = 4)]
    pub planes: usize,
    /// Bodies per plane (a settled pile on a floor).
    #[arg(long, default_value_t = 1_000)]
    pub bodies: usize,
    /// Folder receiving soak.json and soak.md.
    #[arg(long, default_value = "bench-out")]
    pub out: PathBuf,
}

/// Tick rate of the soak planes (the default).
const TICK_RATE: f64 = 60.0;
/// Bodies per plane the client moves (a game's few active objects; the rest of the level
/// rests and sleeps).
const ACTIVE: usize = 10;
/// Velocity writes per plane per frame, on the active bodies in turn.
const WRITES_PER_PLANE: usize = 2;
/// Every this many frames a plane has one body destroyed and a new one added (staggered
/// over the planes).
const CHURN_EVERY: u64 = 30;
/// RSS may grow by this much over the measured window, plus [`RSS_BOUND_FRACTION`] of the
/// RSS at its start: allocator and page-cache settling, not a leak. A leak of 100 bytes per
/// write, or one page per frame, exceeds it within a minute.
const RSS_BOUND_BYTES: f64 = 4.0 * 1024.0 * 1024.0;
const RSS_BOUND_FRACTION: f64 = 0.02;
/// Shared memory is sized when a plane is created; churning bodies must not grow it.
const SHM_BOUND_BYTES: f64 = 0.0;
/// Share of the due ticks the planes must deliver.
const TICK_GOAL: f64 = 0.95;

/// Memory at one moment.
#[derive(Debug, Clone, Copy, serde::Serialize)]
pub struct Sample {
    /// Seconds since the soak started (setup excluded).
    pub t_s: f64,
    pub rss_bytes: u64,
    pub shm_bytes: u64,
    pub shm_backed_bytes: u64,
}

#[derive(Debug, Clone, serde::Serialize)]
pub struct SoakReport {
    pub minutes: f64,
    pub planes: usize,
    pub bodies_per_plane: usize,
    /// Seconds before the measured window (warm-up), and of the window.
    pub warmup_s: f64,
    pub window_s: f64,
    pub frames: u64,
    pub writes: u64,
    pub bodies_replaced: u64,
    pub write_errors: u64,
    pub first_error: Option<String>,
    /// Ticks per second each plane delivered over the window.
    pub ticks_per_s: Vec<f64>,
    /// Step time of the newest tick of each plane at the end (µs).
    pub step_us: Vec<f32>,
    pub start: Sample,
    pub end: Sample,
    pub rss_growth_bytes: i64,
    pub shm_growth_bytes: i64,
    pub shm_backed_growth_bytes: i64,
    /// Least-squares slope of RSS over the second half of the window, per hour.
    pub rss_slope_mib_per_hour: f64,
    pub rss_bound_bytes: f64,
    pub samples: Vec<Sample>,
    pub goals: Vec<Goal>,
    pub method: BTreeMap<&'static str, &'static str>,
}

/// One plane of the soak and the bodies the client churns through.
struct SoakPlane {
    plane: Plane,
    bodies: Vec<Object>,
    /// Where each body's column stands (x, z): its replacement drops onto it.
    spots: Vec<[f32; 2]>,
    next: usize,
}

pub fn run(args: &SoakArgs) -> BenchResult<()> {
    let duration = Duration::from_secs_f64((args.minutes * 60.0).max(1.0));
    let warmup = Duration::from_secs_f64((duration.as_secs_f64() * 0.25).min(15.0));
    let daemon = DaemonProcess::start("soak")?;
    let pid = daemon.pid();
    let client = daemon.connect()?;
    eprintln!(
        "soak: {} planes × {} bodies at {TICK_RATE} Hz for {:.1} min (first {:.0} s warm-up)",
        args.planes,
        args.bodies,
        duration.as_secs_f64() / 60.0,
        warmup.as_secs_f64()
    );
    let mut planes = (0..args.planes.max(1))
        .map(|_| build(&client, args.bodies))
        .collect::<BenchResult<Vec<_>>>()?;
    let sample = |t: f64| -> BenchResult<Sample> {
        let (shm, backed) = procfs::shm_bytes(&daemon.domain)?;
        Ok(Sample {
            t_s: t,
            rss_bytes: procfs::rss_bytes(pid)?,
            shm_bytes: shm,
            shm_backed_bytes: backed,
        })
    };

    let started = Instant::now();
    let every = Duration::from_secs_f64((duration.as_secs_f64() / 30.0).max(1.0));
    let mut next_sample = started + warmup;
    let (mut frames, mut writes, mut replaced, mut errors) = (0u64, 0u64, 0u64, 0u64);
    let mut first_error = None;
    let mut samples = Vec::new();
    let mut start_ticks = Vec::new();
    let mut window_start = None;
    let mut last_note = started;
    while started.elapsed() < duration {
        // One frame per tick of the first plane.
        let _ = planes[0].plane.wait_tick(Duration::from_millis(100));
        let result = frame(&client, &mut planes, frames);
        match result {
            Ok((w, r)) => {
                writes += w;
                replaced += r;
            }
            Err(e) => {
                errors += 1;
                first_error.get_or_insert_with(|| e.to_string());
                if matches!(e, Error::DaemonGone { .. } | Error::Stalled { .. }) {
                    return Err(e.into());
                }
            }
        }
        frames += 1;
        if Instant::now() >= next_sample {
            let t = started.elapsed().as_secs_f64();
            samples.push(sample(t)?);
            if window_start.is_none() {
                window_start = Some(Instant::now());
                start_ticks = ticks(&planes)?;
            }
            next_sample += every;
        }
        if last_note.elapsed() >= Duration::from_secs(30) {
            eprintln!(
                "{:>5.0} s: {frames} frames, {writes} writes, RSS {} MiB",
                started.elapsed().as_secs_f64(),
                samples
                    .last()
                    .map_or("—".into(), |s| mib(s.rss_bytes as f64))
            );
            last_note = Instant::now();
        }
    }
    let end_ticks = ticks(&planes)?;
    let window_s = window_start.map_or(0.0, |w| w.elapsed().as_secs_f64());
    let end = sample(started.elapsed().as_secs_f64())?;
    samples.push(end);
    let step_us = planes
        .iter()
        .map(|p| p.plane.snapshot().map(|s| s.header().step_time_us))
        .collect::<Result<Vec<_>, _>>()?;
    drop(planes);
    drop(client);
    drop(daemon);

    let start = samples[0];
    let ticks_per_s = start_ticks
        .iter()
        .zip(&end_ticks)
        .map(|(a, b)| (b - a) as f64 / window_s.max(1e-9))
        .collect();
    let rss_bound = RSS_BOUND_BYTES + RSS_BOUND_FRACTION * start.rss_bytes as f64;
    let mut report = SoakReport {
        minutes: args.minutes,
        planes: args.planes.max(1),
        bodies_per_plane: args.bodies,
        warmup_s: warmup.as_secs_f64(),
        window_s,
        frames,
        writes,
        bodies_replaced: replaced,
        write_errors: errors,
        first_error,
        ticks_per_s,
        step_us,
        start,
        end,
        rss_growth_bytes: end.rss_bytes as i64 - start.rss_bytes as i64,
        shm_growth_bytes: end.shm_bytes as i64 - start.shm_bytes as i64,
        shm_backed_growth_bytes: end.shm_backed_bytes as i64 - start.shm_backed_bytes as i64,
        rss_slope_mib_per_hour: slope(&samples[samples.len() / 2..]) * 3600.0 / (1024.0 * 1024.0),
        rss_bound_bytes: rss_bound,
        samples,
        goals: Vec::new(),
        method: method(),
    };
    report.goals = goals(&report);
    let md = render(&report);
    let (json, md_path) = report::write(&args.out, "soak", &report, &md)?;
    println!("{md}");
    eprintln!("wrote {} and {}", json.display(), md_path.display());
    Ok(())
}

/// A plane at 60 Hz with a settled pile of `bodies` unit cubes on a floor.
fn build(client: &Client, bodies: usize) -> BenchResult<SoakPlane> {
    let plane = client.create_plane(&PlaneOptions::default())?;
    let mut all = physics_scenes::pile(&mut &plane, bodies)?;
    let bodies: Vec<Object> = all.drain(1..).collect();
    let spots = bodies
        .iter()
        .map(|b| b.position().map(|p| [p[0], p[2]]))
        .collect::<Result<Vec<_>, _>>()?;
    // The floor (all[0]) stays with the plane; only the cubes are churned.
    Ok(SoakPlane {
        plane,
        bodies,
        spots,
        next: 0,
    })
}

/// One frame's writes: velocity kicks on the plane's active bodies (the tops of the first
/// columns) and, every [`CHURN_EVERY`] frames, one body destroyed and replaced by a new one
/// dropped onto its column (slot reuse, new generation). Returns (writes, bodies replaced).
fn frame(client: &Client, planes: &mut [SoakPlane], n: u64) -> Result<(u64, u64), Error> {
    let mut writes = 0;
    let mut replaced = 0;
    for (p, soak) in planes.iter_mut().enumerate() {
        let len = soak.bodies.len();
        if len == 0 {
            continue;
        }
        for k in 0..WRITES_PER_PLANE {
            let m = (n as usize * WRITES_PER_PLANE + k) % ACTIVE;
            let i = (m * 5 + 4).min(len - 1);
            let s = ((n as usize + k) % 5) as f32 * 0.5 - 1.0;
            soak.bodies[i].set_velocity([s, 2.0, -s])?;
            writes += 1;
        }
        if n % CHURN_EVERY == p as u64 % CHURN_EVERY {
            let i = soak.next % len;
            soak.next += 1;
            soak.bodies[i].destroy();
            let [x, z] = soak.spots[i];
            soak.bodies[i] =
                soak.plane
                    .add(Shape::Cube { size: [1.0; 3] }, Pose::at([x, 8.0, z]), &[])?;
            writes += 2;
            replaced += 1;
        }
    }
    client.flush()?;
    Ok((writes, replaced))
}

fn ticks(planes: &[SoakPlane]) -> BenchResult<Vec<u64>> {
    planes.iter().map(|p| Ok(p.plane.info()?.tick)).collect()
}

/// Least-squares slope of RSS (bytes per second) over the samples.
fn slope(samples: &[Sample]) -> f64 {
    let n = samples.len() as f64;
    if n < 2.0 {
        return 0.0;
    }
    let mt = samples.iter().map(|s| s.t_s).sum::<f64>() / n;
    let mr = samples.iter().map(|s| s.rss_bytes as f64).sum::<f64>() / n;
    let (mut num, mut den) = (0.0, 0.0);
    for s in samples {
        num += (s.t_s - mt) * (s.rss_bytes as f64 - mr);
        den += (s.t_s - mt).powi(2);
    }
    if den > 0.0 {
        num / den
    } else {
        0.0
    }
}

fn method() -> BTreeMap<&'static str, &'static str> {
    BTreeMap::from([
        (
            "scene",
            "one daemon; one client creates the planes (TickRate 60, the defaults otherwise), \
             each a pile of unit cubes in columns of 5 on an anchored floor (physics-scenes \
             pile), and keeps them ticking on the daemon's own schedule.",
        ),
        (
            "writes",
            "every tick of the first plane is a frame: per plane 2 SetObject(Velocity) kicks \
             on its 10 active bodies in turn (the tops of the first columns: a game's few \
             moving objects), and every 30 frames one body destroyed and a new one added on \
             its column (slot reuse, new generation, a round trip for its handle); then one \
             flush. A failed flush or add counts as a write error.",
        ),
        (
            "memory",
            "daemon VmRSS (/proc/PID/status) and the size and page-backed bytes of the \
             domain's /dev/shm files, sampled about 30 times; start = the first sample after \
             the warm-up (a quarter of the run, at most 15 s: the piles settle and the \
             allocator reaches its working set), end = after the last frame. Growth = end - \
             start; the slope is a least-squares fit over the second half of the samples \
             (past the settling), per hour.",
        ),
        (
            "ticks",
            "each plane's tick counter (PlaneInfo.tick) at the start and end of the window \
             over the window's wall time.",
        ),
    ])
}

fn goals(r: &SoakReport) -> Vec<Goal> {
    let min_rate = r.ticks_per_s.iter().copied().fold(f64::INFINITY, f64::min);
    vec![
        Goal::new(
            format!(
                "daemon RSS growth over the window ≤ {} MiB (4 MiB + 2 % of the start)",
                mib(r.rss_bound_bytes)
            ),
            format!(
                "{} MiB → {} MiB: {:+.2} MiB ({:+.1} MiB/h over the second half)",
                mib(r.start.rss_bytes as f64),
                mib(r.end.rss_bytes as f64),
                r.rss_growth_bytes as f64 / (1024.0 * 1024.0),
                r.rss_slope_mib_per_hour
            ),
            Some(r.window_s > 0.0 && r.rss_growth_bytes as f64 <= r.rss_bound_bytes),
        ),
        Goal::new(
            "shared memory of the domain does not grow (size and backed pages)",
            format!(
                "size {} → {} MiB, backed {} → {} MiB",
                mib(r.start.shm_bytes as f64),
                mib(r.end.shm_bytes as f64),
                mib(r.start.shm_backed_bytes as f64),
                mib(r.end.shm_backed_bytes as f64)
            ),
            Some(
                r.shm_growth_bytes as f64 <= SHM_BOUND_BYTES
                    && r.shm_backed_growth_bytes as f64 <= SHM_BOUND_BYTES,
            ),
        ),
        Goal::new(
            format!(
                "every plane ticks at ≥ {:.0} % of {TICK_RATE} Hz",
                TICK_GOAL * 100.0
            ),
            r.ticks_per_s
                .iter()
                .map(|t| format!("{t:.1}"))
                .collect::<Vec<_>>()
                .join(", ")
                + " Hz",
            Some(min_rate.is_finite() && min_rate >= TICK_GOAL * TICK_RATE),
        ),
        Goal::new(
            "every frame's writes applied",
            format!(
                "{} writes, {} bodies replaced in {} frames, {} errors{}",
                r.writes,
                r.bodies_replaced,
                r.frames,
                r.write_errors,
                r.first_error
                    .as_ref()
                    .map_or(String::new(), |e| format!(" (first: {e})"))
            ),
            Some(r.write_errors == 0 && r.frames > 0),
        ),
    ]
}

fn render(r: &SoakReport) -> String {
    let mut md = String::new();
    let _ = writeln!(
        md,
        "# physics-bench soak\n\n{} planes × {} bodies at {TICK_RATE} Hz with a client writing \
         every frame, {:.1} min: {:.0} s warm-up, then a {:.0} s window.\n",
        r.planes, r.bodies_per_plane, r.minutes, r.warmup_s, r.window_s
    );
    md.push_str("## Goals\n\n");
    md.push_str(&goals_table(&r.goals));
    let _ = writeln!(
        md,
        "\n## Memory\n\n\
         | | start | end | growth |\n|---|---|---|---|\n\
         | daemon RSS MiB | {} | {} | {:+.3} |\n\
         | shm size MiB | {} | {} | {:+.3} |\n\
         | shm backed MiB | {} | {} | {:+.3} |\n\n\
         RSS slope over the second half of the window: {:+.1} MiB per hour. Step time of the newest tick: {} µs.",
        mib(r.start.rss_bytes as f64),
        mib(r.end.rss_bytes as f64),
        r.rss_growth_bytes as f64 / (1024.0 * 1024.0),
        mib(r.start.shm_bytes as f64),
        mib(r.end.shm_bytes as f64),
        r.shm_growth_bytes as f64 / (1024.0 * 1024.0),
        mib(r.start.shm_backed_bytes as f64),
        mib(r.end.shm_backed_bytes as f64),
        r.shm_backed_growth_bytes as f64 / (1024.0 * 1024.0),
        r.rss_slope_mib_per_hour,
        r.step_us
            .iter()
            .map(|s| num(Some(*s as f64)))
            .collect::<Vec<_>>()
            .join(", ")
    );
    md.push_str("\n## Samples\n\n");
    let mut t = report::Table::new(&["t s", "RSS MiB", "shm MiB", "shm backed MiB"]);
    for s in &r.samples {
        t.row(&[
            format!("{:.0}", s.t_s),
            mib(s.rss_bytes as f64),
            mib(s.shm_bytes as f64),
            mib(s.shm_backed_bytes as f64),
        ]);
    }
    md.push_str(&t.finish());
    md.push_str("\n## Method\n\n");
    for (name, text) in &r.method {
        let _ = writeln!(md, "- **{name}**: {text}");
    }
    md
}

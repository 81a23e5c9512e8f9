//! `physics-bench soak`: a game's load for minutes to an hour against one daemon (planes
//! ticking at 60 Hz; velocity and CFrame writes, cube churn, rays, overlaps and sweeps,
//! controllers walking paths, joints made and broken, Touched events read by a subscriber,
//! a plane created and destroyed and a second client connecting and leaving every cycle),
//! with the daemon's memory and the domain's shared memory sampled every few seconds. After
//! a warm-up, both must stay within 1 MiB of the warm-up's end; the least-squares slope is
//! reported and carried over an hour.
//!
//! - [`game`]: the load.
//! - [`memory`]: the samples and the drift figures.

mod game;
mod memory;

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::PathBuf;
use std::time::{Duration, Instant};

use client_sdk::{Client, Error};

use super::daemon::DaemonProcess;
use super::error::BenchResult;
use super::report::{self, num, Goal};
use game::{Counts, PassingPlane, SoakPlane, VisitingClient};
use memory::{Drift, Sample};

/// Options of the `soak` subcommand.
#[derive(Debug, Clone, clap::Args)]
pub struct SoakArgs {
    /// How long the load runs, in minutes (fractions allowed: 0.5 is 30 s).
    #[arg(long, default_value_t = 10.0)]
    pub minutes: f64,
    /// Warm-up in minutes, not judged. Default: 8 minutes or a quarter of the run, whichever
    /// is longer, at most half the run (measured over an hour: the daemon's RSS rose 2 MiB
    /// in the first 9 minutes, 0.37 MiB in the next 6 and 0.36 MiB in the 45 after).
    #[arg(long)]
    pub warmup_minutes: Option<f64>,
    /// Long-lived planes, each ticking at 60 Hz.
    #[arg(long, default_value_t = 4)]
    pub planes: usize,
    /// Cubes per long-lived plane (a settled pile).
    #[arg(long, default_value_t = 1_000)]
    pub bodies: usize,
    /// Soak a daemon already serving this domain (e.g. one started under heaptrack) instead
    /// of starting one.
    #[arg(long)]
    pub domain: Option<String>,
    /// Folder receiving soak.json and soak.md.
    #[arg(long, default_value = "bench-out")]
    pub out: PathBuf,
}

/// Shortest default warm-up: under this load the daemon's RSS rose for about 7 minutes
/// before it settled (measured with one malloc arena and trims).
const WARMUP_S: f64 = 480.0;
/// Tick rate of the soak planes (the default).
const TICK_RATE: f64 = 60.0;
/// One cycle of the load's comings and goings, in seconds: a passing plane lives for its
/// first [`PLANE_LIVES_S`]; the visiting client comes at [`VISIT_AT_S`]; memory is sampled
/// at [`SAMPLE_AT_S`] (when neither is there, so samples compare like with like).
const CYCLE_S: f64 = 12.0;
const PLANE_LIVES_S: f64 = 4.0;
const VISIT_AT_S: f64 = 6.0;
const SAMPLE_AT_S: [f64; 2] = [5.0, 11.0];
/// After the warm-up, RSS and shared memory may rise at most this much over the warm-up's
/// end, and the fitted slope carried over an hour may not exceed it either.
const FLAT_BYTES: f64 = 1024.0 * 1024.0;
/// Share of the due ticks the planes must deliver.
const TICK_GOAL: f64 = 0.95;

#[derive(Debug, Clone, serde::Serialize)]
pub struct SoakReport {
    pub minutes: f64,
    pub planes: usize,
    pub bodies_per_plane: usize,
    /// Seconds of warm-up, and of the judged window after it.
    pub warmup_s: f64,
    pub window_s: f64,
    pub counts: Counts,
    /// Ticks per second each long-lived plane delivered over the window.
    pub ticks_per_s: Vec<f64>,
    /// Step time of the newest tick of each long-lived plane at the end (µs).
    pub step_us: Vec<f32>,
    /// Drift over the window (from its first sample, the warm-up's end).
    pub rss: Drift,
    pub rss_anon: Drift,
    pub rss_shmem: Drift,
    pub shm: Drift,
    pub shm_backed: Drift,
    pub threads: Drift,
    pub fds: Drift,
    pub samples: Vec<Sample>,
    pub goals: Vec<Goal>,
    pub method: BTreeMap<&'static str, &'static str>,
}

pub fn run(args: &SoakArgs) -> BenchResult<()> {
    let duration = Duration::from_secs_f64((args.minutes * 60.0).max(1.0));
    let warmup = Duration::from_secs_f64(
        args.warmup_minutes
            .map_or((duration.as_secs_f64() * 0.25).max(WARMUP_S), |m| m * 60.0)
            .min(duration.as_secs_f64() * 0.5),
    );
    let daemon = match &args.domain {
        Some(_) => None,
        None => Some(DaemonProcess::start("soak")?),
    };
    let domain = args
        .domain
        .clone()
        .or_else(|| daemon.as_ref().map(|d| d.domain.clone()))
        .unwrap_or_default();
    let client = Client::connect(&domain)?;
    let pid = client.daemon_pid();
    eprintln!(
        "soak: daemon {pid}, {} planes × {} cubes at {TICK_RATE} Hz for {:.1} min (first {:.1} \
         min warm-up), samples every {:.0} s",
        args.planes,
        args.bodies,
        duration.as_secs_f64() / 60.0,
        warmup.as_secs_f64() / 60.0,
        CYCLE_S / 2.0
    );
    let mut planes = (0..args.planes.max(1))
        .map(|_| game::build(&client, args.bodies))
        .collect::<BenchResult<Vec<_>>>()?;
    let mut visitor = VisitingClient::start(&domain);
    let mut counts = Counts::default();
    let mut passing: Option<PassingPlane> = None;
    let mut samples = Vec::new();
    let mut start_ticks = None;
    let mut window_start = None;
    // Per cycle: passing plane created, destroyed, visit started, samples taken.
    let mut cycle = u64::MAX;
    let mut done = [false; 5];
    let mut last_note = Instant::now();

    let started = Instant::now();
    while started.elapsed() < duration {
        // One frame per tick of the first plane.
        let _ = planes[0].plane.wait_tick(Duration::from_millis(100));
        game::frame(&client, &mut planes, counts.frames, &mut counts)?;
        let t = started.elapsed().as_secs_f64();
        let (c, phase) = ((t / CYCLE_S) as u64, t % CYCLE_S);
        if c != cycle {
            // A sample the last cycle could not take (the visit ran long) is taken now.
            for (k, _) in SAMPLE_AT_S.iter().enumerate() {
                if cycle != u64::MAX && !done[3 + k] {
                    visitor.wait(Duration::from_secs(30), &mut counts);
                    samples.push(Sample::read(pid, &domain, t)?);
                }
            }
            cycle = c;
            done = [false; 5];
        }
        if !done[0] {
            done[0] = true;
            match PassingPlane::create(&client) {
                Ok(p) => passing = Some(p),
                Err(e) => counts.error_of("passing plane", e),
            }
        }
        if !done[1] && phase >= PLANE_LIVES_S {
            done[1] = true;
            if let Some(p) = passing.take() {
                match p.destroy() {
                    Ok(()) => counts.planes_cycled += 1,
                    Err(e) => counts.error_of("passing plane", e),
                }
            }
        }
        if !done[2] && phase >= VISIT_AT_S {
            done[2] = true;
            visitor.visit(c);
        }
        let quiet = passing.is_none() && !visitor.busy(&mut counts);
        for (k, at) in SAMPLE_AT_S.iter().enumerate() {
            if !done[3 + k] && phase >= *at && quiet {
                done[3 + k] = true;
                samples.push(Sample::read(pid, &domain, t)?);
                if window_start.is_none() && t >= warmup.as_secs_f64() {
                    window_start = Some(Instant::now());
                    start_ticks = Some(ticks(&planes)?);
                }
            }
        }
        if last_note.elapsed() >= Duration::from_secs(30) {
            eprintln!(
                "{t:>5.0} s: {} frames, {} writes, {} errors, RSS {} MiB",
                counts.frames,
                counts.writes(),
                counts.errors,
                samples
                    .last()
                    .map_or("—".into(), |s: &Sample| mib(s.rss_bytes as f64))
            );
            last_note = Instant::now();
        }
    }
    visitor.wait(Duration::from_secs(30), &mut counts);
    drop(visitor);
    if let Some(p) = passing.take() {
        p.destroy()?;
        counts.planes_cycled += 1;
    }
    let end_ticks = ticks(&planes)?;
    let window_s = window_start.map_or(0.0, |w| w.elapsed().as_secs_f64());
    // The last sample, like the others, a second after the passing plane went.
    std::thread::sleep(Duration::from_secs(1));
    samples.push(Sample::read(pid, &domain, started.elapsed().as_secs_f64())?);
    let step_us = planes
        .iter()
        .map(|p| p.plane.snapshot().map(|s| s.header().step_time_us))
        .collect::<Result<Vec<_>, Error>>()?;
    drop(planes);
    drop(client);
    drop(daemon);

    let ticks_per_s = start_ticks
        .unwrap_or_default()
        .iter()
        .zip(&end_ticks)
        .map(|(a, b)| (b - a) as f64 / window_s.max(1e-9))
        .collect();
    let window: Vec<Sample> = samples
        .iter()
        .copied()
        .filter(|s| s.t_s >= warmup.as_secs_f64())
        .collect();
    let mut report = SoakReport {
        minutes: args.minutes,
        planes: args.planes.max(1),
        bodies_per_plane: args.bodies,
        warmup_s: warmup.as_secs_f64(),
        window_s,
        counts,
        ticks_per_s,
        step_us,
        rss: Drift::of(&window, |s| s.rss_bytes),
        rss_anon: Drift::of(&window, |s| s.rss_anon_bytes),
        rss_shmem: Drift::of(&window, |s| s.rss_shmem_bytes),
        shm: Drift::of(&window, |s| s.shm_bytes),
        shm_backed: Drift::of(&window, |s| s.shm_backed_bytes),
        threads: Drift::of(&window, |s| s.threads),
        fds: Drift::of(&window, |s| s.fds),
        samples,
        goals: Vec::new(),
        method: method(),
    };
    report.goals = goals(&report, window.len());
    let md = render(&report);
    let (json, md_path) = report::write(&args.out, "soak", &report, &md)?;
    report::print(&md_path);
    eprintln!("wrote {} and {}", json.display(), md_path.display());
    Ok(())
}

/// Bytes as MiB with three decimals (the goals judge 1 MiB).
fn mib(bytes: f64) -> String {
    format!("{:.3}", bytes / (1024.0 * 1024.0))
}

fn ticks(planes: &[SoakPlane]) -> BenchResult<Vec<u64>> {
    planes.iter().map(|p| Ok(p.plane.info()?.tick)).collect()
}

fn method() -> BTreeMap<&'static str, &'static str> {
    BTreeMap::from([
        (
            "scene",
            "one daemon; one client creates the long-lived planes (TickRate 60, the defaults \
             otherwise), each a pile of unit cubes in columns of 5 on an anchored floor \
             (physics-scenes pile), a walking floor beside it with 3 character controllers \
             walking a looping 4-corner path, and an anchored platform.",
        ),
        (
            "frame",
            "every tick of the first plane is a frame. Per plane: 2 Velocity kicks on its 10 \
             active cubes in turn, 1 CFrame write moving the platform round a circle, its \
             events drained (Touched started / ended, joint broke, path finished: the \
             controller is sent round again); every 30 frames a cube destroyed and a new one \
             (ReportContacts on) dropped on its column; every 120 frames a joint round: a \
             ball hung from the world by a Ball joint with BreakForce 1 (it breaks), two \
             cubes joined by a Hinge (destroyed by the next round, every other time with the \
             joint destroyed first), the last round's bodies destroyed, one controller \
             destroyed and made anew. One plane per frame in turn casts 16 rays (one \
             RaycastMany), every 10th of its turns also an overlap (BoundsInRadius) and a \
             sphere sweep. Then one flush. Failed calls count as errors.",
        ),
        (
            "cycle",
            "every 12 s: a plane created (100 cubes, a walking floor, a controller on a path, \
             a joint, events subscribed) and destroyed 4 s later; at 6 s a second client \
             (its own thread and connection) connects, builds a manual plane of 50 cubes, \
             steps it 30 times, casts a ray, reads events, writes, and disconnects (every \
             other time destroying its plane first, otherwise leaving it to the daemon).",
        ),
        (
            "memory",
            "daemon VmRSS, RssAnon, RssShmem, threads and open files (/proc/PID), and the \
             size and page-backed bytes of the domain's /dev/shm files, sampled at 5 s and \
             11 s of each cycle (no passing plane or visiting client then: samples compare \
             like with like). The window starts with the first sample after the warm-up \
             (8 min or a quarter of the run, whichever is longer, at most half): rise = the \
             window's largest value - its first; slope = least-squares fit over the window, \
             per minute, and carried over 60 min; threads and open files settle to the least \
             value of the window's last minute.",
        ),
        (
            "ticks",
            "each long-lived plane's tick counter (PlaneInfo.tick) at the start and end of \
             the window over the window's wall time.",
        ),
    ])
}

fn goals(r: &SoakReport, window_samples: usize) -> Vec<Goal> {
    let min_rate = r.ticks_per_s.iter().copied().fold(f64::INFINITY, f64::min);
    let judged = window_samples >= 2;
    let c = &r.counts;
    let mib_signed = |b: f64| format!("{:+.2} MiB", b / (1024.0 * 1024.0));
    vec![
        Goal::new(
            "daemon RSS after the warm-up stays within 1 MiB of the warm-up's end (max - start)",
            format!(
                "{} MiB at {:.0} s, max {} MiB: {} ({} samples)",
                mib(r.rss.start),
                r.warmup_s,
                mib(r.rss.max),
                mib_signed(r.rss.rise),
                window_samples
            ),
            Some(judged && r.rss.rise <= FLAT_BYTES),
        ),
        Goal::new(
            "daemon RSS slope (least squares over the window) carried over 1 h ≤ 1 MiB",
            format!(
                "{:+.1} KiB/min → {} per hour (RssAnon {:+.1} KiB/min)",
                r.rss.slope_per_min / 1024.0,
                mib_signed(r.rss.projected_per_hour),
                r.rss_anon.slope_per_min / 1024.0
            ),
            Some(judged && r.rss.projected_per_hour <= FLAT_BYTES),
        ),
        Goal::new(
            "shared memory of the domain within 1 MiB of the warm-up's end (size and backed)",
            format!(
                "size {} MiB, max {}; backed {} MiB, max {}",
                mib(r.shm.start),
                mib_signed(r.shm.rise),
                mib(r.shm_backed.start),
                mib_signed(r.shm_backed.rise)
            ),
            Some(judged && r.shm.rise <= FLAT_BYTES && r.shm_backed.rise <= FLAT_BYTES),
        ),
        Goal::new(
            "daemon threads and open files do not grow after the warm-up",
            format!(
                "threads {:.0} → {:.0} (max {:.0}), open files {:.0} → {:.0} (max {:.0})",
                r.threads.start,
                r.threads.settled,
                r.threads.max,
                r.fds.start,
                r.fds.settled,
                r.fds.max
            ),
            // Growth is a count that rises and stays: the last minute's least value against
            // the warm-up's end (a sample can catch a visiting client's files mid-exit).
            Some(judged && r.threads.settled <= r.threads.start && r.fds.settled <= r.fds.start),
        ),
        Goal::new(
            format!(
                "every long-lived plane ticks at ≥ {:.0} % of {TICK_RATE} Hz",
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
            "every part of the load ran, without an error",
            format!(
                "{} frames: {} writes, {} cubes replaced, {} rays, {} overlaps, {} sweeps, {} \
                 Touched started / {} ended ({} lost), {} paths finished, {} controllers \
                 replaced, {} joints made / {} broke / {} destroyed, {} planes and {} clients \
                 came and went; {} errors{}",
                c.frames,
                c.writes(),
                c.bodies_replaced,
                c.rays,
                c.overlaps,
                c.sweeps,
                c.contacts_started,
                c.contacts_ended,
                c.events_lost,
                c.paths_finished,
                c.controllers_replaced,
                c.joints_made,
                c.joints_broken,
                c.joints_destroyed,
                c.planes_cycled,
                c.clients_cycled,
                c.errors,
                c.first_error
                    .as_ref()
                    .map_or(String::new(), |e| format!(" (first: {e})"))
            ),
            Some(
                c.errors == 0
                    && [
                        c.frames,
                        c.bodies_replaced,
                        c.rays,
                        c.overlaps,
                        c.contacts_started,
                        c.paths_finished,
                        c.joints_broken,
                        c.planes_cycled,
                        c.clients_cycled,
                    ]
                    .iter()
                    .all(|&n| n > 0),
            ),
        ),
    ]
}

fn render(r: &SoakReport) -> String {
    let mut md = String::new();
    let _ = writeln!(
        md,
        "# physics-bench soak\n\n{} planes × {} cubes at {TICK_RATE} Hz under a game's load, \
         {:.1} min: {:.0} s warm-up, then a {:.0} s window.\n",
        r.planes, r.bodies_per_plane, r.minutes, r.warmup_s, r.window_s
    );
    md.push_str("## Drift over the window\n\n");
    let mut t = report::Table::new(&[
        "",
        "warm-up end",
        "max",
        "end",
        "rise (max - start)",
        "slope per min",
        "slope × 60 min",
    ]);
    let k = 1024.0;
    for (name, d, unit) in [
        ("daemon RSS MiB", &r.rss, k * k),
        ("daemon RssAnon MiB", &r.rss_anon, k * k),
        ("daemon RssShmem MiB", &r.rss_shmem, k * k),
        ("shm size MiB", &r.shm, k * k),
        ("shm backed MiB", &r.shm_backed, k * k),
        ("daemon threads", &r.threads, 1.0),
        ("daemon open files", &r.fds, 1.0),
    ] {
        t.row(&[
            name.into(),
            format!("{:.3}", d.start / unit),
            format!("{:.3}", d.max / unit),
            format!("{:.3}", d.end / unit),
            format!("{:+.3}", d.rise / unit),
            format!("{:+.4}", d.slope_per_min / unit),
            format!("{:+.3}", d.projected_per_hour / unit),
        ]);
    }
    md.push_str(&t.finish());
    let _ = writeln!(
        md,
        "\nStep time of the newest tick: {} µs.",
        r.step_us
            .iter()
            .map(|s| num(Some(*s as f64)))
            .collect::<Vec<_>>()
            .join(", ")
    );
    md.push_str("\n## Samples\n\n");
    let mut t = report::Table::new(&[
        "t s",
        "RSS MiB",
        "RssAnon MiB",
        "RssShmem MiB",
        "shm MiB",
        "shm backed MiB",
        "threads",
        "files",
    ]);
    // At most ~40 rows: every n-th sample, the last always.
    let every = r.samples.len().div_ceil(40).max(1);
    for (i, s) in r.samples.iter().enumerate() {
        if i % every != 0 && i + 1 != r.samples.len() {
            continue;
        }
        t.row(&[
            format!("{:.0}", s.t_s),
            mib(s.rss_bytes as f64),
            mib(s.rss_anon_bytes as f64),
            mib(s.rss_shmem_bytes as f64),
            mib(s.shm_bytes as f64),
            mib(s.shm_backed_bytes as f64),
            s.threads.to_string(),
            s.fds.to_string(),
        ]);
    }
    md.push_str(&t.finish());
    md.push_str("\n## Method\n\n");
    for (name, text) in &r.method {
        let _ = writeln!(md, "- **{name}**: {text}");
    }
    md
}

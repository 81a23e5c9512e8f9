//! Many planes in one daemon: 100 planes of 1,000 bodies (90 % a settled pile, 10 % awake
//! cubes flying without gravity) ticking at 60 Hz from one client, against one plane of
//! 100,000 bodies of the same mix. Two figures:
//!
//! - **lateness** of each plane's ticks: a plane keeps its cadence (tick `k` is due at its
//!   start plus `k` periods), and its tick header carries the end of each step
//!   (`tick_end_ns`, CLOCK_MONOTONIC). For every tick seen, `tick_end_ns − k·period` is the
//!   tick's phase; its lateness is that phase minus the plane's earliest phase (the best
//!   tick: due time plus the shortest step). Ticks are sampled every 20 ms (every tick's
//!   header carries its own time, so sampled ticks measure the same distribution); a plane
//!   that fell behind and restarted its schedule shows as late from then on.
//! - **CPU per body-tick**: the daemon's user + system CPU time over the window divided by
//!   the bodies times the ticks all planes made in it.

use std::time::{Duration, Instant};

use client_sdk::{Client, PlaneOptions, PlaneProp};

use crate::daemon::DaemonProcess;
use crate::error::{BenchError, BenchResult};
use crate::frame::{plane_props, world, SETTLE_TICKS};
use crate::procfs::cpu_time;
use crate::scene::DT;
use crate::stats::{spread, Spread};

/// Ticks per second of every plane.
const RATE: f32 = 60.0;
/// Share of each plane's bodies in the settled pile.
const SETTLED: f64 = 0.9;
/// How often the planes' newest headers are read.
const SAMPLE_EVERY: Duration = Duration::from_millis(20);

/// One configuration's figures.
#[derive(Debug, Clone, serde::Serialize)]
pub struct PlanesRun {
    pub planes: usize,
    pub bodies_per_plane: usize,
    /// Lateness of the sampled ticks, all planes together, ms.
    pub lateness_ms: Spread,
    /// Ticks sampled.
    pub sampled_ticks: usize,
    /// Mean ticks per second of one plane over the window (60 when every tick came).
    pub ticks_per_s: f64,
    /// Daemon CPU per body and tick, ns.
    pub cpu_ns_per_body_tick: f64,
    /// Daemon CPU over the window, percent of one core.
    pub cpu_percent: f64,
    /// Threads of the daemon process during the window.
    pub daemon_threads: usize,
}

/// [`PlanesRun`] of many small planes and of one plane of all their bodies.
#[derive(Debug, Clone, serde::Serialize)]
pub struct ManyPlanes {
    pub many: PlanesRun,
    pub one: PlanesRun,
    /// Many planes' CPU per body-tick over the one plane's.
    pub cpu_ratio: f64,
    pub seconds: f64,
}

/// Threads of process `pid` (/proc/PID/status).
fn threads(pid: u32) -> usize {
    std::fs::read_to_string(format!("/proc/{pid}/status"))
        .ok()
        .and_then(|s| {
            s.lines()
                .find_map(|l| l.strip_prefix("Threads:"))
                .and_then(|v| v.trim().parse().ok())
        })
        .unwrap_or(0)
}

fn measure(planes: usize, bodies: usize, seconds: f64) -> BenchResult<PlanesRun> {
    let daemon = DaemonProcess::start_with(
        "planes",
        &[
            "--max-planes-per-client".to_string(),
            (planes + 8).to_string(),
        ],
        None,
    )?;
    let client: Client = daemon.connect()?;
    let mut options = PlaneOptions::manual();
    for p in plane_props() {
        options = options.with(p);
    }
    let settled = (bodies as f64 * SETTLED).round() as usize;
    let mut all = Vec::with_capacity(planes);
    for _ in 0..planes {
        let plane = client.create_plane(&options)?;
        world(&mut &plane, settled, bodies - settled)?;
        client.flush()?;
        for _ in 0..SETTLE_TICKS {
            plane.step(DT)?;
        }
        all.push(plane);
    }
    for plane in &all {
        plane.set_now(PlaneProp::TickRate(RATE))?;
    }
    std::thread::sleep(Duration::from_millis(500));
    let period_ns = 1e9 / RATE as f64;
    let ticks_now = |all: &[client_sdk::Plane]| -> BenchResult<Vec<u64>> {
        all.iter().map(|p| Ok(p.snapshot()?.tick())).collect()
    };
    let ticks0 = ticks_now(&all)?;
    let cpu0 = cpu_time(daemon.pid())?;
    let started = Instant::now();
    // Per plane: the phases of the ticks seen (tick, phase ns).
    let mut seen: Vec<Vec<(u64, f64)>> = vec![Vec::new(); planes];
    let mut daemon_threads = 0;
    while started.elapsed().as_secs_f64() < seconds {
        for (plane, seen) in all.iter().zip(&mut seen) {
            let snapshot = plane.snapshot()?;
            let h = snapshot.header();
            if seen.last().is_none_or(|&(t, _)| t != h.tick) {
                seen.push((h.tick, h.tick_end_ns as f64 - h.tick as f64 * period_ns));
            }
        }
        daemon_threads = daemon_threads.max(threads(daemon.pid()));
        std::thread::sleep(SAMPLE_EVERY);
    }
    let elapsed = started.elapsed().as_secs_f64();
    let cpu = cpu_time(daemon.pid())?.saturating_sub(cpu0).as_secs_f64();
    let ticks1 = ticks_now(&all)?;
    let ticks: u64 = ticks1.iter().zip(&ticks0).map(|(b, a)| b - a).sum();
    let mut lateness = Vec::new();
    for seen in &seen {
        let best = seen.iter().map(|s| s.1).fold(f64::INFINITY, f64::min);
        lateness.extend(seen.iter().map(|s| (s.1 - best) / 1e6));
    }
    let none = || BenchError::Failed("no tick was seen".into());
    Ok(PlanesRun {
        planes,
        bodies_per_plane: bodies,
        lateness_ms: spread(&lateness).ok_or_else(none)?,
        sampled_ticks: lateness.len(),
        ticks_per_s: ticks as f64 / planes as f64 / elapsed,
        cpu_ns_per_body_tick: cpu * 1e9 / (ticks.max(1) as f64 * bodies as f64),
        cpu_percent: cpu / elapsed * 100.0,
        daemon_threads,
    })
}

/// `planes` planes of `bodies` each, then one plane of `planes × bodies`, each for
/// `seconds` of ticking.
pub fn run(planes: usize, bodies: usize, seconds: f64) -> BenchResult<ManyPlanes> {
    let many = measure(planes, bodies, seconds)?;
    let one = measure(1, planes * bodies, seconds)?;
    Ok(ManyPlanes {
        cpu_ratio: many.cpu_ns_per_body_tick / one.cpu_ns_per_body_tick,
        many,
        one,
        seconds,
    })
}

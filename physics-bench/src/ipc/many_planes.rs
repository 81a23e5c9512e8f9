//! Many planes in one daemon: 100 planes of 1,000 bodies (90 % a settled pile, 10 % awake
//! cubes flying without gravity) ticking at 60 Hz from one client, against one plane of
//! 100,000 bodies of the same mix in a daemon of its own; and 10 planes of 1,000 bodies on
//! time. The two daemons of the comparison hold their planes throughout and tick in
//! interleaved blocks (ABBA: one daemon's planes at 60 Hz, the other's paused), so slow
//! stretches of the machine fall on both. Figures:
//!
//! - **CPU per body-tick** ([`Estimator::CpuMedianOfBlocks`]): the daemon's CPU time over a
//!   block (every thread's schedstat ns) divided by the bodies times the ticks all planes
//!   made in it; the median of each side's blocks. The client only watches the planes
//!   (it reads their headers), so its own CPU is left out.
//! - **cores needed** for 100 planes × 1,000 bodies at 60 Hz: that cost × 100 × 1,000 × 60.
//! - **on time** ([`Estimator::RateSlowestPlane`]): 10 planes × 1,000 bodies at 60 Hz in a
//!   daemon of their own; per block, each plane's ticks (its header's tick counter at the
//!   block's end minus at its start) over the block's wall time, the slowest plane's rate;
//!   the median of the blocks.
//! - **lateness** of each plane's ticks (reported, no goal): a plane keeps its cadence (tick
//!   `k` is due at its start plus `k` periods), and its tick header carries the end of each
//!   step (`tick_end_ns`, CLOCK_MONOTONIC). For every tick seen, `tick_end_ns − k·period` is
//!   the tick's phase; its lateness is that phase minus the plane's earliest phase in the
//!   same block (the best tick: due time plus the shortest step). Ticks are sampled every
//!   20 ms (every tick's header carries its own time, so sampled ticks measure the same
//!   distribution); a plane that fell behind and restarted its schedule shows as late from
//!   then on.

use std::time::{Duration, Instant};

use client_sdk::{Client, PlaneOptions, PlaneProp};

use crate::daemon::DaemonProcess;
use crate::error::{BenchError, BenchResult};
use crate::estimator::{self, Block, CpuClock, Estimator, Order, Pair};
use crate::frame::{plane_props, world, SETTLE_TICKS};
use crate::scene::DT;
use crate::stats::{median, spread, Spread};

/// Ticks per second of every plane.
pub const RATE: f32 = 60.0;
/// Share of each plane's bodies in the settled pile.
const SETTLED: f64 = 0.9;
/// How often the planes' newest headers are read.
const SAMPLE_EVERY: Duration = Duration::from_millis(20);
/// Blocks of each side.
const BLOCKS: usize = 5;
/// Wall time after the planes start ticking before a block is timed.
const WARM_UP: Duration = Duration::from_millis(400);
/// Planes of the on-time goal.
pub const ON_TIME_PLANES: usize = 10;
/// Share of [`RATE`] a plane must tick at to be on time.
pub const ON_TIME_SHARE: f64 = 0.95;

/// One configuration's figures.
#[derive(Debug, Clone, serde::Serialize)]
pub struct PlanesRun {
    pub planes: usize,
    pub bodies_per_plane: usize,
    /// Lateness of the sampled ticks, all planes and blocks together, ms.
    pub lateness_ms: Spread,
    /// Ticks sampled.
    pub sampled_ticks: usize,
    /// Ticks per second of one plane, mean over planes, median of the blocks (60 when every
    /// tick came).
    pub ticks_per_s: f64,
    /// The slowest plane's ticks per second, median of the blocks.
    pub slowest_ticks_per_s: f64,
    /// Daemon CPU per body and tick, ns, median of the blocks ([`Estimator::CpuMedianOfBlocks`]).
    pub cpu_ns_per_body_tick: f64,
    /// The same, minimum of the blocks.
    pub cpu_ns_per_body_tick_min: f64,
    /// Daemon CPU, percent of one core, median of the blocks.
    pub cpu_percent: f64,
    /// Threads of the daemon process during the blocks.
    pub daemon_threads: usize,
    pub blocks: usize,
    pub block_s: f64,
}

/// [`PlanesRun`] of many small planes and of one plane of all their bodies, and the on-time
/// run.
#[derive(Debug, Clone, serde::Serialize)]
pub struct ManyPlanes {
    /// What judges `cpu_ratio`.
    pub estimator: Estimator,
    pub many: PlanesRun,
    pub one: PlanesRun,
    /// Many planes' CPU per body-tick over the one plane's (medians of blocks).
    pub cpu_ratio: f64,
    /// The same of the blocks' minima.
    pub cpu_ratio_min: f64,
    /// Cores 100 planes × 1,000 bodies at 60 Hz need at the many planes' measured cost:
    /// `cpu_ns_per_body_tick × planes × bodies × 60 / 1e9`.
    pub cores_needed: f64,
    /// The blocks, per 1,000 body-ticks (µs, i.e. ns per body-tick: wall, and the daemon's
    /// CPU): A = many planes, B = one plane.
    pub blocks: Pair,
    /// 10 planes × 1,000 bodies at 60 Hz, judged by [`Estimator::RateSlowestPlane`].
    pub on_time: PlanesRun,
    pub on_time_estimator: Estimator,
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

/// A daemon holding `planes` settled planes of `bodies` bodies, paused (TickRate 0).
struct Fleet {
    daemon: DaemonProcess,
    _client: Client,
    planes: Vec<client_sdk::Plane>,
    bodies: usize,
    /// Per block: lateness (ms) of the ticks seen, each plane's ticks per second, the
    /// daemon's CPU (s) and the block's wall (s).
    lateness: Vec<f64>,
    mean_rates: Vec<f64>,
    slowest_rates: Vec<f64>,
    cpu_percent: Vec<f64>,
    daemon_threads: usize,
}

impl Fleet {
    fn new(planes: usize, bodies: usize) -> BenchResult<Fleet> {
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
        Ok(Fleet {
            daemon,
            _client: client,
            planes: all,
            bodies,
            lateness: Vec::new(),
            mean_rates: Vec::new(),
            slowest_rates: Vec::new(),
            cpu_percent: Vec::new(),
            daemon_threads: 0,
        })
    }

    fn set_rate(&self, rate: f32) -> BenchResult<()> {
        for plane in &self.planes {
            plane.set_now(PlaneProp::TickRate(rate))?;
        }
        Ok(())
    }

    fn ticks_now(&self) -> BenchResult<Vec<u64>> {
        self.planes
            .iter()
            .map(|p| Ok(p.snapshot()?.tick()))
            .collect()
    }

    /// One block: the planes tick at [`RATE`] for `seconds` (after [`WARM_UP`]), then
    /// pause. Wall and daemon CPU are per body-tick, in ns.
    fn block(&mut self, seconds: f64) -> BenchResult<Block> {
        self.set_rate(RATE)?;
        std::thread::sleep(WARM_UP);
        let clock = CpuClock::daemons_only(&[self.daemon.pid()]);
        let period_ns = 1e9 / RATE as f64;
        let ticks0 = self.ticks_now()?;
        let cpu0 = clock.read()?;
        let started = Instant::now();
        // Per plane: the phases of the ticks seen (tick, phase ns).
        let mut seen: Vec<Vec<(u64, f64)>> = vec![Vec::new(); self.planes.len()];
        while started.elapsed().as_secs_f64() < seconds {
            for (plane, seen) in self.planes.iter().zip(&mut seen) {
                let snapshot = plane.snapshot()?;
                let h = snapshot.header();
                if seen.last().is_none_or(|&(t, _)| t != h.tick) {
                    seen.push((h.tick, h.tick_end_ns as f64 - h.tick as f64 * period_ns));
                }
            }
            self.daemon_threads = self.daemon_threads.max(threads(self.daemon.pid()));
            std::thread::sleep(SAMPLE_EVERY);
        }
        let cpu_ns = clock.read()?.used_since(&cpu0) as f64;
        let ticks1 = self.ticks_now()?;
        let elapsed = started.elapsed().as_secs_f64();
        self.set_rate(0.0)?;
        let made: Vec<u64> = ticks1
            .iter()
            .zip(&ticks0)
            .map(|(b, a)| b.saturating_sub(*a))
            .collect();
        let ticks: u64 = made.iter().sum();
        let rates: Vec<f64> = made.iter().map(|&t| t as f64 / elapsed).collect();
        self.mean_rates
            .push(rates.iter().sum::<f64>() / rates.len().max(1) as f64);
        self.slowest_rates
            .push(rates.iter().copied().fold(f64::INFINITY, f64::min));
        self.cpu_percent.push(cpu_ns / 1e9 / elapsed * 100.0);
        for seen in &seen {
            let best = seen.iter().map(|s| s.1).fold(f64::INFINITY, f64::min);
            self.lateness
                .extend(seen.iter().map(|s| (s.1 - best) / 1e6));
        }
        if ticks == 0 {
            return Err(BenchError::Failed(format!(
                "no plane of {} ticked in {elapsed:.1} s",
                self.planes.len()
            )));
        }
        let body_ticks = ticks as f64 * self.bodies as f64;
        Ok(Block {
            wall_us: elapsed * 1e9 / body_ticks,
            cpu_us: cpu_ns / body_ticks,
        })
    }

    /// The figures of the blocks run so far (`side` holds their wall and CPU).
    fn run(&self, side: &estimator::Side, block_s: f64) -> BenchResult<PlanesRun> {
        let none = || BenchError::Failed("no tick was seen".into());
        let med = |v: &[f64]| median(v).unwrap_or(f64::NAN);
        Ok(PlanesRun {
            planes: self.planes.len(),
            bodies_per_plane: self.bodies,
            lateness_ms: spread(&self.lateness).ok_or_else(none)?,
            sampled_ticks: self.lateness.len(),
            ticks_per_s: med(&self.mean_rates),
            slowest_ticks_per_s: med(&self.slowest_rates),
            cpu_ns_per_body_tick: side.cpu_us.median,
            cpu_ns_per_body_tick_min: side.cpu_us.min,
            cpu_percent: med(&self.cpu_percent),
            daemon_threads: self.daemon_threads,
            blocks: side.blocks.len(),
            block_s,
        })
    }
}

/// `planes` planes of `bodies` each against one plane of `planes × bodies`, blocks ABBA,
/// `seconds` of ticking per side; then [`ON_TIME_PLANES`] planes of `bodies`.
pub fn run(planes: usize, bodies: usize, seconds: f64) -> BenchResult<ManyPlanes> {
    let block_s = seconds / BLOCKS as f64;
    let (mut many, mut one) = (Fleet::new(planes, bodies)?, Fleet::new(1, planes * bodies)?);
    let pair = estimator::interleaved(
        BLOCKS,
        Order::Abba,
        || many.block(block_s),
        || one.block(block_s),
    )?;
    let (many_run, one_run) = (many.run(&pair.a, block_s)?, one.run(&pair.b, block_s)?);
    drop((many, one));
    let on_time = {
        let mut fleet = Fleet::new(ON_TIME_PLANES, bodies)?;
        let mut blocks = Vec::with_capacity(BLOCKS);
        for _ in 0..BLOCKS {
            blocks.push(fleet.block(block_s)?);
        }
        let side = estimator::Side::of(blocks)
            .ok_or_else(|| BenchError::Failed("the on-time run measured no block".into()))?;
        fleet.run(&side, block_s)?
    };
    let r = pair.ratios();
    Ok(ManyPlanes {
        estimator: Estimator::CpuMedianOfBlocks,
        cores_needed: many_run.cpu_ns_per_body_tick * (planes * bodies) as f64 * RATE as f64 / 1e9,
        many: many_run,
        one: one_run,
        cpu_ratio: r.cpu_median,
        cpu_ratio_min: r.cpu_min,
        blocks: pair,
        on_time,
        on_time_estimator: Estimator::RateSlowestPlane,
        seconds,
    })
}

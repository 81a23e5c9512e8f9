//! Planes side by side in one daemon: a small plane's round trips alone and next to a
//! 10,000-body plane ticking at 60 Hz (head-of-line blocking), and the aggregate ticks per
//! second of two 10,000-body planes stepped at once from two clients against one. Both in
//! interleaved blocks (see [`crate::estimator`]).

use std::sync::mpsc;
use std::time::{Duration, Instant};

use client_sdk::{Client, PlaneOptions, PlaneProp, Pose, Shape};

use crate::daemon::DaemonProcess;
use crate::error::{BenchError, BenchResult};
use crate::estimator::{self, CpuClock, Estimator, Order, Pair, Ratios};
use crate::scene::{Kind, Scene, DT};
use crate::stats::{median, percentile, spread, Spread};

/// Blocks of each side of the head-of-line and multi-plane figures.
const BLOCKS: usize = 8;

#[derive(Debug, Clone, serde::Serialize)]
pub struct HeadOfLine {
    /// [`Estimator::WallP99MinOfBlocks`]: `p99_ratio` is the minimum over blocks of the
    /// blocks' p99 beside the busy plane over the same of the blocks alone.
    pub estimator: Estimator,
    /// The busy plane: free-flying bodies (every one awake each tick).
    pub busy_bodies: usize,
    pub busy_tick_rate: f32,
    /// `Step` round trips of a one-ball manual plane, µs, all blocks of a side together.
    pub alone_us: Spread,
    pub beside_busy_us: Spread,
    /// beside ÷ alone at p99, the minima of the blocks' p99s (the judged figure).
    pub p99_ratio: f64,
    /// The same of the medians of the blocks' p99s.
    pub p99_ratio_median: f64,
    /// Each block's p99, µs.
    pub alone_p99_blocks_us: Vec<f64>,
    pub beside_p99_blocks_us: Vec<f64>,
    /// Ticks the busy plane made while the small plane was measured beside it (it kept its
    /// rate).
    pub busy_ticks_per_s: f64,
    /// Round trips per side.
    pub round_trips: usize,
    /// The blocks, per round trip: A = beside the busy plane, B = alone (wall; CPU of both
    /// processes, the busy plane's ticks included).
    pub blocks: Pair,
}

#[derive(Debug, Clone, serde::Serialize)]
pub struct MultiPlane {
    /// [`Estimator::WallMinOfBlocks`] on the wall per tick of all planes together.
    pub estimator: Estimator,
    pub bodies: usize,
    /// Ticks per second of all planes together, from the least disturbed block of each side
    /// (1 / its wall per tick).
    pub one_plane_ticks_per_s: f64,
    pub two_planes_ticks_per_s: f64,
    /// two ÷ one (the judged figure).
    pub ratio: f64,
    /// The same from the medians of the blocks.
    pub ratio_median: f64,
    /// CPU of both processes per tick, medians of blocks, µs: what a tick costs with one
    /// plane and with two stepping at once.
    pub one_plane_cpu_us: f64,
    pub two_planes_cpu_us: f64,
    /// One over two under every block estimator (per tick: > 1 when two planes tick faster).
    pub ratios: Ratios,
    /// The blocks, per tick of all planes together: A = one plane, B = two.
    pub blocks: Pair,
    pub seconds: f64,
}

fn small_plane(client: &Client) -> BenchResult<client_sdk::Plane> {
    let plane = client.create_plane(&PlaneOptions::manual())?;
    plane.add(
        Shape::Sphere { radius: 0.5 },
        Pose::at([0.0, 1e6, 0.0]),
        &[],
    )?;
    Ok(plane)
}

fn round_trips(plane: &client_sdk::Plane, n: usize) -> BenchResult<Vec<f64>> {
    let mut out = Vec::with_capacity(n);
    for _ in 0..n {
        let t = Instant::now();
        plane.step(DT)?;
        out.push(t.elapsed().as_secs_f64() * 1e6);
    }
    Ok(out)
}

/// The small plane's round trips in blocks, beside the busy plane ticking at 60 Hz (A) and
/// with it paused (B), ABBA; `n` round trips per side.
pub fn head_of_line(busy_bodies: usize, n: usize) -> BenchResult<HeadOfLine> {
    let daemon = DaemonProcess::start("hol")?;
    let client = daemon.connect()?;
    let small = small_plane(&client)?;
    round_trips(&small, n / 10)?; // warm-up
    let owner = daemon.connect()?;
    let scene = Scene {
        kind: Kind::Free,
        bodies: busy_bodies,
    };
    let (busy, _) = scene.build_remote(&owner, 1)?;
    let rate = 60.0;
    let per_block = n.div_ceil(BLOCKS).max(1);
    let clock = CpuClock::new(&[daemon.pid()]);
    let (mut alone, mut beside) = (Vec::new(), Vec::new());
    let (mut alone_p99, mut beside_p99) = (Vec::new(), Vec::new());
    let (mut busy_ticks, mut busy_s) = (0u64, 0.0);
    let blocks = estimator::interleaved(
        BLOCKS,
        Order::Abba,
        || {
            busy.set_now(PlaneProp::TickRate(rate))?;
            // Let the busy plane's timer start.
            std::thread::sleep(Duration::from_millis(300));
            let tick0 = busy.snapshot()?.tick();
            let started = Instant::now();
            let mut times = Vec::new();
            let block = estimator::timed(&clock, || {
                times = round_trips(&small, per_block)?;
                Ok(per_block)
            })?;
            busy_ticks += busy.snapshot()?.tick().saturating_sub(tick0);
            busy_s += started.elapsed().as_secs_f64();
            busy.set_now(PlaneProp::TickRate(0.0))?;
            beside_p99.push(percentile(&times, 0.99).unwrap_or(f64::NAN));
            beside.extend(times);
            Ok(block)
        },
        || {
            let mut times = Vec::new();
            let block = estimator::timed(&clock, || {
                times = round_trips(&small, per_block)?;
                Ok(per_block)
            })?;
            alone_p99.push(percentile(&times, 0.99).unwrap_or(f64::NAN));
            alone.extend(times);
            Ok(block)
        },
    )?;
    let none = || BenchError::Failed("no round trip was measured".into());
    let (alone_s, beside_s) = (
        spread(&alone).ok_or_else(none)?,
        spread(&beside).ok_or_else(none)?,
    );
    let min = |v: &[f64]| v.iter().copied().fold(f64::INFINITY, f64::min);
    let med = |v: &[f64]| median(v).unwrap_or(f64::NAN);
    Ok(HeadOfLine {
        estimator: Estimator::WallP99MinOfBlocks,
        busy_bodies,
        busy_tick_rate: rate,
        p99_ratio: min(&beside_p99) / min(&alone_p99),
        p99_ratio_median: med(&beside_p99) / med(&alone_p99),
        alone_us: alone_s,
        beside_busy_us: beside_s,
        alone_p99_blocks_us: alone_p99,
        beside_p99_blocks_us: beside_p99,
        busy_ticks_per_s: busy_ticks as f64 / busy_s.max(f64::MIN_POSITIVE),
        round_trips: per_block * BLOCKS,
        blocks,
    })
}

/// A client thread stepping a plane of its own on request: it gets a block's length in
/// seconds and answers with the ticks it made.
struct Stepper {
    go: mpsc::Sender<f64>,
    done: mpsc::Receiver<BenchResult<u64>>,
}

/// Builds a plane of `bodies` free-flying bodies from a client of its own, then steps it
/// back to back for each block asked on `go` until `go` closes.
fn stepper(
    domain: &str,
    bodies: usize,
    go: mpsc::Receiver<f64>,
    done: mpsc::Sender<BenchResult<u64>>,
) {
    // The client lives as long as its plane.
    let built = (|| -> BenchResult<(Client, client_sdk::Plane)> {
        let client = Client::connect(domain)?;
        let scene = Scene {
            kind: Kind::Free,
            bodies,
        };
        let (plane, _) = scene.build_remote(&client, 1)?;
        for _ in 0..5 {
            plane.step(DT)?;
        }
        Ok((client, plane))
    })();
    let (_client, plane) = match built {
        Ok(p) => p,
        Err(e) => {
            let _ = done.send(Err(e));
            return;
        }
    };
    if done.send(Ok(0)).is_err() {
        return;
    }
    while let Ok(seconds) = go.recv() {
        let started = Instant::now();
        let mut ticks = 0u64;
        let result = loop {
            if started.elapsed().as_secs_f64() >= seconds {
                break Ok(ticks);
            }
            if let Err(e) = plane.step(DT) {
                break Err(e.into());
            }
            ticks += 1;
        };
        if done.send(result).is_err() {
            return;
        }
    }
}

/// Two planes of `bodies` free-flying bodies in one daemon, each stepped back to back by a
/// client thread of its own: blocks of one plane stepping alone (A) and of both at once (B),
/// ABBA, `seconds` per side.
pub fn multi_plane(bodies: usize, seconds: f64) -> BenchResult<MultiPlane> {
    let daemon = DaemonProcess::start("planes")?;
    let domain = daemon.domain.clone();
    let clock = CpuClock::new(&[daemon.pid()]);
    let block_s = seconds / BLOCKS as f64;
    let blocks = std::thread::scope(|s| -> BenchResult<Pair> {
        let mut steppers = Vec::new();
        for _ in 0..2 {
            let (go_tx, go_rx) = mpsc::channel();
            let (done_tx, done_rx) = mpsc::channel();
            let domain = domain.as_str();
            s.spawn(move || stepper(domain, bodies, go_rx, done_tx));
            steppers.push(Stepper {
                go: go_tx,
                done: done_rx,
            });
        }
        let gone = || BenchError::Failed("a stepping thread ended".into());
        for st in &steppers {
            st.done.recv().map_err(|_| gone())??;
        }
        let run = |count: usize| {
            estimator::timed(&clock, || {
                let active = &steppers[..count];
                for st in active {
                    st.go.send(block_s).map_err(|_| gone())?;
                }
                let mut ticks = 0u64;
                for st in active {
                    ticks += st.done.recv().map_err(|_| gone())??;
                }
                Ok(ticks as usize)
            })
        };
        estimator::interleaved(BLOCKS, Order::Abba, || run(1), || run(2))
        // Dropping the senders ends the threads.
    })?;
    let ratios = blocks.ratios();
    Ok(MultiPlane {
        estimator: Estimator::WallMinOfBlocks,
        bodies,
        one_plane_ticks_per_s: 1e6 / blocks.a.wall_us.min,
        two_planes_ticks_per_s: 1e6 / blocks.b.wall_us.min,
        ratio: ratios.wall_min,
        ratio_median: ratios.wall_median,
        one_plane_cpu_us: blocks.a.cpu_us.median,
        two_planes_cpu_us: blocks.b.cpu_us.median,
        ratios,
        blocks,
        seconds,
    })
}

//! One scene, side by side: the daemon plane (stepped and read by this process as a client)
//! and the same world stepped in process. Measures the overhead ratio, delivery (zero-copy
//! and socket + serde), the daemon's publish copy and its memory.

use std::time::{Duration, Instant};

use client_sdk::{PlaneProp, Snapshot};
use iceoryx2::prelude::*;
use physics_daemon::publish::PlaneOutput;
use physics_scenes::LocalPlane;
use shm_layout::{monotonic_ns, names};

use super::plan::Plan;
use super::socket;
use crate::daemon::{unique_domain, DaemonProcess};
use crate::error::{BenchError, BenchResult};
use crate::estimator::{self, CpuClock, Estimator, Order, Pair, Ratios};
use crate::procfs;
use crate::progress::Progress;
use crate::scene::{asleep_fraction, touch, Kind, Scene, DT};
use crate::stats::median;

#[derive(Debug, Clone, serde::Serialize)]
pub struct Overhead {
    /// The judged figure: daemon over in process under [`Overhead::estimator`].
    pub overhead_ratio: f64,
    /// What judges `overhead_ratio`.
    pub estimator: Estimator,
    /// Wall µs per tick, the minimum of each side's blocks.
    pub daemon_tick_us: f64,
    pub in_process_tick_us: f64,
    /// CPU µs per tick of both processes (this one and the daemon), the median of each
    /// side's blocks (the in-process side's daemon is idle).
    pub daemon_cpu_us: f64,
    pub in_process_cpu_us: f64,
    /// Daemon over in process under every block estimator.
    pub ratios: Ratios,
    /// The blocks: A = the daemon plane, B = in process.
    pub blocks: Pair,
    pub ticks_per_repeat: usize,
    pub repeats: usize,
    /// Share of dynamic bodies asleep when measuring.
    pub asleep_fraction: f64,
}

#[derive(Debug, Clone, serde::Serialize)]
pub struct Delivery {
    /// [`Estimator::WallMedianOfSamples`]: medians of the per-tick latencies.
    pub estimator: Estimator,
    /// Tick end → this process holds the sample with every pose, through shared memory.
    pub zero_copy_us: f64,
    /// Tick end → another thread holds every pose decoded, postcard over a Unix socket.
    pub socket_serde_us: f64,
    pub speedup: f64,
    /// The daemon's publish (copy of every slot into the loaned sample, send, notify),
    /// timed in process with the daemon's own publish code.
    pub publish_us: f64,
    /// `zero_copy_us - publish_us`: the hand-over itself (notify, wake, read).
    pub handover_us: f64,
    /// The same three with readers that poll instead of sleeping (the zero-copy client
    /// spins on its shared-memory queue, the socket reader on a non-blocking socket): the
    /// data path without the scheduler's wake-up latency.
    pub zero_copy_poll_us: f64,
    pub socket_serde_poll_us: f64,
    pub speedup_poll: f64,
    pub handover_poll_us: f64,
    /// After the hand-over: reading every pose once in place (the consumer's own work,
    /// outside the delivery figures, like the socket reader's use of its decoded Vec).
    pub read_all_us: f64,
    pub ticks: usize,
}

#[derive(Debug, Clone, serde::Serialize)]
pub struct Memory {
    pub bodies: usize,
    pub scene: Kind,
    /// Daemon VmRSS with the scene, and its growth per body over the empty daemon.
    pub rss_bytes: u64,
    pub rss_per_body_bytes: f64,
    /// Size of the domain's shared-memory files (what is mapped), and per body.
    pub shm_bytes: u64,
    pub shm_per_body_bytes: f64,
    /// Pages of those files actually backed by memory, and per body.
    pub shm_backed_bytes: u64,
    pub shm_backed_per_body_bytes: f64,
}

/// Round trips and batches, measured on the plane of one scene.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Requests {
    /// [`Estimator::WallMedianOfSamples`] (and the spread of the round trips).
    pub estimator: Estimator,
    pub round_trip_us: crate::stats::Spread,
    pub round_trips: usize,
    pub batched_writes_per_s: f64,
    pub batch_size: usize,
    pub batches: usize,
}

pub struct SceneOutcome {
    pub overhead: Overhead,
    pub delivery: Delivery,
    pub memory: Memory,
    pub requests: Option<Requests>,
}

pub fn run(
    scene: Scene,
    plan: &Plan,
    with_requests: bool,
    progress: &Progress,
) -> BenchResult<SceneOutcome> {
    let label = format!("{} {}", scene.bodies, scene.kind.name());
    let daemon = DaemonProcess::start(scene.kind.name())?;
    let client = daemon.connect()?;
    let rss_empty = procfs::rss_bytes(daemon.pid())?;
    let shm_empty = procfs::shm_bytes(&daemon.domain)?;

    progress.phase(format!("{label}: building both worlds"));
    let (remote, objects) = scene.build_remote(&client, 1)?;
    let mut local = scene.build_local(1)?;
    progress.done();

    progress.phase(format!(
        "{label}: settling ({} ticks)",
        scene.settle_ticks()
    ));
    for _ in 0..scene.settle_ticks() {
        remote.step(DT)?;
        local.step(DT)?;
    }
    let memory = memory(&daemon, scene, rss_empty, shm_empty)?;
    progress.done();

    progress.phase(format!("{label}: overhead"));
    let overhead = overhead(scene, plan, daemon.pid(), &remote, &mut local)?;
    progress.done();

    progress.phase(format!("{label}: delivery"));
    let delivery = delivery(plan, &client, &remote, &mut local)?;
    progress.done();

    let requests = if with_requests {
        progress.phase(format!("{label}: round trips and batches"));
        Some(requests(plan, &client, &objects)?)
    } else {
        None
    };
    Ok(SceneOutcome {
        overhead,
        delivery,
        memory,
        requests,
    })
}

fn memory(
    daemon: &DaemonProcess,
    scene: Scene,
    rss_empty: u64,
    (shm_empty, backed_empty): (u64, u64),
) -> BenchResult<Memory> {
    let rss = procfs::rss_bytes(daemon.pid())?;
    let (shm, backed) = procfs::shm_bytes(&daemon.domain)?;
    let per_body =
        |after: u64, before: u64| after.saturating_sub(before) as f64 / scene.bodies as f64;
    Ok(Memory {
        bodies: scene.bodies,
        scene: scene.kind,
        rss_bytes: rss,
        rss_per_body_bytes: per_body(rss, rss_empty),
        shm_bytes: shm,
        shm_per_body_bytes: per_body(shm, shm_empty),
        shm_backed_bytes: backed,
        shm_backed_per_body_bytes: per_body(backed, backed_empty),
    })
}

/// Ticks per timed block: enough that a block is well above timer noise.
fn block_ticks(bodies: usize) -> usize {
    (200_000 / bodies.max(1)).clamp(10, 2_000)
}

/// What judges the overhead ratio: see [`overhead`].
pub const OVERHEAD_ESTIMATOR: Estimator = Estimator::WallMinOfBlocks;

/// The daemon plane stepped and read by this process (A) against the same world stepped and
/// read in process (B), in blocks ABBA: wall per tick, and the CPU of both processes per tick.
/// Judged on wall, the minimum of each side's blocks: the daemon side's CPU counts the
/// client's bounded polling for the `Step` reply (up to the plane's step time, see
/// client-sdk's `spin`) on top of the daemon's work, a latency choice and not work of the
/// tick, so CPU is reported beside, not judged.
fn overhead(
    scene: Scene,
    plan: &Plan,
    daemon_pid: u32,
    remote: &client_sdk::Plane,
    local: &mut LocalPlane,
) -> BenchResult<Overhead> {
    let block = block_ticks(scene.bodies);
    let clock = CpuClock::new(&[daemon_pid]);
    let remote_block = || {
        estimator::timed(&clock, || {
            for _ in 0..block {
                remote.step(DT)?;
                let snap = remote.snapshot()?;
                std::hint::black_box(touch(snap.bodies()));
            }
            Ok(block)
        })
    };
    let local_block = |local: &mut LocalPlane| {
        estimator::timed(&clock, || {
            for _ in 0..block {
                local.step(DT)?;
                // An in-process game reads every pose straight from the world.
                let mut sum = 0.0f32;
                for i in 0..local.slot_count() {
                    let b = local.body_state(i);
                    sum += b.position[0] + b.position[1] + b.position[2] + b.rotation[3];
                }
                std::hint::black_box(sum);
            }
            Ok(block)
        })
    };
    let pair = estimator::interleaved(plan.repeats, Order::Abba, remote_block, || {
        local_block(local)
    })?;
    let asleep = asleep_fraction(remote.snapshot()?.bodies());
    let ratios = pair.ratios();
    Ok(Overhead {
        overhead_ratio: pair.ratio(OVERHEAD_ESTIMATOR).unwrap_or(f64::NAN),
        estimator: OVERHEAD_ESTIMATOR,
        daemon_tick_us: pair.a.wall_us.min,
        in_process_tick_us: pair.b.wall_us.min,
        daemon_cpu_us: pair.a.cpu_us.median,
        in_process_cpu_us: pair.b.cpu_us.median,
        ratios,
        blocks: pair,
        ticks_per_repeat: block,
        repeats: plan.repeats,
        asleep_fraction: asleep,
    })
}

fn delivery(
    plan: &Plan,
    client: &client_sdk::Client,
    remote: &client_sdk::Plane,
    local: &mut LocalPlane,
) -> BenchResult<Delivery> {
    // Zero-copy: the plane ticks on its own timer; we wait for each tick like a game would,
    // with `wait_tick` (it sleeps, and polls only around the moment the tick is due), then
    // again polling the queue all the time.
    remote.set(PlaneProp::TickRate(60.0))?;
    client.flush()?;
    let mut read_all = Vec::new();
    let zero_copy = zero_copy_us(plan, remote, None, &mut read_all)?;
    let zero_copy_poll = zero_copy_us(plan, remote, Some(POLL_SPIN), &mut read_all)?;
    remote.set(PlaneProp::TickRate(0.0))?;
    client.flush()?;

    let n = zero_copy.len().max(3);
    let socket = socket::delivery_us(local, n, false)?;
    let socket_poll = socket::delivery_us(local, n, true)?;
    let publish = publish_us(local, n)?;

    let none = || BenchError::Failed("no tick was delivered in the time allowed".into());
    let zero_copy_us = median(&zero_copy).ok_or_else(none)?;
    let zero_copy_poll_us = median(&zero_copy_poll).ok_or_else(none)?;
    let socket_serde_us = median(&socket).unwrap_or(f64::NAN);
    let socket_serde_poll_us = median(&socket_poll).unwrap_or(f64::NAN);
    let publish_us = median(&publish).unwrap_or(f64::NAN);
    Ok(Delivery {
        estimator: Estimator::WallMedianOfSamples,
        zero_copy_us,
        socket_serde_us,
        speedup: socket_serde_us / zero_copy_us,
        publish_us,
        handover_us: (zero_copy_us - publish_us).max(0.0),
        zero_copy_poll_us,
        socket_serde_poll_us,
        speedup_poll: socket_serde_poll_us / zero_copy_poll_us,
        handover_poll_us: (zero_copy_poll_us - publish_us).max(0.0),
        read_all_us: median(&read_all).unwrap_or(f64::NAN),
        ticks: zero_copy.len(),
    })
}

/// Two tick intervals at 60 Hz: a polling reader spins at most this long before sleeping
/// (longer than a tick, so timer jitter does not send it to sleep).
const POLL_SPIN: Duration = Duration::from_micros(33_333);

/// Tick end → every pose read, for each tick delivered within the plan's limits.
fn zero_copy_us(
    plan: &Plan,
    remote: &client_sdk::Plane,
    spin: Option<Duration>,
    read_all: &mut Vec<f64>,
) -> BenchResult<Vec<f64>> {
    let mut times = Vec::new();
    let deadline = Instant::now() + plan.delivery_time_cap;
    let mut seen = 0;
    while times.len() < plan.delivery_ticks && Instant::now() < deadline {
        match spin {
            None => remote.wait_tick(Duration::from_secs(10))?,
            Some(spin) => remote.wait_tick_spin(Duration::from_secs(10), spin)?,
        };
        let snap: Snapshot = remote.snapshot()?;
        // Holding the sample is holding every pose: they are read in place from here on.
        let held = monotonic_ns();
        std::hint::black_box(touch(snap.bodies()));
        let read = monotonic_ns();
        // The first ticks after a switch include the switch itself.
        seen += 1;
        if seen > 2 {
            times.push(held.saturating_sub(snap.header().tick_end_ns) as f64 / 1e3);
            read_all.push(read.saturating_sub(held) as f64 / 1e3);
        }
    }
    Ok(times)
}

/// The daemon's publish code on the in-process world, into shared memory of a domain of its
/// own (no reader attached: the copy and send alone).
fn publish_us(local: &mut LocalPlane, times: usize) -> BenchResult<Vec<f64>> {
    let domain = unique_domain("pub");
    let result = (|| {
        let config = names::config(&domain).map_err(physics_daemon::DaemonError::from)?;
        let node = NodeBuilder::new()
            .config(&config)
            .signal_handling_mode(SignalHandlingMode::Disabled)
            .create::<ipc::Service>()
            .map_err(|e| BenchError::Failed(format!("create a node in {domain}: {e:?}")))?;
        let out = PlaneOutput::new(&node, local.id)?;
        out.publish(local)?; // grows the data segment once
        let mut times_us = Vec::with_capacity(times);
        for _ in 0..times {
            let started = Instant::now();
            out.publish(local)?;
            times_us.push(started.elapsed().as_secs_f64() * 1e6);
        }
        Ok(times_us)
    })();
    let _ = physics_daemon::cleanup_domain(&domain);
    result
}

fn requests(
    plan: &Plan,
    client: &client_sdk::Client,
    objects: &[client_sdk::Object],
) -> BenchResult<Requests> {
    // Skip the pile's anchored floor: velocities of dynamic bodies only.
    let dynamic = objects.get(1..).unwrap_or_default();
    if dynamic.len() < plan.batch_size {
        return Err(BenchError::Failed(format!(
            "batch of {} writes needs as many bodies, the scene has {}",
            plan.batch_size,
            dynamic.len()
        )));
    }
    let mut round_trips = Vec::with_capacity(plan.round_trips);
    for i in 0..plan.round_trips {
        dynamic[i % plan.batch_size].set_velocity([0.0, 1e-3 * (i % 7) as f32, 0.0])?;
        let started = Instant::now();
        client.flush()?;
        round_trips.push(started.elapsed().as_secs_f64() * 1e6);
    }
    let mut rates = Vec::with_capacity(plan.batches);
    for b in 0..plan.batches {
        // Queueing the writes is part of their cost, so the clock starts before it.
        let started = Instant::now();
        for o in &dynamic[..plan.batch_size] {
            o.set_velocity([1e-3 * (b % 5) as f32, 0.0, 0.0])?;
        }
        client.flush()?;
        rates.push(plan.batch_size as f64 / started.elapsed().as_secs_f64());
    }
    Ok(Requests {
        estimator: Estimator::WallMedianOfSamples,
        round_trip_us: crate::stats::spread(&round_trips)
            .ok_or_else(|| BenchError::Failed("no round trip was measured".into()))?,
        round_trips: plan.round_trips,
        batched_writes_per_s: median(&rates).unwrap_or(f64::NAN),
        batch_size: plan.batch_size,
        batches: plan.batches,
    })
}

//! Planes side by side in one daemon: a small plane's round trips alone and next to a
//! 10,000-body plane ticking at 60 Hz (head-of-line blocking), and the aggregate ticks per
//! second of two 10,000-body planes stepped at once from two clients against one.

use std::time::{Duration, Instant};

use client_sdk::{Client, PlaneOptions, PlaneProp, Pose, Shape};

use crate::daemon::DaemonProcess;
use crate::error::{BenchError, BenchResult};
use crate::scene::{Kind, Scene, DT};
use crate::stats::{spread, Spread};

#[derive(Debug, Clone, serde::Serialize)]
pub struct HeadOfLine {
    /// The busy plane: free-flying bodies (every one awake each tick).
    pub busy_bodies: usize,
    pub busy_tick_rate: f32,
    /// `Step` round trips of a one-ball manual plane, µs.
    pub alone_us: Spread,
    pub beside_busy_us: Spread,
    /// beside ÷ alone at p99.
    pub p99_ratio: f64,
    /// Ticks the busy plane made while the small plane was measured (it kept its rate).
    pub busy_ticks_per_s: f64,
    pub round_trips: usize,
}

#[derive(Debug, Clone, serde::Serialize)]
pub struct MultiPlane {
    pub bodies: usize,
    pub one_plane_ticks_per_s: f64,
    pub two_planes_ticks_per_s: f64,
    pub ratio: f64,
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

pub fn head_of_line(busy_bodies: usize, n: usize) -> BenchResult<HeadOfLine> {
    let daemon = DaemonProcess::start("hol")?;
    let client = daemon.connect()?;
    let small = small_plane(&client)?;
    round_trips(&small, n / 10)?; // warm-up
    let alone = round_trips(&small, n)?;
    let owner = daemon.connect()?;
    let scene = Scene {
        kind: Kind::Free,
        bodies: busy_bodies,
    };
    let (busy, _) = scene.build_remote(&owner, 1)?;
    let rate = 60.0;
    busy.set(PlaneProp::TickRate(rate))?;
    owner.flush()?;
    std::thread::sleep(Duration::from_millis(300));
    let tick0 = busy.snapshot()?.tick();
    let started = Instant::now();
    let beside = round_trips(&small, n)?;
    let busy_ticks_per_s =
        (busy.snapshot()?.tick() - tick0) as f64 / started.elapsed().as_secs_f64();
    let none = || BenchError::Failed("no round trip was measured".into());
    let (alone, beside) = (
        spread(&alone).ok_or_else(none)?,
        spread(&beside).ok_or_else(none)?,
    );
    Ok(HeadOfLine {
        busy_bodies,
        busy_tick_rate: rate,
        p99_ratio: beside.p99 / alone.p99,
        alone_us: alone,
        beside_busy_us: beside,
        busy_ticks_per_s,
        round_trips: n,
    })
}

/// Steps `planes` planes of `bodies` free-flying bodies, each from a client thread of its
/// own, for `seconds`; returns the ticks per second of all of them together.
fn ticks_per_s(domain: &str, planes: usize, bodies: usize, seconds: f64) -> BenchResult<f64> {
    let barrier = std::sync::Barrier::new(planes);
    std::thread::scope(|s| {
        let workers: Vec<_> = (0..planes)
            .map(|_| {
                let barrier = &barrier;
                s.spawn(move || -> BenchResult<(u64, f64)> {
                    let client = Client::connect(domain)?;
                    let scene = Scene {
                        kind: Kind::Free,
                        bodies,
                    };
                    let (plane, _) = scene.build_remote(&client, 1)?;
                    for _ in 0..5 {
                        plane.step(DT)?;
                    }
                    barrier.wait();
                    let started = Instant::now();
                    let mut ticks = 0u64;
                    while started.elapsed().as_secs_f64() < seconds {
                        plane.step(DT)?;
                        ticks += 1;
                    }
                    Ok((ticks, started.elapsed().as_secs_f64()))
                })
            })
            .collect();
        let mut total = 0.0;
        for w in workers {
            let (ticks, secs) = w
                .join()
                .map_err(|_| BenchError::Failed("a stepping thread panicked".into()))??;
            total += ticks as f64 / secs;
        }
        Ok(total)
    })
}

pub fn multi_plane(bodies: usize, seconds: f64) -> BenchResult<MultiPlane> {
    let daemon = DaemonProcess::start("planes")?;
    let one = ticks_per_s(&daemon.domain, 1, bodies, seconds)?;
    let two = ticks_per_s(&daemon.domain, 2, bodies, seconds)?;
    Ok(MultiPlane {
        bodies,
        one_plane_ticks_per_s: one,
        two_planes_ticks_per_s: two,
        ratio: two / one,
        seconds,
    })
}

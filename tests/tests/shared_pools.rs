//! Planes that ask for the same `Threads` share one thread pool in the daemon. Each plane's
//! worker runs its step inside that pool, and rapier's step hands a tree optimisation of
//! its broad phase to another thread of the pool and later blocks (outside rayon) until it
//! is done. Two planes stepping in the pool at once could each block a pool thread that
//! way with their optimisations still queued behind them: both planes stalled for good,
//! and every request to them went unanswered (found by the fuzzer: a `Step` on one of
//! them waited forever while the daemon sat idle). Planes of one pool now take turns in
//! rapier's step; this runs several such planes side by side, all with moving bodies (so
//! their broad phases optimise every few steps), and asserts every step is answered and
//! the bodies fell as free fall says.

use std::sync::mpsc;
use std::time::{Duration, Instant};

use client_sdk::{PlaneOptions, Pose, Shape};
use integration_tests::TestDaemon;

const DT: f32 = 1.0 / 60.0;
const STEPS: usize = 120;
const PLANES: usize = 4;
const BALLS: usize = 150;
const G: f32 = 9.81;

/// One client's run: a Threads = 2 plane of falling balls (far apart, no floor: no
/// contacts), stepped `STEPS` times; returns the drop of the first ball.
fn run(domain: String, k: usize) -> Result<f32, String> {
    let client = client_sdk::Client::connect(&domain).map_err(|e| e.to_string())?;
    let plane = client
        .create_plane(&PlaneOptions {
            threads: Some(2),
            gravity: Some([0.0, -G, 0.0]),
            linear_damping: Some(0.0),
            ..PlaneOptions::manual()
        })
        .map_err(|e| e.to_string())?;
    let mut balls = Vec::new();
    for i in 0..BALLS {
        let (x, z) = (
            (i % 15) as f32 * 4.0,
            (i / 15) as f32 * 4.0 + k as f32 * 100.0,
        );
        balls.push(
            plane
                .add(Shape::Sphere { radius: 0.5 }, Pose::at([x, 100.0, z]), &[])
                .map_err(|e| e.to_string())?,
        );
    }
    for _ in 0..STEPS {
        plane
            .step(DT)
            .map_err(|e| format!("plane {}: {e}", plane.id()))?;
    }
    Ok(100.0 - balls[0].position().map_err(|e| e.to_string())?[1])
}

#[test]
fn planes_sharing_a_pool_step_side_by_side_without_stalling() {
    let daemon = TestDaemon::start("shared-pools");
    let (tx, rx) = mpsc::channel();
    for k in 0..PLANES {
        let (tx, domain) = (tx.clone(), daemon.domain.clone());
        std::thread::spawn(move || {
            let _ = tx.send((k, run(domain, k)));
        });
    }
    drop(tx);
    // Each run takes a few seconds (debug daemon, 2 cores); a stalled plane never
    // answers, and its client gives up only after its request timeout.
    let deadline = Instant::now() + Duration::from_secs(120);
    let mut done = 0;
    while done < PLANES {
        let left = deadline.saturating_duration_since(Instant::now());
        let (k, result) = rx.recv_timeout(left).unwrap_or_else(|_| {
            panic!(
                "{} of {PLANES} planes still stepping after 120 s",
                PLANES - done
            )
        });
        let drop = result.unwrap_or_else(|e| panic!("plane of client {k}: {e}"));
        // Semi-implicit Euler from rest, n steps of h: g h² n (n + 1) / 2 (rapier may
        // sub-step: between g h² n² / 2 and that); f32 rounding at y = 100 is ~1e-5.
        let n = STEPS as f32;
        let (low, high) = (0.5 * G * DT * DT * n * n, 0.5 * G * DT * DT * n * (n + 1.0));
        assert!(
            drop >= low - 1e-3 && drop <= high + 1e-3,
            "client {k}: the ball fell {drop}, free fall says {low}..{high}"
        );
        done += 1;
    }
}

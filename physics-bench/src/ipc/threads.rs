//! Threads = 2 against Threads = 1 on the same scene, both in one daemon, stepped alternately
//! so both see the same machine load. Timed while the scene is awake (a sleeping pile has
//! nothing to parallelise); the scene is chosen so one thread needs several milliseconds per
//! step (a pile of 10,000 settles too fast for that).

use client_sdk::Plane;

use crate::daemon::DaemonProcess;
use crate::error::{BenchError, BenchResult};
use crate::scene::{Kind, Scene, DT};
use crate::stats::median;

/// Ticks skipped before timing (the first contacts are being found).
const SKIP: usize = 10;
/// Last tick timed: well before rapier's 2 s (120 ticks) sleep delay.
const UNTIL: usize = 100;

#[derive(Debug, Clone, serde::Serialize)]
pub struct Threads {
    pub scene: Kind,
    pub bodies: usize,
    /// Median step time from the tick headers (the daemon's own timing of `step`).
    pub threads1_step_us: f64,
    pub threads2_step_us: f64,
    pub speedup: f64,
    pub ticks: usize,
}

pub fn run(kind: Kind, bodies: usize) -> BenchResult<Threads> {
    let scene = Scene { kind, bodies };
    let daemon = DaemonProcess::start("threads")?;
    let client = daemon.connect()?;
    let (one, _) = scene.build_remote(&client, 1)?;
    let (two, _) = scene.build_remote(&client, 2)?;
    let (mut t1, mut t2) = (Vec::new(), Vec::new());
    let step = |plane: &Plane| -> BenchResult<f64> {
        plane.step(DT)?;
        Ok(plane.snapshot()?.header().step_time_us as f64)
    };
    for tick in 0..UNTIL {
        let (a, b) = (step(&one)?, step(&two)?);
        if tick >= SKIP {
            t1.push(a);
            t2.push(b);
        }
    }
    let missing = || BenchError::Failed("no step was timed".into());
    let (m1, m2) = (
        median(&t1).ok_or_else(missing)?,
        median(&t2).ok_or_else(missing)?,
    );
    Ok(Threads {
        scene: scene.kind,
        bodies,
        threads1_step_us: m1,
        threads2_step_us: m2,
        speedup: m1 / m2,
        ticks: t1.len(),
    })
}

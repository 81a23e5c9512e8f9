//! Threads = 2 against Threads = 1 on the same scene, both in one daemon, stepped alternately
//! so both see the same machine load. Timed while the scene is awake (a sleeping pile has
//! nothing to parallelise), on scenes whose work is what a plane's pool can share:
//!
//! - `pile`: 10,000 unit cubes in columns of 5 on an anchored floor, NeverSleep: every body
//!   awake and resting on another, 10,000 contact pairs for the solver every substep.
//! - `pyramid`: Box2D's large pyramid, base 100 (5,050 unit cubes) on a floor, NeverSleep:
//!   one island of contacts.
//! - `free`: 20,000 free-flying cubes, no gravity, no contacts. Reported without a goal:
//!   rapier gives a step without constraints one solver worker (its staged solver sizes its
//!   workers by constraint chunks), so integrating free bodies stays on one thread.

use client_sdk::{Client, Plane, PlaneOptions};
use physics_scenes::{floor, free_bodies, pair_gap, pile, pyramid};

use crate::daemon::DaemonProcess;
use crate::error::{BenchError, BenchResult};
use crate::scene::DT;
use crate::stats::median;

/// Ticks skipped before timing (the first contacts are being found).
const SKIP: usize = 10;
/// Last tick timed.
const UNTIL: usize = 100;

/// The scenes of the figure.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum ThreadsScene {
    /// Unit cubes in columns of 5 on a floor, all awake (NeverSleep).
    Pile,
    /// A pyramid of unit cubes on a floor, all awake (NeverSleep).
    Pyramid,
    /// Free-flying cubes without gravity or contacts.
    Free,
}

impl ThreadsScene {
    /// Every scene, the ones with a goal first.
    pub const ALL: [ThreadsScene; 3] = [
        ThreadsScene::Pile,
        ThreadsScene::Pyramid,
        ThreadsScene::Free,
    ];

    pub fn name(self) -> &'static str {
        match self {
            ThreadsScene::Pile => "pile",
            ThreadsScene::Pyramid => "pyramid",
            ThreadsScene::Free => "free",
        }
    }

    /// Whether the ≥ 1.6× goal is judged on this scene (the contact scenes).
    pub fn has_goal(self) -> bool {
        self != ThreadsScene::Free
    }

    /// Dynamic bodies of the scene.
    pub fn bodies(self) -> usize {
        match self {
            ThreadsScene::Pile => 10_000,
            ThreadsScene::Pyramid => PYRAMID_BASE * (PYRAMID_BASE + 1) / 2,
            ThreadsScene::Free => 20_000,
        }
    }

    /// What the scene is, for the report.
    pub fn describe(self) -> String {
        match self {
            ThreadsScene::Pile => format!(
                "{} unit cubes in columns of 5 on a floor, NeverSleep",
                self.bodies()
            ),
            ThreadsScene::Pyramid => format!(
                "base-{PYRAMID_BASE} pyramid ({} unit cubes) on a floor, NeverSleep",
                self.bodies()
            ),
            ThreadsScene::Free => format!(
                "{} free-flying cubes, no gravity, no contacts",
                self.bodies()
            ),
        }
    }

    fn build(self, client: &Client, threads: u32) -> BenchResult<Plane> {
        let free = self == ThreadsScene::Free;
        let options = PlaneOptions {
            gravity: free.then_some([0.0; 3]),
            threads: Some(threads),
            tick_rate: Some(0.0),
            never_sleep: Some(!free),
            ..Default::default()
        };
        let plane = client.create_plane(&options)?;
        let mut target = &plane;
        match self {
            ThreadsScene::Pile => {
                pile(&mut target, self.bodies())?;
            }
            ThreadsScene::Pyramid => {
                floor(&mut target, 2.0 * PYRAMID_BASE as f32 + 20.0, &[])?;
                pyramid(&mut target, PYRAMID_BASE, pair_gap(1))?;
            }
            ThreadsScene::Free => {
                free_bodies(&mut target, self.bodies())?;
            }
        }
        // Threads is a creation-only option: check that the plane has the pool asked for.
        let info = plane.info()?;
        if info.settings.threads != threads {
            return Err(BenchError::Failed(format!(
                "asked for Threads = {threads}, the plane has {}",
                info.settings.threads
            )));
        }
        Ok(plane)
    }
}

/// Base of the pyramid scene.
const PYRAMID_BASE: usize = 100;

#[derive(Debug, Clone, serde::Serialize)]
pub struct Threads {
    pub scene: ThreadsScene,
    pub bodies: usize,
    /// Median step time from the tick headers (the daemon's own timing of `step`).
    pub threads1_step_us: f64,
    pub threads2_step_us: f64,
    pub speedup: f64,
    pub ticks: usize,
}

/// Threads = 1 and Threads = 2 planes of `scene` in one daemon, stepped alternately.
pub fn run(scene: ThreadsScene) -> BenchResult<Threads> {
    let daemon = DaemonProcess::start("threads")?;
    let client = daemon.connect()?;
    let one = scene.build(&client, 1)?;
    let two = scene.build(&client, 2)?;
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
        scene,
        bodies: scene.bodies(),
        threads1_step_us: m1,
        threads2_step_us: m2,
        speedup: m1 / m2,
        ticks: t1.len(),
    })
}

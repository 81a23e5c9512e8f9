//! Threads = 2 against Threads = 1 on the same scene. Timed while the scene is awake (a
//! sleeping pile has nothing to parallelise), on scenes whose work is what a plane's pool can
//! share:
//!
//! - `pile`: 10,000 unit cubes in columns of 5 on an anchored floor, NeverSleep: every body
//!   awake and resting on another, 10,000 contact pairs for the solver every substep.
//! - `pyramid`: Box2D's large pyramid, base 100 (5,050 unit cubes) on a floor, NeverSleep:
//!   one island of contacts.
//! - `free`: 20,000 free-flying cubes, no gravity, no contacts. Reported without a goal:
//!   rapier gives a step without constraints one solver worker (its staged solver sizes its
//!   workers by constraint chunks), so integrating free bodies stays on one thread.
//!
//! The goal is judged on the plane's step alone, in process ([`Estimator::StepInProcess`]):
//! the daemon's plane code (`physics_scenes::LocalPlane`) created with `Threads(1)` and with
//! `Threads(2)`, stepped in interleaved blocks. A plane asking for 2 threads gets a pool of
//! its own (`physics_daemon::backend::pools::shared`, workers pinned to cores of their own),
//! apart from the global pool of one thread the other plane steps on, so the comparison is
//! the real one; and no client shares the machine's second core with the pool, as the client
//! stepping a daemon plane does. The same scenes stepped in a daemon by this process as a
//! client are reported beside, without a goal.

use client_sdk::{Client, Plane, PlaneOptions, PlaneProp};
use physics_scenes::{floor, free_bodies, pair_gap, pile, pyramid, LocalPlane, SceneTarget};

use crate::daemon::DaemonProcess;
use crate::error::{BenchError, BenchResult};
use crate::estimator::{self, CpuClock, Estimator, Order, Pair};
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

    /// Adds the scene's objects to `target`.
    fn populate<T: SceneTarget>(self, target: &mut T) -> Result<(), T::Error> {
        match self {
            ThreadsScene::Pile => {
                pile(target, self.bodies())?;
            }
            ThreadsScene::Pyramid => {
                floor(target, 2.0 * PYRAMID_BASE as f32 + 20.0, &[])?;
                pyramid(target, PYRAMID_BASE, pair_gap(1))?;
            }
            ThreadsScene::Free => {
                free_bodies(target, self.bodies())?;
            }
        }
        Ok(())
    }

    /// The scene's plane options with `threads` threads, manual.
    fn props(self, threads: u32) -> Vec<PlaneProp> {
        let free = self == ThreadsScene::Free;
        let mut props = vec![
            PlaneProp::Threads(threads),
            PlaneProp::TickRate(0.0),
            PlaneProp::NeverSleep(!free),
        ];
        if free {
            props.push(PlaneProp::Gravity([0.0; 3]));
        }
        props
    }

    fn build(self, client: &Client, threads: u32) -> BenchResult<Plane> {
        let mut options = PlaneOptions::default();
        for p in self.props(threads) {
            options = options.with(p);
        }
        let plane = client.create_plane(&options)?;
        self.populate(&mut &plane)?;
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

    /// The scene built in this process with the daemon's plane code.
    fn build_local(self, threads: u32) -> BenchResult<LocalPlane> {
        let mut plane = LocalPlane::new(1, &self.props(threads))?;
        self.populate(&mut plane)?;
        let used = plane.info().settings.threads;
        if used != threads {
            return Err(BenchError::Failed(format!(
                "asked for Threads = {threads} in process, the plane has {used} (cores: {})",
                std::thread::available_parallelism().map_or(1, |n| n.get())
            )));
        }
        Ok(plane)
    }
}

/// Base of the pyramid scene.
const PYRAMID_BASE: usize = 100;

/// Blocks of each side of the in-process figure: many short blocks, so that some fall in
/// quiet stretches of a shared machine (a Threads = 2 step needs both cores at once).
const BLOCKS: usize = 12;
/// Steps per block.
const BLOCK_TICKS: usize = 4;

#[derive(Debug, Clone, serde::Serialize)]
pub struct Threads {
    pub scene: ThreadsScene,
    pub bodies: usize,
    /// What judges the goal: [`Estimator::StepInProcess`].
    pub estimator: Estimator,
    /// Step wall time in process, the minimum of the blocks, µs.
    pub threads1_step_us: f64,
    pub threads2_step_us: f64,
    /// `threads1_step_us / threads2_step_us`.
    pub speedup: f64,
    /// The same of the blocks' medians.
    pub speedup_median: f64,
    /// CPU of this process per step, Threads = 2 over Threads = 1 (medians of blocks): what
    /// the second thread costs in all.
    pub cpu_ratio: f64,
    /// Steps timed per side.
    pub ticks: usize,
    /// The blocks: A = Threads 1, B = Threads 2 (per step: wall, CPU of this process).
    pub in_process: Pair,
    /// The same scenes in a daemon, stepped by this process as a client (no goal).
    pub daemon: DaemonThreads,
}

/// Threads = 1 and 2 planes of a scene in one daemon, stepped alternately by this process.
#[derive(Debug, Clone, serde::Serialize)]
pub struct DaemonThreads {
    /// [`Estimator::WallMedianOfSamples`]: medians of the tick headers' step_time_us.
    pub estimator: Estimator,
    pub threads1_step_us: f64,
    pub threads2_step_us: f64,
    pub speedup: f64,
    pub ticks: usize,
}

/// Both figures of `scene`: in process (the judged one), then in a daemon.
pub fn run(scene: ThreadsScene) -> BenchResult<Threads> {
    let in_process = in_process(scene)?;
    let daemon = in_daemon(scene)?;
    let r = in_process.ratios();
    Ok(Threads {
        scene,
        bodies: scene.bodies(),
        estimator: Estimator::StepInProcess,
        threads1_step_us: in_process.a.wall_us.min,
        threads2_step_us: in_process.b.wall_us.min,
        speedup: r.wall_min,
        speedup_median: r.wall_median,
        cpu_ratio: 1.0 / r.cpu_median,
        ticks: BLOCKS * BLOCK_TICKS,
        in_process,
        daemon,
    })
}

/// The plane's step alone in this process, Threads = 1 (A) against 2 (B), blocks ABBA.
fn in_process(scene: ThreadsScene) -> BenchResult<Pair> {
    let mut one = scene.build_local(1)?;
    let mut two = scene.build_local(2)?;
    for _ in 0..SKIP {
        one.step(DT)?;
        two.step(DT)?;
    }
    let clock = CpuClock::new(&[]);
    let block = |plane: &mut LocalPlane| {
        estimator::timed(&clock, || {
            for _ in 0..BLOCK_TICKS {
                plane.step(DT)?;
            }
            Ok(BLOCK_TICKS)
        })
    };
    estimator::interleaved(BLOCKS, Order::Abba, || block(&mut one), || block(&mut two))
}

/// Threads = 1 and Threads = 2 planes of `scene` in one daemon, stepped alternately.
fn in_daemon(scene: ThreadsScene) -> BenchResult<DaemonThreads> {
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
    Ok(DaemonThreads {
        estimator: Estimator::WallMedianOfSamples,
        threads1_step_us: m1,
        threads2_step_us: m2,
        speedup: m1 / m2,
        ticks: t1.len(),
    })
}

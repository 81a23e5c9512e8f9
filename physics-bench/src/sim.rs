//! An in-process plane (the daemon's own plane code) driven at a fixed dt, with the wall time
//! of its step calls accumulated: what the accuracy and stability benches measure.

use std::time::{Duration, Instant};

use client_sdk::{BodyState, Handle, ObjectProp, PlaneProp, Pose, Shape, TickHeader};
use physics_scenes::{LocalPlane, SceneTarget};

use super::error::{BenchError, BenchResult};

/// The knobs a user trades accuracy for time with.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, serde::Serialize)]
pub struct Config {
    pub tick_rate: u32,
    pub solver_iterations: u32,
    pub loop_solver: bool,
    pub hit_box_quality: u32,
    /// Runs the plane on the GPU path (DeferGpu), switched on at the first step, once the
    /// scene is built.
    pub gpu: bool,
}

impl Config {
    /// The plane defaults: 60 Hz, 4 iterations, HitBoxQuality 1.
    pub const DEFAULT: Config = Config {
        tick_rate: 60,
        solver_iterations: 4,
        loop_solver: false,
        hit_box_quality: 1,
        gpu: false,
    };

    /// The most accurate setting the API offers at 240 Hz: LoopSolver (64 iterations) and
    /// HitBoxQuality 32 (CCD, smallest skin and tolerances).
    pub const STRONGEST: Config = Config {
        tick_rate: 240,
        solver_iterations: 64,
        loop_solver: true,
        hit_box_quality: 32,
        gpu: false,
    };

    pub fn dt(&self) -> f32 {
        1.0 / self.tick_rate as f32
    }

    /// Iterations the plane runs before HitBoxQuality scaling (LoopSolver pins 64).
    pub fn iterations_label(&self) -> String {
        if self.loop_solver {
            "64 (LoopSolver)".into()
        } else {
            self.solver_iterations.to_string()
        }
    }

    pub fn label(&self) -> String {
        format!(
            "{} Hz, {} it, q{}",
            self.tick_rate,
            self.iterations_label(),
            self.hit_box_quality
        )
    }

    /// Contact gap a resting pair keeps at this quality: 0.01/q skin per collider.
    pub fn pair_gap(&self) -> f32 {
        physics_scenes::pair_gap(self.hit_box_quality)
    }
}

/// A manual plane stepped at `config.dt()`.
pub struct Sim {
    pub plane: LocalPlane,
    pub config: Config,
    pub dt: f32,
    steps: u64,
    step_wall: Duration,
    /// Set once any body was non-finite after a step (checked outside the timed part).
    pub went_nonfinite: bool,
}

impl Sim {
    /// A plane with `config`'s solver settings, then `props` (gravity, damping, ...).
    pub fn new(config: Config, props: &[PlaneProp]) -> BenchResult<Sim> {
        let mut all = vec![
            PlaneProp::TickRate(0.0),
            PlaneProp::SolverIterations(config.solver_iterations),
            PlaneProp::LoopSolver(config.loop_solver),
        ];
        all.extend_from_slice(props);
        Ok(Sim {
            plane: LocalPlane::new(1, &all)?,
            config,
            dt: config.dt(),
            steps: 0,
            step_wall: Duration::ZERO,
            went_nonfinite: false,
        })
    }

    /// Adds an object at the config's HitBoxQuality (given before `props`, which may
    /// override it).
    pub fn add(&mut self, shape: Shape, pose: Pose, props: &[ObjectProp]) -> BenchResult<Handle> {
        let mut all = vec![ObjectProp::HitBoxQuality(self.config.hit_box_quality)];
        all.extend_from_slice(props);
        Ok(self.plane.add_object(&shape, pose, &all)?)
    }

    /// One timed step.
    pub fn step(&mut self) -> BenchResult<()> {
        if self.config.gpu && !self.plane.on_gpu() {
            self.plane.set(PlaneProp::DeferGpu(true))?;
        }
        let started = Instant::now();
        self.plane.step(self.dt)?;
        self.step_wall += started.elapsed();
        self.steps += 1;
        if !self.went_nonfinite && !self.all_finite() {
            self.went_nonfinite = true;
        }
        Ok(())
    }

    /// Steps covering `seconds` of simulated time (rounded to whole ticks, at least one).
    pub fn steps_for(&self, seconds: f32) -> u64 {
        ((seconds / self.dt).round() as u64).max(1)
    }

    pub fn time(&self) -> f64 {
        self.steps as f64 * self.dt as f64
    }

    pub fn state(&self, h: Handle) -> BodyState {
        self.plane.body_state(h.slot as usize)
    }

    pub fn header(&self) -> TickHeader {
        self.plane.header()
    }

    /// Wall seconds of step calls per simulated second.
    pub fn cost(&self) -> f64 {
        self.step_wall.as_secs_f64() / self.time().max(f64::MIN_POSITIVE)
    }

    /// Steps covering `seconds`.
    pub fn run_for(&mut self, seconds: f32) -> BenchResult<()> {
        for _ in 0..self.steps_for(seconds) {
            self.step()?;
        }
        Ok(())
    }

    /// Whether every body's pose and velocities are finite.
    pub fn all_finite(&self) -> bool {
        (0..self.plane.slot_count()).all(|i| self.plane.body_state(i).is_finite())
    }
}

/// The shared scene builders add through [`Sim::add`]: every object at the config's
/// HitBoxQuality.
impl SceneTarget for Sim {
    type Handle = Handle;
    type Error = BenchError;

    fn add(&mut self, shape: Shape, pose: Pose, props: &[ObjectProp]) -> BenchResult<Handle> {
        Sim::add(self, shape, pose, props)
    }
}

/// Unit quaternion `[x, y, z, w]` for `angle` radians about the z axis.
pub fn about_z(angle: f32) -> [f32; 4] {
    let (s, c) = (angle / 2.0).sin_cos();
    [0.0, 0.0, s, c]
}

pub fn distance(a: [f32; 3], b: [f32; 3]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (*x as f64 - y as f64).powi(2))
        .sum::<f64>()
        .sqrt()
}

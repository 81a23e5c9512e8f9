//! Reference scenes of the 2D GUI plane (pixels, +Y down, gravity 980 px/s²), run in process
//! through the daemon's own GUI plane code like the 3D scenes. TickRate and SolverIterations
//! of the configuration apply; HitBoxQuality and LoopSolver have no 2D meaning.

use std::time::{Duration, Instant};

use physics_daemon::rapier2d::Plane as GuiPlane;
use shm_layout::{GuiObjectProp, GuiPlaneProp, GuiShape, Handle, PlaneProp};

use super::scenes::{Outcome, Scene};
use crate::error::{BenchError, BenchResult};
use crate::sim::Config;

const G: f64 = 980.0;

pub const SCENES_2D: &[Scene] = &[
    Scene {
        name: "gui-free-fall",
        measures: "|y − (y0 + g·t²/2)| of a 20 px circle after 1 s (g = 980 px/s², +Y down)",
        unit: "px",
        run: free_fall,
    },
    Scene {
        name: "gui-bounce",
        measures: "|h1 / h0 − e²| of a circle dropped 300 px onto an anchored floor (e = 0.8)",
        unit: "fraction",
        run: bounce,
    },
    Scene {
        name: "gui-slide",
        measures: "|d − v0²/(2·μ·g)| of a square launched at 300 px/s with μ = 0.5 (d ≈ 91.8 px)",
        unit: "px",
        run: slide,
    },
];

fn err(e: impl std::fmt::Display) -> BenchError {
    BenchError::Failed(e.to_string())
}

/// A manual GUI plane without damping at `config`'s tick rate and iterations, timed.
struct Sim2 {
    plane: GuiPlane,
    dt: f32,
    steps: u64,
    wall: Duration,
}

impl Sim2 {
    fn new(c: Config) -> BenchResult<Sim2> {
        let plane = GuiPlane::new(
            1,
            &[
                PlaneProp::TickRate(0.0),
                PlaneProp::Gui(GuiPlaneProp::LinearDamping(0.0)),
                PlaneProp::Gui(GuiPlaneProp::AngularDamping(0.0)),
                PlaneProp::Gui(GuiPlaneProp::SolverIterations(c.solver_iterations)),
                PlaneProp::Gui(GuiPlaneProp::NeverSleep(true)),
            ],
        )
        .map_err(err)?;
        Ok(Sim2 {
            plane,
            dt: c.dt(),
            steps: 0,
            wall: Duration::ZERO,
        })
    }

    fn add(
        &mut self,
        shape: GuiShape,
        size: [f32; 2],
        at: [f32; 2],
        props: &[GuiObjectProp],
    ) -> BenchResult<Handle> {
        self.plane.add_object(shape, size, at, props).map_err(err)
    }

    fn step(&mut self) -> BenchResult<()> {
        let started = Instant::now();
        self.plane.step(self.dt).map_err(err)?;
        self.wall += started.elapsed();
        self.steps += 1;
        Ok(())
    }

    fn steps_for(&self, seconds: f32) -> u64 {
        ((seconds / self.dt).round() as u64).max(1)
    }

    fn time(&self) -> f64 {
        self.steps as f64 * self.dt as f64
    }

    fn y(&self, h: Handle) -> f64 {
        self.plane.body_state(h.slot as usize).position[1] as f64
    }

    fn x(&self, h: Handle) -> f64 {
        self.plane.body_state(h.slot as usize).position[0] as f64
    }

    fn outcome(&self, error: f64) -> BenchResult<Outcome> {
        Ok(Outcome {
            error,
            cost: self.wall.as_secs_f64() / self.time().max(f64::MIN_POSITIVE),
        })
    }
}

fn free_fall(c: Config) -> BenchResult<Outcome> {
    let mut sim = Sim2::new(c)?;
    let y0 = 100.0;
    let b = sim.add(GuiShape::Circle, [20.0, 20.0], [0.0, y0 as f32], &[])?;
    for _ in 0..sim.steps_for(1.0) {
        sim.step()?;
    }
    let t = sim.time();
    sim.outcome((sim.y(b) - (y0 + G * t * t / 2.0)).abs())
}

/// Floor top at y = 500 (+Y down): an anchored 2000 × 100 square centred at y = 550.
fn floor(sim: &mut Sim2, props: &[GuiObjectProp]) -> BenchResult<()> {
    let mut all = vec![GuiObjectProp::Anchored(true)];
    all.extend_from_slice(props);
    sim.add(GuiShape::Square, [2000.0, 100.0], [0.0, 550.0], &all)
        .map(|_| ())
}

fn bounce(c: Config) -> BenchResult<Outcome> {
    let e = 0.8f64;
    let mut sim = Sim2::new(c)?;
    floor(&mut sim, &[GuiObjectProp::Bounciness(e as f32)])?;
    let r = 10.0;
    let h0 = 300.0;
    let start = 500.0 - r - h0;
    let b = sim.add(
        GuiShape::Circle,
        [2.0 * r as f32; 2],
        [0.0, start as f32],
        &[GuiObjectProp::Bounciness(e as f32)],
    )?;
    // Fall (≈ 0.78 s), bounce, and rise to the first apex (≈ 0.63 s): the apex is the
    // smallest y after the bounce.
    let mut bounced = false;
    let mut apex = f64::MAX;
    for _ in 0..sim.steps_for(2.0) {
        let before = sim.y(b);
        sim.step()?;
        let y = sim.y(b);
        if y < before {
            bounced = true;
        }
        if bounced {
            apex = apex.min(y);
        }
    }
    let h1 = 500.0 - r - apex;
    sim.outcome((h1 / h0 - e * e).abs())
}

fn slide(c: Config) -> BenchResult<Outcome> {
    let (mu, v0) = (0.5f64, 300.0f64);
    let mut sim = Sim2::new(c)?;
    floor(&mut sim, &[GuiObjectProp::Friction(mu as f32)])?;
    let b = sim.add(
        GuiShape::Square,
        [20.0, 20.0],
        [0.0, 490.0],
        &[
            GuiObjectProp::Friction(mu as f32),
            GuiObjectProp::LockedRotation(true),
        ],
    )?;
    // Settle onto the floor, then launch.
    for _ in 0..sim.steps_for(0.2) {
        sim.step()?;
    }
    let x0 = sim.x(b);
    sim.plane
        .set_object(b, GuiObjectProp::Velocity([v0 as f32, 0.0]))
        .map_err(err)?;
    // Stops after v0/(μ·g) ≈ 0.61 s.
    for _ in 0..sim.steps_for(1.0) {
        sim.step()?;
    }
    let exact = v0 * v0 / (2.0 * mu * G);
    sim.outcome((sim.x(b) - x0 - exact).abs())
}

//! Reference scenes with exact answers. Each builds its world in an in-process plane at one
//! configuration, steps it, and returns its error against the closed form and the cost.
//!
//! Conventions of the service that the closed forms account for: gravity (0, -50, 0);
//! LinearDamping / AngularDamping are set to 0 wherever the closed form has none; a resting
//! pair keeps `0.02 / HitBoxQuality` apart (0.01 contact skin per collider), so rest heights
//! include that gap; a pair's friction is `sqrt(a·b)`, so both sides carry the same μ.

use client_sdk::{ObjectProp, PlaneProp, Pose, Shape};
use physics_scenes::{anchored_box, ball, column, cube, floor};
use rapier3d::glamx::{DQuat, DVec3};

use crate::error::BenchResult;
use crate::sim::{about_z, distance, Config, Sim};

const G: f64 = 50.0;

/// One reference scene.
pub struct Scene {
    pub name: &'static str,
    /// What `error` measures, for the report.
    pub measures: &'static str,
    pub unit: &'static str,
    pub run: fn(Config) -> BenchResult<Outcome>,
}

pub struct Outcome {
    pub error: f64,
    /// Wall seconds of step calls per simulated second.
    pub cost: f64,
}

pub const SCENES: &[Scene] = &[
    Scene {
        name: "free-fall",
        measures: "|y − (y0 − g·t²/2)| of a ball after 2 s",
        unit: "units",
        run: free_fall,
    },
    Scene {
        name: "projectile-damping",
        measures: "distance from the closed-form position under LinearDamping 0.5 after 2 s",
        unit: "units",
        run: projectile_damping,
    },
    Scene {
        name: "terminal-velocity",
        measures: "largest |v − v_t·tanh(g·t/v_t)| over 1 s of fall under Drag 2 (v_t = 5)",
        unit: "units/s",
        run: terminal_velocity,
    },
    Scene {
        name: "bouncing-ball",
        measures: "largest |h_n − e^(2n)·h0| / (e^(2n)·h0) over the first 3 apexes (e = 0.8, h0 = 10)",
        unit: "fraction",
        run: bouncing_ball,
    },
    Scene {
        name: "sliding-block",
        measures: "|d − v0²/(2·μ·g)| of a block launched at 10 units/s with μ = 0.5 (d = 2)",
        unit: "units",
        run: sliding_block,
    },
    Scene {
        name: "incline-hold",
        measures: "distance a block slid in 2 s on a 20° incline with μ = 0.6 (must hold: 0)",
        unit: "units",
        run: incline_hold,
    },
    Scene {
        name: "incline-slide",
        measures: "|s − a·t²/2| after 1 s on a 40° incline with μ = 0.3, a = g(sinθ − μ·cosθ)",
        unit: "units",
        run: incline_slide,
    },
    Scene {
        name: "free-rotation",
        measures: "largest relative drift of the angular momentum vector or the kinetic energy over 5 s of a torque-free 1×2×3 box",
        unit: "fraction",
        run: free_rotation,
    },
    Scene {
        name: "hinge-pendulum",
        measures: "|T − 2π√(L/g)(1 + θ0²/16)| / that, of a hinge pendulum (L = 2, θ0 = 0.3) over 6 s",
        unit: "fraction",
        run: hinge_pendulum,
    },
    Scene {
        name: "elastic-collision",
        measures: "max(|Δp|/|p|, |ΔE|/E) of a head-on collision in zero gravity, Bounciness 1, masses 1 and 2 (exact: v1' = −v/3, v2' = 2v/3)",
        unit: "fraction",
        run: elastic_collision,
    },
    Scene {
        name: "pile-666",
        measures: "deepest contact penetration (tick header) over the last second of 216 unit balls (6×6×6) dropped into a 7-wide bin, after 3 s",
        unit: "units",
        run: pile_666,
    },
    Scene {
        name: "stack-drift",
        measures: "largest displacement of any box of a resting 5-box stack from 1 s (settled) to 3 s",
        unit: "units",
        run: stack_drift,
    },
    Scene {
        name: "stack-penetration",
        measures: "deepest contact penetration (tick header) of a resting 5-box stack over 3 s",
        unit: "units",
        run: stack_penetration,
    },
];

/// No damping: the closed forms have none.
const UNDAMPED: [PlaneProp; 2] = [
    PlaneProp::LinearDamping(0.0),
    PlaneProp::AngularDamping(0.0),
];

fn outcome(sim: &Sim, error: f64) -> BenchResult<Outcome> {
    Ok(Outcome {
        error: if sim.went_nonfinite { f64::NAN } else { error },
        cost: sim.cost(),
    })
}

fn free_fall(c: Config) -> BenchResult<Outcome> {
    let mut sim = Sim::new(c, &UNDAMPED)?;
    let y0 = 1000.0;
    let b = ball(&mut sim, [0.0, y0 as f32, 0.0], &[])?;
    for _ in 0..sim.steps_for(2.0) {
        sim.step()?;
    }
    let t = sim.time();
    let exact = y0 - G * t * t / 2.0;
    outcome(&sim, (sim.state(b).position[1] as f64 - exact).abs())
}

fn projectile_damping(c: Config) -> BenchResult<Outcome> {
    let k = 0.5f64;
    let mut sim = Sim::new(
        c,
        &[
            PlaneProp::LinearDamping(k as f32),
            PlaneProp::AngularDamping(0.0),
        ],
    )?;
    let x0 = [0.0, 1000.0, 0.0];
    let v0 = [20.0, 30.0, 0.0];
    let b = ball(&mut sim, x0, &[ObjectProp::Velocity(v0)])?;
    for _ in 0..sim.steps_for(2.0) {
        sim.step()?;
    }
    // dv/dt = g − k·v: v∞ = g/k, x = x0 + v∞·t + (v0 − v∞)(1 − e^(−kt))/k.
    let t = sim.time();
    let g = [0.0, -G, 0.0];
    let exact: Vec<f32> = (0..3)
        .map(|i| {
            let v_inf = g[i] / k;
            (x0[i] as f64 + v_inf * t + (v0[i] as f64 - v_inf) * (1.0 - (-k * t).exp()) / k) as f32
        })
        .collect();
    let exact = [exact[0], exact[1], exact[2]];
    outcome(&sim, distance(sim.state(b).position, exact))
}

fn terminal_velocity(c: Config) -> BenchResult<Outcome> {
    let drag = 2.0f64;
    let mut props = UNDAMPED.to_vec();
    props.push(PlaneProp::Drag(drag as f32));
    let mut sim = Sim::new(c, &props)?;
    let b = ball(&mut sim, [0.0, 1000.0, 0.0], &[])?;
    // m·dv/dt = m·g − Drag·v² from rest (m = 1): v = v_t·tanh(g·t/v_t), v_t = sqrt(g/Drag).
    let vt = (G / drag).sqrt();
    let mut worst = 0.0f64;
    for _ in 0..sim.steps_for(1.0) {
        sim.step()?;
        let exact = -vt * (G * sim.time() / vt).tanh();
        worst = worst.max((sim.state(b).linear_velocity[1] as f64 - exact).abs());
    }
    outcome(&sim, worst)
}

fn bouncing_ball(c: Config) -> BenchResult<Outcome> {
    let e = 0.8f64;
    let h0 = 10.0f64;
    let mut sim = Sim::new(c, &UNDAMPED)?;
    floor(&mut sim, 50.0, &[])?;
    let rest = 0.5 + c.pair_gap() as f64;
    let b = ball(
        &mut sim,
        [0.0, (rest + h0) as f32, 0.0],
        &[ObjectProp::Bounciness(e as f32)],
    )?;
    // Apex = highest sampled height of each rising-then-falling phase after a bounce.
    let mut apexes = Vec::new();
    let (mut rising, mut top) = (false, f64::MIN);
    for _ in 0..sim.steps_for(3.2) {
        sim.step()?;
        let s = sim.state(b);
        let (y, vy) = (s.position[1] as f64 - rest, s.linear_velocity[1]);
        if vy > 0.0 {
            rising = true;
            top = top.max(y);
        } else if rising {
            apexes.push(top.max(y));
            (rising, top) = (false, f64::MIN);
        }
    }
    let worst = (1..=3)
        .map(|n| {
            let exact = e.powi(2 * n) * h0;
            // A missing bounce is a 100 % error.
            apexes
                .get(n as usize - 1)
                .map_or(1.0, |h| (h - exact).abs() / exact)
        })
        .fold(0.0, f64::max);
    outcome(&sim, worst)
}

/// Both sides carry μ, so the pair's friction sqrt(μ·μ) is μ.
fn friction(mu: f64) -> ObjectProp {
    ObjectProp::Friction(mu as f32)
}

fn sliding_block(c: Config) -> BenchResult<Outcome> {
    let (mu, v0) = (0.5f64, 10.0f64);
    let mut sim = Sim::new(c, &UNDAMPED)?;
    floor(&mut sim, 100.0, &[friction(mu)])?;
    let y = 0.5 + c.pair_gap();
    let b = sim.add(
        cube(1.0),
        Pose::at([0.0, y, 0.0]),
        &[friction(mu), ObjectProp::Velocity([v0 as f32, 0.0, 0.0])],
    )?;
    // Stops after v0/(μ·g) = 0.4 s; 1 s leaves time to settle.
    for _ in 0..sim.steps_for(1.0) {
        sim.step()?;
    }
    let exact = v0 * v0 / (2.0 * mu * G);
    outcome(&sim, (sim.state(b).position[0] as f64 - exact).abs())
}

/// A 60-long anchored slab tilted by `theta` (downhill toward +x) whose top face passes
/// through the origin, and a unit box resting on it at the origin. Returns the box and the
/// downhill unit vector.
fn incline(sim: &mut Sim, theta: f64, mu: f64) -> BenchResult<(client_sdk::Handle, [f64; 3])> {
    let (s, co) = (theta.sin(), theta.cos());
    let normal = [s, co, 0.0];
    let downhill = [co, -s, 0.0];
    let rotation = about_z(-theta as f32);
    let at = |d: f64| {
        let p: Vec<f32> = normal.iter().map(|n| (n * d) as f32).collect();
        [p[0], p[1], p[2]]
    };
    anchored_box(
        sim,
        [60.0, 1.0, 10.0],
        Pose {
            position: at(-0.5),
            rotation,
        },
        &[friction(mu)],
    )?;
    let gap = sim.config.pair_gap() as f64;
    let b = sim.add(
        cube(1.0),
        Pose {
            position: at(0.5 + gap),
            rotation,
        },
        &[friction(mu)],
    )?;
    Ok((b, downhill))
}

/// Distance travelled downhill since the start.
fn downhill_travel(sim: &Sim, b: client_sdk::Handle, start: [f32; 3], dir: [f64; 3]) -> f64 {
    let p = sim.state(b).position;
    (0..3).map(|i| (p[i] - start[i]) as f64 * dir[i]).sum()
}

fn incline_hold(c: Config) -> BenchResult<Outcome> {
    let mut sim = Sim::new(c, &UNDAMPED)?;
    let (b, _) = incline(&mut sim, 20f64.to_radians(), 0.6)?;
    let start = sim.state(b).position;
    for _ in 0..sim.steps_for(2.0) {
        sim.step()?;
    }
    outcome(&sim, distance(sim.state(b).position, start))
}

fn incline_slide(c: Config) -> BenchResult<Outcome> {
    let (theta, mu) = (40f64.to_radians(), 0.3);
    let mut sim = Sim::new(c, &UNDAMPED)?;
    let (b, dir) = incline(&mut sim, theta, mu)?;
    let start = sim.state(b).position;
    for _ in 0..sim.steps_for(1.0) {
        sim.step()?;
    }
    let a = G * (theta.sin() - mu * theta.cos());
    let t = sim.time();
    outcome(
        &sim,
        (downhill_travel(&sim, b, start, dir) - a * t * t / 2.0).abs(),
    )
}

fn free_rotation(c: Config) -> BenchResult<Outcome> {
    let mut props = UNDAMPED.to_vec();
    props.push(PlaneProp::Gravity([0.0; 3]));
    let mut sim = Sim::new(c, &props)?;
    let (a, b_, c_) = (1.0f64, 2.0f64, 3.0f64);
    // A CenterOfMass keeps rotation free at HitBoxQuality 1 (the plane keeps the shape's
    // principal inertia; a 1 mm offset only moves the point it turns about).
    let b = sim.add(
        Shape::Cube {
            size: [a as f32, b_ as f32, c_ as f32],
        },
        Pose::at([0.0; 3]),
        &[
            ObjectProp::CenterOfMass([0.0, 0.0, 1e-3]),
            ObjectProp::AngularVelocity([0.4, 3.0, 0.3]),
        ],
    )?;
    let inertia = [
        (b_ * b_ + c_ * c_) / 12.0,
        (a * a + c_ * c_) / 12.0,
        (a * a + b_ * b_) / 12.0,
    ];
    let (l0, e0) = momentum_energy(&sim.state(b), inertia);
    let mut worst = 0.0f64;
    for _ in 0..sim.steps_for(5.0) {
        sim.step()?;
        let (l, e) = momentum_energy(&sim.state(b), inertia);
        let dl = (l - l0).length() / l0.length();
        worst = worst.max(dl).max((e - e0).abs() / e0);
    }
    outcome(&sim, worst)
}

/// World angular momentum `R·I·Rᵀ·ω` and kinetic energy `ω·L/2` of a body with principal
/// inertia `inertia` (unit mass) along its local axes.
fn momentum_energy(s: &client_sdk::BodyState, inertia: [f64; 3]) -> (DVec3, f64) {
    let [x, y, z, w] = s.rotation.map(|v| v as f64);
    let q = DQuat::from_xyzw(x, y, z, w);
    let omega = DVec3::from(s.angular_velocity.map(|v| v as f64));
    // Body frame: L_local = I·(Rᵀ·ω); back to the world with R.
    let l = q * (DVec3::from(inertia) * (q.inverse() * omega));
    (l, 0.5 * omega.dot(l))
}

/// A 5-box stack resting on a floor, each box placed at its rest height. Returns the drift
/// (largest displacement of any box between 1 s, once the contacts have settled into their
/// skin, and 3 s) and the deepest penetration seen over the 3 s.
fn resting_stack(c: Config) -> BenchResult<(Sim, f64, f64)> {
    let mut sim = Sim::new(c, &[])?;
    floor(&mut sim, 50.0, &[])?;
    let boxes = column(&mut sim, [0.0; 3], 1.0, 5, 0.0, c.pair_gap(), |_| vec![])?;
    let mut deepest = 0.0f64;
    let mut settled = Vec::new();
    for _ in 0..sim.steps_for(3.0) {
        sim.step()?;
        deepest = deepest.max(sim.header().max_penetration as f64);
        if settled.is_empty() && sim.time() >= 1.0 {
            settled = boxes.iter().map(|h| sim.state(*h).position).collect();
        }
    }
    let drift = boxes
        .iter()
        .zip(&settled)
        .map(|(h, p)| distance(sim.state(*h).position, *p))
        .fold(0.0, f64::max);
    Ok((sim, drift, deepest))
}

fn elastic_collision(c: Config) -> BenchResult<Outcome> {
    let mut props = UNDAMPED.to_vec();
    props.push(PlaneProp::Gravity([0.0; 3]));
    props.push(PlaneProp::RestThreshold(0.0));
    let mut sim = Sim::new(c, &props)?;
    let v = 10.0f64;
    let e1 = [ObjectProp::Bounciness(1.0), ObjectProp::Friction(0.0)];
    let a = ball(
        &mut sim,
        [-3.0, 0.0, 0.0],
        &[
            e1[0],
            e1[1],
            ObjectProp::Weight(1.0),
            ObjectProp::Velocity([v as f32, 0.0, 0.0]),
        ],
    )?;
    let b = ball(
        &mut sim,
        [0.0, 0.0, 0.0],
        &[e1[0], e1[1], ObjectProp::Weight(2.0)],
    )?;
    // Both balls at HitBoxQuality 1 have locked rotation; masses are set by Weight.
    let (m1, m2) = (1.0f64, 2.0f64);
    let p0 = m1 * v;
    let e0 = 0.5 * m1 * v * v;
    sim.run_for(1.0)?;
    let (va, vb) = (sim.state(a).linear_velocity, sim.state(b).linear_velocity);
    let p = [0, 1, 2].map(|i| m1 * va[i] as f64 + m2 * vb[i] as f64);
    let dp = ((p[0] - p0).powi(2) + p[1].powi(2) + p[2].powi(2)).sqrt() / p0;
    let e = 0.5 * m1 * distance(va, [0.0; 3]).powi(2) + 0.5 * m2 * distance(vb, [0.0; 3]).powi(2);
    outcome(&sim, dp.max((e - e0).abs() / e0))
}

fn pile_666(c: Config) -> BenchResult<Outcome> {
    let mut sim = Sim::new(c, &[])?;
    floor(&mut sim, 20.0, &[])?;
    // Four walls around a 7 × 7 bin.
    for (x, z, sx, sz) in [
        (4.0f32, 0.0f32, 1.0f32, 9.0f32),
        (-4.0, 0.0, 1.0, 9.0),
        (0.0, 4.0, 9.0, 1.0),
        (0.0, -4.0, 9.0, 1.0),
    ] {
        anchored_box(&mut sim, [sx, 20.0, sz], Pose::at([x, 10.0, z]), &[])?;
    }
    for i in 0..6 {
        for j in 0..6 {
            for k in 0..6 {
                let at = |n: usize| (n as f32 - 2.5) * 1.1;
                ball(&mut sim, [at(i), 1.0 + j as f32 * 1.1, at(k)], &[])?;
            }
        }
    }
    let mut deepest = 0.0f64;
    let steps = sim.steps_for(3.0);
    for n in 0..steps {
        sim.step()?;
        if n >= steps - sim.steps_for(1.0) {
            deepest = deepest.max(sim.header().max_penetration as f64);
        }
    }
    outcome(&sim, deepest)
}

fn stack_drift(c: Config) -> BenchResult<Outcome> {
    let (sim, drift, _) = resting_stack(c)?;
    outcome(&sim, drift)
}

fn stack_penetration(c: Config) -> BenchResult<Outcome> {
    let (sim, _, deepest) = resting_stack(c)?;
    outcome(&sim, deepest)
}

/// A small ball on a hinge joint to the world at (0, 10, 0), released from θ0.
fn hinge_pendulum(c: Config) -> BenchResult<Outcome> {
    use physics_daemon::backend::Backend;
    use shm_layout::{JointKind, JointOp, JointProp, PlaneOp};
    let (l, theta0) = (2.0f64, 0.3f64);
    let mut sim = Sim::new(c, &UNDAMPED)?;
    let pivot = [0.0f32, 10.0, 0.0];
    let start = [
        (l * theta0.sin()) as f32,
        (10.0 - l * theta0.cos()) as f32,
        0.0,
    ];
    let bob = sim.add(
        Shape::Sphere { radius: 0.05 },
        Pose::at(start),
        &[ObjectProp::Weight(1.0)],
    )?;
    Backend::apply(
        &mut sim.plane,
        PlaneOp::Joint(JointOp::Create {
            kind: JointKind::Hinge,
            a: bob,
            b: None,
            props: vec![
                JointProp::AnchorA([pivot[0] - start[0], pivot[1] - start[1], 0.0]),
                JointProp::AnchorB(pivot),
                JointProp::Axis([0.0, 0.0, 1.0]),
            ],
        }),
    )
    .map_err(|e| crate::error::BenchError::Failed(e.to_string()))?;
    // Upward zero crossings of x, interpolated within the tick.
    let mut crossings = Vec::new();
    let mut last = (0.0f64, sim.state(bob).position[0] as f64);
    for _ in 0..sim.steps_for(6.0) {
        sim.step()?;
        let now = (sim.time(), sim.state(bob).position[0] as f64);
        if last.1 < 0.0 && now.1 >= 0.0 {
            crossings.push(last.0 + (now.0 - last.0) * (-last.1) / (now.1 - last.1));
        }
        last = now;
    }
    let exact = 2.0 * std::f64::consts::PI * (l / G).sqrt() * (1.0 + theta0 * theta0 / 16.0);
    let error = match crossings.len() {
        n if n >= 2 => {
            let period = (crossings[n - 1] - crossings[0]) / (n - 1) as f64;
            (period - exact).abs() / exact
        }
        _ => f64::INFINITY,
    };
    outcome(&sim, error)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn angular_momentum_of_a_turned_body_is_rotated() {
        // Body turned 90° about z, spinning about world x = its local −y axis.
        let s = client_sdk::BodyState {
            rotation: about_z(std::f32::consts::FRAC_PI_2),
            angular_velocity: [2.0, 0.0, 0.0],
            ..Default::default()
        };
        let (l, e) = momentum_energy(&s, [1.0, 3.0, 5.0]);
        assert!((l[0] - 6.0).abs() < 1e-6 && l[1].abs() < 1e-6, "{l:?}");
        assert!((e - 6.0).abs() < 1e-6, "{e}");
    }
}

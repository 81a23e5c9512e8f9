//! Stress scenes after Box2D / Solver2D and PEEL, each with a pass criterion checked
//! automatically. Every scene also fails when any body turns non-finite on any tick.
//!
//! PEEL's "chain with a heavy end" runs with ball joints (`chain-1000`), next to its
//! contact analogue: a column of light boxes carrying a heavy one.

use client_sdk::{Handle, ObjectProp, Pin, PlaneProp, Pose};
use physics_scenes::{ball, column, floor, launched_box, overlapping_pile, thin_wall};
use shm_layout::settings::plane::DEFAULT_MAX_LINEAR_SPEED;

use super::check::Check;
use super::stress;
use crate::error::BenchResult;
use crate::sim::{distance, Config, Sim};

/// A scene at one configuration.
pub struct Scene {
    pub name: &'static str,
    /// The pass criterion in words.
    pub criterion: &'static str,
    pub unit: &'static str,
    pub config: Config,
    pub run: fn(Config) -> BenchResult<Check>,
}

const Q4: Config = Config {
    hit_box_quality: 4,
    ..Config::DEFAULT
};

pub const SCENES: &[Scene] = &[
    Scene {
        name: "chain-1000",
        criterion: "a 20-link ball-joint chain whose last link is 1,000× heavier: worst joint error (tick header) over 5 s ≤ 0.01 at the defaults (an articulation; as impulse joints ~50 at the defaults, 0.98 at SolverIterations 16)",
        unit: "units",
        config: Config::DEFAULT,
        run: chain_1000,
    },
    Scene {
        name: "stack-15",
        criterion: "top box of a 15-box stack (0.02 side offsets) drifts ≤ 0.05 sideways in 10 s, none falls",
        unit: "units",
        config: Config::DEFAULT,
        run: |c| stack(c, 15, 10.0),
    },
    Scene {
        name: "stack-15-q4",
        criterion: "the same at HitBoxQuality 4 (boxes free to rotate)",
        unit: "units",
        config: Q4,
        run: |c| stack(c, 15, 10.0),
    },
    Scene {
        name: "pyramid-20",
        criterion: "no box of a base-20 pyramid (210 boxes) moves ≥ 0.1 from where it settled (t = 1 s) by t = 10 s",
        unit: "units",
        config: Config::DEFAULT,
        run: pyramid,
    },
    Scene {
        name: "pyramid-20-q4",
        criterion: "the same at HitBoxQuality 4",
        unit: "units",
        config: Q4,
        run: pyramid,
    },
    Scene {
        name: "mass-ratio-100-stack",
        criterion: "a box 100× heavier on a light one sinks ≤ 0.05 below its rest height",
        unit: "units",
        config: Config::DEFAULT,
        run: |c| heavy_on_light(c, 100.0, 1),
    },
    Scene {
        name: "mass-ratio-1000-stack",
        criterion: "a box 1,000× heavier on a light one sinks ≤ 0.05",
        unit: "units",
        config: Config::DEFAULT,
        run: |c| heavy_on_light(c, 1000.0, 1),
    },
    Scene {
        name: "mass-ratio-100-column",
        criterion: "a box 100× heavier on a column of 4 light boxes (the chain's stand-in) sinks ≤ 0.05",
        unit: "units",
        config: Config::DEFAULT,
        run: |c| heavy_on_light(c, 100.0, 4),
    },
    Scene {
        name: "mass-ratio-1000-column",
        criterion: "a box 1,000× heavier on a column of 4 light boxes sinks ≤ 0.05",
        unit: "units",
        config: Config::DEFAULT,
        run: |c| heavy_on_light(c, 1000.0, 4),
    },
    Scene {
        name: "fast-box-400-q4",
        criterion: "a 0.5 box at 400 units/s ends in front of a 0.1-thick wall (no tunnelling) at HitBoxQuality 4",
        unit: "units past the wall's front face",
        config: Q4,
        run: |c| fast_box(c, 400.0),
    },
    Scene {
        name: "fast-box-400-q32",
        criterion: "the same at HitBoxQuality 32",
        unit: "units past the wall's front face",
        config: Config {
            hit_box_quality: 32,
            ..Config::DEFAULT
        },
        run: |c| fast_box(c, 400.0),
    },
    Scene {
        name: "speed-cap",
        criterion: "MaxLinearSpeed (default 10,000, rapier's normalized_max_linear_velocity): a body launched at 20,000 units/s moves at ≤ 10,000 after one step",
        unit: "units/s",
        config: Config::DEFAULT,
        run: speed_cap,
    },
    Scene {
        name: "overlap-25",
        criterion: "a 3×3×3 pile started with 25 % overlap separates (penetration ≤ 0.05 at 3 s) with no body ever faster than 10 units/s",
        unit: "units/s (fastest body)",
        config: Config::DEFAULT,
        run: overlap,
    },
    Scene {
        name: "far-from-origin",
        criterion: "a 5-box stack and a dropped ball at x = z = 100,000: the stack drifts ≤ 0.05 from 1 s to 5 s and the ball rests on the floor",
        unit: "units",
        config: Config::DEFAULT,
        run: far_from_origin,
    },
    Scene {
        name: "tiny-5cm",
        criterion: "a 3-box stack of 5 cm boxes drifts ≤ 0.005 (10 % of a box) from 1 s to 5 s and a 5 cm ball dropped from 1 unit stays above the floor",
        unit: "units",
        config: Config::DEFAULT,
        run: tiny,
    },
    Scene {
        name: "tiny-5cm-q32",
        criterion: "the same at HitBoxQuality 32 (skin 0.02/32 per pair)",
        unit: "units",
        config: Config {
            hit_box_quality: 32,
            ..Config::DEFAULT
        },
        run: tiny,
    },
    Scene {
        name: "extreme-drag",
        criterion: "Drag 1e6 on a falling ball: speed never exceeds v_t (drag and gravity are integrated together, backward Euler) and never points up",
        unit: "units/s",
        config: Config::DEFAULT,
        run: extreme_drag,
    },
    Scene {
        name: "extreme-buoyancy",
        criterion: "Buoyancy 1e4: the velocity after 2 ticks matches (B − g)·t within 0.1 %",
        unit: "fraction",
        config: Config::DEFAULT,
        run: extreme_buoyancy,
    },
    Scene {
        name: "extreme-constant-force",
        criterion: "ConstantForce 1e9 on a unit mass for 1 s: stays finite, speed held at MaxLinearSpeed (10,000)",
        unit: "units/s",
        config: Config::DEFAULT,
        run: extreme_constant_force,
    },
    Scene {
        name: "extreme-pin",
        criterion: "SetPin with force 1e6 pulls a unit-mass ball 10 units: within 0.01 of the target after 2 s",
        unit: "units",
        config: Config::DEFAULT,
        run: extreme_pin,
    },
    Scene {
        name: "tick-rate-10",
        criterion: "at TickRate 10 a 5-box stack drifts ≤ 0.05 from 1 s to 5 s and a dropped ball rests on the floor",
        unit: "units",
        config: Config {
            tick_rate: 10,
            ..Config::DEFAULT
        },
        run: stack_and_ball,
    },
    Scene {
        name: "determinism",
        criterion: "the determinism scene (base-6 pyramid, 12 bouncing balls, quality 4) run twice with Threads = 1 and once with Threads = 2: the tick header's state hash agrees on all 180 ticks",
        unit: "ticks that differ",
        config: Config::DEFAULT,
        run: stress::determinism,
    },
    Scene {
        name: "friction-ramp",
        criterion: "0.25 rad ramp (μ 0.2), boxes μ 0.75 / 0.5 / 0.35 / 0.1 / 0 (pair √(μ1μ2)): the first three move ≤ 0.05 in 2 s, the last two slide ≥ 1",
        unit: "units (worst holding box)",
        config: Config::DEFAULT,
        run: stress::friction_ramp,
    },
    Scene {
        name: "friction-ramp-q4",
        criterion: "the same at HitBoxQuality 4 (boxes free to rotate)",
        unit: "units (worst holding box)",
        config: Q4,
        run: stress::friction_ramp,
    },
    Scene {
        name: "card-house-q4",
        criterion: "at HitBoxQuality 4 (cards free to rotate), Box2D's card house (0.4 × 0.002 cards, μ 0.7, ±25°, 5 levels, 40 cards, g = 9.81) stands 10 s: after 0.5 s of settling from Box2D's start positions (whose gaps alone lower the top pair by ~2 cm), no card gets more than 0.02 from where it settled",
        unit: "units",
        config: Q4,
        run: stress::card_house,
    },
    Scene {
        name: "confined-625",
        criterion: "625 unit balls started 10 % overlapping in a closed box, no gravity: no ball faster than 5 units/s in the 4th second, and its kinetic energy no larger than the 2nd second's (no growing jitter)",
        unit: "units/s",
        config: Config::DEFAULT,
        run: stress::confined,
    },
    Scene {
        name: "rush",
        criterion: "400 balls pulled to the centre by a force of 1,000 each for 3 s, no gravity: finite, no ball faster than 1.1 × √(2·F/m·r0) (a free fall from the farthest start)",
        unit: "units/s",
        config: Config::DEFAULT,
        run: stress::rush,
    },
    Scene {
        name: "smash",
        criterion: "a sleeping 5×5×5 block of boxes hit by 100 balls at 40 units/s: finite, nothing faster than 80 units/s afterwards",
        unit: "units/s",
        config: Config::DEFAULT,
        run: stress::smash,
    },
    Scene {
        name: "pyramid-100",
        criterion: "no box of a base-100 pyramid (5,050 boxes, sleeping off) moves ≥ 0.1 from t = 1 s to t = 10 s (stepped on 2 threads: the same results as 1)",
        unit: "units",
        config: Config::DEFAULT,
        run: stress::pyramid_100,
    },
    Scene {
        name: "thin-rods-q4",
        criterion: "0.05 × 0.05 × 2 rods at 200 units/s (broadside, sideways and end-on) end in front of a 0.1 wall at HitBoxQuality 4 (CCD)",
        unit: "units past the wall's front face",
        config: Q4,
        run: stress::thin_rods,
    },
    Scene {
        name: "tick-rate-1000",
        criterion: "the same at TickRate 1,000",
        unit: "units",
        config: Config {
            tick_rate: 1000,
            ..Config::DEFAULT
        },
        run: stack_and_ball,
    },
    Scene {
        name: "ragdoll-1000-limits",
        criterion: "the default humanoid ragdoll (an articulation) hit in the chest by a ball of a bone's weight at 1,000 units/s, at the defaults: worst swing/twist limit overshoot over 3 s ≤ 0.2 rad (was 1.23 as impulse joints at SolverIterations 16)",
        unit: "rad",
        config: Config::DEFAULT,
        run: ragdoll_limits,
    },
    Scene {
        name: "ragdoll-1000-anchors",
        criterion: "the same hit: worst anchor separation of any joint over 3 s ≤ 0.02 (was 0.49)",
        unit: "units",
        config: Config::DEFAULT,
        run: ragdoll_anchors,
    },
    Scene {
        name: "ragdoll-1000-pass-through",
        criterion: "the same hit (ball and bones at HitBoxQuality 2, CCD): how far the ball's centre gets behind the UpperTorso's back (its centre − radius 0.5 − ball radius 0.4, along the shot) in the first 0.5 s ≤ 0 (never passes through)",
        unit: "units",
        config: Config::DEFAULT,
        run: ragdoll_pass_through,
    },
];

/// `--quick`'s stand-in for `pyramid-100`.
pub const PYRAMID_40: Scene = Scene {
    name: "pyramid-40",
    criterion: "no box of a base-40 pyramid (820 boxes, sleeping off) moves ≥ 0.1 from t = 1 s to t = 10 s (`--quick`'s stand-in for pyramid-100)",
    unit: "units",
    config: Config::DEFAULT,
    run: |c| stress::large_pyramid(c, 40),
};

const G: f64 = 50.0;

/// Largest sideways (x, z) distance between two positions.
fn sideways(a: [f32; 3], b: [f32; 3]) -> f64 {
    distance([a[0], 0.0, a[2]], [b[0], 0.0, b[2]])
}

/// A stack of `n` unit boxes; figure = sideways drift of the top box (∞ if it dropped by
/// more than half a box: the stack fell).
pub fn stack(c: Config, n: usize, seconds: f32) -> BenchResult<Check> {
    let mut sim = Sim::new(c, &[])?;
    floor(&mut sim, 100.0, &[])?;
    let boxes = column(&mut sim, [0.0; 3], 1.0, n, 0.01, c.pair_gap(), |_| vec![])?;
    let top = *boxes.last().expect("n > 0");
    let start = sim.state(top).position;
    sim.run_for(seconds)?;
    let end = sim.state(top).position;
    let fell = end[1] < start[1] - 0.5;
    let figure = if fell {
        f64::INFINITY
    } else {
        sideways(end, start)
    };
    Ok(Check::at_most(&sim, figure, 0.05))
}

fn pyramid(c: Config) -> BenchResult<Check> {
    super::stress::pyramid_drift(c, 20, &[], 100.0, 9.0)
}

/// `light` unit boxes of mass 1 with a unit box of mass `ratio` on top; figure = how far the
/// heavy box sank below its rest height after 3 s (∞ when it fell off).
pub fn heavy_on_light(c: Config, ratio: f64, light: usize) -> BenchResult<Check> {
    let mut sim = Sim::new(c, &[])?;
    floor(&mut sim, 100.0, &[])?;
    let boxes = column(&mut sim, [0.0; 3], 1.0, light + 1, 0.0, c.pair_gap(), |i| {
        if i == light {
            vec![ObjectProp::Weight(ratio as f32)]
        } else {
            vec![]
        }
    })?;
    let heavy = *boxes.last().expect("light + 1 > 0");
    let rest = sim.state(heavy).position;
    sim.run_for(3.0)?;
    let end = sim.state(heavy).position;
    let figure = if sideways(end, rest) > 0.5 {
        f64::INFINITY
    } else {
        (rest[1] - end[1]).max(0.0) as f64
    };
    Ok(Check::at_most(&sim, figure, 0.05))
}

/// A 0.5 box launched at `speed` toward an anchored wall 0.1 thick whose front face is at
/// x = 0, no gravity. Figure = how far the box centre got past the front face, less the
/// half-size and contact gap (≤ 0: it stayed in front).
pub fn fast_box(c: Config, speed: f64) -> BenchResult<Check> {
    let mut sim = Sim::new(c, &[PlaneProp::Gravity([0.0; 3])])?;
    thin_wall(&mut sim, &[])?;
    let b = launched_box(&mut sim, -30.0, speed as f32, &[])?;
    sim.run_for(1.0)?;
    let x = sim.state(b).position[0] as f64;
    let past = x + 0.25;
    // Resting against the face leaves a gap; a tolerance of 0.01 covers solver softness.
    Ok(Check::at_most(&sim, past, 0.01))
}

fn speed_cap(c: Config) -> BenchResult<Check> {
    let mut sim = Sim::new(c, &[PlaneProp::Gravity([0.0; 3])])?;
    let b = launched_box(&mut sim, 0.0, 20_000.0, &[])?;
    sim.step()?;
    let v = sim.state(b).linear_velocity;
    let speed = distance(v, [0.0; 3]);
    Ok(Check::at_most(
        &sim,
        speed,
        DEFAULT_MAX_LINEAR_SPEED as f64 * (1.0 + 1e-5),
    ))
}

fn overlap(c: Config) -> BenchResult<Check> {
    let mut sim = Sim::new(c, &[])?;
    floor(&mut sim, 100.0, &[])?;
    let boxes = overlapping_pile(&mut sim)?;
    let mut fastest = 0.0f64;
    for _ in 0..sim.steps_for(3.0) {
        sim.step()?;
        for h in &boxes {
            fastest = fastest.max(distance(sim.state(*h).linear_velocity, [0.0; 3]));
        }
    }
    let separated = sim.header().max_penetration <= 0.05;
    let mut check = Check::at_most(&sim, fastest, 10.0);
    check.pass &= separated;
    Ok(check)
}

/// A 5-box stack and a ball dropped from 5 units, both standing on a floor centred at
/// `origin`. Figure = the stack's largest drift from 1 s to `seconds` (∞ if the ball sank
/// under the floor's top or flew off).
fn stack_and_ball_at(
    c: Config,
    origin: [f32; 3],
    side: f32,
    seconds: f32,
    bound: f64,
) -> BenchResult<Check> {
    let mut sim = Sim::new(c, &[])?;
    let [ox, oy, oz] = origin;
    let (n, drop) = if side < 1.0 { (3, 1.0) } else { (5, 5.0) };
    let built = physics_scenes::stack_and_ball(&mut sim, origin, side, n, drop, c.pair_gap(), &[])?;
    let (boxes, ball) = (built.boxes, built.ball);
    sim.run_for(1.0)?;
    let settled: Vec<[f32; 3]> = boxes.iter().map(|h| sim.state(*h).position).collect();
    sim.run_for(seconds - 1.0)?;
    let drift = boxes
        .iter()
        .zip(&settled)
        .map(|(h, p)| distance(sim.state(*h).position, *p))
        .fold(0.0, f64::max);
    let b = sim.state(ball).position;
    let ball_rests =
        b[1] > oy && b[1] < oy + side && sideways(b, [ox, oy, oz]) < 50.0 * side as f64;
    let figure = if ball_rests { drift } else { f64::INFINITY };
    Ok(Check::at_most(&sim, figure, bound))
}

fn far_from_origin(c: Config) -> BenchResult<Check> {
    stack_and_ball_at(c, [100_000.0, 0.0, 100_000.0], 1.0, 5.0, 0.05)
}

fn tiny(c: Config) -> BenchResult<Check> {
    // 10 % of a box.
    stack_and_ball_at(c, [0.0; 3], 0.05, 5.0, 0.005)
}

fn stack_and_ball(c: Config) -> BenchResult<Check> {
    stack_and_ball_at(c, [0.0; 3], 1.0, 5.0, 0.05)
}

fn falling_ball(sim: &mut Sim) -> BenchResult<Handle> {
    ball(sim, [0.0, 100.0, 0.0], &[])
}

fn extreme_drag(c: Config) -> BenchResult<Check> {
    let drag = 1e6f64;
    let mut sim = Sim::new(c, &[PlaneProp::Drag(drag as f32)])?;
    let b = falling_ball(&mut sim)?;
    let (mut fastest, mut upward) = (0.0f64, false);
    for _ in 0..sim.steps_for(1.0) {
        sim.step()?;
        let v = sim.state(b).linear_velocity;
        fastest = fastest.max(distance(v, [0.0; 3]));
        upward |= v[1] > 0.0;
    }
    // Drag and gravity are one backward-Euler update: from rest the speed rises to v_t and
    // never past it. f32 rounding: 1e-5 relative.
    let bound = (G / drag).sqrt() * (1.0 + 1e-5);
    let mut check = Check::at_most(&sim, fastest, bound);
    check.pass &= !upward;
    Ok(check)
}

fn extreme_buoyancy(c: Config) -> BenchResult<Check> {
    let b_acc = 1e4f64;
    let mut sim = Sim::new(
        c,
        &[
            PlaneProp::Buoyancy(b_acc as f32),
            PlaneProp::LinearDamping(0.0),
        ],
    )?;
    let b = falling_ball(&mut sim)?;
    sim.step()?;
    sim.step()?;
    let exact = (b_acc - G) * sim.time();
    let v = sim.state(b).linear_velocity[1] as f64;
    Ok(Check::at_most(&sim, (v - exact).abs() / exact, 1e-3))
}

fn extreme_constant_force(c: Config) -> BenchResult<Check> {
    let mut sim = Sim::new(c, &[PlaneProp::ConstantForce([1e9, 0.0, 0.0])])?;
    let b = falling_ball(&mut sim)?;
    let mut fastest = 0.0f64;
    for _ in 0..sim.steps_for(1.0) {
        sim.step()?;
        fastest = fastest.max(distance(sim.state(b).linear_velocity, [0.0; 3]));
    }
    Ok(Check::at_most(
        &sim,
        fastest,
        DEFAULT_MAX_LINEAR_SPEED as f64 * (1.0 + 1e-5),
    ))
}

fn extreme_pin(c: Config) -> BenchResult<Check> {
    let mut sim = Sim::new(c, &[])?;
    let b = ball(&mut sim, [0.0, 10.0, 0.0], &[])?;
    let target = [10.0, 10.0, 0.0];
    sim.plane.set_object(
        b,
        ObjectProp::Pin(Some(Pin {
            force: 1e6,
            relative: [0.0; 3],
            target: Pose::at(target),
        })),
    )?;
    sim.run_for(2.0)?;
    let d = distance(sim.state(b).position, target);
    Ok(Check::at_most(&sim, d, 0.01))
}

/// 20 balls 0.5 apart joined by ball joints, hung from the world, the last 1,000× heavier.
fn chain_1000(c: Config) -> BenchResult<Check> {
    use physics_daemon::backend::Backend;
    use shm_layout::{JointKind, JointOp, JointProp, PlaneOp, Shape};
    let mut sim = Sim::new(
        c,
        &[
            PlaneProp::LinearDamping(0.0),
            PlaneProp::AngularDamping(0.0),
        ],
    )?;
    let mut prev: Option<Handle> = None;
    for i in 0..20 {
        let weight = if i == 19 { 1000.0 } else { 1.0 };
        let link = sim.add(
            Shape::Sphere { radius: 0.2 },
            Pose::at([i as f32 * 0.5 + 0.5, 20.0, 0.0]),
            &[ObjectProp::Weight(weight)],
        )?;
        let anchor_b = match prev {
            Some(_) => [0.5, 0.0, 0.0],
            None => [0.5, 20.0, 0.0],
        };
        Backend::apply(
            &mut sim.plane,
            PlaneOp::Joint(JointOp::Create {
                kind: JointKind::Ball,
                a: link,
                b: prev,
                props: vec![JointProp::AnchorA([0.0; 3]), JointProp::AnchorB(anchor_b)],
            }),
        )
        .map_err(|e| crate::error::BenchError::Failed(e.to_string()))?;
        prev = Some(link);
    }
    let mut worst = 0.0f64;
    for _ in 0..sim.steps_for(5.0) {
        sim.step()?;
        worst = worst.max(sim.header().max_joint_error as f64);
    }
    Ok(Check::at_most(&sim, worst, 0.01))
}

/// What a ragdoll hit measured: worst limit overshoot (rad), worst anchor separation, and
/// how far the ball got behind the chest in the first 0.5 s.
struct RagdollHit {
    sim: Sim,
    overshoot: f64,
    separation: f64,
    behind: f64,
}

/// The default humanoid standing on a floor, hit in the chest at 1,000 units/s by a ball of
/// a bone's weight starting 0.02 in front of it (as tests/tests/ragdoll.rs), for 3 s.
fn ragdoll_hit(c: Config) -> BenchResult<RagdollHit> {
    use client_sdk::ragdoll::BONE_PROPS;
    use client_sdk::{JointKind, RagdollDesc, Shape};
    use physics_daemon::backend::Backend;
    use shm_layout::{JointOp, PlaneOp, Reply};
    let failed = |e: shm_layout::CommandError| crate::error::BenchError::Failed(e.to_string());
    let mut sim = Sim::new(c, &[])?;
    floor(&mut sim, 200.0, &[])?;
    let desc = RagdollDesc::humanoid(Pose::at([0.0, 2.95, 0.0]), 1.0);
    let mut bones = Vec::new();
    for b in &desc.bones {
        bones.push(sim.add(b.shape(), b.pose, &BONE_PROPS)?);
    }
    let mut joints = Vec::new();
    for i in 0..desc.bones.len() {
        if let Some((p, props)) = desc.joint_of(i) {
            let r = Backend::apply(
                &mut sim.plane,
                PlaneOp::Joint(JointOp::Create {
                    kind: JointKind::ConeTwist,
                    a: bones[i],
                    b: Some(bones[p]),
                    props,
                }),
            )
            .map_err(failed)?;
            if let Reply::Joint { handle, .. } = r {
                joints.push(handle);
            }
        }
    }
    let torso = desc
        .bones
        .iter()
        .position(|b| b.name == "UpperTorso")
        .map(|i| bones[i])
        .expect("the humanoid has an UpperTorso");
    let ball = sim.add(
        Shape::Sphere { radius: 0.4 },
        Pose::at([0.0, 4.15, 0.92]),
        &[
            ObjectProp::Weight(1.0),
            ObjectProp::HitBoxQuality(2),
            ObjectProp::Velocity([0.0, 0.0, -1000.0]),
        ],
    )?;
    let (mut overshoot, mut separation, mut behind) = (0.0f64, 0.0f64, f64::MIN);
    for _ in 0..sim.steps_for(3.0) {
        sim.step()?;
        for j in &joints {
            let r = Backend::apply(&mut sim.plane, PlaneOp::Joint(JointOp::Info { joint: *j }))
                .map_err(failed)?;
            if let Reply::JointInfo(info) = r {
                overshoot = overshoot.max(info.angular_error as f64);
                separation = separation.max(info.error as f64);
            }
        }
        if sim.time() <= 0.5 {
            let (t, b) = (sim.state(torso).position[2], sim.state(ball).position[2]);
            behind = behind.max((t - 0.5 - 0.4 - b) as f64);
        }
    }
    Ok(RagdollHit {
        sim,
        overshoot,
        separation,
        behind,
    })
}

fn ragdoll_limits(c: Config) -> BenchResult<Check> {
    let h = ragdoll_hit(c)?;
    Ok(Check::at_most(&h.sim, h.overshoot, 0.2))
}

fn ragdoll_anchors(c: Config) -> BenchResult<Check> {
    let h = ragdoll_hit(c)?;
    Ok(Check::at_most(&h.sim, h.separation, 0.02))
}

fn ragdoll_pass_through(c: Config) -> BenchResult<Check> {
    let h = ragdoll_hit(c)?;
    Ok(Check::at_most(&h.sim, h.behind, 0.0))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_failed_or_non_finite_run_does_not_pass() {
        let sim = Sim::new(Config::DEFAULT, &[]).unwrap();
        assert!(Check::at_most(&sim, 0.01, 0.05).pass);
        assert!(!Check::at_most(&sim, 0.06, 0.05).pass);
        let c = Check::at_most(&sim, f64::INFINITY, 0.05);
        assert!(!c.pass && c.finite);
        assert!(!Check::at_most(&sim, f64::NAN, 0.05).pass);
    }
}

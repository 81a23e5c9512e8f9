//! The stress scenes of Box2D v3 / Solver2D and PEEL beyond stacks and mass ratios: a
//! friction ramp, a card house, 625 over-packed balls without gravity, rush and smash, a
//! base-100 pyramid, thin fast rods (CCD), and determinism (the state hash of every tick).

use client_sdk::{Handle, ObjectProp, PlaneProp, Pose, Shape};
use physics_scenes::{
    anchored_box, cube, determinism_scene, floor, pyramid, thin_wall, CARD_HOUSE_SETTLE,
};

use super::check::Check;
use crate::error::BenchResult;
use crate::sim::{about_z, distance, Config, Sim};

const NO_DAMPING: [PlaneProp; 2] = [
    PlaneProp::LinearDamping(0.0),
    PlaneProp::AngularDamping(0.0),
];

fn speed(v: [f32; 3]) -> f64 {
    distance(v, [0.0; 3])
}

/// The determinism scene three times: Threads = 1, again Threads = 1, Threads = 2. Figure =
/// ticks (of 180) whose state hash differs between any two runs.
pub fn determinism(c: Config) -> BenchResult<Check> {
    let run = |threads: u32| -> BenchResult<(Vec<u64>, Sim)> {
        let mut sim = Sim::new(c, &[PlaneProp::Threads(threads)])?;
        determinism_scene(&mut sim)?;
        let mut hashes = Vec::new();
        for _ in 0..180 {
            sim.step()?;
            hashes.push(sim.header().state_hash);
        }
        Ok((hashes, sim))
    };
    let (a, sim) = run(1)?;
    let (b, _) = run(1)?;
    let (t, _) = run(2)?;
    let differing = (0..a.len())
        .filter(|&i| a[i] != b[i] || a[i] != t[i])
        .count();
    Ok(Check::at_most(&sim, differing as f64, 0.0))
}

/// Box2D's friction ramp: a 0.25 rad ramp of friction 0.2 and five unit boxes of friction
/// 0.75, 0.5, 0.35, 0.1 and 0 (pair friction √(μ1·μ2): 0.39, 0.32, 0.26, 0.14, 0 against
/// tan 0.25 = 0.255). The first three must hold, the last two slide. Figure = the largest
/// distance a holding box moved in 2 s (∞ when a sliding box moved less than 1 unit).
pub fn friction_ramp(c: Config) -> BenchResult<Check> {
    let theta = 0.25f32;
    let mut sim = Sim::new(c, &NO_DAMPING)?;
    let (s, co) = theta.sin_cos();
    let normal = [s, co, 0.0];
    let along = |d: f32, z: f32| [normal[0] * d, normal[1] * d, z];
    let rotation = about_z(-theta);
    anchored_box(
        &mut sim,
        [60.0, 1.0, 20.0],
        Pose {
            position: along(-0.5, 0.0),
            rotation,
        },
        &[ObjectProp::Friction(0.2)],
    )?;
    let mus = [0.75f32, 0.5, 0.35, 0.1, 0.0];
    let boxes: Vec<Handle> = mus
        .iter()
        .enumerate()
        .map(|(i, mu)| {
            sim.add(
                cube(1.0),
                Pose {
                    position: along(0.5, (i as f32 - 2.0) * 3.0),
                    rotation,
                },
                &[ObjectProp::Friction(*mu)],
            )
        })
        .collect::<BenchResult<_>>()?;
    let start: Vec<[f32; 3]> = boxes.iter().map(|b| sim.state(*b).position).collect();
    sim.run_for(2.0)?;
    let moved: Vec<f64> = boxes
        .iter()
        .zip(&start)
        .map(|(b, p)| distance(sim.state(*b).position, *p))
        .collect();
    let held = moved[..3].iter().cloned().fold(0.0, f64::max);
    let slid = moved[3..].iter().cloned().fold(f64::INFINITY, f64::min);
    let figure = if slid >= 1.0 { held } else { f64::INFINITY };
    Ok(Check::at_most(&sim, figure, 0.05))
}

/// An anchored closed box of inner side `inner` centred on the origin (walls 1 thick).
fn closed_box(sim: &mut Sim, inner: f32) -> BenchResult<()> {
    let h = inner / 2.0 + 0.5;
    let long = inner + 2.0;
    for axis in 0..3 {
        for sign in [-1.0f32, 1.0] {
            let mut p = [0.0; 3];
            p[axis] = sign * h;
            let mut size = [long; 3];
            size[axis] = 1.0;
            anchored_box(sim, size, Pose::at(p), &[])?;
        }
    }
    Ok(())
}

/// Box2D's "confined": 625 unit balls started 10 % overlapping on a 9 × 9 × 8 grid in a
/// closed box 0.9 · 9 wide, no gravity, no damping. Figure = the fastest ball during the
/// last second (bound 5 units/s: no blow-up); fails too when the kinetic energy of the last
/// second exceeds that of the second one (growing jitter).
pub fn confined(c: Config) -> BenchResult<Check> {
    let mut props = NO_DAMPING.to_vec();
    props.push(PlaneProp::Gravity([0.0; 3]));
    props.push(PlaneProp::NeverSleep(true));
    let mut sim = Sim::new(c, &props)?;
    let pitch = 0.9f32;
    closed_box(&mut sim, 9.0 * pitch)?;
    let mut balls = Vec::new();
    'fill: for i in 0..9 {
        for j in 0..9 {
            for k in 0..8 {
                if balls.len() == 625 {
                    break 'fill;
                }
                let at = |n: usize, count: f32| (n as f32 - (count - 1.0) / 2.0) * pitch;
                let p = [at(i, 9.0), at(j, 9.0), at(k, 8.0)];
                balls.push(sim.add(Shape::Sphere { radius: 0.5 }, Pose::at(p), &[])?);
            }
        }
    }
    let energy = |sim: &Sim| -> f64 {
        balls
            .iter()
            .map(|b| 0.5 * speed(sim.state(*b).linear_velocity).powi(2))
            .sum()
    };
    let (mut second, mut last, mut fastest) = (0.0f64, 0.0f64, 0.0f64);
    let per_second = sim.steps_for(1.0);
    for tick in 0..4 * per_second {
        sim.step()?;
        let e = energy(&sim);
        if tick / per_second == 1 {
            second = second.max(e);
        }
        if tick / per_second == 3 {
            last = last.max(e);
            for b in &balls {
                fastest = fastest.max(speed(sim.state(*b).linear_velocity));
            }
        }
    }
    let mut check = Check::at_most(&sim, fastest, 5.0);
    check.pass &= last <= second.max(1e-6);
    Ok(check)
}

/// Rush: 400 unit balls on a 8 × 8 × 7 grid 3 apart, no gravity, each pulled toward the
/// centre by a force of 1,000 (its ConstantForce, re-aimed every tick) for 3 s. Figure = the
/// fastest speed any ball reached, against the speed of a fall from the farthest start to
/// the centre under that force, √(2·F/m·r0), the most the pull can give (bound × 1.1).
pub fn rush(c: Config) -> BenchResult<Check> {
    let mut props = NO_DAMPING.to_vec();
    props.push(PlaneProp::Gravity([0.0; 3]));
    let mut sim = Sim::new(c, &props)?;
    let force = 1000.0f32;
    let mut balls = Vec::new();
    let mut r0 = 0.0f64;
    'fill: for i in 0..8 {
        for j in 0..8 {
            for k in 0..7 {
                if balls.len() == 400 {
                    break 'fill;
                }
                let p = [
                    (i as f32 - 3.5) * 3.0,
                    (j as f32 - 3.5) * 3.0,
                    (k as f32 - 3.0) * 3.0,
                ];
                r0 = r0.max(distance(p, [0.0; 3]));
                balls.push(sim.add(Shape::Sphere { radius: 0.5 }, Pose::at(p), &[])?);
            }
        }
    }
    let mass = sim.plane.object_info(balls[0])?.mass as f64;
    let bound = (2.0 * force as f64 / mass * r0).sqrt() * 1.1;
    let mut fastest = 0.0f64;
    for _ in 0..sim.steps_for(3.0) {
        for b in &balls {
            let p = sim.state(*b).position;
            let d = distance(p, [0.0; 3]).max(1e-6) as f32;
            let f = p.map(|x| -x / d * force);
            sim.plane.set_object(*b, ObjectProp::ConstantForce(f))?;
        }
        sim.step()?;
        for b in &balls {
            fastest = fastest.max(speed(sim.state(*b).linear_velocity));
        }
    }
    Ok(Check::at_most(&sim, fastest, bound))
}

/// Smash: a resting 5 × 5 × 5 block of unit boxes, asleep, hit by a 10 × 10 wall of unit
/// balls at 40 units/s. Figure = the fastest box or ball afterwards (bound 80 units/s, twice
/// the incoming speed: no contact may pump energy in).
pub fn smash(c: Config) -> BenchResult<Check> {
    let mut sim = Sim::new(c, &[])?;
    floor(&mut sim, 200.0, &[])?;
    let mut boxes = Vec::new();
    for i in 0..5 {
        for j in 0..5 {
            for k in 0..5 {
                let p = [i as f32 * 1.01, 0.5 + j as f32, (k as f32 - 2.0) * 1.01];
                boxes.push(sim.add(cube(1.0), Pose::at(p), &[])?);
            }
        }
    }
    sim.run_for(2.0)?; // settle and fall asleep
    let mut balls = Vec::new();
    for j in 0..10 {
        for k in 0..10 {
            let p = [-15.0, 0.5 + j as f32 * 0.6, (k as f32 - 4.5) * 0.6];
            let v = ObjectProp::Velocity([40.0, 0.0, 0.0]);
            balls.push(sim.add(Shape::Sphere { radius: 0.25 }, Pose::at(p), &[v])?);
        }
    }
    let mut fastest = 0.0f64;
    for _ in 0..sim.steps_for(3.0) {
        sim.step()?;
        for b in boxes.iter().chain(&balls) {
            fastest = fastest.max(speed(sim.state(*b).linear_velocity));
        }
    }
    Ok(Check::at_most(&sim, fastest, 80.0))
}

/// Box2D's large pyramid: base 100 (5,050 unit boxes), sleeping off (NeverSleep), on 2
/// threads. Figure = the largest displacement of any box from t = 1 s to t = 1 s +
/// [`PYRAMID_100_WINDOW`] (bound 0.1).
pub fn pyramid_100(c: Config) -> BenchResult<Check> {
    pyramid_drift(
        c,
        100,
        &[PlaneProp::NeverSleep(true), PlaneProp::Threads(2)],
        300.0,
        PYRAMID_100_WINDOW,
    )
}

/// Seconds `pyramid-100` watches its settled pyramid for (after 1 s of settling): Box2D's
/// 10 s in all. (It was shortened to 2 s while the pyramid crept at the defaults and the
/// remedy search over the whole grid made the run take longer than 10 minutes; adaptive
/// solving holds it at the defaults.)
pub const PYRAMID_100_WINDOW: f32 = 9.0;

/// Stepped on 2 threads (the plane's own pool: rapier's results are bitwise the same for
/// any pool size), which is what the run's 10-minute budget on a 2-core machine needs.
pub fn large_pyramid(c: Config, base: usize) -> BenchResult<Check> {
    pyramid_drift(
        c,
        base,
        &[PlaneProp::NeverSleep(true), PlaneProp::Threads(2)],
        300.0,
        9.0,
    )
}

/// A base-`base` pyramid of unit boxes on a floor `floor_width` wide. Figure = the largest
/// displacement of any box from t = 1 s to t = 1 s + `window` (bound 0.1).
pub fn pyramid_drift(
    c: Config,
    base: usize,
    plane: &[PlaneProp],
    floor_width: f32,
    window: f32,
) -> BenchResult<Check> {
    let mut sim = Sim::new(c, plane)?;
    floor(&mut sim, floor_width, &[])?;
    let boxes = pyramid(&mut sim, base, c.pair_gap())?;
    sim.run_for(1.0)?;
    let settled: Vec<[f32; 3]> = boxes.iter().map(|h| sim.state(*h).position).collect();
    sim.run_for(window)?;
    let worst = boxes
        .iter()
        .zip(&settled)
        .map(|(h, p)| distance(sim.state(*h).position, *p))
        .fold(0.0, f64::max);
    Ok(Check::at_most(&sim, worst, 0.1))
}

/// Box2D v3's card house (see [`physics_scenes::card_house()`]): 40 cards of 0.4 × 0.002
/// (0.3 deep), friction 0.7, leaning in pairs at ±25° with a flat card across each two
/// pairs, 5 levels, g = 9.81. The cards start as Box2D places them, with gaps that close as
/// the house settles (the top pair lands ~2 cm lower, a rigid solution included), so the
/// house is watched from [`CARD_HOUSE_SETTLE`] s on. Figure = the largest distance a card
/// gets from where it had settled, until t = 10 s (bound 0.02, 5 % of a card: a collapse
/// moves cards by tenths).
pub fn card_house(c: Config) -> BenchResult<Check> {
    let mut sim = Sim::new(c, &[PlaneProp::Gravity([0.0, -9.81, 0.0])])?;
    let cards = physics_scenes::card_house(&mut sim, 5, &[ObjectProp::Friction(0.7)])?;
    sim.run_for(CARD_HOUSE_SETTLE)?;
    let settled: Vec<[f32; 3]> = cards.iter().map(|k| sim.state(k.handle).position).collect();
    let mut worst = 0.0f64;
    for _ in 0..sim.steps_for(10.0 - CARD_HOUSE_SETTLE) {
        sim.step()?;
        for (k, at) in cards.iter().zip(&settled) {
            worst = worst.max(distance(sim.state(k.handle).position, *at));
        }
    }
    Ok(Check::at_most(&sim, worst, 0.02))
}

/// Thin fast rods: 0.05 × 0.05 × 2 rods flying broadside (0.05 along their motion) at 200
/// units/s toward an anchored 0.1 wall, no gravity, at the config's quality; one rod end-on
/// too. Figure = how far the deepest rod centre got past the wall's front face, less its
/// half-thickness (≤ 0.01: no tunnelling).
pub fn thin_rods(c: Config) -> BenchResult<Check> {
    let mut sim = Sim::new(c, &[PlaneProp::Gravity([0.0; 3])])?;
    thin_wall(&mut sim, &[])?;
    let mut rods = Vec::new();
    for (i, size) in [[0.05f32, 0.05, 2.0], [0.05, 2.0, 0.05], [2.0, 0.05, 0.05]]
        .iter()
        .enumerate()
    {
        let half = size[0] / 2.0;
        let at = [-20.0 - i as f32 * 7.3, -2.0 + i as f32 * 2.0, 0.0];
        let v = ObjectProp::Velocity([200.0, 0.0, 0.0]);
        rods.push((
            sim.add(Shape::Cube { size: *size }, Pose::at(at), &[v])?,
            half,
        ));
    }
    sim.run_for(1.0)?;
    let past = rods
        .iter()
        .map(|(r, half)| (sim.state(*r).position[0] + half) as f64)
        .fold(f64::MIN, f64::max);
    Ok(Check::at_most(&sim, past, 0.01))
}

//! `physics-bench controllers`: what character controllers cost per tick. 1, 100 and 1,000
//! controllers walk looping waypoints on an anchored box floor between anchored obstacles,
//! in process with the daemon's own plane code on one core; the step time of the same plane
//! without controllers is subtracted, and the rest is divided by the controller count.
//! Goal: 1,000 controllers under 2 ms per tick.
//!
//! The goal rows compare 1,000 controllers with 1,000 dynamic capsules of the same size
//! doing the same walk on the same floor (their velocity steered toward the same waypoints
//! between steps, outside the timed step like the controllers' path refills): both planes
//! are stepped alternately in one run, so the ratio (what the controllers add to a step ÷
//! what the capsules add) is side by side on a busy machine. Then the same 1,000
//! controllers on Threads = 2 against Threads = 1, again stepped alternately.

use std::fmt::Write as _;
use std::path::PathBuf;
use std::time::Instant;

use client_sdk::{Pose, Shape};
use physics_scenes::LocalPlane;
use shm_layout::{ControllerOp, ObjectProp, PlaneProp, Reply, Restraint};

use super::error::{BenchError, BenchResult};
use super::report::{self, num, Goal};
use super::scene::DT;

/// Options of the `controllers` subcommand.
#[derive(Debug, Clone, clap::Args)]
pub struct ControllersArgs {
    /// Fewer ticks (about a second per row).
    #[arg(long)]
    pub quick: bool,
    /// Folder receiving controllers.json and controllers.md.
    #[arg(long, default_value = "bench-out")]
    pub out: PathBuf,
}

const COUNTS: [usize; 3] = [1, 100, 1_000];
/// 1,000 controllers must take less than this per tick (ms).
const GOAL_MS: f64 = 2.0;
/// Controllers (and capsules) of the goal rows.
const GOAL_COUNT: usize = 1_000;
/// A controller's (and a capsule's) walking speed (units/s): WalkSpeed's default.
const WALK_SPEED: f32 = 16.0;
/// Horizontal distance at which a capsule's waypoint counts as reached: WaypointThreshold's
/// default.
const WAYPOINT_THRESHOLD: f32 = 1.0;
/// A tick of 1,000 controllers against a step of 1,000 dynamic capsules: at most this.
const GOAL_RATIO: f64 = 1.0;
/// 1,000 controllers on Threads = 2 against Threads = 1: at least this speed-up (above
/// the noise of two alternating runs on one machine).
const GOAL_THREADS_SPEEDUP: f64 = 1.25;

#[derive(Debug, Clone, serde::Serialize)]
pub struct Row {
    pub controllers: usize,
    /// Median step time with the controllers (µs).
    pub step_us: f64,
    /// Median step time of the same plane without them (µs).
    pub base_us: f64,
    /// (step - base) / controllers (µs).
    pub per_controller_us: f64,
    /// step - base (ms).
    pub controllers_ms: f64,
}

/// Two planes stepped alternately in one run: their medians side by side.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Pair {
    /// What the first plane is.
    pub a: String,
    /// What the second plane is.
    pub b: String,
    /// Median step time of `a` (µs).
    pub a_step_us: f64,
    /// Median step time of `b` (µs).
    pub b_step_us: f64,
    /// Median step time of the plane without controllers or capsules on `a`'s Threads
    /// (µs), stepped in the same alternation.
    pub a_base_us: f64,
    /// The same on `b`'s Threads (µs).
    pub b_base_us: f64,
    /// (a_step − a_base) ÷ (b_step − b_base).
    pub ratio: f64,
}

#[derive(Debug, Clone, serde::Serialize)]
pub struct ControllersReport {
    pub ticks: usize,
    pub rows: Vec<Row>,
    /// 1,000 controllers against 1,000 dynamic capsules walking the same routes (Threads 1).
    pub versus_capsules: Pair,
    /// 1,000 controllers on Threads = 2 against Threads = 1.
    pub threads: Pair,
    /// The goals, each with its measured value and verdict.
    pub goals: Vec<Goal>,
}

fn err(e: impl std::fmt::Display) -> BenchError {
    BenchError::Failed(e.to_string())
}

/// A 400 × 400 floor with a grid of 3-unit boxes every 20 units.
fn world() -> BenchResult<LocalPlane> {
    world_on(1)
}

/// [`world`] on a plane of `threads` Threads.
fn world_on(threads: u32) -> BenchResult<LocalPlane> {
    let mut plane = LocalPlane::new(1, &[PlaneProp::TickRate(0.0), PlaneProp::Threads(threads)])
        .map_err(err)?;
    let mut add = |size: [f32; 3], at: [f32; 3]| {
        plane
            .add_object(
                &Shape::Cube { size },
                Pose::at(at),
                &[ObjectProp::Anchored(true)],
            )
            .map(|_| ())
            .map_err(err)
    };
    add([400.0, 1.0, 400.0], [0.0, -0.5, 0.0])?;
    for i in -9..=9 {
        for k in -9..=9 {
            add(
                [3.0, 3.0, 3.0],
                [i as f32 * 20.0 + 10.0, 1.5, k as f32 * 20.0 + 10.0],
            )?;
        }
    }
    Ok(plane)
}

/// Median step time (µs) over `ticks` steps after a short warm-up; `between` runs before each
/// step (path refills).
fn time_steps(
    plane: &mut LocalPlane,
    ticks: usize,
    mut between: impl FnMut(&mut LocalPlane, usize),
) -> BenchResult<f64> {
    for t in 0..20 {
        between(plane, t);
        plane.step(DT).map_err(err)?;
    }
    let mut samples = Vec::with_capacity(ticks);
    for t in 0..ticks {
        between(plane, t);
        let started = Instant::now();
        plane.step(DT).map_err(err)?;
        samples.push(started.elapsed().as_secs_f64() * 1e6);
    }
    super::stats::median(&samples).ok_or_else(|| err("no samples"))
}

/// Where controller (or capsule) `i` of `n` starts: a grid 6 units apart.
fn start_of(i: usize, n: usize) -> [f32; 3] {
    let side = (n as f64).sqrt().ceil() as usize;
    let (gx, gz) = ((i % side) as f32, (i / side) as f32);
    [gx * 6.0 - 150.0, 2.6, gz * 6.0 - 150.0]
}

/// Each walks a 30 × 30 square from where it stands.
fn route(at: [f32; 3]) -> Vec<[f32; 3]> {
    vec![
        [at[0] + 30.0, 0.0, at[2]],
        [at[0] + 30.0, 0.0, at[2] + 30.0],
        [at[0], 0.0, at[2] + 30.0],
        at,
    ]
}

/// `n` controllers on a fresh [`world_on`] `threads`, with their handles and starts.
fn with_controllers(n: usize, threads: u32) -> BenchResult<(LocalPlane, Walkers)> {
    let mut plane = world_on(threads)?;
    let mut handles = Vec::with_capacity(n);
    for i in 0..n {
        let at = start_of(i, n);
        let reply = plane
            .controller_op(ControllerOp::Create {
                pose: Pose::at(at),
                size: [2.0, 5.0, 2.0],
                controlled: false,
                props: vec![],
            })
            .map_err(err)?;
        let Reply::Object { handle, .. } = reply else {
            return Err(err(format!("unexpected reply {reply:?}")));
        };
        handles.push(Walker {
            handle,
            at,
            next: 0,
        });
    }
    Ok((plane, Walkers::Controllers(handles)))
}

/// `n` dynamic capsules of the controllers' size on a fresh [`world`], kept upright
/// (rotation locked, as a game keeps a physics-driven character).
fn with_capsules(n: usize) -> BenchResult<(LocalPlane, Walkers)> {
    let mut plane = world()?;
    let mut capsules = Vec::with_capacity(n);
    let upright = ObjectProp::FieldRestraint(Restraint {
        lock_rot_x: Some(true),
        lock_rot_y: Some(true),
        lock_rot_z: Some(true),
        ..Restraint::KEEP
    });
    for i in 0..n {
        let at = start_of(i, n);
        let handle = plane
            .add_object(
                &Shape::Capsule {
                    size: [2.0, 5.0, 2.0],
                },
                Pose::at(at),
                &[upright],
            )
            .map_err(err)?;
        capsules.push(Walker {
            handle,
            at,
            next: 0,
        });
    }
    Ok((plane, Walkers::Capsules(capsules)))
}

/// One walker: its object, where it started (its route's corner), the waypoint it walks to
/// (capsules only; controllers follow their path themselves).
struct Walker {
    handle: shm_layout::Handle,
    at: [f32; 3],
    next: usize,
}

/// What walks on a plane.
enum Walkers {
    /// Controllers, whose paths are refilled every 240 ticks.
    Controllers(Vec<Walker>),
    /// Dynamic capsules, steered toward their waypoint at WalkSpeed before every step
    /// (vertical velocity kept, so they fall and rest on the floor).
    Capsules(Vec<Walker>),
    /// Nothing (the plane the others are measured against).
    None,
}

impl Walkers {
    /// Runs before step `t`: path refills or capsule steering.
    fn before_step(&mut self, plane: &mut LocalPlane, t: usize) {
        match self {
            Walkers::Controllers(handles) => {
                if t.is_multiple_of(240) {
                    for w in handles.iter() {
                        let _ = plane.controller_op(ControllerOp::SetPath {
                            handle: w.handle,
                            waypoints: route(w.at),
                        });
                    }
                }
            }
            Walkers::Capsules(capsules) => {
                for w in capsules.iter_mut() {
                    let state = plane.body_state(w.handle.slot as usize);
                    let [x, _, z] = state.position;
                    let waypoints = route(w.at);
                    let mut target = waypoints[w.next % waypoints.len()];
                    let (mut dx, mut dz) = (target[0] - x, target[2] - z);
                    if dx.hypot(dz) < WAYPOINT_THRESHOLD {
                        w.next = (w.next + 1) % waypoints.len();
                        target = waypoints[w.next];
                        (dx, dz) = (target[0] - x, target[2] - z);
                    }
                    let d = dx.hypot(dz).max(1e-6);
                    let vy = state.linear_velocity[1];
                    let _ = plane.set_object(
                        w.handle,
                        ObjectProp::Velocity([dx / d * WALK_SPEED, vy, dz / d * WALK_SPEED]),
                    );
                }
            }
            Walkers::None => {}
        }
    }
}

/// Median step time (µs) of each plane, stepped alternately (each tick every plane in turn)
/// over `ticks` steps after a short warm-up.
fn time_alternating(planes: &mut [(LocalPlane, Walkers)], ticks: usize) -> BenchResult<Vec<f64>> {
    let mut samples = vec![Vec::with_capacity(ticks); planes.len()];
    for t in 0..20 + ticks {
        for (i, (plane, walkers)) in planes.iter_mut().enumerate() {
            walkers.before_step(plane, t);
            let started = Instant::now();
            plane.step(DT).map_err(err)?;
            if t >= 20 {
                samples[i].push(started.elapsed().as_secs_f64() * 1e6);
            }
        }
    }
    samples
        .iter()
        .map(|s| super::stats::median(s).ok_or_else(|| err("no samples")))
        .collect()
}

pub fn run(args: &ControllersArgs) -> BenchResult<()> {
    let ticks = if args.quick { 60 } else { 300 };
    let mut base = world()?;
    let base_us = time_steps(&mut base, ticks, |_, _| {})?;
    let mut rows = Vec::new();
    for n in COUNTS {
        let (mut plane, mut walkers) = with_controllers(n, 1)?;
        let step_us = time_steps(&mut plane, ticks, |p, t| walkers.before_step(p, t))?;
        let extra = (step_us - base_us).max(0.0);
        rows.push(Row {
            controllers: n,
            step_us,
            base_us,
            per_controller_us: extra / n as f64,
            controllers_ms: extra / 1e3,
        });
    }
    // The goal rows: planes stepped alternately, side by side.
    let mut planes = vec![
        with_controllers(GOAL_COUNT, 1)?,
        with_capsules(GOAL_COUNT)?,
        (world()?, Walkers::None),
    ];
    let m = time_alternating(&mut planes, ticks)?;
    let versus_capsules = pair(
        "1,000 controllers, Threads 1",
        "1,000 dynamic capsules, Threads 1",
        (m[0], m[2]),
        (m[1], m[2]),
    );
    let mut planes = vec![
        with_controllers(GOAL_COUNT, 2)?,
        with_controllers(GOAL_COUNT, 1)?,
        (world_on(2)?, Walkers::None),
        (world()?, Walkers::None),
    ];
    let m = time_alternating(&mut planes, ticks)?;
    let threads = pair(
        "1,000 controllers, Threads 2",
        "1,000 controllers, Threads 1",
        (m[0], m[2]),
        (m[1], m[3]),
    );
    let goals = goals(&rows, &versus_capsules, &threads);
    let report = ControllersReport {
        ticks,
        rows,
        versus_capsules,
        threads,
        goals,
    };
    let md = markdown(&report);
    let (json, md_path) = report::write(&args.out, "controllers", &report, &md)?;
    report::print(&md_path);
    println!("wrote {} and {}", json.display(), md_path.display());
    Ok(())
}

/// A [`Pair`] from each side's (step, base) medians.
fn pair(a: &str, b: &str, (a_step, a_base): (f64, f64), (b_step, b_base): (f64, f64)) -> Pair {
    let extra_a = (a_step - a_base).max(0.0);
    let extra_b = (b_step - b_base).max(1e-9);
    Pair {
        a: a.into(),
        b: b.into(),
        a_step_us: a_step,
        b_step_us: b_step,
        a_base_us: a_base,
        b_base_us: b_base,
        ratio: extra_a / extra_b,
    }
}

fn goals(rows: &[Row], versus: &Pair, threads: &Pair) -> Vec<Goal> {
    let mut goals: Vec<Goal> = rows
        .iter()
        .filter(|row| row.controllers == GOAL_COUNT)
        .map(|row| {
            Goal::new(
                format!("1,000 controllers under {GOAL_MS} ms per tick on one core"),
                format!("{} ms", num(Some(row.controllers_ms))),
                Some(row.controllers_ms < GOAL_MS),
            )
        })
        .collect();
    goals.push(Goal::new(
        format!(
            "a tick of 1,000 controllers ≤ {GOAL_RATIO} × a step of 1,000 dynamic capsules \
             walking the same routes (each minus the plane without them)"
        ),
        format!(
            "{} ({} ms against {} ms)",
            num(Some(versus.ratio)),
            num(Some((versus.a_step_us - versus.a_base_us) / 1e3)),
            num(Some((versus.b_step_us - versus.b_base_us) / 1e3)),
        ),
        Some(versus.ratio <= GOAL_RATIO),
    ));
    goals.push(Goal::new(
        format!("1,000 controllers at least {GOAL_THREADS_SPEEDUP}× faster on Threads = 2 than on Threads = 1"),
        format!(
            "{}× ({} ms against {} ms)",
            num(Some(1.0 / threads.ratio.max(1e-9))),
            num(Some((threads.a_step_us - threads.a_base_us) / 1e3)),
            num(Some((threads.b_step_us - threads.b_base_us) / 1e3)),
        ),
        Some(1.0 / threads.ratio.max(1e-9) >= GOAL_THREADS_SPEEDUP),
    ));
    goals
}

fn markdown(r: &ControllersReport) -> String {
    let mut md = String::new();
    let _ = writeln!(
        md,
        "# Character controllers: cost per tick\n\nControllers walking looping waypoints on a box \
         floor between 361 box obstacles, in process on one core, median of {} ticks at 60 Hz. \
         The same plane without controllers is subtracted.\n",
        r.ticks
    );
    let mut t = report::Table::new(&[
        "controllers",
        "step (µs)",
        "without them (µs)",
        "per controller (µs)",
        "all controllers (ms)",
    ]);
    for row in &r.rows {
        t.row(&[
            row.controllers.to_string(),
            num(Some(row.step_us)),
            num(Some(row.base_us)),
            num(Some(row.per_controller_us)),
            num(Some(row.controllers_ms)),
        ]);
    }
    md.push_str(&t.finish());
    let _ = writeln!(
        md,
        "\nSide by side (planes stepped alternately in one run; ratio = (a − its base) ÷ \
         (b − its base)):\n"
    );
    let mut t = report::Table::new(&[
        "a",
        "b",
        "a step (µs)",
        "b step (µs)",
        "bases (µs)",
        "ratio",
    ]);
    for p in [&r.versus_capsules, &r.threads] {
        t.row(&[
            p.a.clone(),
            p.b.clone(),
            num(Some(p.a_step_us)),
            num(Some(p.b_step_us)),
            format!("{} / {}", num(Some(p.a_base_us)), num(Some(p.b_base_us))),
            num(Some(p.ratio)),
        ]);
    }
    md.push_str(&t.finish());
    md
}

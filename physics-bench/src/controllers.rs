//! `physics-bench controllers`: what character controllers cost per tick. 1, 100 and 1,000
//! controllers walk looping waypoints on an anchored box floor between anchored obstacles,
//! in process with the daemon's own plane code on one core; the step time of the same plane
//! without controllers is subtracted, and the rest is divided by the controller count.
//! Goal: 1,000 controllers under 2 ms per tick.

use std::fmt::Write as _;
use std::path::PathBuf;
use std::time::Instant;

use client_sdk::{Pose, Shape};
use physics_scenes::LocalPlane;
use shm_layout::{ControllerOp, ObjectProp, PlaneProp, Reply};

use super::error::{BenchError, BenchResult};
use super::report::{self, goals_table, num, Goal};
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

#[derive(Debug, Clone, serde::Serialize)]
pub struct ControllersReport {
    pub ticks: usize,
    pub rows: Vec<Row>,
}

fn err(e: impl std::fmt::Display) -> BenchError {
    BenchError::Failed(e.to_string())
}

/// A 400 × 400 floor with a grid of 3-unit boxes every 20 units.
fn world() -> BenchResult<LocalPlane> {
    let mut plane = LocalPlane::new(1, &[PlaneProp::TickRate(0.0)]).map_err(err)?;
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

pub fn run(args: &ControllersArgs) -> BenchResult<()> {
    let ticks = if args.quick { 60 } else { 300 };
    let mut base = world()?;
    let base_us = time_steps(&mut base, ticks, |_, _| {})?;
    let mut rows = Vec::new();
    for n in COUNTS {
        let mut plane = world()?;
        let mut handles = Vec::with_capacity(n);
        let side = (n as f64).sqrt().ceil() as usize;
        for i in 0..n {
            let (gx, gz) = ((i % side) as f32, (i / side) as f32);
            let at = [gx * 6.0 - 150.0, 2.6, gz * 6.0 - 150.0];
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
            handles.push((handle, at));
        }
        // Each walks a 30 × 30 square from where it stands, refilled when done.
        let route = |at: [f32; 3]| {
            vec![
                [at[0] + 30.0, 0.0, at[2]],
                [at[0] + 30.0, 0.0, at[2] + 30.0],
                [at[0], 0.0, at[2] + 30.0],
                at,
            ]
        };
        let refill = |plane: &mut LocalPlane, t: usize| {
            if t.is_multiple_of(240) {
                for (handle, at) in &handles {
                    let _ = plane.controller_op(ControllerOp::SetPath {
                        handle: *handle,
                        waypoints: route(*at),
                    });
                }
            }
        };
        let step_us = time_steps(&mut plane, ticks, refill)?;
        let extra = (step_us - base_us).max(0.0);
        rows.push(Row {
            controllers: n,
            step_us,
            base_us,
            per_controller_us: extra / n as f64,
            controllers_ms: extra / 1e3,
        });
    }
    let report = ControllersReport { ticks, rows };
    let md = markdown(&report);
    let (json, md_path) = report::write(&args.out, "controllers", &report, &md)?;
    println!("{md}");
    println!("wrote {} and {}", json.display(), md_path.display());
    Ok(())
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
    let goals: Vec<Goal> = r
        .rows
        .iter()
        .filter(|row| row.controllers == 1_000)
        .map(|row| {
            Goal::new(
                format!("1,000 controllers under {GOAL_MS} ms per tick on one core"),
                format!("{} ms", num(Some(row.controllers_ms))),
                Some(row.controllers_ms < GOAL_MS),
            )
        })
        .collect();
    let _ = writeln!(md, "\n{}", goals_table(&goals));
    md
}

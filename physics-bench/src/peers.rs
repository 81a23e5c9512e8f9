//! `physics-bench peers`: scenes other engines publish figures for, measured on our side
//! with the defaults.
//!
//! - Jolt's PerformanceTest scene "Pyramid" (1,240 boxes 2 × 2 × 2, 15 layers, 0.5 apart,
//!   sleeping off) on a 3D plane with the plane's defaults but gravity 9.81 (Jolt's; ours is
//!   50), Threads = 1 and Threads = 2 planes in one daemon stepped alternately, so both see
//!   the same machine load.
//! - Box2D v3's benchmark `large_pyramid` (5,050 squares of half-size 0.5 in rows of 100 down
//!   to 1) on a GUI plane at 100 px per unit with gravity 10 units/s² (Box2D's), sleeping off.
//!   GUI planes have no Threads option: Threads 1 only.
//! - The Pyramid again at SolverIterations 1, 2, 4 and 8 (`--solver-iterations`), with
//!   AdaptiveSolving on (the default) and off, eight planes stepped alternately: steps/s,
//!   contact pairs, the deepest contact of each tick and, from those depths, the ticks the
//!   adaptive pass boosted and the substeps they ran (see [`boost_estimate`]).
//!
//! Every plane is manual (TickRate 0) and stepped at 60 Hz through client-sdk, as a game
//! would; steps/s is steps ÷ the daemon's own step time (the tick headers' `step_time_us`,
//! what the peers' harnesses time around their step call), with the round trip beside it.
//! One step runs before timing (Box2D's harness does the same: the first step is the
//! broad phase's build).

use std::fmt::Write as _;
use std::path::PathBuf;
use std::time::Instant;

use client_sdk::{Client, GuiPlane, GuiPlaneOptions, Object, Plane, PlaneOptions, Snapshot};
use physics_scenes::peers::{
    jolt_pyramid_rest_top, JOLT_BOX_SIZE, JOLT_PYRAMID_BOXES, LARGE_PYRAMID_BASE,
    LARGE_PYRAMID_HALF,
};
use physics_scenes::{jolt_pyramid, jolt_pyramid_layout, large_pyramid_gui, Placed};

use super::daemon::DaemonProcess;
use super::error::{BenchError, BenchResult};
use super::progress::Progress;
use super::report::{self, num, Goal, Table};
use super::scene::DT;
use super::stats::median;

/// Options of the `peers` subcommand.
#[derive(Debug, Clone, clap::Args)]
pub struct PeersArgs {
    /// Fewer steps (100 instead of the peers' 500).
    #[arg(long)]
    pub quick: bool,
    /// Folder receiving peers.json and peers.md.
    #[arg(long, default_value = "bench-out")]
    pub out: PathBuf,
    /// Runs only these parts (repeatable; all when none is named).
    #[arg(long, value_enum)]
    pub only: Vec<Part>,
    /// SolverIterations of the sweep, ascending.
    #[arg(long, value_delimiter = ',', default_values_t = [1, 2, 4, 8])]
    pub solver_iterations: Vec<u32>,
    /// AdaptiveSolving settings of the sweep.
    #[arg(long, value_delimiter = ',', default_values_t = [true, false])]
    pub adaptive_solving: Vec<bool>,
}

/// The parts of the report.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Part {
    /// Jolt's Pyramid, Threads 1 and 2.
    Jolt,
    /// Box2D's large_pyramid on a GUI plane.
    Box2d,
    /// The Pyramid at SolverIterations 1, 2, 4, 8, AdaptiveSolving on and off.
    Sweep,
}

/// Steps of both peers' runs (Jolt's PerformanceTest default, Box2D's large_pyramid).
const STEPS: usize = 500;
/// Steps of a `--quick` run: the Pyramid has landed and settled after about 1.2 s.
const QUICK_STEPS: usize = 100;
/// Jolt's gravity (its PhysicsSettings default), set explicitly: a plane's default is 50.
const JOLT_GRAVITY: f32 = 9.81;
/// Box2D's gravity (b2DefaultWorldDef), units/s².
const BOX2D_GRAVITY: f32 = 10.0;
/// Pixels per Box2D unit on the GUI plane: the GUI plane's rapier length unit, so its
/// tolerances are Box2D's at that scale.
const PX_PER_UNIT: f32 = physics_daemon::rapier2d::LENGTH_UNIT;

/// A Pyramid box stands when it is at most this far (horizontally) from its start: a
/// quarter of its side. Settling moves a box by hundredths; a box that slides off its four
/// supports or tips over moves by half a side (1.0) or more.
const JOLT_DRIFT: f32 = 0.25 * JOLT_BOX_SIZE;
/// The top box must end at most this far below its rest height (the layers' 0.5 gaps
/// closed, 29): a quarter box, the sinking of 15 stacked contacts allowed for. A lost layer
/// lowers it by a whole box (2).
const JOLT_SINK: f32 = 0.25 * JOLT_BOX_SIZE;
/// A large_pyramid square stands within a quarter of its side of its start x (units).
const BOX2D_DRIFT: f32 = 0.5 * LARGE_PYRAMID_HALF;
/// The top square may sink this far (units): the squares start touching, so their start is
/// their rest; a collapsed row lowers it by a whole side (1).
const BOX2D_SINK: f32 = 0.5 * LARGE_PYRAMID_HALF;

/// The adaptive pass's load rule (physics-daemon `rapier3d/adaptive.rs`, at HitBoxQuality
/// 1): a contact deeper than this boosts its bodies…
const ADAPTIVE_TRIGGER: f32 = 0.03;
/// …a boosted pair keeps its boost while deeper than this…
const ADAPTIVE_RELEASE: f32 = 0.01;
/// …and the boost is this many extra substeps for the whole island holding the pair.
const ADAPTIVE_EXTRA: u32 = 12;
/// The pass runs when a contact is deeper than the release depth, and every this many ticks.
const ADAPTIVE_PASS_EVERY: u64 = 32;

/// A higher SolverIterations may be this much faster than a lower one before the cost is
/// called non-monotonic (alternating runs on a shared machine differ by a few percent).
const MONOTONIC_SLACK: f64 = 1.15;

/// What a plane's header said about each timed tick.
#[derive(Debug, Default)]
struct Trace {
    /// The untimed first tick and its deepest contact.
    first: (u64, f32),
    tick: Vec<u64>,
    step_us: Vec<f64>,
    wall_us: Vec<f64>,
    pairs: Vec<u32>,
    penetration: Vec<f32>,
}

impl Trace {
    fn push(&mut self, snapshot: &Snapshot, wall_us: f64) {
        let h = snapshot.header();
        self.tick.push(h.tick);
        self.step_us.push(h.step_time_us as f64);
        self.wall_us.push(wall_us);
        self.pairs.push(h.contact_pairs);
        self.penetration.push(h.max_penetration);
    }
}

/// Whether a scene stood at the end, with the figures that say so (the scene's units).
#[derive(Debug, Clone, serde::Serialize)]
pub struct Stand {
    /// Largest horizontal distance of a body from its start.
    pub max_drift: f32,
    /// Allowed drift.
    pub drift_allowed: f32,
    /// Height of the top body's centre at the end.
    pub top_height: f32,
    /// Lowest top height that still stands.
    pub top_needed: f32,
    /// Bodies whose state could not be read (removed by the daemon: non-finite).
    pub missing: usize,
    pub stands: bool,
}

/// One plane's run.
#[derive(Debug, Clone, serde::Serialize)]
pub struct PlaneRun {
    pub threads: u32,
    pub solver_iterations: u32,
    /// AdaptiveSolving (3D planes only).
    pub adaptive_solving: Option<bool>,
    pub steps: usize,
    /// Steps ÷ the daemon's summed step time.
    pub steps_per_s: f64,
    /// Steps ÷ the summed round trips (step request and reading the new tick).
    pub wall_steps_per_s: f64,
    pub median_step_ms: f64,
    pub mean_contact_pairs: f64,
    pub last_contact_pairs: u32,
    /// Deepest contact of any timed tick.
    pub max_penetration: f32,
    /// Deepest contact of the last tick.
    pub last_penetration: f32,
    /// See [`boost_estimate`] (3D planes with AdaptiveSolving only).
    pub boost: Option<Boost>,
    pub stand: Stand,
}

/// The adaptive pass replayed on the deepest contact of each tick (see [`boost_estimate`]).
#[derive(Debug, Clone, serde::Serialize)]
pub struct Boost {
    /// Timed ticks stepped with the island boosted.
    pub boosted_ticks: usize,
    /// Mean substeps per timed tick: SolverIterations, plus the boost on boosted ticks.
    pub mean_substeps: f64,
    /// Mean step time of the boosted ticks (ms).
    pub boosted_step_ms: Option<f64>,
    /// Mean step time of the other ticks (ms).
    pub plain_step_ms: Option<f64>,
}

#[derive(Debug, Clone, serde::Serialize)]
pub struct PeersReport {
    pub steps: usize,
    /// Jolt's Pyramid, Threads 1 then 2.
    pub jolt: Vec<PlaneRun>,
    /// Box2D's large_pyramid on a GUI plane.
    pub box2d: Option<PlaneRun>,
    /// The Pyramid at each SolverIterations, AdaptiveSolving on then off, Threads 1.
    pub sweep: Vec<PlaneRun>,
    pub goals: Vec<Goal>,
}

fn failed(what: impl Into<String>) -> BenchError {
    BenchError::Failed(what.into())
}

/// Steps `planes` in turn, one tick each per round, `steps` timed rounds after one untimed.
fn step_alternately(
    planes: &[&Plane],
    steps: usize,
    progress: &Progress,
    what: &str,
) -> BenchResult<Vec<Trace>> {
    let mut traces: Vec<Trace> = planes.iter().map(|_| Trace::default()).collect();
    for round in 0..=steps {
        for (plane, trace) in planes.iter().zip(traces.iter_mut()) {
            let started = Instant::now();
            plane.step(DT)?;
            let snapshot = plane.snapshot()?;
            let wall = started.elapsed().as_secs_f64() * 1e6;
            if round > 0 {
                trace.push(&snapshot, wall);
            } else {
                trace.first = (snapshot.header().tick, snapshot.header().max_penetration);
            }
        }
        if round % 50 == 0 {
            progress.phase(format!("{what}: step {round}/{steps}"));
        }
    }
    Ok(traces)
}

/// Replays the adaptive pass's load rule on the deepest contact of each tick: a pass after a
/// tick boosts the island when that tick had a contact deeper than [`ADAPTIVE_TRIGGER`],
/// keeps a boost while one is deeper than [`ADAPTIVE_RELEASE`], and drops it otherwise; no
/// pass runs (the boost stays as it was) when no contact is deeper than the release depth,
/// except every [`ADAPTIVE_PASS_EVERY`] ticks. The Pyramid is one island, and rapier runs an
/// island at its bodies' largest boost, so one deep pair boosts every box. An estimate: the
/// daemon reads each pair's depth, the header only the deepest.
fn boost_estimate(trace: &Trace, solver_iterations: u32) -> Boost {
    // The boost of the tick after the untimed first one.
    let pass = |boosted: bool, (tick, depth): (u64, f32)| {
        if depth <= ADAPTIVE_RELEASE && !tick.is_multiple_of(ADAPTIVE_PASS_EVERY) {
            boosted
        } else {
            depth > ADAPTIVE_TRIGGER || (boosted && depth > ADAPTIVE_RELEASE)
        }
    };
    let mut boosted = pass(false, trace.first);
    let (mut on, mut off) = (Vec::new(), Vec::new());
    let mut substeps = 0u64;
    for (i, &us) in trace.step_us.iter().enumerate() {
        if boosted {
            on.push(us);
            substeps += u64::from(solver_iterations + ADAPTIVE_EXTRA);
        } else {
            off.push(us);
            substeps += u64::from(solver_iterations);
        }
        boosted = pass(boosted, (trace.tick[i], trace.penetration[i]));
    }
    let mean_ms = |v: &[f64]| (!v.is_empty()).then(|| v.iter().sum::<f64>() / v.len() as f64 / 1e3);
    Boost {
        boosted_ticks: on.len(),
        mean_substeps: substeps as f64 / trace.step_us.len().max(1) as f64,
        boosted_step_ms: mean_ms(&on),
        plain_step_ms: mean_ms(&off),
    }
}

/// The figures of a run from its trace.
fn plane_run(
    trace: &Trace,
    (threads, solver_iterations, adaptive_solving): (u32, u32, Option<bool>),
    boost: Option<Boost>,
    stand: Stand,
) -> BenchResult<PlaneRun> {
    let steps = trace.step_us.len();
    let total_s = |v: &[f64]| v.iter().sum::<f64>() / 1e6;
    let median_us = median(&trace.step_us).ok_or_else(|| failed("no step was timed"))?;
    Ok(PlaneRun {
        threads,
        solver_iterations,
        adaptive_solving,
        steps,
        steps_per_s: steps as f64 / total_s(&trace.step_us).max(1e-9),
        wall_steps_per_s: steps as f64 / total_s(&trace.wall_us).max(1e-9),
        median_step_ms: median_us / 1e3,
        mean_contact_pairs: trace.pairs.iter().map(|&p| p as f64).sum::<f64>()
            / steps.max(1) as f64,
        last_contact_pairs: trace.pairs.last().copied().unwrap_or(0),
        max_penetration: trace.penetration.iter().copied().fold(0.0, f32::max),
        last_penetration: trace.penetration.last().copied().unwrap_or(0.0),
        boost,
        stand,
    })
}

/// A Pyramid plane of `threads` Threads (`solver_iterations` and `adaptive` set when given,
/// else the defaults), with its boxes.
struct Pyramid {
    plane: Plane,
    boxes: Vec<Object>,
    threads: u32,
    solver_iterations: u32,
    adaptive: bool,
}

impl Pyramid {
    fn build(
        client: &Client,
        threads: u32,
        solver_iterations: Option<u32>,
        adaptive: Option<bool>,
    ) -> BenchResult<Pyramid> {
        let options = PlaneOptions {
            gravity: Some([0.0, -JOLT_GRAVITY, 0.0]),
            threads: Some(threads),
            tick_rate: Some(0.0),
            never_sleep: Some(true),
            solver_iterations,
            adaptive_solving: adaptive,
            ..Default::default()
        };
        let plane = client.create_plane(&options)?;
        let boxes = jolt_pyramid(&mut &plane, &[], &[])?;
        let s = plane.info()?.settings;
        if s.threads != threads || s.gravity != [0.0, -JOLT_GRAVITY, 0.0] || !s.never_sleep {
            return Err(failed(format!(
                "Pyramid plane: asked Threads {threads}, gravity {JOLT_GRAVITY}, NeverSleep; \
                 it has Threads {}, gravity {:?}, NeverSleep {}",
                s.threads, s.gravity, s.never_sleep
            )));
        }
        Ok(Pyramid {
            plane,
            boxes,
            threads,
            solver_iterations: s.solver_iterations,
            adaptive: s.adaptive_solving,
        })
    }

    /// Whether every box ended within [`JOLT_DRIFT`] of its start x/z and the top box within
    /// [`JOLT_SINK`] of its rest height.
    fn stand(&self) -> BenchResult<Stand> {
        let snapshot = self.plane.snapshot()?;
        let starts = jolt_pyramid_layout();
        let (mut drift, mut missing, mut top) = (0.0f32, 0, f32::NEG_INFINITY);
        for (object, start) in self.boxes.iter().zip(&starts) {
            match snapshot.get(object.handle()) {
                Some(b) => {
                    let [x, y, z] = b.position;
                    drift = drift.max((x - start[0]).hypot(z - start[2]));
                    top = y;
                }
                None => missing += 1,
            }
        }
        let needed = jolt_pyramid_rest_top() - JOLT_SINK;
        Ok(Stand {
            max_drift: drift,
            drift_allowed: JOLT_DRIFT,
            top_height: top,
            top_needed: needed,
            missing,
            stands: missing == 0 && drift <= JOLT_DRIFT && top >= needed,
        })
    }

    fn run(&self, trace: &Trace) -> BenchResult<PlaneRun> {
        let boost = self
            .adaptive
            .then(|| boost_estimate(trace, self.solver_iterations));
        plane_run(
            trace,
            (self.threads, self.solver_iterations, Some(self.adaptive)),
            boost,
            self.stand()?,
        )
    }
}

/// Steps the Pyramids alternately and reads each one's run.
fn run_pyramids(
    pyramids: &[Pyramid],
    steps: usize,
    progress: &Progress,
    what: &str,
) -> BenchResult<Vec<PlaneRun>> {
    let planes: Vec<&Plane> = pyramids.iter().map(|p| &p.plane).collect();
    let traces = step_alternately(&planes, steps, progress, what)?;
    pyramids
        .iter()
        .zip(&traces)
        .map(|(p, t)| p.run(t))
        .collect()
}

/// Jolt's Pyramid on Threads 1 and 2, defaults otherwise.
fn jolt(steps: usize, progress: &Progress) -> BenchResult<Vec<PlaneRun>> {
    let daemon = DaemonProcess::start("peers")?;
    let client = daemon.connect()?;
    progress.phase("Pyramid: building Threads 1 and 2");
    let pyramids = [
        Pyramid::build(&client, 1, None, None)?,
        Pyramid::build(&client, 2, None, None)?,
    ];
    run_pyramids(&pyramids, steps, progress, "Pyramid")
}

/// The Pyramid at each SolverIterations and AdaptiveSolving of `args`.
fn sweep(args: &PeersArgs, steps: usize, progress: &Progress) -> BenchResult<Vec<PlaneRun>> {
    let daemon = DaemonProcess::start("peers-sweep")?;
    let client = daemon.connect()?;
    let mut pyramids = Vec::new();
    for &adaptive in &args.adaptive_solving {
        for &n in &args.solver_iterations {
            progress.phase(format!(
                "sweep: building SolverIterations {n}, AdaptiveSolving {adaptive}"
            ));
            pyramids.push(Pyramid::build(&client, 1, Some(n), Some(adaptive))?);
        }
    }
    run_pyramids(&pyramids, steps, progress, "sweep")
}

/// Box2D's large_pyramid on a GUI plane.
fn box2d(steps: usize, progress: &Progress) -> BenchResult<PlaneRun> {
    let daemon = DaemonProcess::start("peers-2d")?;
    let client = daemon.connect()?;
    progress.phase("large_pyramid: building 5,050 squares");
    let options = GuiPlaneOptions {
        gravity: Some([0.0, BOX2D_GRAVITY * PX_PER_UNIT]),
        never_sleep: Some(true),
        ..GuiPlaneOptions::manual()
    };
    let gui: GuiPlane = client.create_gui_plane(&options)?;
    let squares = large_pyramid_gui(&gui, LARGE_PYRAMID_BASE, PX_PER_UNIT, &[])?;
    let settings = gui.info()?.settings;
    let plane = gui.plane();
    let traces = step_alternately(&[plane], steps, progress, "large_pyramid")?;
    let trace = traces.first().ok_or_else(|| failed("no trace"))?;
    let stand = box2d_stand(&plane.snapshot()?, &squares);
    plane_run(trace, (1, settings.solver_iterations, None), None, stand)
}

/// Whether every square ended within [`BOX2D_DRIFT`] of its start x and the top one within
/// [`BOX2D_SINK`] of its start height (Box2D units, +Y up).
fn box2d_stand(snapshot: &Snapshot, squares: &[Placed<client_sdk::GuiObject>]) -> Stand {
    let (mut drift, mut missing, mut top) = (0.0f32, 0, f32::NEG_INFINITY);
    let mut top_start = f32::NEG_INFINITY;
    for s in squares {
        match snapshot.get(s.handle.handle()) {
            Some(b) => {
                drift = drift.max((b.position[0] - s.start[0]).abs() / PX_PER_UNIT);
                top = -b.position[1] / PX_PER_UNIT;
            }
            None => missing += 1,
        }
        top_start = -s.start[1] / PX_PER_UNIT;
    }
    let needed = top_start - BOX2D_SINK;
    Stand {
        max_drift: drift,
        drift_allowed: BOX2D_DRIFT,
        top_height: top,
        top_needed: needed,
        missing,
        stands: missing == 0 && drift <= BOX2D_DRIFT && top >= needed,
    }
}

pub fn run(args: &PeersArgs) -> BenchResult<()> {
    let steps = if args.quick { QUICK_STEPS } else { STEPS };
    let wants = |p: Part| args.only.is_empty() || args.only.contains(&p);
    let progress = Progress::new(3);
    let jolt = if wants(Part::Jolt) {
        let runs = jolt(steps, &progress)?;
        for r in &runs {
            progress.note(format!(
                "Pyramid, Threads {}: {} steps/s, stands: {}",
                r.threads,
                num(Some(r.steps_per_s)),
                r.stand.stands
            ));
        }
        runs
    } else {
        Vec::new()
    };
    progress.done();
    let box2d = if wants(Part::Box2d) {
        let r = box2d(steps, &progress)?;
        progress.note(format!(
            "large_pyramid: {} steps/s, stands: {}",
            num(Some(r.steps_per_s)),
            r.stand.stands
        ));
        Some(r)
    } else {
        None
    };
    progress.done();
    let sweep = if wants(Part::Sweep) {
        let runs = sweep(args, steps, &progress)?;
        for r in &runs {
            progress.note(format!(
                "Pyramid, SolverIterations {}, AdaptiveSolving {:?}: {} steps/s",
                r.solver_iterations,
                r.adaptive_solving,
                num(Some(r.steps_per_s))
            ));
        }
        runs
    } else {
        Vec::new()
    };
    progress.done();
    progress.finish();
    let goals = goals(&jolt, box2d.as_ref(), &sweep, steps);
    let report = PeersReport {
        steps,
        jolt,
        box2d,
        sweep,
        goals,
    };
    let md = markdown(&report);
    let (json, md_path) = report::write(&args.out, "peers", &report, &md)?;
    report::print(&md_path);
    println!("wrote {} and {}", json.display(), md_path.display());
    Ok(())
}

/// Whether steps/s never rises by more than [`MONOTONIC_SLACK`] from one SolverIterations to
/// the next higher (`runs` in ascending SolverIterations), with the worst ratio.
fn monotonic(runs: &[&PlaneRun]) -> Option<(bool, f64, u32, u32)> {
    runs.windows(2)
        .map(|w| {
            let ratio = w[1].steps_per_s / w[0].steps_per_s.max(1e-9);
            (ratio, w[0].solver_iterations, w[1].solver_iterations)
        })
        .max_by(|a, b| a.0.total_cmp(&b.0))
        .map(|(ratio, lo, hi)| (ratio <= MONOTONIC_SLACK, ratio, lo, hi))
}

/// `a / b`, figures of f32.
fn pair(a: f32, b: f32) -> String {
    format!("{} / {}", num(Some(a as f64)), num(Some(b as f64)))
}

fn steps_text(r: &PlaneRun) -> String {
    format!(
        "{} steps/s ({} ms/step; {} steps/s with the round trip)",
        num(Some(r.steps_per_s)),
        num(Some(1e3 / r.steps_per_s.max(1e-9))),
        num(Some(r.wall_steps_per_s))
    )
}

fn stand_text(s: &Stand) -> String {
    format!(
        "{}: drift ≤ {} (allowed {}), top at {} (needed ≥ {}){}",
        if s.stands { "stands" } else { "falls" },
        num(Some(s.max_drift as f64)),
        num(Some(s.drift_allowed as f64)),
        num(Some(s.top_height as f64)),
        num(Some(s.top_needed as f64)),
        if s.missing > 0 {
            format!(", {} bodies gone", s.missing)
        } else {
            String::new()
        }
    )
}

fn goals(
    jolt: &[PlaneRun],
    box2d: Option<&PlaneRun>,
    sweep: &[PlaneRun],
    steps: usize,
) -> Vec<Goal> {
    let mut goals = Vec::new();
    for r in jolt {
        let speedup = match (r.threads, jolt.first()) {
            (2, Some(one)) => format!(
                ", {}× Threads 1",
                num(Some(r.steps_per_s / one.steps_per_s))
            ),
            _ => String::new(),
        };
        goals.push(Goal::new(
            format!(
                "Jolt's Pyramid ({JOLT_PYRAMID_BOXES} boxes) through the daemon, Threads {}: \
                 steps/s",
                r.threads
            ),
            format!("{}{speedup}", steps_text(r)),
            None,
        ));
    }
    if !jolt.is_empty() {
        let all = jolt.iter().all(|r| r.stand.stands);
        let text: Vec<String> = jolt
            .iter()
            .map(|r| format!("Threads {}: {}", r.threads, stand_text(&r.stand)))
            .collect();
        goals.push(Goal::new(
            format!(
                "Jolt's Pyramid stands after {steps} steps (every box within {JOLT_DRIFT} of \
                 its start x/z, the top box at most {JOLT_SINK} below its rest height)"
            ),
            text.join("; "),
            Some(all),
        ));
    }
    if let Some(r) = box2d {
        goals.push(Goal::new(
            "Box2D's large_pyramid (5,050 squares) on a GUI plane, Threads 1 (GUI planes have \
             no Threads option): steps/s",
            steps_text(r),
            None,
        ));
        goals.push(Goal::new(
            format!(
                "Box2D's large_pyramid stands after {steps} steps (every square within \
                 {BOX2D_DRIFT} of its start x, the top one at most {BOX2D_SINK} below its start)"
            ),
            stand_text(&r.stand),
            Some(r.stand.stands),
        ));
    }
    for adaptive in [true, false] {
        let runs: Vec<&PlaneRun> = sweep
            .iter()
            .filter(|r| r.adaptive_solving == Some(adaptive))
            .collect();
        if let Some((ok, ratio, lo, hi)) = monotonic(&runs) {
            let list: Vec<String> = runs
                .iter()
                .map(|r| r.solver_iterations.to_string())
                .collect();
            goals.push(Goal::new(
                format!(
                    "the Pyramid's step cost does not fall as SolverIterations rises ({}; \
                     AdaptiveSolving {}; a rise of steps/s up to {MONOTONIC_SLACK}× is noise)",
                    list.join(", "),
                    if adaptive { "on" } else { "off" }
                ),
                format!(
                    "worst: SolverIterations {hi} runs {}× the steps/s of {lo}",
                    num(Some(ratio))
                ),
                Some(ok),
            ));
        }
    }
    goals
}

fn row(t: &mut Table, label: String, r: &PlaneRun) {
    t.row(&[
        label,
        num(Some(r.steps_per_s)),
        num(Some(r.wall_steps_per_s)),
        num(Some(r.median_step_ms)),
        num(Some(r.mean_contact_pairs)),
        pair(r.max_penetration, r.last_penetration),
        pair(r.stand.max_drift, r.stand.top_height),
        if r.stand.stands { "yes" } else { "**no**" }.into(),
    ]);
}

const RUN_HEADERS: [&str; 8] = [
    "plane",
    "steps/s (daemon step time)",
    "steps/s (round trip)",
    "median step (ms)",
    "contact pairs (mean)",
    "deepest contact (run / last tick)",
    "max drift / top height",
    "stands",
];

fn markdown(r: &PeersReport) -> String {
    let mut md = String::from("# Peer scenes: Jolt's Pyramid and Box2D's large_pyramid\n\n");
    let _ = writeln!(
        md,
        "Scenes other engines publish benchmark figures for, built as their benchmark \
         programs build them and stepped here through a real daemon (client-sdk, manual \
         planes, 60 Hz), {} timed steps after one untimed step. Steps/s is steps ÷ the \
         daemon's own step time (the tick headers), as the peers' harnesses time their step \
         call; the round trip (step request and reading the new tick) is beside it. No peer \
         speed is quoted: their figures come from their machines, and the setups below differ \
         from ours where said.\n",
        r.steps
    );
    if !r.jolt.is_empty() {
        md.push_str(&jolt_section(&r.jolt));
    }
    if let Some(b) = &r.box2d {
        md.push_str(&box2d_section(b));
    }
    if !r.sweep.is_empty() {
        md.push_str(&sweep_section(&r.sweep));
    }
    md
}

fn jolt_section(runs: &[PlaneRun]) -> String {
    let mut md = String::from("## Jolt's Pyramid\n\n");
    let _ = writeln!(
        md,
        "{JOLT_PYRAMID_BOXES} boxes 2 × 2 × 2 in 15 square layers (15², 14², … 1), each layer \
         0.5 above the one below and shifted by half a box on odd layers, on an anchored 100 × \
         2 × 100 floor whose top is y = 0 (Jolt's `PyramidScene`). Plane defaults (4 \
         SolverIterations, AdaptiveSolving on, friction 0.5) but gravity 9.81 (ours is 50) \
         and NeverSleep (Jolt's scene turns sleeping off). Threads 1 and 2 are two planes in \
         one daemon stepped alternately. Stands: every box within {JOLT_DRIFT} of its start \
         x/z and the top box at most {JOLT_SINK} below {} (its height once the gaps close).\n",
        jolt_pyramid_rest_top()
    );
    let mut t = Table::new(&RUN_HEADERS);
    for run in runs {
        row(&mut t, format!("Threads {}", run.threads), run);
    }
    md.push_str(&t.finish());
    md.push_str(
        "\nJolt's published setup: its PerformanceTest program (`-s=Pyramid`), 60 Hz \
         (`cDeltaTime = 1/60`), one collision step per update, 500 steps by default (`-i`), \
         steps/s = steps ÷ the summed time of `PhysicsSystem::Update`, each thread count from \
         1 to the machine's; Jolt's solver defaults are 10 velocity and 2 position iterations \
         per step; the boxes have no convex radius and may not sleep; gravity (0, −9.81, 0); \
         Discrete and LinearCast motion quality are both run (ours has no CCD on these \
         boxes, like Discrete).\n\n",
    );
    md
}

fn box2d_section(run: &PlaneRun) -> String {
    let mut md = String::from("## Box2D's large_pyramid\n\n");
    let _ = writeln!(
        md,
        "Rows of 100, 99, … 1 squares of half-size 0.5 (5,050), each row shifted by half a \
         square and resting on the one below, on a 200 × 2 ground whose top is y = 0 \
         (Box2D's `LargePyramid`), on a GUI plane at {PX_PER_UNIT} px per unit (+Y down). \
         GUI plane defaults ({} SolverIterations, friction 0.3, mass 1 per square, damping \
         0.05 / 0.10) but gravity {BOX2D_GRAVITY} units/s² (Box2D's) and NeverSleep. GUI \
         planes have no Threads option: Threads 1 only. Stands: every square within \
         {BOX2D_DRIFT} of its start x and the top one at most {BOX2D_SINK} below its start \
         (units).\n",
        run.solver_iterations
    );
    let mut t = Table::new(&RUN_HEADERS);
    row(&mut t, "GUI plane".into(), run);
    md.push_str(&t.finish());
    md.push_str(
        "\nDrift and heights in Box2D units (px ÷ 100). Box2D's published setup: its \
         benchmark program (`benchmark/main.c`), 60 Hz with 4 substeps, 500 steps for \
         large_pyramid after one untimed step, sleeping off, continuous collision on, density \
         1 and friction 0.6, gravity (0, −10), the best of 4 runs per thread count.\n\n",
    );
    md
}

fn sweep_section(runs: &[PlaneRun]) -> String {
    let mut md = String::from("## Cost against SolverIterations\n\n");
    md.push_str(
        "The Pyramid on Threads 1 at each SolverIterations below, AdaptiveSolving on (the \
         default) and off, all planes in one daemon stepped alternately. Boosted ticks and \
         substeps are the adaptive pass's load rule replayed on each tick's deepest contact \
         (a contact deeper than 0.03 gives the whole island 12 more substeps until it is \
         back under 0.01; the Pyramid is one island), an estimate: the daemon reads every \
         pair, the header only the deepest.\n\n",
    );
    let mut t = Table::new(&[
        "SolverIterations",
        "AdaptiveSolving",
        "steps/s",
        "median step (ms)",
        "contact pairs (mean)",
        "deepest contact (run / last tick)",
        "boosted ticks",
        "substeps per tick (mean)",
        "step boosted / not (ms)",
        "stands",
    ]);
    for r in runs {
        let (boosted, substeps, split) = match &r.boost {
            Some(b) => (
                format!("{} of {}", b.boosted_ticks, r.steps),
                num(Some(b.mean_substeps)),
                format!("{} / {}", num(b.boosted_step_ms), num(b.plain_step_ms)),
            ),
            None => (
                "—".into(),
                num(Some(r.solver_iterations as f64)),
                "—".into(),
            ),
        };
        t.row(&[
            r.solver_iterations.to_string(),
            if r.adaptive_solving == Some(true) {
                "on"
            } else {
                "off"
            }
            .into(),
            num(Some(r.steps_per_s)),
            num(Some(r.median_step_ms)),
            num(Some(r.mean_contact_pairs)),
            pair(r.max_penetration, r.last_penetration),
            boosted,
            substeps,
            split,
            if r.stand.stands { "yes" } else { "**no**" }.into(),
        ]);
    }
    md.push_str(&t.finish());
    md.push_str(&sweep_cause(runs));
    md
}

/// What the sweep's figures say about a cost that falls as SolverIterations rises.
fn sweep_cause(runs: &[PlaneRun]) -> String {
    let on: Vec<&PlaneRun> = runs
        .iter()
        .filter(|r| r.adaptive_solving == Some(true))
        .collect();
    let mut md = String::from("\n");
    let Some((false, _, lo, hi)) = monotonic(&on) else {
        md.push_str(
            "With AdaptiveSolving on, the step cost rises with SolverIterations (within the \
             noise allowance).\n",
        );
        return md;
    };
    let pick = |n: u32, a: bool| {
        runs.iter()
            .find(|r| r.solver_iterations == n && r.adaptive_solving == Some(a))
    };
    let (Some(low), Some(high)) = (pick(lo, true), pick(hi, true)) else {
        return md;
    };
    let boosted = |r: &PlaneRun| r.boost.as_ref().map_or(0, |b| b.boosted_ticks);
    let substeps = |r: &PlaneRun| r.boost.as_ref().map_or(0.0, |b| b.mean_substeps);
    let _ = writeln!(
        md,
        "Why SolverIterations {lo} costs more than {hi}: with {lo} substeps the Pyramid's \
         lower contacts sink deeper (deepest {} against {}), past the adaptive pass's 0.03 \
         trigger on {} of {} ticks (against {} at {hi}), and a boosted tick runs the whole \
         island at {lo} + 12 substeps: {} substeps per tick on average against {} at {hi}. \
         The contact pairs are the same ({} against {} on average): the pyramid does not \
         collapse, it is solved more often.",
        num(Some(low.max_penetration as f64)),
        num(Some(high.max_penetration as f64)),
        boosted(low),
        low.steps,
        boosted(high),
        num(Some(substeps(low))),
        num(Some(substeps(high))),
        num(Some(low.mean_contact_pairs)),
        num(Some(high.mean_contact_pairs)),
    );
    if let (Some(off_low), Some(off_high)) = (pick(lo, false), pick(hi, false)) {
        let _ = writeln!(
            md,
            "With AdaptiveSolving off the same two run at {} and {} steps/s.",
            num(Some(off_low.steps_per_s)),
            num(Some(off_high.steps_per_s)),
        );
    }
    md
}

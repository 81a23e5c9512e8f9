//! `physics-bench peers`: scenes other engines publish figures for, measured on our side
//! with the defaults, through a real daemon (client-sdk, manual planes stepped at 60 Hz):
//! Jolt's PerformanceTest "Pyramid" on Threads 1 and 2, Box2D v3's `large_pyramid` on a GUI
//! plane, and the Pyramid at SolverIterations 1, 2, 4 and 8 with AdaptiveSolving on and off
//! (the adaptive pass's boosts replayed from the tick headers: [`boost_estimate`]). Planes
//! of one part share a daemon and are stepped alternately, so all see the same load.
//! Steps/s is steps ÷ the daemon's own step times (the tick headers), what the peers'
//! harnesses time around their step call; one untimed step first, as Box2D's harness does.

use std::fmt::Write as _;
use std::path::PathBuf;
use std::time::Instant;

use client_sdk::{Client, GuiPlane, GuiPlaneOptions, Object, Plane, PlaneOptions, Snapshot};
use physics_scenes::peers::{
    jolt_pyramid_rest_top, JOLT_BOX_SIZE, LARGE_PYRAMID_BASE, LARGE_PYRAMID_HALF,
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
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Part {
    /// Jolt's Pyramid, Threads 1 and 2.
    Jolt,
    /// Box2D's large_pyramid on a GUI plane.
    Box2d,
    /// The Pyramid at SolverIterations 1, 2, 4, 8, AdaptiveSolving on and off.
    Sweep,
}

/// Steps of both peers' runs.
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
/// The top box may end this far below its rest height (gaps closed: 29): a quarter box for
/// 15 stacked contacts' sinking. A lost layer lowers it by a whole box (2).
const JOLT_SINK: f32 = 0.25 * JOLT_BOX_SIZE;
/// A large_pyramid square stands within a quarter of its side of its start x (units).
const BOX2D_DRIFT: f32 = 0.5 * LARGE_PYRAMID_HALF;
/// The top square may sink this far below its start (its rest: squares start touching); a
/// lost row lowers it by a whole side (1).
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

/// A higher SolverIterations may run this many times the steps/s of a lower one (noise).
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
    /// Largest horizontal distance of a body from its start, and the most allowed.
    pub max_drift: f32,
    pub drift_allowed: f32,
    /// Height of the top body's centre at the end, and the least allowed.
    pub top_height: f32,
    pub top_needed: f32,
    /// Bodies whose state could not be read (removed by the daemon: non-finite).
    pub missing: usize,
    pub stands: bool,
}

impl Stand {
    /// Stands when nothing is missing, the drift is within `allowed` and the top at `needed`
    /// or higher.
    fn new(
        max_drift: f32,
        drift_allowed: f32,
        (top_height, top_needed): (f32, f32),
        missing: usize,
    ) -> Stand {
        let mut s = Stand {
            max_drift,
            drift_allowed,
            top_height,
            top_needed,
            missing,
            stands: false,
        };
        s.stands = missing == 0 && max_drift <= drift_allowed && top_height >= top_needed;
        s
    }
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
    /// Median over the timed ticks of each tick's deepest contact.
    pub median_penetration: f32,
    /// Deepest contact of any timed tick.
    pub max_penetration: f32,
    /// Deepest contact of the last tick.
    pub last_penetration: f32,
    /// See [`boost_estimate`] (3D planes with AdaptiveSolving only).
    pub boost: Option<Boost>,
    /// The deepest contact pair after the last step (Pyramids only).
    pub deepest: Option<Deepest>,
    pub stand: Stand,
}

/// A Pyramid's deepest contact pair, read from its boxes' contacts.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Deepest {
    pub depth: f32,
    /// The box's layer (0: on the floor).
    pub layer: usize,
    /// The other body's layer; `None`: the floor.
    pub other_layer: Option<usize>,
    /// The pair's normal, from the box toward the other body.
    pub normal: [f32; 3],
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
            let (wall, h) = (started.elapsed().as_secs_f64() * 1e6, snapshot.header());
            match round {
                0 => trace.first = (h.tick, h.max_penetration),
                _ => trace.push(&snapshot, wall),
            }
        }
        if round % 50 == 0 {
            progress.phase(format!("{what}: step {round}/{steps}"));
        }
    }
    Ok(traces)
}

/// Replays the adaptive pass's load rule on each tick's deepest contact: after a tick with
/// a contact deeper than [`ADAPTIVE_TRIGGER`] the island is boosted, a boost stays while one
/// is deeper than [`ADAPTIVE_RELEASE`]; no pass runs (nothing changes) while none is, but
/// every [`ADAPTIVE_PASS_EVERY`] ticks. The Pyramid is one island, run at its bodies'
/// largest boost. An estimate: the daemon reads every pair, the header only the deepest.
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
    let depths: Vec<f64> = trace.penetration.iter().map(|&d| d as f64).collect();
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
        median_penetration: median(&depths).unwrap_or(0.0) as f32,
        max_penetration: trace.penetration.iter().copied().fold(0.0, f32::max),
        last_penetration: trace.penetration.last().copied().unwrap_or(0.0),
        boost,
        deepest: None,
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
        Ok(Stand::new(drift, JOLT_DRIFT, (top, needed), missing))
    }

    /// The deepest contact pair among the boxes' contacts now.
    fn deepest(&self) -> BenchResult<Option<Deepest>> {
        let layers: Vec<usize> = jolt_pyramid_layout()
            .iter()
            .map(|p| ((p[1] - 1.0) / 2.5).round() as usize)
            .collect();
        let layer_of: std::collections::HashMap<_, _> = self
            .boxes
            .iter()
            .map(|b| b.handle())
            .zip(layers.iter().copied())
            .collect();
        let mut deepest: Option<Deepest> = None;
        for (object, &layer) in self.boxes.iter().zip(&layers) {
            for c in object.contacts()? {
                let depth = c.points.iter().map(|p| p.depth).fold(f32::MIN, f32::max);
                if deepest.as_ref().is_none_or(|d| depth > d.depth) {
                    let other_layer = layer_of.get(&c.other).copied();
                    let normal = c.normal;
                    deepest = Some(Deepest {
                        depth,
                        layer,
                        other_layer,
                        normal,
                    });
                }
            }
        }
        Ok(deepest)
    }

    fn run(&self, trace: &Trace) -> BenchResult<PlaneRun> {
        let boost = self
            .adaptive
            .then(|| boost_estimate(trace, self.solver_iterations));
        let mut run = plane_run(
            trace,
            (self.threads, self.solver_iterations, Some(self.adaptive)),
            boost,
            self.stand()?,
        )?;
        run.deepest = self.deepest()?;
        Ok(run)
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
    Stand::new(drift, BOX2D_DRIFT, (top, top_start - BOX2D_SINK), missing)
}

pub fn run(args: &PeersArgs) -> BenchResult<()> {
    let steps = if args.quick { QUICK_STEPS } else { STEPS };
    let wants = |p: Part| args.only.is_empty() || args.only.contains(&p);
    let progress = Progress::new(3);
    let note = |what: String, r: &PlaneRun| {
        let (speed, stands) = (num(Some(r.steps_per_s)), r.stand.stands);
        progress.note(format!("{what}: {speed} steps/s, stands: {stands}"));
    };
    let jolt = wants(Part::Jolt).then(|| jolt(steps, &progress));
    let jolt = jolt.transpose()?.unwrap_or_default();
    jolt.iter()
        .for_each(|r| note(format!("Pyramid, Threads {}", r.threads), r));
    progress.done();
    let box2d = wants(Part::Box2d).then(|| box2d(steps, &progress));
    let box2d = box2d.transpose()?;
    box2d.iter().for_each(|r| note("large_pyramid".into(), r));
    progress.done();
    let sweep = wants(Part::Sweep).then(|| sweep(args, steps, &progress));
    let sweep = sweep.transpose()?.unwrap_or_default();
    for r in &sweep {
        let (n, a) = (r.solver_iterations, r.adaptive_solving);
        note(
            format!("Pyramid, SolverIterations {n}, AdaptiveSolving {a:?}"),
            r,
        );
    }
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

fn on_off(on: bool) -> &'static str {
    if on {
        "on"
    } else {
        "off"
    }
}

/// `a / b`, figures of f32.
fn pair(a: f32, b: f32) -> String {
    format!("{} / {}", num(Some(a as f64)), num(Some(b as f64)))
}

/// "0.035: layer 0 on the floor (vertical)", "0.012: layer 3 against layer 3 (horizontal)".
fn deepest_text(d: &Deepest) -> String {
    let other = d
        .other_layer
        .map_or("the floor".into(), |l| format!("layer {l}"));
    let axis = if d.normal[1].abs() > 0.7 {
        "vertical"
    } else {
        "horizontal"
    };
    format!("{:.3}: layer {} against {other} ({axis})", d.depth, d.layer)
}

/// A run's deepest contacts (median, largest and last tick's), to the millimetre.
fn depths(r: &PlaneRun) -> String {
    let (m, x, l) = (r.median_penetration, r.max_penetration, r.last_penetration);
    format!("{m:.3} / {x:.3} / {l:.3}")
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
        "{}: drift ≤ {} (allowed {}), top at {} (needed ≥ {}), {} bodies gone",
        if s.stands { "stands" } else { "falls" },
        num(Some(s.max_drift as f64)),
        num(Some(s.drift_allowed as f64)),
        num(Some(s.top_height as f64)),
        num(Some(s.top_needed as f64)),
        s.missing
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
        let one = jolt.first().map_or(1.0, |o| o.steps_per_s);
        let speedup = num(Some(r.steps_per_s / one));
        let what = format!(
            "Jolt's Pyramid (1,240 boxes), Threads {}: steps/s",
            r.threads
        );
        let value = format!("{}, {speedup}× Threads 1", steps_text(r));
        goals.push(Goal::new(what, value, None));
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
            let list: Vec<_> = runs
                .iter()
                .map(|r| r.solver_iterations.to_string())
                .collect();
            goals.push(Goal::new(
                format!(
                    "the Pyramid's step cost does not fall as SolverIterations rises ({}; \
                     AdaptiveSolving {}; a rise of steps/s up to {MONOTONIC_SLACK}× is noise)",
                    list.join(", "),
                    on_off(adaptive)
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
        depths(r),
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
    "deepest contact (median / max / last tick)",
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

/// A section: `intro`, a row per run, then the peer's published `setup`.
fn section(title: &str, intro: &str, runs: &[(String, &PlaneRun)], setup: &str) -> String {
    let mut t = Table::new(&RUN_HEADERS);
    for (label, run) in runs {
        row(&mut t, label.clone(), run);
    }
    format!("## {title}\n\n{intro}\n\n{}\n{setup}\n\n", t.finish())
}

fn jolt_section(runs: &[PlaneRun]) -> String {
    let intro = format!(
        "1,240 boxes 2 × 2 × 2 in 15 square layers (15², 14², … 1), each layer \
         0.5 above the one below and shifted by half a box on odd layers, on an anchored 100 × \
         2 × 100 floor whose top is y = 0 (Jolt's `PyramidScene`). Plane defaults (4 \
         SolverIterations, AdaptiveSolving on, friction 0.5) but gravity 9.81 (ours is 50) \
         and NeverSleep (Jolt's scene turns sleeping off). Threads 1 and 2 are two planes in \
         one daemon stepped alternately. Stands: every box within {JOLT_DRIFT} of its start \
         x/z and the top box at most {JOLT_SINK} below {} (its height once the gaps close).",
        jolt_pyramid_rest_top()
    );
    let rows: Vec<_> = runs
        .iter()
        .map(|r| (format!("Threads {}", r.threads), r))
        .collect();
    section(
        "Jolt's Pyramid",
        &intro,
        &rows,
        "Jolt's published setup: its PerformanceTest program (`-s=Pyramid`), 60 Hz \
         (`cDeltaTime = 1/60`), one collision step per update, 500 steps by default (`-i`), \
         steps/s = steps ÷ the summed time of `PhysicsSystem::Update`, each thread count from \
         1 to the machine's; Jolt's solver defaults are 10 velocity and 2 position iterations \
         per step; the boxes have no convex radius and may not sleep; gravity (0, −9.81, 0); \
         Discrete and LinearCast motion quality are both run (ours has no CCD on these \
         boxes, like Discrete).",
    )
}

fn box2d_section(run: &PlaneRun) -> String {
    let intro = format!(
        "Rows of 100, 99, … 1 squares of half-size 0.5 (5,050), each row shifted by half a \
         square and resting on the one below, on a 200 × 2 ground whose top is y = 0 \
         (Box2D's `LargePyramid`), on a GUI plane at {PX_PER_UNIT} px per unit (+Y down). \
         GUI plane defaults ({} SolverIterations, friction 0.3, mass 1 per square, damping \
         0.05 / 0.10) but gravity {BOX2D_GRAVITY} units/s² (Box2D's) and NeverSleep. GUI \
         planes have no Threads option: Threads 1 only. Stands: every square within \
         {BOX2D_DRIFT} of its start x and the top one at most {BOX2D_SINK} below its start \
         (units).",
        run.solver_iterations
    );
    section(
        "Box2D's large_pyramid",
        &intro,
        &[("GUI plane".into(), run)],
        "Drift and heights in Box2D units (px ÷ 100), contact depths in px. Box2D's \
         published setup: its benchmark program (`benchmark/main.c`), 60 Hz with 4 substeps, \
         500 steps for large_pyramid after one untimed step, sleeping off, continuous \
         collision on, density 1 and friction 0.6, gravity (0, −10), the best of 4 runs per \
         thread count.",
    )
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
        "deepest contact (median / max / last tick)",
        "boosted ticks",
        "substeps per tick (mean)",
        "step boosted / not (ms)",
        "deepest pair at the end",
        "stands",
    ]);
    for r in runs {
        let (boosted, substeps, split) = r.boost.as_ref().map_or_else(
            || ("—".into(), r.solver_iterations as f64, "—".into()),
            |b| {
                let split = format!("{} / {}", num(b.boosted_step_ms), num(b.plain_step_ms));
                (
                    format!("{} of {}", b.boosted_ticks, r.steps),
                    b.mean_substeps,
                    split,
                )
            },
        );
        t.row(&[
            r.solver_iterations.to_string(),
            on_off(r.adaptive_solving == Some(true)).into(),
            num(Some(r.steps_per_s)),
            num(Some(r.median_step_ms)),
            num(Some(r.mean_contact_pairs)),
            depths(r),
            boosted,
            num(Some(substeps)),
            split,
            r.deepest.as_ref().map_or_else(|| "—".into(), deepest_text),
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
    let pick = |n| on.iter().find(|r| r.solver_iterations == n);
    let (Some(low), Some(high)) = (pick(lo), pick(hi)) else {
        return md;
    };
    let boosted = |r: &PlaneRun| r.boost.as_ref().map_or(0, |b| b.boosted_ticks);
    let substeps = |r: &PlaneRun| r.boost.as_ref().map_or(0.0, |b| b.mean_substeps);
    let _ = writeln!(
        md,
        "Why SolverIterations {lo} costs more than {hi}: at {lo} the Pyramid's deepest \
         contact is deeper ({:.3} against {:.3} in the median tick), past the adaptive pass's \
         0.03 trigger on {} of {} ticks (against {} at {hi}), and a boosted tick runs the \
         whole island at {lo} + 12 substeps: {} substeps per tick on average against {} at \
         {hi}. The contact pairs are the same ({} against {} on average): the pyramid does \
         not collapse, it is solved more often.",
        low.median_penetration,
        high.median_penetration,
        boosted(low),
        low.steps,
        boosted(high),
        num(Some(substeps(low))),
        num(Some(substeps(high))),
        num(Some(low.mean_contact_pairs)),
        num(Some(high.mean_contact_pairs)),
    );
    md
}

//! What adaptive solving (`AdaptiveSolving`, on by default) costs: each scene built twice,
//! once with it and once without, stepped in alternating blocks in one run, the median step
//! of each compared. Scenes that do not need it (a settled and an awake 10,000-box pile) must
//! cost the same within 3 %; scenes that need it show their price. Written as
//! `adaptive.json` / `adaptive.md` beside the stability report, and as a section of the
//! accuracy report (see [`section`]).

use client_sdk::{ObjectProp, PlaneProp};
use physics_scenes::{column, floor, pile, pyramid};

use crate::error::BenchResult;
use crate::report::{Goal, Table};
use crate::sim::{Config, Sim};

/// One scene's cost with and without adaptive solving.
#[derive(Debug, Clone, serde::Serialize)]
pub struct CostRow {
    pub scene: &'static str,
    /// Whether the scene needs adaptive solving to pass at the defaults.
    pub needs_it: bool,
    pub bodies: usize,
    pub on_ms: f64,
    pub off_ms: f64,
    /// on / off.
    pub ratio: f64,
}

/// The report: rows and goals.
#[derive(Debug, Clone, serde::Serialize)]
pub struct CostReport {
    pub rows: Vec<CostRow>,
    pub goals: Vec<Goal>,
}

/// The most a scene that does not need adaptive solving may pay for it.
const UNNEEDED_BOUND: f64 = 1.03;

type Build = fn(&mut Sim) -> BenchResult<usize>;

fn settled_pile(sim: &mut Sim) -> BenchResult<usize> {
    let n = pile(sim, 10_000)?.len() - 1;
    sim.run_for(3.0)?;
    Ok(n)
}

fn awake_pile(sim: &mut Sim) -> BenchResult<usize> {
    sim.plane.set(PlaneProp::NeverSleep(true))?;
    let n = pile(sim, 10_000)?.len() - 1;
    sim.run_for(0.5)?;
    Ok(n)
}

fn ratio_column(sim: &mut Sim) -> BenchResult<usize> {
    floor(sim, 100.0, &[])?;
    let gap = sim.config.pair_gap();
    let boxes = column(sim, [0.0; 3], 1.0, 5, 0.0, gap, |i| {
        if i == 4 {
            vec![ObjectProp::Weight(1000.0)]
        } else {
            vec![]
        }
    })?;
    sim.plane.set(PlaneProp::NeverSleep(true))?;
    sim.run_for(0.5)?;
    Ok(boxes.len())
}

fn pyramid_60(sim: &mut Sim) -> BenchResult<usize> {
    sim.plane.set(PlaneProp::NeverSleep(true))?;
    floor(sim, 200.0, &[])?;
    let gap = sim.config.pair_gap();
    let n = pyramid(sim, 60, gap)?.len();
    sim.run_for(1.0)?;
    Ok(n)
}

/// The ratio column beside a 10,000-box awake pile on one plane: only the column's island
/// pays (rapier runs each connected group at its own substeps).
fn ratio_column_beside_pile(sim: &mut Sim) -> BenchResult<usize> {
    sim.plane.set(PlaneProp::NeverSleep(true))?;
    let n = pile(sim, 10_000)?.len() - 1;
    let gap = sim.config.pair_gap();
    let boxes = column(sim, [-20.0, 0.0, -20.0], 1.0, 5, 0.0, gap, |i| {
        let mut v = vec![];
        if i == 0 {
            v.push(ObjectProp::Anchored(true));
        }
        if i == 4 {
            v.push(ObjectProp::Weight(1000.0));
        }
        v
    })?;
    sim.run_for(0.5)?;
    Ok(n + boxes.len())
}

const SCENES: &[(&str, bool, Build)] = &[
    ("settled pile, 10,000 boxes", false, settled_pile),
    ("awake pile, 10,000 boxes (NeverSleep)", false, awake_pile),
    ("1,000:1 box on a column of 4", true, ratio_column),
    ("pyramid, base 60 (1,830 boxes)", true, pyramid_60),
    (
        "1,000:1 column beside an awake 10,000-box pile",
        true,
        ratio_column_beside_pile,
    ),
];

/// Median milliseconds per step of `sim` over `rounds` blocks of `block` steps, alternating
/// with `other` block by block (so both see the same machine).
fn alternate(a: &mut Sim, b: &mut Sim, rounds: usize, block: usize) -> BenchResult<(f64, f64)> {
    let (mut ta, mut tb) = (Vec::new(), Vec::new());
    for _ in 0..rounds {
        for (sim, times) in [(&mut *a, &mut ta), (&mut *b, &mut tb)] {
            for _ in 0..block {
                let started = std::time::Instant::now();
                sim.step()?;
                times.push(started.elapsed().as_secs_f64() * 1e3);
            }
        }
    }
    Ok((median(ta), median(tb)))
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// Measures every scene; `quick` takes fewer rounds.
pub fn measure(quick: bool) -> BenchResult<CostReport> {
    let (rounds, block) = if quick { (6, 5) } else { (12, 10) };
    let mut rows = Vec::new();
    for (scene, needs_it, build) in SCENES {
        let mut on = Sim::new(Config::DEFAULT, &[PlaneProp::AdaptiveSolving(true)])?;
        let mut off = Sim::new(Config::DEFAULT, &[PlaneProp::AdaptiveSolving(false)])?;
        let bodies = build(&mut on)?;
        build(&mut off)?;
        let (on_ms, off_ms) = alternate(&mut on, &mut off, rounds, block)?;
        rows.push(CostRow {
            scene,
            needs_it: *needs_it,
            bodies,
            on_ms,
            off_ms,
            ratio: on_ms / off_ms,
        });
    }
    let goals = rows
        .iter()
        .filter(|r| !r.needs_it)
        .map(|r| {
            Goal::new(
                format!(
                    "{}: step with adaptive solving / without ≤ {UNNEEDED_BOUND}",
                    r.scene
                ),
                format!("{:.3} ({:.2} vs {:.2} ms)", r.ratio, r.on_ms, r.off_ms),
                Some(r.ratio <= UNNEEDED_BOUND),
            )
        })
        .collect();
    Ok(CostReport { rows, goals })
}

/// The markdown page.
pub fn markdown(r: &CostReport) -> String {
    let mut t = Table::new(&[
        "scene",
        "needs it",
        "bodies",
        "step, adaptive (ms)",
        "step, without (ms)",
        "ratio",
    ]);
    for row in &r.rows {
        t.row(&[
            row.scene.into(),
            if row.needs_it { "yes" } else { "no" }.into(),
            row.bodies.to_string(),
            format!("{:.3}", row.on_ms),
            format!("{:.3}", row.off_ms),
            format!("{:.3}", row.ratio),
        ]);
    }
    format!(
        "# Adaptive solving: what it costs\n\nEach scene twice (AdaptiveSolving on and off, \
         the defaults otherwise), stepped in alternating blocks in one run; median step.\n\n{}",
        t.finish(),
    )
}

/// The same page as a section of another report (the accuracy report): its headings one
/// level down.
pub fn section(r: &CostReport) -> String {
    let page = markdown(r).replace("\n## ", "\n### ");
    format!("#{page}")
}

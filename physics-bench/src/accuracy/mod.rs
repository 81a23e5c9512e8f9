//! `physics-bench accuracy`: error against run time. Reference scenes with exact answers run
//! in process through the daemon's own plane code (`physics_scenes::LocalPlane`, what the
//! daemon steps), so the cost is the step calls alone, without IPC.

mod chart;
pub mod markdown;
mod pareto;
mod point;
pub(crate) mod scenes;
mod scenes_2d;
pub mod sweep;

use std::path::PathBuf;

use super::error::BenchResult;
use super::progress::Progress;
use super::report;
use super::sim::Config;
use super::stability::adaptive_cost;
use super::stats::median;
use point::Point;

/// Options of the `accuracy` subcommand.
#[derive(Debug, Clone, clap::Args)]
pub struct AccuracyArgs {
    /// The three families only, 5 repeats (under 2 minutes); otherwise also the full
    /// TickRate × SolverIterations × HitBoxQuality cross product, 9 repeats.
    #[arg(long)]
    pub quick: bool,
    /// Folder receiving accuracy.json, accuracy.md and accuracy-*.svg.
    #[arg(long, default_value = "bench-out")]
    pub out: PathBuf,
}

/// accuracy.json: every point, and the cost of adaptive solving with its goals (the only
/// goals of this report: error against cost is a trade-off, not a verdict).
#[derive(serde::Serialize)]
struct AccuracyReport<'a> {
    quick: bool,
    repeats: usize,
    points: &'a [Point],
    adaptive: &'a adaptive_cost::CostReport,
    goals: &'a [report::Goal],
}

pub fn run(args: &AccuracyArgs) -> BenchResult<()> {
    let configs = sweep::configs(!args.quick);
    let repeats = if args.quick { 5 } else { 9 };
    // 2D scenes have no HitBoxQuality or LoopSolver: only the configurations without them.
    let configs_2d: Vec<Config> = configs
        .iter()
        .copied()
        .filter(|c| c.hit_box_quality == 1 && !c.loop_solver)
        .collect();
    let runs = scenes::SCENES.len() * configs.len() + scenes_2d::SCENES_2D.len() * configs_2d.len();
    let progress = Progress::new(runs as u64);
    progress.note(format!(
        "accuracy: {} 3D scenes × {} configurations and {} 2D scenes × {}, × {repeats} repeats, \
         in process",
        scenes::SCENES.len(),
        configs.len(),
        scenes_2d::SCENES_2D.len(),
        configs_2d.len()
    ));
    let mut points = Vec::new();
    let all = scenes::SCENES
        .iter()
        .map(|s| (s, &configs))
        .chain(scenes_2d::SCENES_2D.iter().map(|s| (s, &configs_2d)));
    for (scene, configs) in all {
        let mut these = Vec::new();
        for config in configs {
            progress.phase(format!("{} at {}", scene.name, config.label()));
            let mut errors = Vec::new();
            let mut costs = Vec::new();
            for _ in 0..repeats {
                let o = (scene.run)(*config)?;
                errors.push(o.error);
                costs.push(o.cost);
            }
            // The error is deterministic; the median also keeps a NaN run visible.
            let error = if errors.iter().any(|e| e.is_nan()) {
                f64::NAN
            } else {
                median(&errors).unwrap_or(f64::NAN)
            };
            these.push(Point {
                scene: scene.name,
                config: *config,
                dt: config.dt(),
                error,
                error_unit: scene.unit,
                cost: median(&costs).unwrap_or(f64::NAN),
                pareto: false,
                is_default: *config == Config::DEFAULT,
            });
            progress.done();
        }
        pareto::mark(&mut these);
        if let Some(d) = these.iter().find(|p| p.is_default) {
            progress.note(format!(
                "{:<20} default: error {:.3e} {}, cost {:.2e}",
                scene.name, d.error, scene.unit, d.cost
            ));
        }
        points.extend(these);
    }
    progress.finish();
    let mut md = markdown::render(&points, args.quick, repeats);
    // What adaptive solving costs on scenes that need it and on scenes that do not, beside
    // the error-against-cost figures it trades against. Always the full rounds (~30 s): the
    // quick ones were too few to resolve the 3 % goal on a busy machine (an awake pile read
    // 1.28 where the full rounds read 0.94 to 1.02).
    let cost = adaptive_cost::measure(false)?;
    md.push('\n');
    md.push_str(&adaptive_cost::section(&cost));
    report::write(
        &args.out,
        "adaptive",
        &cost,
        &adaptive_cost::markdown(&cost),
    )?;
    let report = AccuracyReport {
        quick: args.quick,
        repeats,
        points: &points,
        adaptive: &cost,
        goals: &cost.goals,
    };
    let (json, md_path) = report::write(&args.out, "accuracy", &report, &md)?;
    let charts = chart::draw_all(&args.out, &points)?;
    println!("wrote {}, {}", json.display(), md_path.display());
    for c in charts {
        println!("wrote {}", c.display());
    }
    Ok(())
}

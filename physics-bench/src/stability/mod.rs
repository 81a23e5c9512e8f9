//! `physics-bench stability`: stress scenes with automatic pass criteria, and sweeps for the
//! critical values. In process, through the daemon's own plane code, like `accuracy`.

pub(crate) mod adaptive_cost;
mod before;
mod check;
mod entry;
mod markdown;
pub mod scenes;
mod stress;
mod sweeps;

use std::path::PathBuf;

use super::accuracy::sweep as configs;
use super::error::BenchResult;
use super::progress::Progress;
use super::report;
use super::sim::Config;
use check::Check;
use entry::{Entry, Remedy};
use sweeps::SweepPoint;

/// Options of the `stability` subcommand.
#[derive(Debug, Clone, clap::Args)]
pub struct StabilityArgs {
    /// Folder receiving stability.json and stability.md.
    #[arg(long, default_value = "bench-out")]
    pub out: PathBuf,
    /// Only the scenes and sweeps whose name contains this.
    #[arg(long)]
    pub only: Option<String>,
    /// The large pyramid at base 40 (820 boxes) instead of 100 (5,050: minutes on a busy
    /// 2-core machine), and no remedy search for failing scenes.
    #[arg(long)]
    pub quick: bool,
}

/// Configurations tried on a scene failing at `at`: the whole TickRate × SolverIterations ×
/// HitBoxQuality grid of the accuracy bench (the strongest configuration included). A scene
/// about a tick rate keeps its tick rate.
fn candidates(at: Config) -> Vec<Config> {
    let mut v = configs::configs(true);
    if at.tick_rate != Config::DEFAULT.tick_rate {
        for c in &mut v {
            c.tick_rate = at.tick_rate;
        }
        v.sort();
        v.dedup();
    }
    v
}

/// stability.json: one entry per scene and sweep, and the goal they add up to.
#[derive(serde::Serialize)]
struct StabilityReport<'a> {
    quick: bool,
    only: Option<&'a str>,
    entries: &'a [Entry],
    goals: Vec<report::Goal>,
}

pub fn run(args: &StabilityArgs) -> BenchResult<()> {
    let wanted = |name: &str| args.only.as_ref().is_none_or(|o| name.contains(o.as_str()));
    let scene_list: Vec<&scenes::Scene> = scenes::SCENES
        .iter()
        .filter(|s| wanted(s.name))
        .map(|s| {
            if args.quick && s.name == "pyramid-100" {
                &scenes::PYRAMID_40
            } else {
                s
            }
        })
        .collect();
    let sweep_list: Vec<&sweeps::Sweep> =
        sweeps::SWEEPS.iter().filter(|s| wanted(s.name)).collect();
    let sweep_runs: usize = sweep_list.iter().map(|s| 2 * s.values.len()).sum();
    let progress = Progress::new((scene_list.len() + sweep_runs) as u64);
    progress.note("stability: in process, through the daemon's plane code");
    let mut entries = Vec::new();
    for scene in scene_list {
        progress.phase(format!("{} at {}", scene.name, scene.config.label()));
        let started = std::time::Instant::now();
        let check = (scene.run)(scene.config)?;
        let mut remedy = None;
        if !check.pass && !args.quick {
            progress.phase(format!(
                "{}: searching a configuration that passes",
                scene.name
            ));
            remedy = Some(find_remedy(scene.run, scene.config)?);
        }
        let wall_s = started.elapsed().as_secs_f64();
        progress.note(format!(
            "{:<24} {} ({:.3e} vs bound {:.3e}, {wall_s:.1} s)",
            scene.name,
            if check.pass { "pass" } else { "FAIL" },
            check.figure,
            check.bound
        ));
        let mut e = entry(
            scene.name,
            scene.criterion.into(),
            scene.unit,
            scene.config,
            check,
            remedy,
        );
        e.wall_s = wall_s;
        entries.push(e);
        progress.done();
    }
    for sweep in sweep_list {
        let mut points = Vec::new();
        for config in [Config::DEFAULT, Config::STRONGEST] {
            for &value in sweep.values {
                progress.phase(format!("{} = {value} at {}", sweep.name, config.label()));
                let check = (sweep.run)(config, value)?;
                points.push(SweepPoint {
                    config,
                    value,
                    check,
                });
                progress.done();
            }
        }
        let at = |c: Config| -> Vec<SweepPoint> {
            points.iter().filter(|p| p.config == c).cloned().collect()
        };
        let (default, strongest) = (at(Config::DEFAULT), at(Config::STRONGEST));
        let critical_default = sweeps::critical(&default);
        let critical_strongest = sweeps::critical(&strongest);
        let judged = if sweep.judged_at_default {
            critical_default
        } else {
            critical_strongest
        };
        let judged_points = if sweep.judged_at_default {
            &default
        } else {
            &strongest
        };
        let reached = judged.unwrap_or(0.0);
        let cost = judged_points
            .iter()
            .find(|p| p.value == sweep.required)
            .map_or(f64::NAN, |p| p.check.cost);
        progress.note(format!(
            "{:<24} critical {} at default, {} at strongest",
            sweep.name,
            critical_default.map_or("none".into(), |v| v.to_string()),
            critical_strongest.map_or("none".into(), |v| v.to_string()),
        ));
        entries.push(Entry {
            scene: sweep.name,
            criterion: format!(
                "{}: at least {} at {}",
                sweep.what,
                sweep.required,
                if sweep.judged_at_default {
                    "the defaults"
                } else {
                    "the strongest configuration"
                }
            ),
            pass: reached >= sweep.required,
            figure: reached,
            bound: sweep.required,
            unit: "critical value",
            config: if sweep.judged_at_default {
                Config::DEFAULT
            } else {
                Config::STRONGEST
            },
            finite: points.iter().all(|p| p.check.finite),
            cost,
            remedy: None,
            remedy_candidates: 0,
            critical_default,
            critical_strongest,
            points,
            before: before::before(sweep.name),
            wall_s: 0.0,
        });
    }
    progress.finish();
    let md = markdown::render(&entries);
    let passed = entries.iter().filter(|e| e.pass).count();
    let goals = vec![report::Goal::new(
        "every stress scene and sweep passes its criterion",
        format!("{passed} of {} pass", entries.len()),
        Some(passed == entries.len()),
    )];
    let json = StabilityReport {
        quick: args.quick,
        only: args.only.as_deref(),
        entries: &entries,
        goals,
    };
    let (json, md_path) = report::write(&args.out, "stability", &json, &md)?;
    println!("wrote {}, {}", json.display(), md_path.display());
    let cost = adaptive_cost::measure(args.quick)?;
    let (json, md_path) = report::write(
        &args.out,
        "adaptive",
        &cost,
        &adaptive_cost::markdown(&cost),
    )?;
    for row in &cost.rows {
        println!(
            "adaptive solving, {}: {:.3} vs {:.3} ms per step ({:.3}×)",
            row.scene, row.on_ms, row.off_ms, row.ratio
        );
    }
    println!("wrote {}, {}", json.display(), md_path.display());
    let failed = entries.iter().filter(|e| !e.pass).count();
    println!(
        "{} of {} scenes pass",
        entries.len() - failed,
        entries.len()
    );
    Ok(())
}

fn entry(
    scene: &'static str,
    criterion: String,
    unit: &'static str,
    config: Config,
    check: Check,
    remedy: Option<(Option<Remedy>, usize)>,
) -> Entry {
    Entry {
        scene,
        criterion,
        pass: check.pass,
        figure: check.figure,
        bound: check.bound,
        unit,
        config,
        finite: check.finite,
        cost: check.cost,
        remedy_candidates: remedy.as_ref().map_or(0, |r| r.1),
        remedy: remedy.and_then(|r| r.0),
        critical_default: None,
        critical_strongest: None,
        points: Vec::new(),
        before: before::before(scene),
        wall_s: 0.0,
    }
}

/// The cheapest candidate configuration under which the scene passes, and how many were
/// tried.
fn find_remedy(
    run: fn(Config) -> BenchResult<Check>,
    at: Config,
) -> BenchResult<(Option<Remedy>, usize)> {
    let candidates = candidates(at);
    let mut best: Option<Remedy> = None;
    for config in &candidates {
        let check = run(*config)?;
        if check.pass && best.as_ref().is_none_or(|b| check.cost < b.cost) {
            best = Some(Remedy {
                config: *config,
                figure: check.figure,
                cost: check.cost,
            });
        }
    }
    Ok((best, candidates.len()))
}

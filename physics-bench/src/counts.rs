//! `physics-bench counts`: the instruction counts of `benches/instructions` (Valgrind's
//! Callgrind through gungraun) against the baselines kept in the repository.
//!
//! `.ci/instructions` runs the benchmarks with `--save-summary=json`, then this reads every
//! `summary.json` under `--summaries`, compares each count with `--baseline` and writes
//! `counts.json` / `counts.md`: one goal per benchmark (its count within ±2 % of the
//! baseline: a rise is a regression, a fall is an improvement whose commit must carry the
//! new baseline), and the cost per entity of each benchmark run at two sizes (the slope
//! between them). `--update` writes the counts as the new baseline instead of judging.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use super::error::{BenchError, BenchResult};
use super::report::{self, Goal, Table};

/// Options of the `counts` subcommand.
#[derive(Debug, Clone, clap::Args)]
pub struct CountsArgs {
    /// Folder holding gungraun's output (its `summary.json` files, at any depth).
    #[arg(long, default_value = "target/gungraun")]
    pub summaries: PathBuf,
    /// The baselines kept in the repository.
    #[arg(
        long,
        default_value = "physics-bench/benches/instructions/baseline.json"
    )]
    pub baseline: PathBuf,
    /// Write the counts as the new baseline instead of judging them.
    #[arg(long)]
    pub update: bool,
    /// Folder receiving counts.json and counts.md.
    #[arg(long, default_value = "bench-out")]
    pub out: PathBuf,
}

/// How far a count may move from its baseline, either way (percent).
pub const TOLERANCE_PCT: f64 = 2.0;

/// The baselines file: counts by benchmark name, with how they were made.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct Baseline {
    /// How the counts were made (the profile, the tool).
    pub made_by: String,
    /// Instructions (Callgrind's `Ir`) by benchmark name.
    pub counts: BTreeMap<String, u64>,
}

/// One benchmark's count against its baseline.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Row {
    pub bench: String,
    pub instructions: u64,
    pub baseline: Option<u64>,
    /// (count − baseline) / baseline, percent.
    pub change_pct: Option<f64>,
}

/// The cost per entity of a benchmark run at two sizes.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Slope {
    /// The benchmark without its size (`step::awake`, `publish::publish moving`).
    pub bench: String,
    pub sizes: [u64; 2],
    /// Instructions per entity: (count at the larger size − at the smaller) / (size gap).
    pub per_entity: f64,
    /// What the count at the smaller size has besides its entities.
    pub fixed: f64,
}

#[derive(Debug, Clone, serde::Serialize)]
struct CountsReport {
    goals: Vec<Goal>,
    rows: Vec<Row>,
    slopes: Vec<Slope>,
    tolerance_pct: f64,
}

pub fn run(args: &CountsArgs) -> BenchResult<()> {
    let counts = read_summaries(&args.summaries)?;
    if counts.is_empty() {
        return Err(BenchError::Failed(format!(
            "no summary.json under {}: run the benchmarks with --save-summary=json (.ci/instructions)",
            args.summaries.display()
        )));
    }
    if args.update {
        let baseline = Baseline {
            made_by: "cargo bench --profile dev -p physics-bench --bench instructions \
                      (gungraun, Callgrind, Ir)"
                .into(),
            counts,
        };
        let text = serde_json::to_string_pretty(&baseline)
            .map_err(|e| BenchError::Failed(format!("encode the baseline: {e}")))?;
        std::fs::write(&args.baseline, text + "\n")
            .map_err(BenchError::io(format!("write {}", args.baseline.display())))?;
        println!(
            "wrote {} counts to {}",
            baseline.counts.len(),
            args.baseline.display()
        );
        return Ok(());
    }
    let baseline = read_baseline(&args.baseline)?;
    let report = judge(&counts, &baseline);
    let body = markdown(&report);
    let (_, md) = report::write(&args.out, "counts", &report, &body)?;
    report::print(&md);
    let failed: Vec<&Goal> = report
        .goals
        .iter()
        .filter(|g| g.met == Some(false))
        .collect();
    if failed.is_empty() {
        Ok(())
    } else {
        Err(BenchError::Failed(format!(
            "{} of {} instruction counts moved more than {TOLERANCE_PCT} % from {} (a fall: \
             update the baseline in the same commit with .ci/instructions --update): {}",
            failed.len(),
            report.goals.len(),
            args.baseline.display(),
            failed
                .iter()
                .map(|g| format!("{} ({})", g.goal, g.value))
                .collect::<Vec<_>>()
                .join("; ")
        )))
    }
}

fn read_baseline(path: &Path) -> BenchResult<Baseline> {
    let text = std::fs::read_to_string(path).map_err(BenchError::io(format!(
        "read the baseline {}",
        path.display()
    )))?;
    serde_json::from_str(&text)
        .map_err(|e| BenchError::Failed(format!("{} is not a baseline: {e}", path.display())))
}

/// Every count, judged against its baseline; a benchmark without one (new) or a baseline
/// without a benchmark (removed) is a goal not met, so the file stays complete.
fn judge(counts: &BTreeMap<String, u64>, baseline: &Baseline) -> CountsReport {
    let mut goals = Vec::new();
    let mut rows = Vec::new();
    for (bench, &count) in counts {
        let base = baseline.counts.get(bench).copied();
        let change = base.map(|b| (count as f64 - b as f64) / (b.max(1) as f64) * 100.0);
        let (value, met) = match (base, change) {
            (Some(b), Some(c)) => (
                format!("{count} (baseline {b}, {c:+.2} %)"),
                c.abs() <= TOLERANCE_PCT,
            ),
            _ => (format!("{count} (no baseline)"), false),
        };
        goals.push(Goal::new(
            format!("{bench}: instructions within ±{TOLERANCE_PCT} % of the baseline"),
            value,
            Some(met),
        ));
        rows.push(Row {
            bench: bench.clone(),
            instructions: count,
            baseline: base,
            change_pct: change,
        });
    }
    for (bench, &b) in &baseline.counts {
        if !counts.contains_key(bench) {
            goals.push(Goal::new(
                format!("{bench}: instructions within ±{TOLERANCE_PCT} % of the baseline"),
                format!("not run (baseline {b})"),
                Some(false),
            ));
        }
    }
    let slopes = slopes(counts);
    goals.extend(recording_goal(&slopes));
    CountsReport {
        goals,
        slopes,
        rows,
        tolerance_pct: TOLERANCE_PCT,
    }
}

/// Bodies, writes a tick and ticks between keyframes of the recording goal's plane.
const RECORDED_PLANE: (f64, f64, f64) = (1_000.0, 100.0, 600.0);

/// What recording adds to a tick, in instructions, from the slopes (the goal of
/// docs/recording.md judged where wall and CPU time swing with the machine's load): per
/// recorded write and per tick, the recorded frame less the same frame unrecorded; a
/// keyframe every 600 ticks at a snapshot's cost per body; against a tick of 1,000 awake
/// bodies (the awake pile's step) and 100 velocity writes. `None` without those benchmarks.
fn recording_goal(slopes: &[Slope]) -> Option<Goal> {
    let of = |name: &str| slopes.iter().find(|s| s.bench == name);
    let (rec, plain) = (
        of("record::recorded_frame")?,
        of("record::unrecorded_frame")?,
    );
    let (snapshot, step, apply) = (
        of("history::snapshot")?,
        of("step::awake")?,
        of("apply::set_velocity")?,
    );
    let (bodies, writes, every) = RECORDED_PLANE;
    let per_write = rec.per_entity - plain.per_entity;
    let per_tick = rec.fixed - plain.fixed;
    let keyframe = snapshot.per_entity * bodies / every;
    let added = per_write * writes + per_tick + keyframe;
    let tick = step.per_entity * bodies + apply.per_entity * writes;
    let pct = added / tick * 100.0;
    Some(Goal::new(
        "recording adds <= 5 % to a tick (1,000 awake bodies, 100 writes a tick, a keyframe \
         every 600 ticks; instructions, from the slopes) [instructions-from-slopes]",
        format!(
            "{pct:+.2} % ({per_write:.0} a write, {per_tick:.0} a tick, {keyframe:.0} a tick \
             of keyframes, against {tick:.0} a tick)"
        ),
        Some(pct <= 5.0),
    ))
}

/// Splits a benchmark name's size off: `step::awake n200` → (`step::awake`, 200);
/// `publish::publish moving_n1000` → (`publish::publish moving`, 1000).
fn sized(bench: &str) -> Option<(String, u64)> {
    let (head, last) = bench.rsplit_once(' ')?;
    let (prefix, n) = match last.rsplit_once('_') {
        Some((prefix, n)) => (format!("{head} {prefix}"), n),
        None => (head.to_string(), last),
    };
    let n = n.strip_prefix('n')?.parse().ok()?;
    Some((prefix, n))
}

/// The cost per entity of each benchmark run at two (or more: the smallest and largest)
/// sizes.
fn slopes(counts: &BTreeMap<String, u64>) -> Vec<Slope> {
    let mut by_bench: BTreeMap<String, Vec<(u64, u64)>> = BTreeMap::new();
    for (bench, &count) in counts {
        if let Some((name, n)) = sized(bench) {
            by_bench.entry(name).or_default().push((n, count));
        }
    }
    by_bench
        .into_iter()
        .filter_map(|(bench, mut points)| {
            points.sort_unstable();
            let (&(n0, c0), &(n1, c1)) = (points.first()?, points.last()?);
            (n1 > n0).then(|| {
                let per_entity = (c1 as f64 - c0 as f64) / (n1 - n0) as f64;
                Slope {
                    bench,
                    sizes: [n0, n1],
                    per_entity,
                    fixed: c0 as f64 - per_entity * n0 as f64,
                }
            })
        })
        .collect()
}

/// Every benchmark's instruction count in the `summary.json` files under `dir`, by
/// `module::function id` with the benchmark file's name left off.
fn read_summaries(dir: &Path) -> BenchResult<BTreeMap<String, u64>> {
    let mut counts = BTreeMap::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(at) = stack.pop() {
        let Ok(entries) = std::fs::read_dir(&at) else {
            continue;
        };
        for entry in entries.flatten() {
            let path = entry.path();
            if path.is_dir() {
                stack.push(path);
            } else if path.file_name().is_some_and(|n| n == "summary.json") {
                let (name, ir) = read_summary(&path)?;
                counts.insert(name, ir);
            }
        }
    }
    Ok(counts)
}

/// One benchmark's name and instruction count from its gungraun `summary.json`.
fn read_summary(path: &Path) -> BenchResult<(String, u64)> {
    let bad = |what: &str| BenchError::Failed(format!("{}: {what}", path.display()));
    let text = std::fs::read_to_string(path)
        .map_err(BenchError::io(format!("read {}", path.display())))?;
    let json: serde_json::Value =
        serde_json::from_str(&text).map_err(|e| bad(&format!("not JSON: {e}")))?;
    let module = json["module_path"]
        .as_str()
        .ok_or_else(|| bad("no module_path"))?;
    // `instructions::step_group::settled` → `step::settled`.
    let module = module.split_once("::").map_or(module, |(_, rest)| rest);
    let module = module.replacen("_group::", "::", 1);
    let name = match json["id"].as_str() {
        Some(id) => format!("{module} {id}"),
        None => module.to_string(),
    };
    let ir = json["profiles"]
        .as_array()
        .and_then(|profiles| profiles.first())
        .and_then(|p| instructions(&p["data"]["total"]["metrics"]))
        .ok_or_else(|| bad("no instruction count (Ir) in its first profile's total"))?;
    Ok((name, ir))
}

/// The new `Ir` of a tool's metrics: `Ir.values.new` as gungraun 0.20 writes it, else the
/// first integer under the key `Ir` (the new run's value before the old one's).
fn instructions(metrics: &serde_json::Value) -> Option<u64> {
    fn first_int(v: &serde_json::Value) -> Option<u64> {
        match v {
            serde_json::Value::Number(n) => n.as_u64(),
            serde_json::Value::String(s) => s.parse().ok(),
            serde_json::Value::Array(items) => items.iter().find_map(first_int),
            serde_json::Value::Object(map) => map.values().find_map(first_int),
            _ => None,
        }
    }
    if let Some(n) = metrics["Ir"]["values"]["new"].as_u64() {
        return Some(n);
    }
    match metrics {
        serde_json::Value::Object(map) => map
            .get("Ir")
            .and_then(first_int)
            .or_else(|| map.values().find_map(instructions)),
        serde_json::Value::Array(items) => items.iter().find_map(instructions),
        _ => None,
    }
}

fn markdown(report: &CountsReport) -> String {
    let mut out = String::from("# Instruction counts\n\n");
    let _ = writeln!(
        out,
        "Callgrind's instruction count (`Ir`) of each benchmark in \
         `physics-bench/benches/instructions`, against the baseline kept beside them \
         (±{} % either way). Counts do not depend on the machine's load; they change with \
         the code, the compiler and the build profile.\n",
        report.tolerance_pct
    );
    out.push_str("## Cost per entity\n\n");
    let mut slopes = Table::new(&["benchmark", "sizes", "instructions per entity", "fixed"]);
    for s in &report.slopes {
        slopes.row(&[
            s.bench.clone(),
            format!("{}, {}", s.sizes[0], s.sizes[1]),
            format!("{:.0}", s.per_entity),
            format!("{:.0}", s.fixed),
        ]);
    }
    out.push_str(&slopes.finish());
    out.push_str("\n## Counts\n\n");
    let mut rows = Table::new(&["benchmark", "instructions", "baseline", "change"]);
    for r in &report.rows {
        rows.row(&[
            r.bench.clone(),
            r.instructions.to_string(),
            r.baseline.map_or("none".into(), |b| b.to_string()),
            r.change_pct.map_or("n/a".into(), |c| format!("{c:+.2} %")),
        ]);
    }
    out.push_str(&rows.finish());
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn counts(pairs: &[(&str, u64)]) -> BTreeMap<String, u64> {
        pairs.iter().map(|(k, v)| (k.to_string(), *v)).collect()
    }

    #[test]
    fn names_split_into_bench_and_size() {
        assert_eq!(sized("step::awake n200"), Some(("step::awake".into(), 200)));
        assert_eq!(
            sized("publish::publish moving_n1000"),
            Some(("publish::publish moving".into(), 1000))
        );
        assert_eq!(sized("step::awake"), None);
        assert_eq!(sized("step::awake big"), None);
    }

    #[test]
    fn slope_is_the_cost_per_entity_between_the_sizes() {
        let s = slopes(&counts(&[("a::b n10", 1_500), ("a::b n110", 11_500)]));
        assert_eq!(s.len(), 1);
        assert!((s[0].per_entity - 100.0).abs() < 1e-9);
        assert!((s[0].fixed - 500.0).abs() < 1e-9);
    }

    #[test]
    fn the_recording_goal_adds_writes_ticks_and_keyframes_against_a_tick() {
        let c = counts(&[
            ("record::recorded_frame n10", 10 * 130 + 50),
            ("record::recorded_frame n100", 100 * 130 + 50),
            ("record::unrecorded_frame n10", 10 * 100 + 20),
            ("record::unrecorded_frame n100", 100 * 100 + 20),
            ("history::snapshot n50", 50 * 600),
            ("history::snapshot n200", 200 * 600),
            ("step::awake n50", 50 * 1_000),
            ("step::awake n200", 200 * 1_000),
            ("apply::set_velocity n10", 10 * 10),
            ("apply::set_velocity n1000", 1000 * 10),
        ]);
        let goal = recording_goal(&slopes(&c)).expect("every slope there");
        // 30 a write × 100 + 30 a tick + 600 × 1,000 / 600 = 4,030 against 1,001,000.
        assert!(goal.value.starts_with("+0.40 %"), "{}", goal.value);
        assert_eq!(goal.met, Some(true));
        assert!(recording_goal(&slopes(&counts(&[("step::awake n1", 1)]))).is_none());
    }

    #[test]
    fn a_count_outside_two_percent_either_way_fails() {
        let baseline = Baseline {
            made_by: String::new(),
            counts: counts(&[
                ("a n1", 1000),
                ("b n1", 1000),
                ("c n1", 1000),
                ("gone n1", 5),
            ]),
        };
        let report = judge(
            &counts(&[("a n1", 1020), ("b n1", 1021), ("c n1", 970), ("new n1", 7)]),
            &baseline,
        );
        let met: BTreeMap<&str, Option<bool>> = report
            .goals
            .iter()
            .map(|g| (g.goal.split(':').next().unwrap(), g.met))
            .collect();
        assert_eq!(met["a n1"], Some(true), "+2.0 % is within");
        assert_eq!(met["b n1"], Some(false), "+2.1 % is a regression");
        assert_eq!(met["c n1"], Some(false), "−3 % needs the baseline updated");
        assert_eq!(met["new n1"], Some(false), "a benchmark without a baseline");
        assert_eq!(
            met["gone n1"],
            Some(false),
            "a baseline without a benchmark"
        );
    }

    #[test]
    fn instructions_are_found_however_nested() {
        let v: serde_json::Value = serde_json::from_str(
            r#"{"EstimatedCycles":{"values":{"new":9}},"Ir":{"values":{"new":4321,"old":5}}}"#,
        )
        .unwrap();
        assert_eq!(instructions(&v), Some(4321));
        let v: serde_json::Value =
            serde_json::from_str(r#"{"Callgrind":{"Ir":{"Both":[{"Int":1234},{"Int":99}]}}}"#)
                .unwrap();
        assert_eq!(instructions(&v), Some(1234));
        let v: serde_json::Value = serde_json::from_str(r#"{"Ir":{"Left":{"Int":"77"}}}"#).unwrap();
        assert_eq!(instructions(&v), Some(77));
    }
}

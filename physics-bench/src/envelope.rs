//! `physics-bench envelope`: the physics fuzzer of `physics_envelope` for a number of cases
//! or minutes (scenes drawn over the issue's parameter ranges, judged by physical-law
//! oracles, failures shrunk to Luau repros), then every critical-value probe at the
//! defaults and the strong setting, and the goals. Writes DIR/envelope.json,
//! DIR/envelope.md and DIR/repro-FAMILY-ORACLE.luau; with `--docs FILE`, replaces the
//! section between `<!-- envelope -->` and `<!-- /envelope -->` of FILE (appending it when
//! the markers are missing) and leaves the rest of the file alone.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Duration;

use physics_envelope::critical::{self, CriticalValue, GoalResult};
use physics_envelope::{space, FuzzConfig, FuzzReport, Setting, FAMILIES};

use super::error::{BenchError, BenchResult};
use super::report::{self, goals_table, Goal, Table};

/// Options of the `envelope` subcommand.
#[derive(Debug, Clone, clap::Args)]
pub struct EnvelopeArgs {
    /// Seeds the case generator (default 1: the same cases each run).
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Fuzz for this many minutes ...
    #[arg(long, conflicts_with = "cases")]
    pub minutes: Option<f64>,
    /// ... or for this many cases (default 120 when neither is given).
    #[arg(long)]
    pub cases: Option<usize>,
    /// Draw from the documented envelope (where the defaults hold) instead of the full
    /// ranges.
    #[arg(long)]
    pub holds: bool,
    /// Skip the critical-value probes and the goals' dedicated runs.
    #[arg(long)]
    pub no_critical: bool,
    /// Folder receiving envelope.json, envelope.md and the repros.
    #[arg(long, default_value = "bench-out")]
    pub out: PathBuf,
    /// A markdown file whose envelope section is replaced by this run's tables.
    #[arg(long)]
    pub docs: Option<PathBuf>,
}

pub const BEGIN: &str = "<!-- envelope -->";
pub const END: &str = "<!-- /envelope -->";

#[derive(serde::Serialize)]
struct Json<'a> {
    goals: Vec<Goal>,
    critical: &'a [CriticalValue],
    fuzz: &'a FuzzReport,
    space: space::Space,
    space_name: &'static str,
}

pub fn run(args: &EnvelopeArgs) -> BenchResult<()> {
    let (space, space_name) = if args.holds {
        (space::HOLDS, "HOLDS (the documented envelope)")
    } else {
        (space::FULL, "FULL (the issue's ranges)")
    };
    let cfg = FuzzConfig {
        seed: args.seed,
        cases: match (args.cases, args.minutes) {
            (Some(n), _) => Some(n),
            (None, None) => Some(120),
            (None, Some(_)) => None,
        },
        time: args.minutes.map(|m| Duration::from_secs_f64(m * 60.0)),
        space,
        determinism_every: 2,
        shrink_budget: 40,
        shrink_per_oracle: 1,
    };
    eprintln!(
        "envelope: seed {}, {}, drawing from {space_name}",
        cfg.seed,
        match (cfg.cases, args.minutes) {
            (Some(n), _) => format!("{n} cases"),
            (None, Some(m)) => format!("{m} minutes"),
            _ => unreachable!(),
        }
    );
    let fuzz = physics_envelope::fuzz(&cfg, |i, case, v| {
        if !v.is_empty() {
            let names: Vec<&str> = v.iter().map(|x| x.oracle).collect();
            eprintln!(
                "envelope: case {i} ({}) fails {}: {}",
                case.family(),
                names.join(", "),
                case.describe()
            );
        } else if i % 20 == 0 {
            eprintln!("envelope: case {i} ({}) holds", case.family());
        }
    });
    eprintln!(
        "envelope: {} cases in {:.0} s, {} failing, {} findings shrunk",
        fuzz.cases,
        fuzz.wall_s,
        fuzz.failing(),
        fuzz.findings.len()
    );
    let (crit, goal_results) = if args.no_critical {
        (Vec::new(), Vec::new())
    } else {
        let c = critical::search_all(|p, s| eprintln!("envelope: probe {p} at {}", s.label()));
        let g = critical::goals(&c, Some(&fuzz));
        (c, g)
    };
    let goals: Vec<Goal> = goal_results
        .iter()
        .map(|g: &GoalResult| Goal::new(g.goal.clone(), g.value.clone(), g.met))
        .collect();
    // The docs section carries its goals; the page shows them in its header instead.
    let section_docs = section(&goals, &crit, &fuzz, space_name);
    let mut md = String::from("# Envelope: the physics fuzzer\n\n");
    md.push_str(&section(&[], &crit, &fuzz, space_name));
    md.push_str("\n## Repros\n");
    for f in &fuzz.findings {
        let _ = write!(
            md,
            "\n### {} / {}\n\n```lua\n{}```\n",
            f.family, f.oracle, f.luau
        );
    }
    let json = Json {
        goals: goals.clone(),
        critical: &crit,
        fuzz: &fuzz,
        space,
        space_name,
    };
    let (j, m) = report::write(&args.out, "envelope", &json, &md)?;
    for f in &fuzz.findings {
        let path = args.out.join(format!(
            "repro-{}-{}.luau",
            f.family,
            f.oracle.replace(' ', "-")
        ));
        std::fs::write(&path, &f.luau)
            .map_err(BenchError::io(format!("write {}", path.display())))?;
    }
    eprintln!("envelope: wrote {} and {}", j.display(), m.display());
    if let Some(docs) = &args.docs {
        replace_section(docs, &section_docs)?;
        eprintln!(
            "envelope: replaced the envelope section of {}",
            docs.display()
        );
    }
    Ok(())
}

/// Replaces the text between the markers of `path` with `section` (appending the markers
/// and the section when the file has none).
pub fn replace_section(path: &Path, section: &str) -> BenchResult<()> {
    let old = std::fs::read_to_string(path)
        .map_err(BenchError::io(format!("read {}", path.display())))?;
    let block = format!("{BEGIN}\n{section}{END}\n");
    let new = match (old.find(BEGIN), old.find(END)) {
        (Some(b), Some(e)) if e > b => {
            let rest = &old[e + END.len()..];
            format!(
                "{}{block}{}",
                &old[..b],
                rest.strip_prefix('\n').unwrap_or(rest)
            )
        }
        _ => format!("{}\n{block}", old.trim_end_matches('\n').to_string() + "\n"),
    };
    std::fs::write(path, new).map_err(BenchError::io(format!("write {}", path.display())))
}

fn fig(v: f64) -> String {
    if v == 0.0 {
        "0".into()
    } else if v.abs() >= 1e5 || v.abs() < 1e-3 {
        format!("{v:.3e}")
    } else {
        format!("{}", physics_envelope::round3(v))
    }
}

fn critical_cell(c: Option<&CriticalValue>) -> String {
    match c {
        None => "—".into(),
        Some(c) => match (&c.first_failure, c.value) {
            (None, _) => format!("≥ {} (whole grid)", fig(c.value.unwrap_or(f64::NAN))),
            (Some((f, o)), Some(v)) => {
                format!("**{}** (fails at {}: {})", fig(v), fig(*f), o.join(", "))
            }
            (Some((f, o)), None) => format!("none (fails at {}: {})", fig(*f), o.join(", ")),
        },
    }
}

/// The generated section: goals, critical values, the fuzz run by family, the findings.
fn section(goals: &[Goal], crit: &[CriticalValue], fuzz: &FuzzReport, space: &str) -> String {
    let mut md = String::from("## Envelope: critical values at the defaults\n\n");
    md.push_str(
        "Generated by `physics-bench envelope --docs docs/stability.md` (crate \
         `physics-envelope`): scenes drawn over parameter spaces, stepped in process through \
         the daemon's own plane code, judged by oracles from physical law (every value \
         finite; nothing crosses a target's mid-plane between ticks; resting heights, \
         penetration, sleep, tilt and drift within tolerances stated per family in \
         `envelope/src/families/`; undamped energy kept within 1 %; momentum kept in free \
         collisions; the state-hash fold equal across two runs). A critical value is the \
         last value of the probe's grid (easy to hard) at which every oracle still holds.\n\n",
    );
    if !goals.is_empty() {
        md.push_str("### Goals\n\n");
        md.push_str(&goals_table(goals));
        md.push('\n');
    }
    if !crit.is_empty() {
        md.push_str("### Critical values\n\n");
        let mut others: Vec<Setting> = Vec::new();
        for c in crit {
            if c.setting != Setting::DEFAULT
                && c.setting != Setting::STRONG
                && !others.contains(&c.setting)
            {
                others.push(c.setting);
            }
        }
        let mut headers = vec![
            "probe".to_string(),
            "parameter".to_string(),
            format!("defaults ({})", Setting::DEFAULT.label()),
            format!("strong ({})", Setting::STRONG.label()),
        ];
        for s in &others {
            headers.push(s.label());
        }
        let refs: Vec<&str> = headers.iter().map(|s| s.as_str()).collect();
        let mut t = Table::new(&refs);
        let mut probes: Vec<&'static str> = Vec::new();
        for c in crit {
            if !probes.contains(&c.probe) {
                probes.push(c.probe);
            }
        }
        for p in probes {
            let at = |s: Setting| crit.iter().find(|c| c.probe == p && c.setting == s);
            let first = at(Setting::DEFAULT).or_else(|| crit.iter().find(|c| c.probe == p));
            let mut row = vec![
                p.to_string(),
                first.map_or(String::new(), |c| {
                    let g: Vec<String> = c.grid.iter().map(|v| fig(*v)).collect();
                    format!("{} ({})", c.parameter, g.join(", "))
                }),
                critical_cell(at(Setting::DEFAULT)),
                critical_cell(at(Setting::STRONG)),
            ];
            for s in &others {
                row.push(critical_cell(at(*s)));
            }
            t.row(&row);
        }
        md.push_str(&t.finish());
        md.push('\n');
    }
    let _ = write!(
        md,
        "### Fuzz run\n\nSeed {}, {} cases drawn from {space} in {:.0} s; {} failing. Per family \
         (failures by oracle):\n\n",
        fuzz.seed,
        fuzz.cases,
        fuzz.wall_s,
        fuzz.failing()
    );
    let mut t = Table::new(&["family", "cases", "failing", "by oracle", "wall s"]);
    for f in FAMILIES {
        if let Some(s) = fuzz.families.get(f) {
            let by: Vec<String> = s
                .by_oracle
                .iter()
                .map(|(o, n)| format!("{o} {n}"))
                .collect();
            t.row(&[
                f.to_string(),
                s.cases.to_string(),
                s.failing.to_string(),
                by.join(", "),
                format!("{:.0}", s.wall_s),
            ]);
        }
    }
    md.push_str(&t.finish());
    if !fuzz.findings.is_empty() {
        md.push_str(
            "\nShrunk failures (the first of each family and oracle; `physics-bench envelope` \
             writes each as a runnable `repro-FAMILY-ORACLE.luau` for `physics-lua`):\n\n",
        );
        for f in &fuzz.findings {
            let figs: Vec<String> = f
                .violations
                .iter()
                .filter(|v| v.oracle == f.oracle)
                .map(|v| format!("{} against {}", fig(v.figure), fig(v.bound)))
                .collect();
            let _ = writeln!(
                md,
                "- **{} / {}** ({}): `{}`",
                f.family,
                f.oracle,
                figs.join(", "),
                f.shrunk.describe()
            );
        }
    }
    md
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_section_is_replaced_in_place_or_appended() {
        let dir = std::env::temp_dir().join(format!("envelope-docs-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("stability.md");
        std::fs::write(&path, "# Stability\n\ntable\n").unwrap();
        replace_section(&path, "first\n").unwrap();
        let once = std::fs::read_to_string(&path).unwrap();
        assert_eq!(
            once,
            format!("# Stability\n\ntable\n\n{BEGIN}\nfirst\n{END}\n")
        );
        std::fs::write(&path, once.replace("table", "new table") + "after\n").unwrap();
        replace_section(&path, "second\n").unwrap();
        assert_eq!(
            std::fs::read_to_string(&path).unwrap(),
            format!("# Stability\n\nnew table\n\n{BEGIN}\nsecond\n{END}\nafter\n")
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
}

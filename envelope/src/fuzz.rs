//! A fuzz run: cases drawn family by family in turn ([`fuzz`]), judged, the first failures
//! of each (family, oracle) shrunk into [`Finding`]s, counted in a [`FuzzReport`].

use std::collections::BTreeMap;
use std::time::{Duration, Instant};

use crate::case::{judge, shrink, Case, FAMILIES};
use crate::oracle::Violation;
use crate::rng::Rng;
use crate::space;

/// A failure shrunk: the case as drawn, the simplest case found that still fails the same
/// oracle, and that case's violations.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Finding {
    pub family: &'static str,
    pub oracle: &'static str,
    pub drawn: Case,
    pub shrunk: Case,
    pub violations: Vec<Violation>,
    /// Runs the shrinking took.
    pub shrink_runs: usize,
    pub luau: String,
}

/// How a fuzz run is bounded and what it draws from.
#[derive(Debug, Clone)]
pub struct FuzzConfig {
    pub seed: u64,
    /// Stop after this many cases ...
    pub cases: Option<usize>,
    /// ... or after this long (whichever comes first; one of them must be set).
    pub time: Option<Duration>,
    pub space: space::Space,
    /// Rerun every n-th case for the determinism oracle (1: every case; 0: never).
    pub determinism_every: usize,
    /// Runs each shrink may take (0: no shrinking).
    pub shrink_budget: usize,
    /// Findings shrunk per (family, oracle); later failures of the same pair are counted.
    pub shrink_per_oracle: usize,
}

/// Per family: cases run, cases failing, failures by oracle.
#[derive(Debug, Clone, Default, serde::Serialize)]
pub struct FamilyStats {
    pub cases: usize,
    pub failing: usize,
    pub by_oracle: BTreeMap<&'static str, usize>,
    pub wall_s: f64,
}

/// What a fuzz run found.
#[derive(Debug, Clone, serde::Serialize)]
pub struct FuzzReport {
    pub seed: u64,
    pub cases: usize,
    pub wall_s: f64,
    pub families: BTreeMap<&'static str, FamilyStats>,
    /// Cases in which some body turned non-finite.
    pub non_finite_cases: usize,
    pub findings: Vec<Finding>,
}

impl FuzzReport {
    pub fn failing(&self) -> usize {
        self.families.values().map(|f| f.failing).sum()
    }
}

/// Draws cases family by family in turn, judges each, and shrinks the first failures of
/// each (family, oracle). `progress` hears each case's index, family and verdict.
pub fn fuzz(cfg: &FuzzConfig, mut progress: impl FnMut(usize, &Case, &[Violation])) -> FuzzReport {
    let started = Instant::now();
    let mut rng = Rng::new(cfg.seed);
    let mut report = FuzzReport {
        seed: cfg.seed,
        cases: 0,
        wall_s: 0.0,
        families: FAMILIES
            .iter()
            .map(|f| (*f, FamilyStats::default()))
            .collect(),
        non_finite_cases: 0,
        findings: Vec::new(),
    };
    let mut shrunk: BTreeMap<(&'static str, &'static str), usize> = BTreeMap::new();
    let mut i = 0usize;
    loop {
        if cfg.cases.is_some_and(|n| i >= n) || cfg.time.is_some_and(|t| started.elapsed() >= t) {
            break;
        }
        let case = Case::draw(i, &mut rng, &cfg.space);
        let determinism = cfg.determinism_every > 0 && i.is_multiple_of(cfg.determinism_every);
        let t0 = Instant::now();
        let v = judge(&case, determinism);
        let stats = report
            .families
            .get_mut(case.family())
            .expect("every family has stats");
        stats.cases += 1;
        stats.wall_s += t0.elapsed().as_secs_f64();
        progress(i, &case, &v);
        if !v.is_empty() {
            stats.failing += 1;
            if v.iter().any(|x| x.oracle == "finite") {
                report.non_finite_cases += 1;
            }
            let mut seen = Vec::new();
            for x in &v {
                if seen.contains(&x.oracle) {
                    continue;
                }
                seen.push(x.oracle);
                *stats.by_oracle.entry(x.oracle).or_default() += 1;
            }
            // Shrink for the first oracle of this case not yet shrunk enough.
            for oracle in seen {
                let n = shrunk.entry((case.family(), oracle)).or_default();
                if *n >= cfg.shrink_per_oracle || cfg.shrink_budget == 0 {
                    continue;
                }
                *n += 1;
                let (s, sv, runs) = shrink(&case, oracle, cfg.shrink_budget);
                report.findings.push(Finding {
                    family: case.family(),
                    oracle,
                    luau: s.luau(),
                    drawn: case.clone(),
                    shrunk: s,
                    violations: sv,
                    shrink_runs: runs,
                });
                break;
            }
        }
        i += 1;
        report.cases = i;
    }
    report.wall_s = started.elapsed().as_secs_f64();
    report
}

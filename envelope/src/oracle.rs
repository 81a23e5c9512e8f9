//! What a run gave and how the oracles report: [`Violation`] (a figure against its bound),
//! [`Outcome`], the `at_most` / `at_least` checks and the shared `finite` oracle ([`finish`]).

use crate::plane::Run;

/// One oracle that did not hold: its figure against its bound.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Violation {
    pub oracle: &'static str,
    pub figure: f64,
    pub bound: f64,
}

impl Violation {
    pub fn new(oracle: &'static str, figure: f64, bound: f64) -> Violation {
        Violation {
            oracle,
            figure,
            bound,
        }
    }
}

/// What one run of a case gave.
#[derive(Debug, Clone, Default)]
pub struct Outcome {
    pub violations: Vec<Violation>,
    pub hash: u64,
}

/// Pushes a violation when `figure > bound` (or is NaN).
pub fn at_most(v: &mut Vec<Violation>, oracle: &'static str, figure: f64, bound: f64) {
    if figure.is_nan() || figure > bound {
        v.push(Violation::new(oracle, figure, bound));
    }
}

/// Pushes a violation when `figure < bound` (or is NaN).
pub fn at_least(v: &mut Vec<Violation>, oracle: &'static str, figure: f64, bound: f64) {
    if figure.is_nan() || figure < bound {
        v.push(Violation::new(oracle, figure, bound));
    }
}

/// Ends a run: adds the shared `finite` oracle.
pub fn finish(run: &Run, mut violations: Vec<Violation>) -> Outcome {
    if let Some(t) = run.non_finite_at {
        violations.insert(0, Violation::new("finite", t as f64, 0.0));
    }
    Outcome {
        violations,
        hash: run.hash,
    }
}

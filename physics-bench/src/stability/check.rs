//! What one run of a stress scene measured, and its verdict.

use crate::sim::Sim;

/// What one run of a scene measured.
#[derive(Debug, Clone, Copy, serde::Serialize)]
pub struct Check {
    pub figure: f64,
    pub bound: f64,
    pub pass: bool,
    pub finite: bool,
    pub cost: f64,
}

impl Check {
    /// Pass when the scene stayed finite and `figure <= bound`.
    pub fn at_most(sim: &Sim, figure: f64, bound: f64) -> Check {
        let finite = !sim.went_nonfinite;
        Check {
            figure,
            bound,
            pass: finite && figure <= bound,
            finite,
            cost: sim.cost(),
        }
    }
}

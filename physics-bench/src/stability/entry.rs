//! The entries of stability.json: what `stability` measured per scene and sweep, which
//! the markdown renders.

use super::sweeps::SweepPoint;
use crate::sim::Config;

/// A configuration that makes a failing scene pass, and what it costs.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Remedy {
    #[serde(flatten)]
    pub config: Config,
    pub figure: f64,
    pub cost: f64,
}

/// One entry of stability.json: a scene, or a sweep judged by its critical value.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Entry {
    pub scene: &'static str,
    pub criterion: String,
    pub pass: bool,
    pub figure: f64,
    pub bound: f64,
    pub unit: &'static str,
    pub config: Config,
    pub finite: bool,
    pub cost: f64,
    /// For a scene failing at its configuration: the cheapest candidate that passes
    /// (`None` with `remedy_searched` when none does).
    pub remedy: Option<Remedy>,
    /// Configurations tried for a remedy (0: the scene passed).
    pub remedy_candidates: usize,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub critical_default: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub critical_strongest: Option<f64>,
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub points: Vec<SweepPoint>,
    /// The scene's figure before articulations, in words (see `before`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub before: Option<&'static str>,
    /// Wall seconds the scene took (its remedy search included).
    pub wall_s: f64,
}

//! A point of the accuracy report (one scene at one configuration) and the scene it
//! belongs to, which the markdown, the charts and the Pareto marking read.

use super::{scenes, scenes_2d};
use crate::sim::Config;

/// One scene at one configuration.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Point {
    pub scene: &'static str,
    #[serde(flatten)]
    pub config: Config,
    pub dt: f32,
    /// NaN (null in JSON) when a body went non-finite.
    pub error: f64,
    pub error_unit: &'static str,
    /// Median wall seconds of step calls per simulated second.
    pub cost: f64,
    pub pareto: bool,
    pub is_default: bool,
}

/// The reference scenes, for the report's headings.
pub fn scene_info(name: &str) -> Option<&'static scenes::Scene> {
    scenes::SCENES
        .iter()
        .chain(scenes_2d::SCENES_2D)
        .find(|s| s.name == name)
}

//! The scene families. Each module holds one family's case (its parameters as a struct),
//! how a case is drawn from its ranges, built and stepped, its oracles with their stated
//! tolerances, its shrinking steps and its Luau repro.

pub mod chain;
pub mod drop;
pub mod pile;
pub mod projectile;
pub mod spring;
pub mod stack;

use crate::rng::Rng;
use crate::setting::{Setting, SettingRanges};

/// A setting drawn from `r`: tick rate log-uniform, iterations and quality log-uniform
/// integers.
pub fn draw_setting(rng: &mut Rng, r: &SettingRanges) -> Setting {
    Setting {
        tick_rate: rng.log_uniform(r.tick_rate).round() as f32,
        iterations: rng.int_log(r.iterations.0, r.iterations.1),
        quality: rng.int_log(r.quality.0, r.quality.1),
    }
}

/// The Luau plane options of a setting (after `TickRate = 0, `).
pub fn plane_opts(s: &Setting, extra: &str) -> String {
    format!("SolverIterations = {}{extra}", s.iterations)
}

/// Degrees between the body's up axis (`local_up` in its own frame) and world up.
pub fn tilt_deg(rotation: [f32; 4], local_up: [f32; 3]) -> f64 {
    let up = crate::plane::rotate(rotation, local_up);
    (up[1] / crate::plane::norm(up))
        .clamp(-1.0, 1.0)
        .acos()
        .to_degrees()
}

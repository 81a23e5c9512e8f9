//! Solver settings of a plane: SolverIterations / LoopSolver, scaled plane-wide by the
//! largest HitBoxQuality among its objects.

use rapier3d::prelude::*;
use shm_layout::validate::{MAX_HIT_BOX_QUALITY, MAX_SOLVER_ITERATIONS};

use super::Plane;

/// Rapier's defaults at HitBoxQuality 1.
const ALLOWED_LINEAR_ERROR: f32 = 0.005;
const PREDICTION_DISTANCE: f32 = 0.02;
/// Largest solver-work factor, reached at HitBoxQuality 32. Contact stiffness (rapier's
/// natural frequency) scales by the same factor: raising the damping ratio instead would
/// slow penetration recovery, and heavy bodies would sink deeper at higher quality.
const MAX_WORK_FACTOR: f32 = 2.5;

/// What one tick of the plane's solver runs with.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct SolverSettings {
    pub iterations: usize,
    pub internal_iterations: usize,
    pub allowed_linear_error: f32,
    pub prediction_distance: f32,
    pub stiffness_factor: f32,
}

impl Plane {
    pub(super) fn max_quality(&self) -> u32 {
        (1..=MAX_HIT_BOX_QUALITY)
            .rev()
            .find(|q| self.quality_counts[*q as usize] > 0)
            .unwrap_or(1)
    }

    /// LoopSolver pins 64 iterations; otherwise SolverIterations, scaled linearly from ×1 at
    /// quality 1 to ×2.5 at quality 32. Tolerances shrink as 1/√quality.
    pub(super) fn solver_settings(&self) -> SolverSettings {
        let q = self.max_quality() as f32;
        let factor = 1.0 + (MAX_WORK_FACTOR - 1.0) * (q - 1.0) / (MAX_HIT_BOX_QUALITY as f32 - 1.0);
        let iterations = if self.settings.loop_solver {
            MAX_SOLVER_ITERATIONS as usize
        } else {
            (self.settings.solver_iterations as f32 * factor).round() as usize
        };
        SolverSettings {
            iterations: iterations.max(1),
            internal_iterations: factor.round() as usize,
            allowed_linear_error: ALLOWED_LINEAR_ERROR / q.sqrt(),
            prediction_distance: PREDICTION_DISTANCE / q.sqrt(),
            stiffness_factor: factor,
        }
    }

    pub(super) fn tune_solver(&mut self) {
        let s = self.solver_settings();
        let p = &mut self.world.integration_parameters;
        p.num_solver_iterations = s.iterations;
        p.num_internal_pgs_iterations = s.internal_iterations;
        p.num_internal_stabilization_iterations = s.internal_iterations;
        p.normalized_allowed_linear_error = s.allowed_linear_error;
        p.normalized_prediction_distance = s.prediction_distance;
        let base = SpringCoefficients::<f32>::contact_defaults();
        let base_static = SpringCoefficients::<f32>::contact_static_defaults();
        p.contact_softness.natural_frequency = base.natural_frequency * s.stiffness_factor;
        p.static_contact_softness.natural_frequency =
            base_static.natural_frequency * s.stiffness_factor;
    }
}

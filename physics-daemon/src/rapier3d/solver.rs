//! Solver settings of a plane: SolverIterations / LoopSolver, scaled plane-wide by the
//! largest HitBoxQuality among its objects and by the step's length.
//!
//! - Substeps: rapier runs one substep per solver iteration. A step longer than 1/60 s gets
//!   proportionally more iterations (`SolverIterations · dt · 60`, rounded up), so a substep
//!   never exceeds what the defaults give at 60 Hz (1/240 s): TickRate 10 runs 24.
//! - Contact stiffness (rapier's natural frequency, 30 Hz and 60 Hz against anchored bodies)
//!   follows the substep rate once that is high: `max(30 · quality factor, substeps per second
//!   / 8)`. Soft contacts leak a fraction of their impulse every iteration (the CFM), and a
//!   heavy body on a light one (the light body sets the constraint's mass) sinks by that leak;
//!   a stiffer contact leaks less. At the defaults (240 substeps/s) nothing changes; at 1,920
//!   substeps/s and above (e.g. 240 Hz × 8, 60 Hz × 32) a 1,000:1 box holds.
//! - Contact prediction: a body that moves more than half the prediction distance in a tick
//!   gets rapier's soft CCD (`soft_ccd_prediction`, up to `SOFT_CCD_REACH` ahead): the
//!   contacts it will make during the tick are predicted along its velocity, so it is
//!   stopped in that tick. The published velocity of the tick of impact is the solved one,
//!   and a bounce starts at the surface instead of from wherever the body had sunk to (that
//!   depth varied with the phase of the ticks, which made the bounce error jump with dt).
//!   Slower bodies keep the plain prediction distance: rapier's soft-CCD pair test sweeps
//!   the bare shapes by the relative velocity, and drops the contact of a body resting
//!   still at the skin's distance.
//! - Internal PGS iterations: 1 at quality 1, 4 as soon as any object has HitBoxQuality > 1
//!   (free rotation). One sweep over a face's four contact points in the substep of a fast
//!   impact hands the first point the whole impulse and spins the body: a box at 400
//!   units/s rebounded at 14 units/s; four sweeps converge (< 1 units/s).

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
/// The longest step the SolverIterations count is meant for (60 Hz).
const REFERENCE_DT: f32 = 1.0 / 60.0;
/// Contact natural frequency as a fraction of the substep rate, once that exceeds the base.
const SUBSTEPS_PER_CONTACT_PERIOD: f32 = 8.0;
/// Internal PGS sweeps per substep when any object rotates freely (HitBoxQuality > 1).
const FREE_ROTATION_PGS: usize = 4;

/// What one tick of the plane's solver runs with.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct SolverSettings {
    pub iterations: usize,
    pub pgs_iterations: usize,
    pub stabilization_iterations: usize,
    pub allowed_linear_error: f32,
    pub prediction_distance: f32,
    /// Contact natural frequency (Hz) between dynamic bodies; twice that against anchored.
    pub contact_frequency: f32,
}

impl Plane {
    /// After a step: boosts the bodies of the pairs that need more substeps and lets the
    /// others' boosts go (see `adaptive`).
    pub(super) fn adapt_solving(&mut self) {
        let awake = self.awake_count();
        let step = (self.clock.max_penetration, self.clock.tick);
        let on = self.settings.adaptive_solving;
        self.adaptive.adapt(&mut self.world, on, awake, step);
    }

    /// Whether the plane's contacts follow the boosted substep rate in stiffness this step.
    pub(super) fn contacts_stiffened(&self) -> bool {
        self.adaptive.stiffened() && self.settings.adaptive_solving
    }

    pub(super) fn max_quality(&self) -> u32 {
        self.objects.tally().max_quality()
    }

    /// The step length the solver settings are computed for when no step gives one (plane
    /// info): the last step's, else the TickRate's, else 1/60 s.
    pub(super) fn nominal_dt(&self) -> f32 {
        if self.clock.last_dt > 0.0 {
            self.clock.last_dt
        } else if self.settings.tick_rate > 0.0 {
            1.0 / self.settings.tick_rate
        } else {
            REFERENCE_DT
        }
    }

    /// LoopSolver pins 64 iterations; otherwise SolverIterations, scaled linearly from ×1 at
    /// quality 1 to ×2.5 at quality 32, and by `dt / (1/60 s)` for steps longer than 1/60 s.
    /// Tolerances shrink as 1/√quality.
    pub(super) fn solver_settings(&self, dt: f32) -> SolverSettings {
        let q = self.max_quality() as f32;
        let factor = 1.0 + (MAX_WORK_FACTOR - 1.0) * (q - 1.0) / (MAX_HIT_BOX_QUALITY as f32 - 1.0);
        let iterations = if self.settings.loop_solver {
            MAX_SOLVER_ITERATIONS as usize
        } else {
            (self.settings.solver_iterations as f32 * factor).round() as usize
        }
        .max(1);
        // Long steps: as many substeps as the same iterations take at 60 Hz.
        let per_reference = (dt / REFERENCE_DT).max(1.0);
        let iterations = ((iterations as f32 * per_reference) - 1e-3).ceil().max(1.0) as usize;
        let base = SpringCoefficients::<f32>::contact_defaults().natural_frequency * factor;
        let substep_rate = iterations as f32 / dt;
        SolverSettings {
            iterations,
            pgs_iterations: if q > 1.0 { FREE_ROTATION_PGS } else { 1 },
            stabilization_iterations: factor.round() as usize,
            allowed_linear_error: ALLOWED_LINEAR_ERROR / q.sqrt(),
            prediction_distance: PREDICTION_DISTANCE / q.sqrt(),
            contact_frequency: base.max(substep_rate / SUBSTEPS_PER_CONTACT_PERIOD),
        }
    }

    pub(super) fn tune_solver(&mut self, dt: f32) {
        let s = self.solver_settings(dt);
        // A pair of a high mass ratio: contacts as stiff as its islands' substeps allow.
        let s = if self.contacts_stiffened() {
            let rate = (s.iterations + super::adaptive::RATIO_EXTRA) as f32 / dt;
            SolverSettings {
                contact_frequency: s.contact_frequency.max(rate / SUBSTEPS_PER_CONTACT_PERIOD),
                ..s
            }
        } else {
            s
        };
        let p = &mut self.world.integration_parameters;
        p.num_solver_iterations = s.iterations;
        p.num_internal_pgs_iterations = s.pgs_iterations;
        p.num_internal_stabilization_iterations = s.stabilization_iterations;
        p.normalized_allowed_linear_error = s.allowed_linear_error;
        p.normalized_prediction_distance = s.prediction_distance;
        let base = SpringCoefficients::<f32>::contact_defaults();
        let base_static = SpringCoefficients::<f32>::contact_static_defaults();
        p.contact_softness.natural_frequency = s.contact_frequency;
        p.static_contact_softness.natural_frequency =
            s.contact_frequency * base_static.natural_frequency / base.natural_frequency;
    }
}

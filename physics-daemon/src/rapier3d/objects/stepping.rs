//! The plane's calls into its objects around a step: the per-body pass before it and the
//! angular speed cap after it (`body_pass`), with the plane-wide inputs they read.

use std::sync::Arc;

use crate::rapier3d::objects::body_pass::{self, Inputs, Prediction};
use crate::rapier3d::objects::forces::Env;
use crate::rapier3d::plane::Plane;

impl Plane {
    /// The plane's pool when it has one (Threads > 1) and `items` are worth handing to it.
    pub(in crate::rapier3d) fn pool_for(&self, items: usize) -> Option<Arc<rayon::ThreadPool>> {
        body_pass::pool_for(&self.world, items)
    }

    /// Before a step (after `tune_solver`): hands MaxLinearSpeed to rapier, then forces,
    /// angular speed caps and contact prediction for every body the step will move.
    pub(in crate::rapier3d) fn prepare_bodies(&mut self, dt: f32) {
        let p = &mut self.world.integration_parameters;
        p.normalized_max_linear_velocity = self.settings.max_linear_speed / p.length_unit;
        let inputs = Inputs {
            forces: Env::new(
                &self.settings,
                self.world.gravity,
                self.objects.tally().driven(),
                dt,
            ),
            max_angular_speed: self.settings.max_angular_speed,
            prediction: Prediction::new(&self.world, dt),
        };
        self.objects.prepare_bodies(&mut self.world, &inputs);
    }

    /// After a step: caps the angular speed of the awake bodies (MaxAngularSpeed).
    pub(in crate::rapier3d) fn limit_speeds_after_step(&mut self) {
        let max = self.settings.max_angular_speed;
        self.objects.cap_angular_speeds(&mut self.world, max);
    }
}

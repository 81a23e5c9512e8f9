//! Speed limits of a plane: `MaxLinearSpeed` and `MaxAngularSpeed`.
//!
//! - MaxLinearSpeed is rapier's own linear cap (`normalized_max_linear_velocity`, which the
//!   solver applies after every substep, before positions move), set before every step.
//! - MaxAngularSpeed is enforced here. Rapier caps angular speed internally at a quarter turn
//!   per step (`MAX_ROTATION · inv_dt` in its staged island solver: 47 rad/s at 60 Hz) unless
//!   a body allows fast rotation; every body does (`Part::configure_body`), so that internal
//!   cap never applies and this one is the only limit. |ω| is scaled down to the limit for
//!   every body the step moves before it runs (after the force pass, so RotateTo, SetPin and
//!   written AngularVelocity are capped before they turn anything) and for every awake body
//!   after it, so published angular velocities never exceed it. Within one step contacts
//!   may spin a body faster for that step's substeps only.

use rapier3d::prelude::*;

use super::Plane;

impl Plane {
    /// Before a step: hands MaxLinearSpeed to rapier and caps the angular speed of the bodies
    /// the step will move (awake ones and those changed by ops since the last step).
    pub(super) fn limit_speeds_before_step(&mut self) {
        let p = &mut self.world.integration_parameters;
        p.normalized_max_linear_velocity = self.settings.max_linear_speed / p.length_unit;
        let max = self.settings.max_angular_speed;
        let bodies = &mut self.world.bodies;
        for h in self.world.islands.active_bodies() {
            cap_spin(bodies.get_mut(h), max);
        }
        for slot in self.dirty.since_step() {
            if let Some(b) = self.bodies.at(*slot as usize) {
                cap_spin(bodies.get_mut(b.handle), max);
            }
        }
    }

    /// After a step: caps the angular speed of the awake bodies (sleeping ones are at rest).
    pub(super) fn limit_speeds_after_step(&mut self) {
        let max = self.settings.max_angular_speed;
        let bodies = &mut self.world.bodies;
        for h in self.world.islands.active_bodies() {
            cap_spin(bodies.get_mut(h), max);
        }
    }
}

/// Scales a dynamic body's angular velocity down to `max` rad/s (direction kept).
fn cap_spin(body: Option<&mut RigidBody>, max: f32) {
    let Some(body) = body.filter(|b| b.is_dynamic()) else {
        return;
    };
    let w = body.angvel();
    let speed = w.length();
    if speed > max {
        body.set_angvel(w * (max / speed), false);
    }
}

//! The per-tick pass of a GUI plane, before the step: the reference's damping
//! (`v *= max(0, 1 - k·dt)`, linear and angular), quadratic drag (`F = -Drag·|v|·v`, solved
//! backward in closed form, `v / (1 + Drag·|v|·dt / m)`, so it never overshoots), the plane's
//! and the body's ConstantForce (handed to rapier's force accumulator, integrated per
//! substep like gravity) and one-shot ImpulseDirection. Only awake bodies and bodies an op
//! touched since the last tick are visited; a plane with nothing to apply skips the pass.

use rapier2d::prelude::*;

use super::object::unlocked;
use super::plane::Plane;

impl Plane {
    pub(super) fn apply_forces(&mut self, dt: f32) {
        let s = self.settings;
        let plane_force = Vector::from(s.constant_force);
        let had_force = plane_force != Vector::ZERO;
        if s.linear_damping == 0.0
            && s.angular_damping == 0.0
            && s.drag == 0.0
            && !had_force
            && self.driven == 0
        {
            return;
        }
        let lin = (1.0 - s.linear_damping * dt).max(0.0);
        let ang = (1.0 - s.angular_damping * dt).max(0.0);
        let mut visit: Vec<RigidBodyHandle> = self.world.active_bodies().map(|(h, _)| h).collect();
        for &slot in self.bodies.since_step() {
            if let Some(b) = self.bodies.at(slot as usize) {
                visit.push(b.handle);
            }
        }
        visit.sort_unstable_by_key(|h| h.into_raw_parts());
        visit.dedup();
        for h in visit {
            let Some(rb) = self.world.bodies.get_mut(h) else {
                continue;
            };
            if !rb.is_dynamic() {
                continue;
            }
            let Some(body) = self.bodies.at_mut(rb.user_data as usize) else {
                continue;
            };
            let mut v = unlocked(&body.settings, rb.linvel()) * lin;
            if s.drag > 0.0 {
                v /= 1.0 + s.drag * v.length() * dt / rb.mass();
            }
            rb.set_linvel(v, false);
            rb.set_angvel(rb.angvel() * ang, false);
            let force = plane_force + Vector::from(body.settings.constant_force);
            rb.reset_forces(false);
            if force != Vector::ZERO {
                rb.add_force(force, true);
            }
            let j = std::mem::take(&mut body.settings.impulse_direction);
            if j != [0.0; 2] {
                let v = rb.linvel() + Vector::from(j) / rb.mass();
                rb.set_linvel(unlocked(&body.settings, v), true);
                if body.settings.constant_force == [0.0; 2] {
                    self.driven -= 1;
                }
            }
        }
    }
}

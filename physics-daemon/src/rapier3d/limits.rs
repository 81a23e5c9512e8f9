//! Speed limits of a plane: `MaxLinearSpeed` and `MaxAngularSpeed`.
//!
//! - MaxLinearSpeed is rapier's own linear cap (`normalized_max_linear_velocity`, which the
//!   solver applies after every substep, before positions move), set before every step.
//! - MaxAngularSpeed is enforced here. Rapier caps angular speed internally at a quarter turn
//!   per step (`MAX_ROTATION · inv_dt` in its staged island solver: 47 rad/s at 60 Hz) unless
//!   a body allows fast rotation; every body does (`Part::configure_body`), so that internal
//!   cap never applies and this one is the only limit. |ω| is scaled down to the limit for
//!   every body the step moves before it runs (in the per-body pass, `body_pass`, after the
//!   force pass, so RotateTo, SetPin and written AngularVelocity are capped before they turn
//!   anything) and for every awake body after it, so published angular velocities never
//!   exceed it. Within one step contacts may spin a body faster for that step's substeps
//!   only.

use rapier3d::prelude::*;
use rayon::prelude::*;

use super::body_pass::MIN_TASK;
use super::Plane;

impl Plane {
    /// After a step: caps the angular speed of the awake bodies (sleeping ones are at rest).
    /// Finding the few bodies over the cap reads every awake body: on the plane's pool when
    /// it has one and many bodies are awake.
    pub(super) fn limit_speeds_after_step(&mut self) {
        let max = self.settings.max_angular_speed;
        let over = |b: &RigidBody| b.is_dynamic() && b.angvel().length() > max;
        let mut handles = std::mem::take(&mut self.pass.handles);
        handles.clear();
        match self.pool_for(self.world.islands.num_active_bodies()) {
            Some(pool) => {
                let bodies = &self.world.bodies;
                let active = &mut self.pass.active;
                active.clear();
                active.extend(self.world.islands.active_bodies());
                pool.install(|| {
                    handles.par_extend(
                        active
                            .par_iter()
                            .with_min_len(MIN_TASK)
                            .filter(|h| bodies.get(**h).is_some_and(over)),
                    )
                });
            }
            None => {
                let bodies = &self.world.bodies;
                handles.extend(
                    self.world
                        .islands
                        .active_bodies()
                        .filter(|h| bodies.get(*h).is_some_and(over)),
                );
            }
        }
        for h in &handles {
            if let Some(body) = self.world.bodies.get_mut(*h) {
                body.set_angvel(capped(body.angvel(), max), false);
            }
        }
        self.pass.handles = handles;
    }
}

/// `w` scaled down to `max` rad/s (direction kept).
pub(super) fn capped(w: Vector, max: f32) -> Vector {
    let speed = w.length();
    if speed > max {
        w * (max / speed)
    } else {
        w
    }
}

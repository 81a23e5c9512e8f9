//! Explosions on a 3D plane (`plane:Explode`): every dynamic object whose shape meets the
//! blast sphere gets an impulse away from the centre, woken if asleep; every controller
//! there gets the matching velocity kick (impulse / its part's mass); anchored objects and
//! other kinematic bodies are left alone. The impulse falls off with the distance from the
//! centre to the object's centre of mass (a controller's: its capsule's centre).

use rapier3d::prelude::*;
use shm_layout::{CommandError, Explosion, Falloff, Handle, Reply};

use crate::rapier3d::plane::Plane;

/// Below this distance from the centre an object is pushed straight up (no direction).
const CENTRE_EPS: f32 = 1.0e-6;

/// The share of the impulse at distance `d` of a blast of `radius`.
fn falloff(kind: Falloff, d: f32, radius: f32) -> f32 {
    match kind {
        Falloff::Linear => (1.0 - d / radius).max(0.0),
        Falloff::None => 1.0,
        Falloff::InverseSquare => 1.0 / d.max(1.0).powi(2),
    }
}

impl Plane {
    /// Applies an explosion; replies with the objects it pushed (ascending slots).
    pub(in crate::rapier3d) fn explode(&mut self, e: Explosion) -> Result<Reply, CommandError> {
        let e = e.checked()?;
        self.refresh_scene();
        let centre = Vector::from(e.center);
        let blast = Ball::new(e.radius);
        let mut touched: Vec<Handle> = {
            let f = self.resolve(&e.filter, None)?;
            let predicate = |c: ColliderHandle, co: &Collider| f.accepts(c, co);
            let pipeline = self
                .query_pipeline(rapier3d::prelude::QueryFilter::default().predicate(&predicate));
            pipeline
                .intersect_shape(rapier3d::math::Pose::from_translation(centre), &blast)
                .filter_map(|(c, _)| self.handle_of_collider(c))
                .collect()
        };
        touched.sort_by_key(|h| h.slot);
        touched.dedup();
        let mut affected = Vec::new();
        for handle in touched {
            let Ok(h) = self.body_of(handle) else {
                continue;
            };
            let controller = self.controllers.contains_key(&handle.slot);
            let body = &self.world.bodies[h];
            if !controller && !body.is_dynamic() {
                continue; // anchored or driven: explosions do not move it
            }
            let at = if controller {
                body.translation()
            } else {
                body.center_of_mass()
            };
            let offset = at - centre;
            let d = offset.length();
            let dir = if d > CENTRE_EPS {
                offset / d
            } else {
                Vector::Y
            };
            let share = falloff(e.falloff, d, e.radius);
            let impulse = dir * (e.impulse * share);
            if share <= 0.0 || e.impulse == 0.0 {
                continue;
            }
            let mass: f32 = body
                .colliders()
                .iter()
                .filter_map(|c| self.world.colliders.get(*c))
                .map(|co| co.mass())
                .sum();
            // The object changes: its slot is marked.
            let h = self.changing(handle)?;
            if !controller {
                self.world.bodies[h].apply_impulse(impulse, true);
            } else if mass > 0.0 {
                self.kick_controller(handle.slot, impulse / mass);
            }
            affected.push(handle);
        }
        Ok(Reply::Objects(affected))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn falloffs_match_their_documented_forms() {
        assert_eq!(falloff(Falloff::Linear, 0.0, 10.0), 1.0);
        assert!((falloff(Falloff::Linear, 2.5, 10.0) - 0.75).abs() < 1e-6);
        assert_eq!(falloff(Falloff::Linear, 12.0, 10.0), 0.0);
        assert_eq!(falloff(Falloff::None, 9.0, 10.0), 1.0);
        assert_eq!(falloff(Falloff::InverseSquare, 0.5, 10.0), 1.0);
        assert!((falloff(Falloff::InverseSquare, 2.0, 10.0) - 0.25).abs() < 1e-6);
    }
}

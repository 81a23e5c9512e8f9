//! A controller and the bodies it meets: pushing dynamic bodies, kicks (explosions).

use super::tick::{Push, Scene};
use super::*;
use crate::rapier3d::plane::Plane;

impl Scene<'_> {
    /// Dynamic bodies the move ran into get an impulse along the push, capped at
    /// PushStrength × dt (a crate heavier than that cap can move blocks the controller):
    /// the impulses (applied when the tick commits) and the colliders that gave way.
    pub(super) fn plan_pushes(
        &self,
        collisions: &[CharacterCollision],
        c: &Controller,
        dt: f32,
    ) -> (Vec<Push>, Vec<ColliderHandle>) {
        let cap = c.settings.push_strength * dt;
        let mut pushes = Vec::new();
        let mut gave_way = Vec::new();
        for col in collisions {
            let Some(body) = self
                .refs
                .colliders
                .get(col.handle)
                .and_then(|co| co.parent())
            else {
                continue;
            };
            let Some(rb) = self.refs.bodies.get(body) else {
                continue;
            };
            if !rb.is_dynamic() {
                continue;
            }
            // Push along the horizontal part of the contact normal, away from the capsule.
            let n = -horizontal(col.hit.normal1).normalize_or_zero();
            let wanted = horizontal(col.translation_remaining).dot(n).max(0.0) / dt;
            let relative = (wanted - rb.linvel().dot(n)).max(0.0);
            let needed = rb.mass() * relative;
            let impulse = needed.min(cap);
            if impulse > 0.0 {
                pushes.push(Push {
                    body,
                    impulse: n * impulse,
                    point: col.hit.witness1,
                });
            }
            if needed <= cap {
                gave_way.push(col.handle);
            }
        }
        (pushes, gave_way)
    }
}

impl Plane {
    /// Adds `dv` to a controller's velocity (an explosion's kick); a kick upward lifts it
    /// off the ground.
    pub(in crate::rapier3d) fn kick_controller(&mut self, slot: u32, dv: Vector) {
        if let Some(c) = self.controllers.get_mut(&slot) {
            c.velocity += dv;
            if dv.y > 0.0 {
                c.on_ground = false;
            }
        }
    }
}

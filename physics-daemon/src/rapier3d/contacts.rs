//! What the plane reads from rapier's contacts: the RestThreshold rule, the error figures of
//! the tick header, and contact started / stopped events.

use rapier3d::prelude::*;
use shm_layout::{EventRecord, EVENT_CONTACT_STARTED, EVENT_CONTACT_STOPPED};

use super::Plane;

/// RestThreshold: a contact whose normal approach speed is below the threshold does not
/// bounce. Runs only for pairs where a collider has Bounciness > 0 (its active hook).
pub(super) struct RestThreshold(pub f32);

impl PhysicsHooks for RestThreshold {
    fn modify_solver_contacts(&self, context: &mut ContactModificationContext) {
        let bodies = context.bodies;
        let (b1, b2) = (context.rigid_body1, context.rigid_body2);
        let Some(manifold) = context.rigid_mut() else {
            return;
        };
        if *manifold.restitution == 0.0 {
            return;
        }
        let velocity = |h: Option<RigidBodyHandle>, p: Vector| {
            h.and_then(|h| bodies.get(h))
                .map_or(Vector::ZERO, |b| b.velocity_at_point(p))
        };
        // The normal points from collider 1 toward collider 2.
        let normal = *manifold.normal;
        let approach = manifold
            .solver_contacts
            .iter()
            .map(|c| (velocity(b1, c.anchor1) - velocity(b2, c.anchor2)).dot(normal))
            .fold(0.0f32, f32::max);
        if approach < self.0 {
            *manifold.restitution = 0.0;
        }
    }
}

impl Plane {
    /// Deepest penetration and number of touching pairs, for the tick header.
    pub(super) fn contact_figures(&self) -> (f32, u32) {
        let mut deepest = 0.0f32;
        let mut pairs = 0;
        for (_, contact) in self
            .world
            .narrow_phase
            .contact_pairs()
            .filter_map(|p| p.find_deepest_contact())
        {
            deepest = deepest.max(-contact.dist);
            pairs += 1;
        }
        (deepest, pairs)
    }

    pub(super) fn collect_events(&mut self) {
        self.events.clear();
        while let Ok(event) = self.collision_rx.try_recv() {
            let kind = if event.started() {
                EVENT_CONTACT_STARTED
            } else {
                EVENT_CONTACT_STOPPED
            };
            let (Some(a), Some(b)) = (
                self.handle_of_collider(event.collider1()),
                self.handle_of_collider(event.collider2()),
            ) else {
                continue; // one side was removed in the same step
            };
            self.events.push(EventRecord {
                kind,
                a_slot: a.slot,
                a_generation: a.generation,
                b_slot: b.slot,
                b_generation: b.generation,
                _reserved: 0,
                tick: self.tick,
            });
        }
    }
}

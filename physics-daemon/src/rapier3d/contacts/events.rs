//! Contact started / stopped events: the step's collision events turned into records.

use rapier3d::prelude::*;
use shm_layout::{EventRecord, EVENT_CONTACT_STARTED, EVENT_CONTACT_STOPPED};

use crate::rapier3d::plane::Plane;

impl Plane {
    /// Turns the step's collision events into records: both objects, and for a start the
    /// contact point, the normal (from `a` toward `b`), the normal impulse of the step and
    /// the pair's manifold points (`points.rs`).
    pub(in crate::rapier3d) fn collect_events(&mut self) {
        // Events the controllers produced before the step come first, in their order.
        self.events.begin_tick(self.clock.tick);
        while let Some(event) = self.events.next_collision() {
            let (c1, c2) = (event.collider1(), event.collider2());
            let (Some(a), Some(b)) = (self.handle_of_collider(c1), self.handle_of_collider(c2))
            else {
                continue; // a collider of neither a live nor a just-removed object
            };
            let mut record = EventRecord {
                kind: EVENT_CONTACT_STOPPED,
                a_slot: a.slot,
                a_generation: a.generation,
                b_slot: b.slot,
                b_generation: b.generation,
                tick: self.clock.tick,
                ..EventRecord::default()
            };
            if event.started() {
                record.kind = EVENT_CONTACT_STARTED;
                if let Some((position, normal, impulse)) = self.contact_geometry(c1, c2) {
                    record.position = position.into();
                    record.normal = normal.into();
                    record.impulse = impulse;
                }
                let points = self.pair_points(c1, c2);
                record.point_count = points.len() as u32;
                record.points[..points.len()].copy_from_slice(&points);
            }
            self.events.record(record);
        }
    }

    /// The deepest contact point of the pair (world space), its normal from `c1` toward
    /// `c2`, and the total normal impulse of the pair.
    fn contact_geometry(
        &self,
        c1: ColliderHandle,
        c2: ColliderHandle,
    ) -> Option<(Vector, Vector, f32)> {
        let pair = self.world.narrow_phase.contact_pair(c1, c2)?;
        let (manifold, contact) = pair.find_deepest_contact()?;
        let first = self.world.colliders.get(pair.collider1)?;
        let position = first.position().transform_point(contact.local_p1);
        let normal = match pair.collider1 == c1 {
            true => manifold.data.normal,
            false => -manifold.data.normal,
        };
        Some((position, normal, pair.total_impulse_magnitude()))
    }
}

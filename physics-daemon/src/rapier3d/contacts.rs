//! What the plane reads from rapier's contacts: the RestThreshold rule, the error figures of
//! the tick header, and contact started / stopped events.

use rapier3d::prelude::*;
use rayon::prelude::*;
use shm_layout::{EventRecord, EVENT_CONTACT_STARTED, EVENT_CONTACT_STOPPED};

use super::body_pass::MIN_TASK;
use super::Plane;

/// The plane's contact hook, run only for pairs where a collider asks for it (Bounciness >
/// 0, or a character controller's capsule):
/// - RestThreshold: a contact whose normal approach speed is below the threshold does not
///   bounce.
/// - Bounce speed at the time of impact: rapier reflects the approach speed the tick starts
///   with (`e·v0`), but a body still `d` away from the surface hits it `τ` into the tick,
///   faster by what gravity added meanwhile: `v_imp² = v0² + 2·a·d` (`a` the closing
///   acceleration gravity gives the pair). The pair's restitution is scaled by `v_imp / v0`
///   so the bounce leaves at `e·v_imp` and reaches the exact apex `(e·v_imp)²/(2g)`; without
///   it the apex fell short by ≈ `2·g·dt/v` (5 % at 60 Hz for a 10-unit drop).
/// - A controller (the only kinematic bodies) pressing sideways on a dynamic body: the
///   solver does not push it (a kinematic body would push with infinite strength); the
///   controller pushes it itself with a force capped at its PushStrength. Contacts along
///   the vertical stay: a crate dropped on a character rests on its head.
pub(super) struct RestThreshold {
    /// The plane's RestThreshold (units/s).
    pub threshold: f32,
    /// The plane's gravity.
    pub gravity: Vector,
}

/// Contacts more vertical than this (|normal.y|) between a controller and a dynamic body are
/// left to the solver.
const VERTICAL: f32 = 0.7;

impl PhysicsHooks for RestThreshold {
    fn modify_solver_contacts(&self, context: &mut ContactModificationContext) {
        let bodies = context.bodies;
        let (b1, b2) = (context.rigid_body1, context.rigid_body2);
        let kind = |h: Option<RigidBodyHandle>| {
            h.and_then(|h| bodies.get(h))
                .map(|b| (b.is_kinematic(), b.is_dynamic()))
        };
        let controller_push = matches!(
            (kind(b1), kind(b2)),
            (Some((true, _)), Some((_, true))) | (Some((_, true)), Some((true, _)))
        );
        let Some(manifold) = context.rigid_mut() else {
            return;
        };
        if controller_push && manifold.normal.y.abs() < VERTICAL {
            manifold.solver_contacts.clear();
            return;
        }
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
        if approach < self.threshold {
            *manifold.restitution = 0.0;
            return;
        }
        // Closing acceleration from gravity (bodies that do not feel it add none).
        let pull = |h: Option<RigidBodyHandle>| {
            h.and_then(|h| bodies.get(h))
                .filter(|b| b.is_dynamic())
                .map_or(Vector::ZERO, |b| self.gravity * b.gravity_scale())
        };
        let closing = (pull(b1) - pull(b2)).dot(normal);
        let gap = manifold
            .solver_contacts
            .iter()
            .map(|c| c.dist)
            .fold(f32::MAX, f32::min);
        if closing > 0.0 && gap > 0.0 && gap < f32::MAX {
            let at_impact = (approach * approach + 2.0 * closing * gap).sqrt();
            let e = *manifold.restitution;
            let scaled = e * at_impact / approach;
            // Below 1 stays below 1 (rapier keeps contacts of restitution ≥ 1 bouncing).
            *manifold.restitution = if e < 1.0 { scaled.min(0.999) } else { scaled };
        }
    }
}

impl Plane {
    /// Turns the step's collision events into records: both objects, and for a start the
    /// contact point, the normal (from `a` toward `b`), the normal impulse of the step and
    /// the pair's manifold points (`contact_points.rs`).
    pub(super) fn collect_events(&mut self) {
        self.events.clear();
        // Events the controllers produced before the step come first, in their order.
        for mut record in std::mem::take(&mut self.pending_events) {
            record.tick = self.clock.tick;
            record.seq = self.event_seq;
            self.event_seq += 1;
            self.events.push(record);
        }
        while let Ok(event) = self.collision_rx.try_recv() {
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
                seq: self.event_seq,
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
            self.event_seq += 1;
            self.events.push(record);
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

/// Deepest penetration and number of touching pairs, for the tick header. `split`: in
/// pieces on the current rayon pool (the figures do not depend on the order pairs are
/// visited in).
pub(super) fn contact_figures(narrow_phase: &NarrowPhase, split: bool) -> (f32, u32) {
    let edges = narrow_phase.contact_graph().raw_graph().raw_edges();
    if split {
        // One task per chunk: run beside the state hash, the figures are taken up by
        // whichever thread is free, chunk by chunk (rayon would otherwise split them in
        // two and leave the half it kept to one thread).
        edges
            .par_chunks(MIN_TASK)
            .with_max_len(1)
            .map(|chunk| pair_figures(chunk, |e| &e.weight))
            .reduce(|| (0.0, 0), |a, b| (deeper(a.0, b.0), a.1 + b.1))
    } else {
        pair_figures(edges, |e| &e.weight)
    }
}

/// Deepest penetration (0 without any) and number of touching pairs among `items`.
fn pair_figures<'a, T>(items: &'a [T], pair: impl Fn(&'a T) -> &'a ContactPair) -> (f32, u32) {
    items
        .iter()
        .filter_map(|item| pair(item).find_deepest_contact())
        .fold((0.0, 0), |(deepest, n), (_, c)| {
            (deeper(deepest, -c.dist), n + 1)
        })
}

/// The larger depth; a tie or a NaN keeps `a`, so any grouping of the pairs gives the same
/// bits.
fn deeper(a: f32, b: f32) -> f32 {
    if b > a {
        b
    } else {
        a
    }
}

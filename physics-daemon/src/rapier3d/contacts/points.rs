//! Contact manifolds read from rapier: up to four points per touching pair (position,
//! normal, depth, the normal impulse of the last step), for contact-started events and for
//! `ObjectOp::Contacts` (every pair an object touches now).
//!
//! The points are those the solver saw (rapier's solver manifolds: the contact clusters
//! when it merged manifolds), so their impulses sum to what held the pair apart in the
//! last step; a pair with more than four is reduced by [`reduce_points`].

use rapier3d::prelude::*;
use shm_layout::contact_points::reduce_points;
use shm_layout::{CommandError, ContactInfo, ContactPoint, Handle};

use crate::rapier3d::plane::Plane;

impl Plane {
    /// The contact points of the pair `c1`, `c2` (world space, normals from `c1` toward
    /// `c2`), at most [`shm_layout::MAX_CONTACT_POINTS`]; empty when they do not touch.
    pub(in crate::rapier3d) fn pair_points(
        &self,
        c1: ColliderHandle,
        c2: ColliderHandle,
    ) -> Vec<ContactPoint> {
        let Some(pair) = self.world.narrow_phase.contact_pair(c1, c2) else {
            return Vec::new();
        };
        let Some(first) = self.world.colliders.get(pair.collider1) else {
            return Vec::new();
        };
        let flip = if pair.collider1 == c1 { 1.0 } else { -1.0 };
        let mut points = Vec::new();
        for manifold in pair.solver_manifolds() {
            let normal = manifold.data.normal * flip;
            for c in &manifold.points {
                let at = first.position().transform_point(c.local_p1);
                // The point on c1's surface: from c2's side, step back across the gap.
                let at = if flip > 0.0 {
                    at
                } else {
                    at + manifold.data.normal * c.dist
                };
                if !(at.is_finite() && normal.is_finite() && c.dist.is_finite()) {
                    continue;
                }
                points.push(ContactPoint {
                    position: at.into(),
                    normal: normal.into(),
                    depth: -c.dist,
                    impulse: c.data.impulse,
                });
            }
        }
        reduce_points(&points)
    }

    /// Every object `handle` touches now: the deepest point, its normal (from `handle`
    /// toward the other), the pair's total impulse and its points. Pairs with objects the
    /// API does not name (a joint's world anchor) are left out.
    pub(in crate::rapier3d) fn object_contacts(
        &self,
        handle: Handle,
    ) -> Result<Vec<ContactInfo>, CommandError> {
        let body = self.body_of(handle)?;
        let mut out = Vec::new();
        for &mine in self.world.bodies[body].colliders() {
            for pair in self.world.narrow_phase.contact_pairs_with(mine) {
                if !pair.has_any_active_contact() {
                    continue;
                }
                let theirs = if pair.collider1 == mine {
                    pair.collider2
                } else {
                    pair.collider1
                };
                let Some(other) = self.handle_of_collider(theirs) else {
                    continue;
                };
                let points = self.pair_points(mine, theirs);
                let Some(deepest) =
                    points
                        .iter()
                        .copied()
                        .reduce(|a, b| if b.depth > a.depth { b } else { a })
                else {
                    continue;
                };
                out.push(ContactInfo {
                    other,
                    position: deepest.position,
                    normal: deepest.normal,
                    impulse: pair.total_impulse_magnitude(),
                    points,
                });
            }
        }
        Ok(out)
    }
}

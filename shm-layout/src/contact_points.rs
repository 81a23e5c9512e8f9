//! Contact manifolds on the wire: the points where two touching objects meet, up to
//! [`MAX_CONTACT_POINTS`] per pair, each with its position, normal, penetration depth and
//! the normal impulse the solver applied there. A box resting flat on a floor touches it at
//! its four bottom corners; one averaged point cannot say whether it rests, rocks or tips.
//!
//! The points travel inside contact-started events ([`crate::EventRecord::points`]) and in
//! the answer of [`crate::ObjectOp::Contacts`] (every pair an object touches now).

use iceoryx2::prelude::ZeroCopySend;
use serde::{Deserialize, Serialize};

use crate::geometry::Vec3;
use crate::ids::Handle;

/// Most points reported per touching pair. A pair whose manifolds hold more keeps the
/// deepest point and the three that span the largest area with it; the impulse of every
/// point left out is added to the nearest kept point, so the points' impulses still sum to
/// the pair's total.
pub const MAX_CONTACT_POINTS: usize = 4;

/// One point of a contact manifold. 32 bytes.
#[derive(Debug, Clone, Copy, PartialEq, Default, ZeroCopySend, Serialize, Deserialize)]
#[type_name("physics::ContactPoint")]
#[repr(C)]
pub struct ContactPoint {
    /// World-space point (on the surface of the first object of the pair).
    pub position: Vec3,
    /// Unit normal at the point, from the first object toward the second.
    pub normal: Vec3,
    /// Penetration depth (units): ≥ 0 while the surfaces touch or overlap, negative for a
    /// point the engine already tracks a hair's breadth before touching (within its contact
    /// margin).
    pub depth: f32,
    /// Normal impulse the solver applied at the point in the last step (mass × velocity).
    pub impulse: f32,
}

/// One object another one touches now ([`crate::ObjectOp::Contacts`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ContactInfo {
    /// The other object (a map piece or a controller's capsule are objects too).
    pub other: Handle,
    /// The deepest point of the pair (world space).
    pub position: Vec3,
    /// Its unit normal, from the asking object toward `other`.
    pub normal: Vec3,
    /// Total normal impulse of the pair in the last step.
    pub impulse: f32,
    /// Up to [`MAX_CONTACT_POINTS`] points, normals from the asking object toward `other`.
    pub points: Vec<ContactPoint>,
}

/// Reduces `points` to at most [`MAX_CONTACT_POINTS`]: the deepest, the farthest from it,
/// the one spanning the largest triangle with those two, the one adding the most area to
/// that triangle; each dropped point's impulse goes to the nearest kept point. Fewer points
/// are returned as they are.
pub fn reduce_points(points: &[ContactPoint]) -> Vec<ContactPoint> {
    if points.len() <= MAX_CONTACT_POINTS {
        return points.to_vec();
    }
    let p = |i: usize| points[i].position;
    let sub = |a: Vec3, b: Vec3| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    let dot = |a: Vec3, b: Vec3| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let cross = |a: Vec3, b: Vec3| {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    };
    let area = |a: Vec3, b: Vec3, c: Vec3| {
        let n = cross(sub(b, a), sub(c, a));
        dot(n, n)
    };
    // The first index with the largest score (ties keep the earlier point: deterministic).
    let best = |score: &dyn Fn(usize) -> f32, taken: &[usize]| {
        let mut pick = None::<(usize, f32)>;
        for i in (0..points.len()).filter(|i| !taken.contains(i)) {
            let s = score(i);
            if pick.is_none_or(|(_, b)| s > b) {
                pick = Some((i, s));
            }
        }
        pick.map_or(0, |(i, _)| i)
    };
    let mut kept = Vec::with_capacity(MAX_CONTACT_POINTS);
    kept.push(best(&|i| points[i].depth, &kept));
    let a = p(kept[0]);
    kept.push(best(&|i| dot(sub(p(i), a), sub(p(i), a)), &kept));
    let b = p(kept[1]);
    kept.push(best(&|i| area(a, b, p(i)), &kept));
    let c = p(kept[2]);
    // The area a point adds lies beyond one edge of the triangle: the edge's triangle with
    // it turns the other way than the triangle itself.
    let n = cross(sub(b, a), sub(c, a));
    let beyond = |x: Vec3, y: Vec3, q: Vec3| -dot(cross(sub(y, x), sub(q, x)), n);
    kept.push(best(
        &|i| {
            let q = p(i);
            beyond(a, b, q).max(beyond(b, c, q)).max(beyond(c, a, q))
        },
        &kept,
    ));
    let mut out: Vec<ContactPoint> = kept.iter().map(|i| points[*i]).collect();
    for (i, point) in points.iter().enumerate() {
        if kept.contains(&i) {
            continue;
        }
        let d2 = |k: &ContactPoint| {
            let d = sub(k.position, point.position);
            dot(d, d)
        };
        let mut nearest = 0;
        for k in 1..out.len() {
            if d2(&out[k]) < d2(&out[nearest]) {
                nearest = k;
            }
        }
        out[nearest].impulse += point.impulse;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(x: f32, z: f32, depth: f32, impulse: f32) -> ContactPoint {
        ContactPoint {
            position: [x, 0.0, z],
            normal: [0.0, -1.0, 0.0],
            depth,
            impulse,
        }
    }

    #[test]
    fn eight_points_of_a_face_reduce_to_its_corners_keeping_the_impulse() {
        // The corners of a square and the middles of its edges.
        let pts = [
            at(-1.0, -1.0, 0.01, 1.0),
            at(0.0, -1.0, 0.0, 1.0),
            at(1.0, -1.0, 0.0, 1.0),
            at(1.0, 0.0, 0.0, 1.0),
            at(1.0, 1.0, 0.0, 1.0),
            at(0.0, 1.0, 0.0, 1.0),
            at(-1.0, 1.0, 0.0, 1.0),
            at(-1.0, 0.0, 0.0, 1.0),
        ];
        let out = reduce_points(&pts);
        assert_eq!(out.len(), 4);
        for p in &out {
            assert_eq!(p.position[0].abs(), 1.0, "{out:?}");
            assert_eq!(p.position[2].abs(), 1.0, "{out:?}");
        }
        // The deepest comes first.
        assert_eq!(out[0].position, [-1.0, 0.0, -1.0]);
        let total: f32 = out.iter().map(|p| p.impulse).sum();
        assert_eq!(total, 8.0);
        // Four points or fewer pass unchanged.
        assert_eq!(reduce_points(&pts[..3]), pts[..3].to_vec());
    }
}

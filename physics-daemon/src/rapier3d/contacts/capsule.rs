//! Contacts of a capsule with a box or another capsule in closed form.
//!
//! Controllers are capsules among boxes and other controllers, and every stage of their
//! tick (the move's casts, the ground test after each slide, the ground probe,
//! depenetration) asks for these contacts many times. Parry answers them with GJK (and the
//! plane's dispatcher tries six support points per box first); here:
//! - capsule–box: the squared distance from a point of the capsule's segment to the solid
//!   box is a convex piecewise quadratic of the segment's parameter, whose pieces change
//!   only where a coordinate crosses one of the box's faces, so its minimum is the least of
//!   at most seven one-dimensional quadratic minima;
//! - capsule–capsule: the closest points of two segments (Ericson, *Real-Time Collision
//!   Detection*, 5.1.9).
//!
//! The contact is the segment's distance less the radii, exact (to f32 rounding of the
//! coordinates) at any box size, and a capsule's depth is `radius − distance` exactly while
//! its segment stays outside the other shape's core (the box, the other segment); a
//! segment touching it is left to the general path.

use rapier3d::math::{Pose, Vector};
use rapier3d::parry::query::Contact;
use rapier3d::parry::shape::Shape;

/// The contact of `g1` and `g2` (placed at `pos12` in `g1`'s frame) when one is a capsule
/// and the other a box and the capsule's segment lies outside the box: `Some(None)` when
/// they are farther apart than `prediction`. `None` when the closed form does not apply.
pub(crate) fn contact(
    pos12: &Pose,
    g1: &dyn Shape,
    g2: &dyn Shape,
    prediction: f32,
) -> Option<Option<Contact>> {
    if let (Some(capsule), Some(cuboid)) = (g1.as_capsule(), g2.as_cuboid()) {
        capsule_box(
            pos12,
            capsule.segment.a,
            capsule.segment.b,
            capsule.radius,
            cuboid.half_extents,
            prediction,
        )
    } else if let (Some(cuboid), Some(capsule)) = (g1.as_cuboid(), g2.as_capsule()) {
        capsule_box(
            &pos12.inverse(),
            capsule.segment.a,
            capsule.segment.b,
            capsule.radius,
            cuboid.half_extents,
            prediction,
        )
        .map(|found| found.map(Contact::flipped))
    } else if let (Some(c1), Some(c2)) = (g1.as_capsule(), g2.as_capsule()) {
        capsule_capsule(pos12, c1, c2, prediction)
    } else {
        None
    }
}

/// The contact of capsule `c1` with capsule `c2` placed at `pos12` in `c1`'s frame.
fn capsule_capsule(
    pos12: &Pose,
    c1: &rapier3d::parry::shape::Capsule,
    c2: &rapier3d::parry::shape::Capsule,
    prediction: f32,
) -> Option<Option<Contact>> {
    let (a2, b2) = (*pos12 * c2.segment.a, *pos12 * c2.segment.b);
    let (p1, p2) = segment_segment(c1.segment.a, c1.segment.b, a2, b2);
    let between = p2 - p1;
    let d = between.length();
    if !d.is_finite() || d <= 1.0e-5 * (1.0 + c1.radius + c2.radius) {
        return None;
    }
    let dist = d - c1.radius - c2.radius;
    if dist > prediction {
        return Some(None);
    }
    let n = between / d;
    let to_2 = pos12.inverse();
    Some(Some(Contact::new(
        p1 + n * c1.radius,
        to_2 * (p2 - n * c2.radius),
        n,
        to_2.rotation * -n,
        dist,
    )))
}

/// The closest points of the segments `p1`–`q1` and `p2`–`q2`.
fn segment_segment(p1: Vector, q1: Vector, p2: Vector, q2: Vector) -> (Vector, Vector) {
    let (d1, d2, r) = (q1 - p1, q2 - p2, p1 - p2);
    let (a, e, f) = (d1.length_squared(), d2.length_squared(), d2.dot(r));
    const EPS: f32 = 1.0e-12;
    let (s, t) = if a <= EPS && e <= EPS {
        (0.0, 0.0)
    } else if a <= EPS {
        (0.0, (f / e).clamp(0.0, 1.0))
    } else {
        let c = d1.dot(r);
        if e <= EPS {
            ((-c / a).clamp(0.0, 1.0), 0.0)
        } else {
            let b = d1.dot(d2);
            let denom = a * e - b * b;
            let mut s = if denom > EPS * a * e {
                ((b * f - c * e) / denom).clamp(0.0, 1.0)
            } else {
                0.0 // parallel: any s, the clamps below find the matching t
            };
            let mut t = (b * s + f) / e;
            if t < 0.0 {
                t = 0.0;
                s = (-c / a).clamp(0.0, 1.0);
            } else if t > 1.0 {
                t = 1.0;
                s = ((b - c) / a).clamp(0.0, 1.0);
            }
            (s, t)
        }
    };
    (p1 + d1 * s, p2 + d2 * t)
}

/// The contact of the capsule (segment `a`–`b`, `radius`, in its own frame) with the box of
/// half extents `he` placed at `pos12` in the capsule's frame; `None` where the closed
/// form does not apply (see [`contact`]).
pub(crate) fn capsule_box(
    pos12: &Pose,
    a: Vector,
    b: Vector,
    radius: f32,
    he: Vector,
    prediction: f32,
) -> Option<Option<Contact>> {
    let to_box = pos12.inverse();
    let Some((on_segment, on_box, n, dist)) =
        closest_in_box_frame(to_box * a, to_box * b, radius, he, prediction)?
    else {
        return Some(None);
    };
    Some(Some(Contact::new(
        *pos12 * (on_segment - n * radius),
        on_box,
        pos12.rotation * -n,
        n,
        dist,
    )))
}

/// [`capsule_box`] asked from the box's side, the box first (as [`contact`] answers a box
/// and a capsule): the capsule (segment `a`–`b`, `radius`, in its own frame) placed at
/// `pose21` in the frame of the box of half extents `he`. A cast moves the capsule in the
/// box's frame, so this saves inverting its pose twice per step; the pose back to the
/// capsule's frame is worked out only for a contact within `prediction`.
pub(crate) fn box_capsule(
    pose21: &Pose,
    a: Vector,
    b: Vector,
    radius: f32,
    he: Vector,
    prediction: f32,
) -> Option<Option<Contact>> {
    let Some((on_segment, on_box, n, dist)) =
        closest_in_box_frame(*pose21 * a, *pose21 * b, radius, he, prediction)?
    else {
        return Some(None);
    };
    let to_capsule = pose21.inverse();
    Some(Some(Contact::new(
        on_box,
        to_capsule * (on_segment - n * radius),
        n,
        to_capsule.rotation * -n,
        dist,
    )))
}

/// The closest points of the capsule (segment `a`–`b` in the box's frame, `radius`) and the
/// box of half extents `he`, the box's outward normal there (toward the segment) and the
/// distance: `Some(None)` beyond `prediction`, `None` where the closed form does not apply
/// (touching or inside: no direction to read from the closest points; non-finite input).
#[allow(clippy::type_complexity)]
fn closest_in_box_frame(
    a: Vector,
    b: Vector,
    radius: f32,
    he: Vector,
    prediction: f32,
) -> Option<Option<(Vector, Vector, Vector, f32)>> {
    let (on_segment, on_box, d2) = segment_box(a, b, he);
    if !d2.is_finite() || !on_segment.is_finite() {
        return None;
    }
    let d = d2.sqrt();
    if d <= 1.0e-5 * (1.0 + he.max_element()) {
        return None;
    }
    let dist = d - radius;
    if dist > prediction {
        return Some(None);
    }
    Some(Some((on_segment, on_box, (on_segment - on_box) / d, dist)))
}

/// The closest points of the segment `a`–`b` and the solid box `[-he, he]` and their
/// squared distance: (point of the segment, point of the box, squared distance).
fn segment_box(a: Vector, b: Vector, he: Vector) -> (Vector, Vector, f32) {
    let d = b - a;
    parallel_segment_box(a, d, he).unwrap_or_else(|| segment_box_pieces(a, d, he))
}

/// [`segment_box`] for any segment `a` + `d` t, t in [0, 1]: the least of the pieces'
/// minima.
fn segment_box_pieces(a: Vector, d: Vector, he: Vector) -> (Vector, Vector, f32) {
    // Where a coordinate crosses a face: the pieces' ends.
    let mut cuts = [0.0f32; 8];
    let mut n = 0;
    cuts[n] = 0.0;
    n += 1;
    for k in 0..3 {
        if d[k] != 0.0 {
            for bound in [-he[k], he[k]] {
                let t = (bound - a[k]) / d[k];
                if t > 0.0 && t < 1.0 {
                    cuts[n] = t;
                    n += 1;
                }
            }
        }
    }
    cuts[n] = 1.0;
    n += 1;
    let cuts = &mut cuts[..n];
    cuts.sort_unstable_by(f32::total_cmp);
    let at = |t: f32| a + d * t;
    let mut best = (a, a.clamp(-he, he), f32::INFINITY);
    for w in cuts.windows(2) {
        let (t0, t1) = (w[0], w[1]);
        // On this piece each coordinate stays below, inside or above the box: the squared
        // distance is Σ over the outside ones of (a_k + d_k t − bound_k)², minimal where
        // its derivative vanishes.
        let mid = at(0.5 * (t0 + t1));
        let (mut num, mut den) = (0.0f32, 0.0f32);
        for k in 0..3 {
            let bound = if mid[k] > he[k] {
                he[k]
            } else if mid[k] < -he[k] {
                -he[k]
            } else {
                continue;
            };
            num += d[k] * (bound - a[k]);
            den += d[k] * d[k];
        }
        let t = if den > 0.0 {
            (num / den).clamp(t0, t1)
        } else {
            t0
        };
        let p = at(t);
        let q = p.clamp(-he, he);
        let d2 = (p - q).length_squared();
        if d2 < best.2 {
            best = (p, q, d2);
        }
    }
    best
}

/// [`segment_box`] for a segment parallel to one of the box's axes (an upright capsule
/// beside an upright box, the controllers' usual case): the two other coordinates stay
/// put, so the closest point of the segment is where it enters the box's slab along that
/// axis (its start when it starts inside, else the end nearer the slab), the point the
/// general path picks too (the first of equally close points). `None` when `d` is not
/// along one axis.
fn parallel_segment_box(a: Vector, d: Vector, he: Vector) -> Option<(Vector, Vector, f32)> {
    let axis = match (d.x != 0.0, d.y != 0.0, d.z != 0.0) {
        (false, true, false) => 1,
        (true, false, false) => 0,
        (false, false, true) => 2,
        _ => return None,
    };
    let entry = a[axis].max(-he[axis]).min(he[axis]);
    let t = ((entry - a[axis]) / d[axis]).clamp(0.0, 1.0);
    let p = a + d * t;
    let q = p.clamp(-he, he);
    Some((p, q, (p - q).length_squared()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use rapier3d::parry::query::{DefaultQueryDispatcher, QueryDispatcher};
    use rapier3d::parry::shape::{Capsule, Cuboid};

    /// From the box's side: the capsule's contact flipped, for capsules beside, over and
    /// into boxes, upright and tilted, near and beyond the prediction.
    #[test]
    fn box_first_is_the_flipped_capsule_contact() {
        let capsule = Capsule::new_y(1.5, 1.0);
        let he = Vector::new(1.5, 0.5, 4.0);
        let mut checked = 0;
        for at in [
            [3.0f32, 0.2, 0.5],
            [0.3, 3.05, -1.0],
            [-2.4, -3.2, 3.9],
            [0.0, 2.2, 0.0],
            [9.0, 0.0, 0.0],
        ] {
            for angle in [0.0f32, 0.7] {
                for axis in [Vector::Y, Vector::new(0.3, 0.5, 0.8).normalize()] {
                    let pose21 = Pose::from_parts(
                        Vector::from(at),
                        rapier3d::math::Rotation::from_axis_angle(axis, angle),
                    );
                    let (a, b) = (capsule.segment.a, capsule.segment.b);
                    let ours = box_capsule(&pose21, a, b, capsule.radius, he, 2.0);
                    let theirs = capsule_box(&pose21.inverse(), a, b, capsule.radius, he, 2.0)
                        .map(|found| found.map(Contact::flipped));
                    let what = format!("at {at:?} angle {angle}: {ours:?} against {theirs:?}");
                    match (ours, theirs) {
                        (Some(Some(o)), Some(Some(t))) => {
                            assert!((o.dist - t.dist).abs() < 1e-5, "{what}");
                            assert!((o.point1 - t.point1).length() < 1e-4, "{what}");
                            assert!((o.point2 - t.point2).length() < 1e-4, "{what}");
                            assert!((o.normal1 - t.normal1).length() < 1e-5, "{what}");
                            assert!((o.normal2 - t.normal2).length() < 1e-5, "{what}");
                            checked += 1;
                        }
                        (Some(None), Some(None)) | (None, None) => {}
                        _ => panic!("{what}"),
                    }
                }
            }
        }
        assert!(checked >= 8, "only {checked} contacts compared");
    }

    /// The axis-parallel closed form gives the general path's closest points: beside,
    /// above, below, crossing and inside the box, along each axis and both ways.
    #[test]
    fn parallel_segments_match_the_pieces() {
        let he = Vector::new(1.5, 0.5, 2.0);
        let mut checked = 0;
        for axis in 0..3 {
            for len in [-5.0f32, -0.3, 0.3, 5.0] {
                for start in [-7.0f32, -2.1, -0.2, 0.4, 1.7, 6.0] {
                    for side in [[0.0f32, 0.0], [0.7, -0.3], [2.5, 0.1], [-3.0, 4.0]] {
                        let mut a = Vector::new(side[0], side[1], 0.0);
                        a = Vector::new(a[(3 - axis) % 3], a[(4 - axis) % 3], a[(5 - axis) % 3]);
                        a[axis] = start;
                        let mut d = Vector::ZERO;
                        d[axis] = len;
                        let fast = parallel_segment_box(a, d, he).expect("axis-parallel");
                        let general = segment_box_pieces(a, d, he);
                        let what = format!("a {a:?} d {d:?}: {fast:?} against {general:?}");
                        assert!((fast.2 - general.2).abs() < 1e-5, "{what}");
                        assert!((fast.0 - general.0).length() < 1e-5, "{what}");
                        assert!((fast.1 - general.1).length() < 1e-5, "{what}");
                        checked += 1;
                    }
                }
            }
        }
        assert_eq!(checked, 3 * 4 * 6 * 4);
        // Not along one axis: left to the pieces.
        assert!(parallel_segment_box(Vector::ZERO, Vector::new(1.0, 1.0, 0.0), he).is_none());
    }

    /// Against parry's GJK on small boxes (where it is exact): capsules beside faces, over
    /// edges and corners, tilted, separated and sunk less than their radius.
    #[test]
    fn matches_gjk_on_small_boxes() {
        let capsule = Capsule::new_y(1.5, 1.0);
        let cuboid = Cuboid::new(Vector::new(1.5, 1.5, 1.5));
        let mut checked = 0;
        for (i, at) in [
            [4.0f32, 0.3, 0.2],
            [2.9, 0.0, 0.0],
            [2.2, 4.1, 0.3],
            [2.3, 2.2, 2.1],
            [0.4, 4.5, -0.2],
            [-3.0, -2.0, 2.6],
            [2.6, 0.5, 2.6],
        ]
        .into_iter()
        .enumerate()
        {
            for angle in [0.0f32, 0.4, 1.2] {
                let rotation = rapier3d::math::Rotation::from_axis_angle(
                    Vector::new(0.3, 0.5, 0.8).normalize(),
                    angle + i as f32 * 0.1,
                );
                // The box placed in the capsule's frame.
                let pos12 = Pose::from_parts(Vector::from(at), rotation);
                let ours = contact(&pos12, &capsule, &cuboid, 10.0);
                let gjk = DefaultQueryDispatcher
                    .contact(&pos12, &capsule, &cuboid, 10.0)
                    .unwrap()
                    .unwrap();
                let what = format!("box at {at:?}, angle {angle}");
                let Some(ours) = ours else {
                    continue; // the segment touches the box: left to GJK
                };
                let ours = ours.expect("within the prediction");
                // Ours is the distance of two real points, so it bounds the true distance
                // from above, as GJK's does: never above GJK's, and within its tolerance.
                assert!(
                    ours.dist <= gjk.dist + 1e-5 && ours.dist > gjk.dist - 1e-3,
                    "{what}: {ours:?} {gjk:?}"
                );
                assert!(
                    (ours.normal1 - gjk.normal1).length() < 2e-2,
                    "{what}: {ours:?} {gjk:?}"
                );
                // The witness points need not be GJK's (a segment parallel to a face has a
                // whole edge of closest points), but they lie `dist` apart along normal1.
                let gap = pos12 * ours.point2 - ours.point1;
                assert!(
                    (gap - ours.normal1 * ours.dist).length() < 1e-3,
                    "{what}: {ours:?}"
                );
                // Flipped: the box first.
                let flipped = contact(&pos12.inverse(), &cuboid, &capsule, 10.0)
                    .unwrap()
                    .unwrap();
                assert!((flipped.dist - ours.dist).abs() < 1e-5, "{what}");
                assert!((flipped.normal2 - ours.normal1).length() < 1e-5, "{what}");
                checked += 1;
            }
        }
        assert!(checked >= 18, "only {checked} placements in closed form");
    }

    /// Against parry's GJK: capsules side by side, crossed, tilted, end to end, parallel.
    #[test]
    fn capsule_pairs_match_gjk() {
        let c1 = Capsule::new_y(1.5, 1.0);
        let c2 = Capsule::new_y(0.5, 0.4);
        let mut checked = 0;
        for at in [
            [2.5f32, 0.0, 0.0],
            [0.0, 0.0, 2.3],
            [1.0, 4.2, 0.5],
            [-1.8, -3.0, 1.0],
            [2.2, 1.0, -0.3],
        ] {
            for (axis, angle) in [
                ([1.0f32, 0.0, 0.0], 0.0f32),
                ([1.0, 0.0, 0.0], 1.5),
                ([0.3, 0.5, 0.8], 0.7),
            ] {
                let rotation = rapier3d::math::Rotation::from_axis_angle(
                    Vector::from(axis).normalize(),
                    angle,
                );
                let pos12 = Pose::from_parts(Vector::from(at), rotation);
                let what = format!("at {at:?}, angle {angle}");
                let Some(ours) = contact(&pos12, &c1, &c2, 10.0) else {
                    continue;
                };
                let ours = ours.expect("within the prediction");
                let gjk = DefaultQueryDispatcher
                    .contact(&pos12, &c1, &c2, 10.0)
                    .unwrap()
                    .unwrap();
                assert!(
                    (ours.dist - gjk.dist).abs() < 1e-3,
                    "{what}: {ours:?} {gjk:?}"
                );
                let gap = pos12 * ours.point2 - ours.point1;
                assert!(
                    (gap - ours.normal1 * ours.dist).length() < 1e-3,
                    "{what}: {ours:?}"
                );
                assert!(
                    (pos12.rotation * ours.normal2 + ours.normal1).length() < 1e-4,
                    "{what}: {ours:?}"
                );
                checked += 1;
            }
        }
        assert!(checked >= 12, "only {checked} placements in closed form");
        // Parallel and side by side, 0.7 apart: the gap along X.
        let pos12 = Pose::from_translation(Vector::new(2.7, 0.4, 0.0));
        let side = contact(&pos12, &c1, &Capsule::new_y(1.5, 1.0), 1.0)
            .unwrap()
            .unwrap();
        assert!((side.dist - 0.7).abs() < 1e-5, "{side:?}");
        assert!((side.normal1 - Vector::X).length() < 1e-5, "{side:?}");
    }

    /// A capsule standing 0.01 over floors of any width, its foot near the centre and off
    /// it: gap 0.01, normal straight down from the capsule.
    #[test]
    fn capsule_over_wide_floors() {
        let capsule = Capsule::new_y(1.5, 1.0);
        for width in [1.0f32, 50.0, 400.0, 5000.0, 100_000.0] {
            let floor = Cuboid::new(Vector::new(width / 2.0, 0.5, width / 2.0));
            for x in [0.0f32, 0.2, 0.49 * width] {
                let pos12 = Pose::from_translation(Vector::new(-x, -(2.5 + 0.01) - 0.5, 0.3));
                let c = contact(&pos12, &capsule, &floor, 1.0).unwrap().unwrap();
                let what = format!("width {width} x {x}: {c:?}");
                assert!((c.dist - 0.01).abs() < 1e-3, "{what}");
                assert!(c.normal1.y < -0.9999, "{what}");
                assert!((c.point2.y - 0.5).abs() < 1e-3, "{what}");
            }
        }
    }
}

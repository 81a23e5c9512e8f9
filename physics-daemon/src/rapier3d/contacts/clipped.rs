//! Queries that stay exact next to very large boxes.
//!
//! Parry answers capsule-, cylinder- and hull-against-box queries with GJK/EPA, whose
//! simplex spans the whole Minkowski difference: against a floor hundreds of units wide the
//! corners sit hundreds of units away while the gap being measured is a hundredth of a unit,
//! and f32 loses it. Measured on parry 0.31 with a capsule (radius 1, half height 1.5)
//! resting 0.01 above an anchored box floor: a 400 × 1 × 400 floor gave a contact 6.01 deep
//! with its normal pointing *down* (the controller was pushed 6 units into the floor and fell
//! through); a cast from 0.05 inside reported no hit; a 5000 × 2 × 5000 floor reported
//! casts 0.5 too long (the controller stood 0.49 too low). Floors of 50, 100 and 2048 happened
//! to be fine, and so did the 400 floor a few units off its centre.
//!
//! GJK also goes wrong, at any size, when a shape sits exactly over the middle of a box
//! (ties between the box's corners): a capsule sunk 0.05 into a 10 × 1 × 10 box cast down
//! finds no hit; two capsules meeting exactly head-on pass through each other.
//!
//! [`ClippedQueries`], the dispatcher every query of a 3D plane uses, answers:
//! - a contact of a capsule with a box whose segment stays outside the box in closed form
//!   (`capsule`);
//! - a contact of a convex shape with a box from the box's face when the shape's deepest
//!   point lies over it (exact at any size, see [`face_contact`]);
//! - otherwise any query against a much larger box on that box clipped to the region near
//!   the other shape (off its centre, widened several shape-sizes: the same surface there,
//!   where GJK is exact to f32 rounding), witness points given back in the box's own frame;
//! - a cast of two convex shapes by conservative advancement on that contact
//!   ([`cast_convex`]);
//! - everything else through parry's default dispatcher unchanged.

use rapier3d::math::{Pose, Vector};
use rapier3d::parry::bounding_volume::Aabb;
use rapier3d::parry::query::{
    ClosestPoints, Contact, DefaultQueryDispatcher, NonlinearRigidMotion, QueryDispatcher,
    ShapeCastHit, ShapeCastOptions, ShapeCastStatus, ShapeDistance, ShapeIntersection, Unsupported,
};
use rapier3d::parry::shape::{Cuboid, Shape};

/// The clipped region is the other shape's box widened by this many times its own largest
/// half-extent (plus [`MIN_MARGIN`]): far enough that the cut faces never matter to a query
/// about the shape (a penetration through a cut face would be deeper than the shape is
/// wide), near enough for GJK to stay exact.
const MARGIN_SIZES: f32 = 4.0;
/// Smallest widening of the clipped region (units).
const MIN_MARGIN: f32 = 1.0;
/// A box is clipped only when it is this many times larger than the region in some axis:
/// small boxes go to parry untouched.
const CLIP_RATIO: f32 = 4.0;

/// The one dispatcher every query of a 3D plane uses.
static CLIPPED: ClippedQueries = ClippedQueries;

/// `world`'s colliders as a query pipeline that answers through [`ClippedQueries`].
pub(crate) fn query_pipeline<'a>(
    world: &'a rapier3d::prelude::PhysicsWorld,
    filter: rapier3d::prelude::QueryFilter<'a>,
) -> rapier3d::prelude::QueryPipeline<'a> {
    world
        .broad_phase
        .as_query_pipeline(&CLIPPED, &world.bodies, &world.colliders, filter)
}

/// The dispatcher of the module docs: exact contacts and casts next to boxes of any size.
#[derive(Debug, Clone, Copy, Default)]
pub struct ClippedQueries;

/// The part of `cuboid` near `region` (both in the cuboid's frame): the clipped box and its
/// centre in the cuboid's frame. `None` when clipping would not shrink the box much, or when
/// the region misses the box (then the shapes are far apart and parry is exact enough).
fn clip(cuboid: &Cuboid, region: Aabb) -> Option<(Cuboid, Vector)> {
    let he = cuboid.half_extents;
    let size = region.half_extents().max_element();
    let margin = size * MARGIN_SIZES + MIN_MARGIN;
    // Off-centre by uneven fractions of the margin: GJK also goes wrong when a shape sits
    // exactly over a box's centre (ties between its corners; the 400-wide floor failed only
    // there), and clipping around the shape would put it there every time.
    let shift = Vector::new(0.371, 0.293, 0.229) * margin;
    let region = Aabb::new(
        region.mins - Vector::splat(margin) + shift,
        region.maxs + Vector::splat(margin) + shift,
    );
    let lo = region.mins.max(-he);
    let hi = region.maxs.min(he);
    if lo.cmpgt(hi).any() {
        return None;
    }
    let clipped = (hi - lo) * 0.5;
    if (he / clipped.max(Vector::splat(f32::MIN_POSITIVE)))
        .cmplt(Vector::splat(CLIP_RATIO))
        .all()
    {
        return None;
    }
    Some((Cuboid::new(clipped), (hi + lo) * 0.5))
}

/// Which side of a query was clipped, and where its clipped box's centre lies in its frame.
enum Clipped {
    /// The second shape: its clipped box and centre.
    Second(Cuboid, Vector),
    /// The first shape.
    First(Cuboid, Vector),
}

/// The clipping for a query of `g1` against `g2` placed at `pos12`, if either is a box much
/// larger than the other shape.
fn clipping(pos12: &Pose, g1: &dyn Shape, g2: &dyn Shape) -> Option<Clipped> {
    if let Some(c2) = g2.as_cuboid() {
        if let Some((c, centre)) = clip(c2, g1.compute_aabb(&pos12.inverse())) {
            return Some(Clipped::Second(c, centre));
        }
    }
    let c1 = g1.as_cuboid()?;
    let (c, centre) = clip(c1, g2.compute_aabb(pos12))?;
    Some(Clipped::First(c, centre))
}

/// Runs `query` on the clipped pair (or the pair itself when nothing is clipped), with the
/// offsets that bring points of each shape back to its own frame.
fn with_clipping<R>(
    pos12: &Pose,
    g1: &dyn Shape,
    g2: &dyn Shape,
    query: impl FnOnce(&Pose, &dyn Shape, &dyn Shape, (Vector, Vector)) -> R,
) -> R {
    match clipping(pos12, g1, g2) {
        Some(c) => {
            let (s1, s2) = c.shapes(g1, g2);
            query(&c.pos12(pos12), s1, s2, c.offsets())
        }
        None => query(pos12, g1, g2, (Vector::ZERO, Vector::ZERO)),
    }
}

impl Clipped {
    /// The query's pose of the second shape relative to the first after clipping.
    fn pos12(&self, pos12: &Pose) -> Pose {
        match self {
            Clipped::Second(_, centre) => *pos12 * Pose::from_translation(*centre),
            Clipped::First(_, centre) => Pose::from_translation(-*centre) * *pos12,
        }
    }

    /// The two shapes after clipping.
    fn shapes<'a>(
        &'a self,
        g1: &'a dyn Shape,
        g2: &'a dyn Shape,
    ) -> (&'a dyn Shape, &'a dyn Shape) {
        match self {
            Clipped::Second(c, _) => (g1, c),
            Clipped::First(c, _) => (c, g2),
        }
    }

    /// Offsets that bring points of the clipped shapes back to their own frames.
    fn offsets(&self) -> (Vector, Vector) {
        match self {
            Clipped::Second(_, centre) => (Vector::ZERO, *centre),
            Clipped::First(_, centre) => (*centre, Vector::ZERO),
        }
    }
}

/// The contact of a convex shape `g1` with the box `b` placed at `pos12`, found from the
/// box's faces: for each face, the point of `g1` deepest toward it. When the face that
/// separates most has that point right over it (not past an edge), the distance to its
/// plane is the exact distance (or depth) and the face normal the exact normal, whatever
/// the box's size: the separating plane bounds the distance from below and the point's
/// projection onto the face reaches it. Returns `None` when the closest feature is an edge
/// or a corner of the box (the caller asks GJK then).
fn face_contact(
    pos12: &Pose,
    g1: &dyn Shape,
    b: &Cuboid,
    prediction: f32,
) -> Option<Option<Contact>> {
    let support = g1.as_support_map()?;
    let to_box = pos12.inverse();
    let he = b.half_extents;
    let mut best: Option<(f32, usize, Vector, Vector, Vector)> = None;
    for axis in 0..3 {
        for sign in [1.0f32, -1.0] {
            let mut n = Vector::ZERO;
            n[axis] = sign;
            let p1 = support.local_support_point(pos12.rotation * -n);
            let p = to_box * p1;
            let sep = n.dot(p) - he[axis];
            if best.is_none_or(|(s, ..)| sep > s) {
                best = Some((sep, axis, n, p, p1));
            }
        }
    }
    let (sep, axis, n, p, p1) = best?;
    if !sep.is_finite() || (0..3).any(|k| k != axis && p[k].abs() > he[k]) {
        return None;
    }
    if sep > prediction {
        return Some(None);
    }
    Some(Some(Contact::new(
        p1,
        p - n * sep,
        pos12.rotation * -n,
        n,
        sep,
    )))
}

/// The contact query every path here uses: a box's face when that decides it (exact at any
/// size), else GJK on the box clipped near the other shape, else parry's default.
pub(crate) fn contact(
    pos12: &Pose,
    g1: &dyn Shape,
    g2: &dyn Shape,
    prediction: f32,
) -> Result<Option<Contact>, Unsupported> {
    if let Some(found) = crate::rapier3d::contacts::capsule::contact(pos12, g1, g2, prediction) {
        return Ok(found);
    }
    if let Some(b) = g2.as_cuboid() {
        if let Some(found) = face_contact(pos12, g1, b, prediction) {
            return Ok(found);
        }
    } else if let Some(b) = g1.as_cuboid() {
        if let Some(found) = face_contact(&pos12.inverse(), g2, b, prediction) {
            return Ok(found.map(Contact::flipped));
        }
    }
    with_clipping(pos12, g1, g2, |pos12, s1, s2, (o1, o2)| {
        Ok(DefaultQueryDispatcher
            .contact(pos12, s1, s2, prediction)?
            .map(|mut contact| {
                contact.point1 += o1;
                contact.point2 += o2;
                contact
            }))
    })
}

/// How far before the touch (units) [`cast_convex`] reads a hit's witness points and
/// normals: near enough to be the touch's geometry within the tolerance of a hit, far
/// enough that the contact query does not pick a thin box's far face.
const WITNESS_BACKOFF: f32 = 1.0e-3;

/// Newton steps of [`cast_convex`] before it hands the cast to parry.
const ADVANCE_STEPS: usize = 24;
/// A cast has hit once the gap left is within this of the target distance (units).
const ADVANCE_TOLERANCE: f32 = 1.0e-4;

/// A cast of two convex shapes by conservative advancement on the contact query. Parry's
/// own cast (GJK's directional distance) goes wrong when a shape sits exactly over the
/// middle of a box: a capsule 0.0005 above the centre of a 100 × 0.05 × 100 box cast down by
/// 1 reports no hit, sunk 0.05 into a 10 × 1 × 10 box no hit either, into a 64 × 1 × 64 box a
/// hit one unit late; a controller standing there lost its ground every other tick.
///
/// The gap between two convex shapes under a translation is a convex function of the
/// time, whose slope is the contact normal's closing speed: Newton's method from the start
/// never steps past the first touch and converges in a few steps. As in parry, a start
/// that already touches (or is within the target distance) is a hit at time 0 unless it
/// moves apart along the contact normal and `stop_at_penetration` is off, then no hit.
fn cast_convex(
    pos12: &Pose,
    vel12: Vector,
    g1: &dyn Shape,
    g2: &dyn Shape,
    options: ShapeCastOptions,
) -> Result<Option<ShapeCastHit>, Unsupported> {
    cast_convex_with(pos12, vel12, g1, g2, options, |at, reach| {
        contact(at, g1, g2, reach)
    })
}

/// [`cast_convex`] with `contact(pos12, prediction)` answering the contact query of `g1`
/// and `g2` (a caller that knows the pair's shapes skips the dispatch; it must answer as
/// [`contact`] does).
pub(crate) fn cast_convex_with(
    pos12: &Pose,
    vel12: Vector,
    g1: &dyn Shape,
    g2: &dyn Shape,
    options: ShapeCastOptions,
    contact: impl Fn(&Pose, f32) -> Result<Option<Contact>, Unsupported>,
) -> Result<Option<ShapeCastHit>, Unsupported> {
    let speed = vel12.length();
    if !speed.is_finite() || speed == 0.0 {
        return DefaultQueryDispatcher.cast_shapes(pos12, vel12, g1, g2, options);
    }
    let target = options.target_distance.max(0.0);
    let max_toi = options.max_time_of_impact;
    let mut t = 0.0f32;
    // The contact before the last step: at the touch itself the contact query can pick
    // the wrong face (a thin box's far side), so a hit reports the geometry seen just
    // before it (the closest points of a translation's touch, in each shape's own frame).
    let mut before: Option<Contact> = None;
    for step in 0..ADVANCE_STEPS {
        let at = Pose::from_translation(vel12 * t) * *pos12;
        // Nothing within the rest of the travel: no hit.
        let reach = target + speed * (max_toi - t) + ADVANCE_TOLERANCE;
        let Some(found) = contact(&at, reach)? else {
            return Ok(None);
        };
        if found.dist > reach {
            return Ok(None);
        }
        let gap = found.dist - target;
        // Closing speed along the normal; motion along a surface (a controller walking on a
        // floor it is within the target distance of) neither approaches nor leaves it, whatever
        // the rounding of a rotated normal says.
        let closing = -found.normal1.dot(vel12);
        let closing = if closing.abs() <= speed * 1.0e-5 {
            0.0
        } else {
            closing
        };
        if gap <= ADVANCE_TOLERANCE {
            if step == 0 && !options.stop_at_penetration && closing <= 0.0 {
                return Ok(None);
            }
            // The geometry just before the touch: a step back of [`WITNESS_BACKOFF`] from
            // it, not the previous iterate (Newton's first step from far away lands on a
            // plane at once, and the contact seen from the start lies elsewhere on a slope).
            let touch = match before {
                Some(_) => {
                    let back = (t - WITNESS_BACKOFF / speed).max(0.0);
                    let near = Pose::from_translation(vel12 * back) * *pos12;
                    contact(&near, reach)?.or(before).unwrap_or(found)
                }
                None => found,
            };
            return Ok(Some(ShapeCastHit {
                time_of_impact: t,
                witness1: touch.point1,
                witness2: touch.point2,
                normal1: touch.normal1,
                normal2: touch.normal2,
                status: if step == 0 && touch.dist < target {
                    ShapeCastStatus::PenetratingOrWithinTargetDist
                } else {
                    ShapeCastStatus::Converged
                },
                subshape1: 0,
                subshape2: 0,
            }));
        }
        if closing <= 0.0 {
            return Ok(None); // moving apart: a convex pair never meets again
        }
        t += gap / closing;
        before = Some(found);
        if t > max_toi {
            return Ok(None);
        }
    }
    DefaultQueryDispatcher.cast_shapes(pos12, vel12, g1, g2, options)
}

impl QueryDispatcher for ClippedQueries {
    fn intersection_test(
        &self,
        pos12: &Pose,
        g1: &dyn Shape,
        g2: &dyn Shape,
    ) -> Result<ShapeIntersection, Unsupported> {
        with_clipping(pos12, g1, g2, |pos12, s1, s2, _| {
            DefaultQueryDispatcher.intersection_test(pos12, s1, s2)
        })
    }

    fn distance(
        &self,
        pos12: &Pose,
        g1: &dyn Shape,
        g2: &dyn Shape,
    ) -> Result<ShapeDistance, Unsupported> {
        with_clipping(pos12, g1, g2, |pos12, s1, s2, _| {
            DefaultQueryDispatcher.distance(pos12, s1, s2)
        })
    }

    fn contact(
        &self,
        pos12: &Pose,
        g1: &dyn Shape,
        g2: &dyn Shape,
        prediction: f32,
    ) -> Result<Option<Contact>, Unsupported> {
        contact(pos12, g1, g2, prediction)
    }

    fn closest_points(
        &self,
        pos12: &Pose,
        g1: &dyn Shape,
        g2: &dyn Shape,
        max_dist: f32,
    ) -> Result<ClosestPoints, Unsupported> {
        with_clipping(pos12, g1, g2, |pos12, s1, s2, (o1, o2)| {
            Ok(
                match DefaultQueryDispatcher.closest_points(pos12, s1, s2, max_dist)? {
                    ClosestPoints::WithinMargin(p1, p2) => {
                        ClosestPoints::WithinMargin(p1 + o1, p2 + o2)
                    }
                    other => other,
                },
            )
        })
    }

    fn cast_shapes(
        &self,
        pos12: &Pose,
        local_vel12: Vector,
        g1: &dyn Shape,
        g2: &dyn Shape,
        options: ShapeCastOptions,
    ) -> Result<Option<ShapeCastHit>, Unsupported> {
        // Composite shapes (maps, compounds) go to parry, which casts their parts itself.
        if g1.is_convex() && g2.is_convex() {
            return cast_convex(pos12, local_vel12, g1, g2, options);
        }
        DefaultQueryDispatcher.cast_shapes(pos12, local_vel12, g1, g2, options)
    }

    fn cast_shapes_nonlinear(
        &self,
        motion1: &NonlinearRigidMotion,
        g1: &dyn Shape,
        motion2: &NonlinearRigidMotion,
        g2: &dyn Shape,
        start_time: f32,
        end_time: f32,
        stop_at_penetration: bool,
    ) -> Result<Option<ShapeCastHit>, Unsupported> {
        DefaultQueryDispatcher.cast_shapes_nonlinear(
            motion1,
            g1,
            motion2,
            g2,
            start_time,
            end_time,
            stop_at_penetration,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rapier3d::parry::query::ShapeCastOptions;
    use rapier3d::prelude::SharedShape;

    fn options(reach: f32) -> ShapeCastOptions {
        ShapeCastOptions {
            max_time_of_impact: reach,
            target_distance: 0.0,
            stop_at_penetration: false,
            compute_impact_geometry_on_penetration: true,
        }
    }

    /// A capsule 0.01 above box floors of every width: the default dispatcher gets some of
    /// these wrong by units (the 400-wide floor among them); the clipped one is within
    /// f32 rounding of the closed form for all.
    #[test]
    fn capsule_over_floors_of_any_width() {
        let capsule = SharedShape::capsule_y(1.5, 1.0);
        for width in [
            1.0f32, 10.0, 24.0, 50.0, 64.0, 100.0, 128.0, 400.0, 2048.0, 5000.0, 10_000.0,
        ] {
            for thickness in [0.05f32, 1.0, 2.0, 20.0] {
                let floor = SharedShape::cuboid(width / 2.0, thickness / 2.0, width / 2.0);
                let floor_pose = Pose::from_translation(Vector::new(0.0, -thickness / 2.0, 0.0));
                for (x, gap) in [
                    (0.0f32, 0.01f32),
                    (0.0, 0.1),
                    (0.0, 0.0005),
                    (3.0, 0.01),
                    (0.2, -0.05),
                ] {
                    // Sunk deeper than half the floor's thickness is beneath it, not on it.
                    if x.abs() > width / 2.0 || -gap >= thickness / 2.0 {
                        continue;
                    }
                    let at = Pose::from_translation(Vector::new(x, 2.5 + gap, 0.0));
                    let pos12 = at.inv_mul(&floor_pose);
                    let what = format!("width {width} thickness {thickness} x {x} gap {gap}");
                    let contact = ClippedQueries
                        .contact(&pos12, &*capsule, &*floor, 1.0)
                        .unwrap()
                        .expect("contact within the prediction");
                    assert!(
                        (contact.dist - gap).abs() < 1e-3,
                        "{what}: contact {contact:?}"
                    );
                    assert!(contact.normal1.y < -0.999, "{what}: normal {contact:?}");
                    for reach in [1.0, 3.0] {
                        let cast = ClippedQueries
                            .cast_shapes(&pos12, Vector::Y, &*capsule, &*floor, options(reach))
                            .unwrap()
                            .unwrap_or_else(|| panic!("{what} reach {reach}: no hit"));
                        assert!(
                            (cast.time_of_impact - gap.max(0.0)).abs() < 1e-3,
                            "{what}: cast {cast:?}"
                        );
                        // Witness on the floor's top face, in the floor's own frame.
                        assert!(
                            (cast.witness2.y - thickness / 2.0).abs() < 1e-3,
                            "{what}: witness {cast:?}"
                        );
                    }
                }
            }
        }
    }
}

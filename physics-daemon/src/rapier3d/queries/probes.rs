//! Proximity queries of a 3D plane: the ground under a sphere (`ProbeGround`), the closest
//! surface point to a point (`ClosestPoint`), the gap between a shape and the scene
//! (`Clearance`) and the nearest wall beside a capsule (`ProbeWall`, which the controllers'
//! `OnWall` / `WallNormal` also use). All of them go through the plane's query pipeline and
//! [`crate::rapier3d::contacts::clipped::contact`], so they stay exact next to boxes of any size, and they look
//! at each triangle of a triangle-mesh map on its own (a map's floor never hides its walls).

use rapier3d::parry::bounding_volume::BoundingVolume;
use rapier3d::parry::query::ShapeCastOptions;
use rapier3d::parry::shape::Shape as ParryShape;
use rapier3d::prelude::*;
use shm_layout::{CommandError, ProbeHit, QueryOp};

use crate::rapier3d::objects::part::Part;
use crate::rapier3d::plane::Plane;
use crate::rapier3d::queries::ops::Resolved;

/// Tolerance on the slope test (cosines): a slope of exactly the limit is walkable.
const SLOPE_TOLERANCE: f32 = 1.0e-4;
/// First search reach of [`Plane::nearest`] past the shape's own size (units).
const FIRST_REACH: f32 = 1.0;

/// Whether a surface of unit normal `n` is a wall for a slope limit of `max_slope` degrees:
/// too steep to stand on, and not a ceiling either.
pub(in crate::rapier3d) fn is_wall(n: Vector, max_slope: f32) -> bool {
    let limit = max_slope.to_radians().cos() - SLOPE_TOLERANCE;
    n.y.abs() < limit
}

/// Whether a surface of unit normal `n` can be stood on under `max_slope` degrees.
fn is_walkable(n: Vector, max_slope: f32) -> bool {
    n.y >= max_slope.to_radians().cos() - SLOPE_TOLERANCE
}

/// An upright capsule of full `height` (caps included) and `radius`, as parry builds it.
pub(in crate::rapier3d) fn capsule(radius: f32, height: f32) -> Capsule {
    Capsule::new_y((height / 2.0 - radius).max(0.0), radius)
}

impl Plane {
    /// Runs one proximity query (already checked, scene already refreshed).
    pub(in crate::rapier3d) fn probe(&self, op: QueryOp) -> Result<Option<ProbeHit>, CommandError> {
        Ok(match op {
            QueryOp::ProbeGround {
                position,
                radius,
                max_distance,
                max_slope,
                filter,
            } => {
                let f = self.resolve(&filter, None)?;
                self.probe_ground_sphere(&f, Vector::from(position), radius, max_distance)
                    .map(|mut hit| {
                        hit.walkable = is_walkable(Vector::from(hit.normal), max_slope);
                        hit
                    })
            }
            QueryOp::ClosestPoint {
                position,
                max_distance,
                filter,
            } => {
                let f = self.resolve(&filter, None)?;
                self.closest_point(&f, Vector::from(position), max_distance)
            }
            QueryOp::Clearance {
                shape,
                pose,
                max_distance,
                own,
                filter,
            } => {
                let own = own.and_then(|h| self.body_of(h).ok());
                let f = self.resolve(&filter, own)?;
                let shape = Part::new(&shape).collider_shape()?;
                let pose = crate::rapier3d::objects::object::rapier_pose(pose);
                self.nearest(&f, &*shape, &pose, max_distance, |_| true)
            }
            QueryOp::ProbeWall {
                pose,
                radius,
                height,
                max_distance,
                max_slope,
                filter,
            } => {
                let f = self.resolve(&filter, None)?;
                let pose = crate::rapier3d::objects::object::rapier_pose(pose);
                self.nearest(&f, &capsule(radius, height), &pose, max_distance, |n| {
                    is_wall(n, max_slope)
                })
            }
            other => {
                return Err(CommandError::invalid(format!(
                    "{other:?} is not a proximity query"
                )))
            }
        })
    }

    /// The first thing a sphere of `radius` meets cast straight down from `position` by at
    /// most `reach`; a sphere that starts touching or overlapping something hits it at 0.
    fn probe_ground_sphere(
        &self,
        f: &Resolved<'_>,
        position: Vector,
        radius: f32,
        reach: f32,
    ) -> Option<ProbeHit> {
        let predicate = |c: ColliderHandle, co: &Collider| f.accepts(c, co);
        let pipeline =
            self.query_pipeline(rapier3d::prelude::QueryFilter::default().predicate(&predicate));
        let options = ShapeCastOptions {
            max_time_of_impact: reach,
            target_distance: 0.0,
            stop_at_penetration: true,
            compute_impact_geometry_on_penetration: true,
        };
        let start = rapier3d::math::Pose::from_translation(position);
        let (c, hit) = pipeline.cast_shape(&start, -Vector::Y, &Ball::new(radius), options)?;
        Some(ProbeHit {
            object: self.handle_of_collider(c)?,
            position: hit.witness1.into(),
            normal: hit.normal1.into(),
            distance: hit.time_of_impact,
            // The sphere's own witness is in its frame: placed where the cast stopped.
            point_on_shape: (position - Vector::Y * hit.time_of_impact + hit.witness2).into(),
            walkable: false,
        })
    }

    /// The closest surface point of any accepted object to `point` within `reach`; the
    /// distance is negative when `point` lies inside a solid.
    fn closest_point(&self, f: &Resolved<'_>, point: Vector, reach: f32) -> Option<ProbeHit> {
        let predicate = |c: ColliderHandle, co: &Collider| f.accepts(c, co);
        let pipeline =
            self.query_pipeline(rapier3d::prelude::QueryFilter::default().predicate(&predicate));
        let (c, projection) = pipeline.project_point(point, reach, false)?;
        let gap = point - projection.point;
        let length = gap.length();
        // Off the surface: the normal is along the gap (out of the solid toward the point).
        // On it: the normal of the contact of a point-sized ball there.
        let normal = if length > 1.0e-5 {
            if projection.is_inside {
                -gap / length
            } else {
                gap / length
            }
        } else {
            let at = rapier3d::math::Pose::from_translation(point);
            self.nearest(f, &Ball::new(0.0), &at, 1.0e-3, |_| true)
                .map_or(Vector::Y, |hit| Vector::from(hit.normal))
        };
        Some(ProbeHit {
            object: self.handle_of_collider(c)?,
            position: projection.point.into(),
            normal: normal.into(),
            distance: if projection.is_inside {
                -length
            } else {
                length
            },
            point_on_shape: point.into(),
            walkable: false,
        })
    }

    /// The accepted object nearest to `shape` at `pose` within `reach` whose surface normal
    /// there passes `wanted`, with the closest points. The search widens from the shape's
    /// size outward, doubling, so a near object is found without testing far ones.
    pub(in crate::rapier3d) fn nearest(
        &self,
        f: &Resolved<'_>,
        shape: &dyn ParryShape,
        pose: &rapier3d::math::Pose,
        reach: f32,
        wanted: impl Fn(Vector) -> bool,
    ) -> Option<ProbeHit> {
        let predicate = |c: ColliderHandle, co: &Collider| f.accepts(c, co);
        let pipeline =
            self.query_pipeline(rapier3d::prelude::QueryFilter::default().predicate(&predicate));
        let own_box = shape.compute_aabb(pose);
        let mut search = (own_box.half_extents().max_element() + FIRST_REACH).min(reach);
        loop {
            let mut best: Option<(f32, ColliderHandle, Vector, Vector, Vector)> = None;
            for (c, co) in pipeline.intersect_aabb_conservative(own_box.loosened(search)) {
                self.each_piece(co, shape, pose, search, |piece, piece_pose| {
                    let pos12 = pose.inv_mul(&piece_pose);
                    let Ok(Some(contact)) =
                        crate::rapier3d::contacts::clipped::contact(&pos12, shape, piece, search)
                    else {
                        return;
                    };
                    if contact.dist > search || best.is_some_and(|(d, ..)| contact.dist >= d) {
                        return;
                    }
                    let normal = piece_pose.rotation * contact.normal2;
                    if !wanted(normal) {
                        return;
                    }
                    best = Some((
                        contact.dist,
                        c,
                        piece_pose.transform_point(contact.point2),
                        pose.transform_point(contact.point1),
                        normal,
                    ));
                });
            }
            if let Some((distance, c, on_hit, on_shape, normal)) = best {
                return Some(ProbeHit {
                    object: self.handle_of_collider(c)?,
                    position: on_hit.into(),
                    normal: normal.normalize_or_zero().into(),
                    distance,
                    point_on_shape: on_shape.into(),
                    walkable: false,
                });
            }
            if search >= reach {
                return None;
            }
            search = (search * 2.0).min(reach);
        }
    }

    /// Calls `each` with every convex piece of `co` near `shape` at `pose` (within
    /// `reach`): the collider's own shape, or each nearby triangle of a triangle mesh.
    pub(in crate::rapier3d) fn each_piece(
        &self,
        co: &Collider,
        shape: &dyn ParryShape,
        pose: &rapier3d::math::Pose,
        reach: f32,
        mut each: impl FnMut(&dyn ParryShape, rapier3d::math::Pose),
    ) {
        let co_pose = *co.position();
        let Some(mesh) = co.shape().as_trimesh() else {
            each(co.shape(), co_pose);
            return;
        };
        let local = shape.compute_aabb(&co_pose.inv_mul(pose)).loosened(reach);
        for i in mesh.bvh().intersect_aabb(&local) {
            each(&mesh.triangle(i), co_pose);
        }
    }
}

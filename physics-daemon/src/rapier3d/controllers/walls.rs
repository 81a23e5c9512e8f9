//! Wall detection beside the capsule (`WallNormal` / `OnWall`).

use super::*;
use crate::rapier3d::plane::Plane;

impl Plane {
    /// The wall beside controller `c` (object `handle`) where it stands now, or zero.
    pub(in crate::rapier3d) fn controller_wall(&self, handle: Handle, c: &Controller) -> Vector {
        let Ok(h) = self.body_of(handle) else {
            return Vector::ZERO;
        };
        let body = &self.world.bodies[h];
        let groups = body
            .colliders()
            .first()
            .map(|col| self.world.colliders[*col].collision_groups())
            .unwrap_or_default();
        self.wall_beside(
            h,
            &c.shape(),
            body.translation(),
            c.yaw,
            c.settings.max_slope,
            groups,
        )
    }

    /// The unit normal of the nearest wall (steeper than `max_slope`, not a ceiling) within
    /// [`WALL_SKIN`] of the capsule at `position`, or zero.
    #[allow(clippy::too_many_arguments)]
    pub(in crate::rapier3d) fn wall_beside(
        &self,
        own: RigidBodyHandle,
        shape: &SharedShape,
        position: Vector,
        yaw: f32,
        max_slope: f32,
        groups: InteractionGroups,
    ) -> Vector {
        let pred = |_: ColliderHandle, co: &Collider| {
            co.parent() != Some(own) && co.collision_groups().test(groups) && !co.is_sensor()
        };
        let pipeline =
            self.query_pipeline(rapier3d::prelude::QueryFilter::default().predicate(&pred));
        let pose = rapier3d::math::Pose::from_parts(position, yaw_rotation(yaw));
        let mut best: Option<(f32, Vector)> = None;
        let region = shape.compute_aabb(&pose).loosened(WALL_SKIN);
        for (_, co) in pipeline.intersect_aabb_conservative(region) {
            self.each_piece(co, &**shape, &pose, WALL_SKIN, |piece, piece_pose| {
                let pos12 = pose.inv_mul(&piece_pose);
                let Ok(Some(contact)) =
                    crate::rapier3d::contacts::clipped::contact(&pos12, &**shape, piece, WALL_SKIN)
                else {
                    return;
                };
                let normal = (piece_pose.rotation * contact.normal2).normalize_or_zero();
                if contact.dist <= WALL_SKIN
                    && crate::rapier3d::queries::probes::is_wall(normal, max_slope)
                    && best.is_none_or(|(d, _)| contact.dist < d)
                {
                    best = Some((contact.dist, normal));
                }
            });
        }
        best.map_or(Vector::ZERO, |(_, n)| n)
    }
}

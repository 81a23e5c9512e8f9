//! What is under and around the capsule: the platform it rides, the ground probe, steps,
//! depenetration. Each reads the tick's [`Nearby`] colliders.

use rapier3d::parry::bounding_volume::BoundingVolume;
use rapier3d::parry::shape::Capsule;

use super::nearby::{capsule_aabb, Nearby};
use super::tick::Scene;
use super::*;

impl Scene<'_> {
    /// The platform's motion at `foot` since the last tick: (translation to ride along,
    /// its velocity there, its yaw change).
    pub(super) fn platform_motion(
        &self,
        c: &Controller,
        foot: Vector,
        dt: f32,
    ) -> (Vector, Vector, f32) {
        let none = (Vector::ZERO, Vector::ZERO, 0.0);
        let Some(ground) = c.ground.filter(|_| c.on_ground) else {
            return none;
        };
        let Some(body) = self.refs.bodies.get(ground.body) else {
            return none;
        };
        if body.is_dynamic()
            || (body.is_kinematic() && body.body_type() == RigidBodyType::KinematicVelocityBased)
        {
            let v = body.velocity_at_point(foot);
            return (v * dt, v, body.angvel().y * dt);
        }
        // Anchored or pose-driven: how far its pose moved since we stood on it (nothing, when
        // it has not moved at all: the floor under most controllers).
        let now = *body.position();
        if super::tick::same_pose(&now, &ground.pose) {
            return none;
        }
        let delta = now * ground.pose.inverse();
        let carried = delta.transform_point(foot) - foot;
        let yaw = yaw_of(delta.rotation.to_array());
        (carried, carried / dt, yaw)
    }

    /// Quake's stair step for a capsule blocked at `position` with `remaining` horizontal
    /// motion: lift by StepHeight (as far as the ceiling allows), move forward by the
    /// remaining motion (at least far enough for the capsule's bottom to clear the edge),
    /// drop back down. Accepted when it lands on walkable ground higher than it started and
    /// no higher than StepHeight.
    pub(super) fn step_up(
        &self,
        shape: &Capsule,
        position: Vector,
        rotation: Rotation,
        remaining: Vector,
        s: &ControllerSettings,
        nearby: &mut Nearby<'_>,
    ) -> Option<Vector> {
        let dir = remaining.normalize_or_zero();
        if dir == Vector::ZERO {
            return None;
        }
        let reach = remaining.length().max(s.capsule_radius);
        // Everything the lift, the move and the drop can touch.
        let here = capsule_aabb(shape, &rapier3d::math::Pose::from_parts(position, rotation));
        let need = here
            .merged(&here.translated(Vector::Y * s.step_height + dir * reach))
            .loosened(SKIN * 4.0);
        nearby.ensure(need, 1.0);
        let cast = |from: Vector, along: Vector, reach: f32| {
            let options = ShapeCastOptions {
                max_time_of_impact: reach,
                target_distance: SKIN,
                stop_at_penetration: false,
                compute_impact_geometry_on_penetration: true,
            };
            nearby
                .cast_shape(
                    &rapier3d::math::Pose::from_parts(from, rotation),
                    along,
                    shape,
                    options,
                )
                .map(|(_, hit)| hit)
        };
        // Lift.
        let lift =
            cast(position, Vector::Y, s.step_height).map_or(s.step_height, |h| h.time_of_impact);
        if lift < SKIN * 2.0 {
            return None;
        }
        let lifted = position + Vector::Y * lift;
        // Forward: the remaining motion, at least enough to get the capsule's bottom over
        // the tread.
        let forward = cast(lifted, dir, reach).map_or(reach, |h| h.time_of_impact);
        if forward < SKIN * 2.0 {
            return None;
        }
        let ahead = lifted + dir * forward;
        // Drop.
        let hit = cast(ahead, -Vector::Y, lift + SKIN * 2.0)?;
        // The contact normal as the capsule feels it (a box reports a face normal at its
        // edges; the capsule's own normal there leans, and says it would stand on an edge).
        let felt = -(rotation * hit.normal2);
        if hit.time_of_impact <= 0.0 || felt.y < s.max_slope.to_radians().cos() - 1e-4 {
            return None; // started inside something, or landed on a slope too steep
        }
        let landed = ahead - Vector::Y * hit.time_of_impact;
        // How high the step is: where the capsule stands on it, above its bottom now.
        let bottom = position.y - (s.capsule_half_height + s.capsule_radius);
        let rise = hit.witness1.y - bottom;
        if landed.y - position.y <= SKIN || rise > s.step_height + SKIN {
            return None;
        }
        // Nothing may overlap the capsule where it lands.
        let pose = rapier3d::math::Pose::from_parts(landed, rotation);
        if nearby.intersects_any(&pose, shape) {
            return None;
        }
        Some(landed)
    }

    /// Pushes the capsule at `position` out of everything it overlaps, deepest first.
    pub(super) fn depenetrate(
        &self,
        shape: &Capsule,
        position: Vector,
        nearby: &mut Nearby<'_>,
    ) -> Vector {
        let mut offset = Vector::ZERO;
        for _ in 0..DEPENETRATION_PASSES {
            let pose = rapier3d::math::Pose::from_translation(position + offset);
            let aabb = capsule_aabb(shape, &pose);
            nearby.ensure(aabb, 1.0);
            let mut deepest: Option<(f32, Vector)> = None;
            for c in nearby.within(aabb) {
                // The pose has no rotation: the contact's capsule-local normal is the world's.
                let pos12 = pose.inv_mul(&c.pose);
                if let Ok(Some(contact)) = nearby.contact(c, &pos12, shape, 0.0) {
                    if contact.dist < 0.0 && deepest.is_none_or(|(d, _)| contact.dist < d) {
                        deepest = Some((contact.dist, contact.normal1));
                    }
                }
            }
            let Some((dist, normal)) = deepest else {
                break;
            };
            // normal1 points from the capsule toward the obstacle: move the other way.
            offset += normal * (dist - SKIN);
        }
        offset
    }

    /// The ground within `reach` under the capsule at `position`: (its body, the gap to it,
    /// whether the contact normal as the capsule feels it is walkable under `max_slope`,
    /// whether the surface's own normal is).
    pub(super) fn probe_ground(
        &self,
        shape: &Capsule,
        position: Vector,
        rotation: Rotation,
        reach: f32,
        max_slope: f32,
        nearby: &mut Nearby<'_>,
    ) -> Option<(RigidBodyHandle, f32, bool, bool)> {
        let pose = rapier3d::math::Pose::from_parts(position, rotation);
        let here = capsule_aabb(shape, &pose);
        nearby.ensure(here.merged(&here.translated(-Vector::Y * reach)), 1.0);
        let options = ShapeCastOptions {
            max_time_of_impact: reach,
            target_distance: 0.0,
            stop_at_penetration: false,
            compute_impact_geometry_on_penetration: true,
        };
        let (col, hit) = nearby.cast_shape(&pose, -Vector::Y, shape, options)?;
        // The normal as the capsule feels it: on a box's edge it leans (a box reports its
        // face normal there).
        let felt = -(pose.rotation * hit.normal2);
        let limit = max_slope.to_radians().cos() - 1e-4;
        let body = self.refs.colliders.get(col)?.parent()?;
        Some((
            body,
            hit.time_of_impact,
            felt.y >= limit,
            hit.normal1.y >= limit,
        ))
    }
}

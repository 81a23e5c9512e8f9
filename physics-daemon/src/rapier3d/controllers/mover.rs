//! The capsule's move: slide along what it hits, no climbing past MaxSlope, snap to the
//! ground while grounded. The algorithm of rapier's `KinematicCharacterController::move_shape`
//! (rapier 0.36, Apache-2.0; without autostep, which the controllers replace with their own
//! step), run over the tick's [`Nearby`] colliders with the plane's exact dispatcher.
//!
//! Three things differ from rapier's, all for speed: every query reads the short candidate
//! list instead of the plane's tree; whether the capsule is grounded at the start (which
//! decides the snap) comes from one contact per nearby collider through the plane's
//! dispatcher (a box's face answers it in closed form) instead of full contact manifolds
//! from parry's GJK-based default dispatcher, which rapier's version hard-wires; and the
//! pass after every slide iteration asks only kinematic bodies for a contact (it carries
//! the capsule along them; whether the capsule ended grounded, rapier's other use of it,
//! is read by nobody here: the tick's own ground probe decides OnGround). A manifold's
//! test — its normal leans less than 89.94° from up and one of its points lies within the
//! prediction — holds exactly when the deepest point's does, since all of a convex pair's
//! manifold points share its normal. The push of a kinematic body the capsule touches (rapier's
//! kinematic friction) is taken at that deepest point instead of the manifold's centre.

use rapier3d::control::CharacterCollision;
use rapier3d::parry::bounding_volume::BoundingVolume;
use rapier3d::parry::query::{ShapeCastHit, ShapeCastOptions};
use rapier3d::parry::shape::Capsule;
use rapier3d::prelude::*;

use super::nearby::{capsule_aabb, Nearby};

/// Rapier's default nudge along a hit's normal after sliding (units).
const NORMAL_NUDGE: f32 = 1.0e-4;
/// Slide iterations at most (rapier's).
const MAX_ITERATIONS: usize = 20;
/// Shorter motions are no motion (rapier's threshold).
const MIN_MOTION: f32 = 1.0e-5;

/// How a controller moves: the gap it keeps, its slope limits, how far it snaps down.
#[derive(Debug, Clone, Copy)]
pub(super) struct Mover {
    /// Gap kept from what it touches (units).
    pub offset: f32,
    /// Steepest slope climbed (radians).
    pub max_slope_climb_angle: f32,
    /// Gentlest slope slid down (radians).
    pub min_slope_slide_angle: f32,
    /// How far it snaps down to the ground after the move, when grounded at the start.
    pub snap_to_ground: Option<f32>,
}

/// The move's result.
#[derive(Debug, Clone, Copy)]
pub(super) struct Moved {
    /// The translation it made.
    pub translation: Vector,
}

/// A hit and how the slope rules read it.
struct HitInfo {
    toi: ShapeCastHit,
    is_wall: bool,
    is_nonslip_slope: bool,
}

/// A motion split against a hit's normal.
struct Decomposition {
    normal_part: Vector,
    horizontal_tangent: Vector,
    vertical_tangent: Vector,
}

fn normalize_and_length(v: Vector, threshold: f32) -> Option<(Vector, f32)> {
    let len = v.length();
    (len > threshold).then(|| (v / len, len))
}

impl Mover {
    /// Moves `shape` at `pose` by `desired` (a tick of `dt`) among `nearby`; every hit is
    /// handed to `events`.
    pub fn move_shape(
        &self,
        dt: f32,
        nearby: &Nearby<'_>,
        shape: &Capsule,
        pose: &Pose,
        desired: Vector,
        mut events: impl FnMut(CharacterCollision),
    ) -> Moved {
        let mut result = Moved {
            translation: Vector::ZERO,
        };
        // Nothing near: the whole motion, nothing to stand on.
        if nearby.is_empty() {
            result.translation = desired;
            return result;
        }
        let height = shape.compute_local_aabb().extents().y;
        if normalize_and_length(desired, MIN_MOTION).is_none() {
            self.fix_penetrations(nearby, shape, pose, height, &mut result);
        }
        let at = |t: Vector| Pose::from_translation(t) * *pose;
        let mut remaining = desired;
        let grounded_at_start = self.grounded(nearby, shape, &at(result.translation));
        let mut friction = Vector::ZERO;
        let mut iterations = MAX_ITERATIONS;
        while let Some((dir, dist)) = normalize_and_length(remaining, MIN_MOTION) {
            if iterations == 0 {
                break;
            }
            iterations -= 1;
            let options = ShapeCastOptions {
                target_distance: self.offset,
                stop_at_penetration: false,
                max_time_of_impact: dist,
                compute_impact_geometry_on_penetration: true,
            };
            if let Some((handle, hit)) =
                nearby.cast_shape(&at(result.translation), dir, shape, options)
            {
                let allowed = dir * hit.time_of_impact;
                result.translation += allowed;
                remaining -= allowed;
                events(CharacterCollision {
                    handle,
                    character_pos: at(result.translation),
                    translation_applied: result.translation,
                    translation_remaining: remaining,
                    hit,
                });
                let info = self.hit_info(hit);
                remaining = self.handle_slopes(&info, desired, remaining);
            } else {
                result.translation += remaining;
                break;
            }
            self.kinematic_friction(
                dt,
                nearby,
                shape,
                &at(result.translation),
                &mut friction,
                &mut remaining,
            );
        }
        if grounded_at_start {
            self.snap(nearby, shape, &at(result.translation), &mut result);
        }
        result
    }

    /// Rapier's snap to the ground: down by at most the snap distance unless the move rose.
    fn snap(&self, nearby: &Nearby<'_>, shape: &Capsule, pose: &Pose, result: &mut Moved) {
        let Some(distance) = self.snap_to_ground else {
            return;
        };
        if result.translation.y > 0.0 {
            return;
        }
        let options = ShapeCastOptions {
            target_distance: self.offset,
            stop_at_penetration: false,
            max_time_of_impact: distance,
            compute_impact_geometry_on_penetration: true,
        };
        if let Some((_, hit)) = nearby.cast_shape(pose, -Vector::Y, shape, options) {
            result.translation -= Vector::Y * hit.time_of_impact;
        }
    }

    /// Pushes the shape out of what it overlaps when it does not move (rapier's
    /// `check_and_fix_penetrations`).
    fn fix_penetrations(
        &self,
        nearby: &Nearby<'_>,
        shape: &Capsule,
        pose: &Pose,
        height: f32,
        result: &mut Moved,
    ) {
        let max_correction = height * 0.25;
        let mut applied = 0.0;
        for _ in 0..4 {
            let here = Pose::from_translation(result.translation) * *pose;
            let aabb = capsule_aabb(shape, &here).loosened(self.offset);
            let mut corrected = false;
            for c in nearby.within(aabb) {
                let here = Pose::from_translation(result.translation) * *pose;
                let pos12 = here.inv_mul(&c.pose);
                if let Ok(Some(contact)) = nearby.contact(c, &pos12, shape, 0.0) {
                    if contact.dist < -1.0e-5 {
                        let push = (self.offset - contact.dist).min(max_correction - applied);
                        if push <= 0.0 {
                            return;
                        }
                        result.translation -= (here.rotation * contact.normal1) * push;
                        applied += push;
                        corrected = true;
                    }
                }
            }
            if !corrected {
                break;
            }
        }
    }

    /// Whether the shape at `pose` is grounded (rapier's notion: a contact within the
    /// prediction leaning less than 89.94° from up).
    fn grounded(&self, nearby: &Nearby<'_>, shape: &Capsule, pose: &Pose) -> bool {
        let prediction = self.offset + 0.05;
        let aabb = capsule_aabb(shape, pose).loosened(prediction);
        nearby.within(aabb).any(|c| {
            let pos12 = pose.inv_mul(&c.pose);
            let Ok(Some(contact)) = nearby.contact(c, &pos12, shape, prediction) else {
                return false;
            };
            let normal = -(pose.rotation * contact.normal1);
            contact.dist <= prediction && normal.y >= 1.0e-3
        })
    }

    /// While sliding, carries the shape at `pose` along the kinematic bodies it touches
    /// (rapier's kinematic friction, applied after every slide iteration): only kinematic
    /// candidates are asked for a contact (rapier's pass also decides whether the shape is
    /// grounded there, which nothing reads).
    fn kinematic_friction(
        &self,
        dt: f32,
        nearby: &Nearby<'_>,
        shape: &Capsule,
        pose: &Pose,
        friction: &mut Vector,
        remaining: &mut Vector,
    ) {
        let prediction = self.offset + 0.05;
        let aabb = capsule_aabb(shape, pose).loosened(prediction);
        for c in nearby.within(aabb) {
            let Some(body) = c
                .parent
                .and_then(|p| nearby.bodies().get(p))
                .filter(|rb| rb.is_kinematic())
            else {
                continue;
            };
            let pos12 = pose.inv_mul(&c.pose);
            let Ok(Some(contact)) = nearby.contact(c, &pos12, shape, prediction) else {
                continue;
            };
            if contact.dist > prediction {
                continue;
            }
            let normal = -(pose.rotation * contact.normal1);
            let before = *friction;
            let point = c.pose * contact.point2;
            let target = body.velocity_at_point(point);
            *remaining += normal * (target.dot(normal) * dt - remaining.dot(normal));
            let tangent = (target - normal * target.dot(normal)) * dt;
            for k in 0..3 {
                if tangent[k].abs() > friction[k].abs() {
                    friction[k] = tangent[k];
                }
            }
            *remaining += *friction - before;
        }
    }

    fn hit_info(&self, toi: ShapeCastHit) -> HitInfo {
        let angle = Vector::Y.angle_between(toi.normal1);
        let is_ceiling = toi.normal1.y < 0.0;
        HitInfo {
            toi,
            is_wall: angle >= self.max_slope_climb_angle && !is_ceiling,
            is_nonslip_slope: angle <= self.min_slope_slide_angle,
        }
    }

    /// Rapier's `handle_slopes`: what is left of the motion after the hit.
    fn handle_slopes(&self, hit: &HitInfo, input: Vector, remaining: Vector) -> Vector {
        let vertical_input = Vector::Y * input.y;
        let horizontal_input = input - vertical_input;
        let horizontal = decompose(horizontal_input, &hit.toi);
        let decomp = decompose(remaining, &hit.toi);
        let slipping_intent = horizontal.vertical_tangent.y < 0.0;
        let slipping = decomp.vertical_tangent.y < 0.0;
        let climbing_intent = vertical_input.y > 0.0;
        let climbing = decomp.vertical_tangent.y > 0.0;
        let allowed = if (hit.is_wall && climbing && !climbing_intent)
            || (hit.is_nonslip_slope && slipping && !slipping_intent)
        {
            decomp.horizontal_tangent + decomp.normal_part
        } else {
            decomp.normal_part + decomp.horizontal_tangent + decomp.vertical_tangent
        };
        allowed + hit.toi.normal1 * NORMAL_NUDGE
    }
}

/// Rapier's `decompose_hit`.
fn decompose(translation: Vector, hit: &ShapeCastHit) -> Decomposition {
    let to_surface = translation.dot(hit.normal1);
    let (normal_part, penetration_part) = if to_surface < 0.0 {
        (Vector::ZERO, hit.normal1 * to_surface)
    } else {
        (hit.normal1 * to_surface, Vector::ZERO)
    };
    let tangent = translation - normal_part - penetration_part;
    let dir = hit
        .normal1
        .cross(Vector::Y)
        .try_normalize()
        .unwrap_or_default();
    let horizontal_tangent = dir * tangent.dot(dir);
    Decomposition {
        normal_part,
        horizontal_tangent,
        vertical_tangent: tangent - horizontal_tangent,
    }
}

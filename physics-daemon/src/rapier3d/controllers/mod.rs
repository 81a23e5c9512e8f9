//! Kinematic character controllers, ticked inside the plane before each physics step.
//!
//! A controller is an object of the plane: a kinematic capsule published like any body. Each
//! tick it
//! 1. rides what it stands on (the displacement of an anchored or kinematic platform since
//!    the last tick, the velocity of a dynamic one),
//! 2. turns its motion intent or path into a wish direction and runs Quake's movement model
//!    (ground friction with a stop speed, `accelerate` toward the wish speed, air control,
//!    gravity integrated exactly so the jump apex is JumpPower² / 2g),
//! 3. pushes itself out of anything it overlaps (depenetration, deepest first),
//! 4. moves with a shape-casting mover (rapier's character controller's algorithm over the
//!    colliders near it, `mover`: slide along walls, no climbing past MaxSlope, snap down
//!    slopes and steps while grounded) and steps up to StepHeight,
//! 5. probes the ground under its capsule (OnGround, the platform for the next tick),
//! 6. clips its velocity against what stopped it, pushes dynamic bodies it ran into with a
//!    force capped at PushStrength, turns toward its velocity and advances its path,
//! 7. and hands rapier its next kinematic pose.
//!
//! Every query of a controller's tick reads the colliders near it, gathered once per tick
//! from the broad phase (`nearby`). Controllers tick in slot order; on a plane with a pool
//! those that read nothing another controller changes tick side by side on it (`tick`). A
//! plane without controllers skips all of it.

use std::collections::BTreeMap;

use rapier3d::control::CharacterCollision;
use rapier3d::parry::query::ShapeCastOptions;
use rapier3d::prelude::*;
use shm_layout::controller_op::ControllerInfo;
use shm_layout::{
    CommandError, ControllerOp, ControllerProp, ControllerSettings, EventRecord, Handle, Pose,
    Reply, Shape, Vec3, EVENT_CONTROLLER_JUMPED, EVENT_CONTROLLER_LANDED, EVENT_CONTROLLER_MOVED,
    EVENT_PATH_FINISHED, EVENT_WAYPOINT_REACHED,
};

use crate::backend::counted::{CountedVec, Counter};
use crate::rapier3d::objects::object::Object;
use crate::rapier3d::objects::part::Part;

mod ground;
mod movement;
mod mover;
mod nearby;
mod ops;
mod push;
mod tick;
mod walls;

use movement::{accelerate, apply_friction, horizontal};

/// Gap kept between the capsule and what it touches (units).
const SKIN: f32 = 0.01;
/// Depenetration passes per tick (deepest overlap first).
const DEPENETRATION_PASSES: usize = 4;
/// Below this horizontal speed a controller does not turn toward its velocity.
const TURN_MIN_SPEED: f32 = 0.1;

/// What a controller stands on.
#[derive(Debug, Clone, Copy, serde::Serialize, serde::Deserialize)]
struct Ground {
    body: RigidBodyHandle,
    /// Its pose when the controller last stood on it (for platforms moved by pose writes).
    pose: rapier3d::math::Pose,
}

/// One controller's own state (its body lives in the plane's slot table).
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub(super) struct Controller {
    pub settings: ControllerSettings,
    velocity: Vector,
    yaw: f32,
    on_ground: bool,
    ground: Option<Ground>,
    move_vector: [f32; 2],
    /// The facing when the motion intent was last set (see [`Controller::wish`]).
    intent_yaw: f32,
    /// Counted in the plane's state bytes (a client's quota).
    path: CountedVec<Vector>,
    /// 0-based index of the waypoint being walked to.
    path_index: usize,
    jump: bool,
}

/// The yaw of a rotation: the angle about +Y that turns the controller's forward, the
/// CFrame's LookVector (its −Z, as on Roblox), to the rotation's LookVector.
pub(super) fn yaw_of(rotation: [f32; 4]) -> f32 {
    let q = Rotation::from_array(rotation);
    let look = q * Vector::NEG_Z;
    yaw_toward(look)
}

/// The yaw whose LookVector points along the horizontal part of `direction`.
fn yaw_toward(direction: Vector) -> f32 {
    (-direction.x).atan2(-direction.z)
}

fn yaw_rotation(yaw: f32) -> Rotation {
    Rotation::from_axis_angle(Vector::Y, yaw)
}

/// The shortest signed angle from `a` to `b`.
fn angle_diff(a: f32, b: f32) -> f32 {
    let tau = std::f32::consts::TAU;
    (b - a + std::f32::consts::PI).rem_euclid(tau) - std::f32::consts::PI
}

impl Controller {
    fn new(settings: ControllerSettings, yaw: f32, state_bytes: &Counter) -> Controller {
        Controller {
            settings,
            velocity: Vector::ZERO,
            yaw,
            on_ground: false,
            ground: None,
            move_vector: [0.0; 2],
            intent_yaw: yaw,
            path: CountedVec::new(state_bytes),
            path_index: 0,
            jump: false,
        }
    }

    fn shape(&self) -> SharedShape {
        SharedShape::capsule_y(
            self.settings.capsule_half_height,
            self.settings.capsule_radius,
        )
    }

    /// The capsule as a plain shape (no allocation, for a tick's queries).
    fn capsule(&self) -> rapier3d::parry::shape::Capsule {
        rapier3d::parry::shape::Capsule::new_y(
            self.settings.capsule_half_height,
            self.settings.capsule_radius,
        )
    }

    /// Full size of the capsule's box, for the object's Size.
    fn size(&self) -> Vec3 {
        let r = self.settings.capsule_radius;
        [
            2.0 * r,
            2.0 * (self.settings.capsule_half_height + r),
            2.0 * r,
        ]
    }

    /// The wish direction (unit or zero) and its intensity in [0, 1], for a controller at
    /// `position`: toward the next waypoint, else the motion intent (+z forward along the
    /// LookVector, +x right) turned by the facing. A controller that turns toward where it
    /// moves (LookWhereMoving) takes the intent in the facing it had when the intent was
    /// given: turning must not turn the intent too, or any intent but straight ahead would
    /// walk it in circles.
    fn wish(&self, position: Vector) -> (Vector, f32) {
        if let Some(target) = self.path.get(self.path_index) {
            return (horizontal(*target - position).normalize_or_zero(), 1.0);
        }
        let [x, z] = self.move_vector;
        let local = Vector::new(x, 0.0, -z);
        let amount = local.length().min(1.0);
        let yaw = if self.settings.look_where_moving {
            self.intent_yaw
        } else {
            self.yaw
        };
        (yaw_rotation(yaw) * local.normalize_or_zero(), amount)
    }
}

/// How far from the capsule's side a wall still counts for `OnWall` (units): a few times
/// the gap the mover keeps from what it touches.
const WALL_SKIN: f32 = 5.0 * SKIN;

/// Moves the count of every controller's path to `counter` (controllers restored from a
/// snapshot count in their new plane).
pub(super) fn count_paths_in(controllers: &mut Controllers, counter: &Counter) {
    for c in controllers.values_mut() {
        c.path.count_in(counter);
    }
}

/// The controllers of a plane, by slot.
pub(super) type Controllers = BTreeMap<u32, Controller>;

//! Ops of the 2D GUI plane (`PhysicsService.NewGUI`): objects wrapping GUI primitives, the
//! `GUIController`, and rays. They travel as [`PlaneOp::Gui`](crate::PlaneOp::Gui); a 3D
//! plane refuses them, and a GUI plane refuses the 3D object ops other than `Wake` and
//! `Destroy`.
//!
//! Published state of a GUI body (the same [`BodyState`](crate::BodyState) record as 3D):
//! `position = [x, y, 0]` in pixels (+Y down), `rotation` the quaternion of the rotation
//! about +Z (`[0, 0, sin(θ/2), cos(θ/2)]`, θ clockwise on screen), `linear_velocity =
//! [vx, vy, 0]` px/s, `angular_velocity = [0, 0, ω]` in rad/s; flags as in 3D.
//!
//! Controller signals are events in the plane's event stream (one record each, in the
//! order they happened within a tick): see [`EVENT_GUI_GROUND_CHANGED`] and the others.

use serde::{Deserialize, Serialize};

use crate::error::CommandError;
use crate::geometry::Vec2;
use crate::ids::Handle;
use crate::object_op_of::ObjectOpOf;
use crate::settings::gui_object::{GuiObjectProp, GuiObjectSettings, GuiShape};
use crate::settings::gui_plane::GuiPlaneSettings;
use crate::validate::{finite, finite2, non_negative, positive};

pub use crate::records::{
    EVENT_GUI_GROUND_CHANGED, EVENT_GUI_MOVED, EVENT_GUI_PATH_FINISHED, EVENT_GUI_WAYPOINT_REACHED,
};

/// Most waypoints of one controller path.
pub const MAX_WAYPOINTS: usize = 4096;

/// An op on a GUI plane.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum GuiOp {
    /// Describes the GUI plane (every option, counts). Replies [`GuiReply::Plane`].
    Info,
    /// Adds a body for a primitive of `shape` whose box is `size`, centred at `position`.
    /// Replies `Reply::Object`.
    Add {
        /// The primitive's shape.
        shape: GuiShape,
        /// Its Size (px).
        size: Vec2,
        /// Its Position (px): the centre of its box.
        position: Vec2,
        /// Further properties (Rotation, ZIndex, Anchored, ...), applied in order.
        props: Vec<GuiObjectProp>,
    },
    /// An op on one object of the plane.
    Object {
        /// The object.
        handle: Handle,
        /// What to do.
        op: GuiObjectOp,
    },
    /// An op on the controller bound to the object `handle`.
    Controller {
        /// The controller's body.
        handle: Handle,
        /// What to do.
        op: GuiControllerOp,
    },
    /// The first collidable body on the ray from `from` along `dir` (any ZIndex). Replies
    /// [`GuiReply::Hit`].
    Raycast {
        /// Start (px).
        from: Vec2,
        /// Direction; only its direction counts (non-zero).
        dir: Vec2,
        /// Reach in px; `None` = unbounded.
        max_distance: Option<f32>,
    },
}

/// An op on one GUI object: the object op every plane kind shares
/// ([`ObjectOpOf`]) over the GUI object properties and 2D impulses. `Set`
/// replies `Reply::Applied`, `ApplyImpulse` (`Δv = impulse / Mass` now; wakes the body)
/// `Reply::Velocity`, `Info` [`GuiReply::Object`], `Wake` and `Destroy` (the body and its
/// controller) `Reply::Applied`.
pub type GuiObjectOp = ObjectOpOf<GuiObjectProp, Vec2>;

/// A tunable of a GUI controller.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum GuiControllerProp {
    /// Largest horizontal speed it drives toward (px/s). Default 240.
    MoveSpeed(f32),
    /// How fast velocity approaches the target (px/s²). Default 1800.
    Acceleration(f32),
    /// Upward velocity change of a jump (px/s, `Δv = JumpStrength / Mass`). Default 700.
    JumpStrength(f32),
    /// Distance (px) at which a waypoint counts as reached. Default 8.
    WaypointRadius(f32),
}

impl GuiControllerProp {
    /// The property's name in the API.
    pub fn name(&self) -> &'static str {
        match self {
            GuiControllerProp::MoveSpeed(_) => "MoveSpeed",
            GuiControllerProp::Acceleration(_) => "Acceleration",
            GuiControllerProp::JumpStrength(_) => "JumpStrength",
            GuiControllerProp::WaypointRadius(_) => "WaypointRadius",
        }
    }

    /// The property as the daemon applies it, or an error naming it and the value.
    pub fn checked(self) -> Result<GuiControllerProp, CommandError> {
        use GuiControllerProp::*;
        Ok(match self {
            MoveSpeed(v) => MoveSpeed(non_negative("MoveSpeed", v)?),
            Acceleration(v) => Acceleration(non_negative("Acceleration", v)?),
            JumpStrength(v) => JumpStrength(non_negative("JumpStrength", v)?),
            WaypointRadius(v) => WaypointRadius(positive("WaypointRadius", v)?),
        })
    }
}

/// The tunables of a GUI controller.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct GuiControllerSettings {
    /// `MoveSpeed`, default 240.
    pub move_speed: f32,
    /// `Acceleration`, default 1800.
    pub acceleration: f32,
    /// `JumpStrength`, default 700.
    pub jump_strength: f32,
    /// `WaypointRadius`, default 8.
    pub waypoint_radius: f32,
}

impl Default for GuiControllerSettings {
    fn default() -> Self {
        GuiControllerSettings {
            move_speed: 240.0,
            acceleration: 1800.0,
            jump_strength: 700.0,
            waypoint_radius: 8.0,
        }
    }
}

impl GuiControllerSettings {
    /// Checks and stores one property.
    pub fn apply(&mut self, prop: GuiControllerProp) -> Result<GuiControllerProp, CommandError> {
        let prop = prop.checked()?;
        match prop {
            GuiControllerProp::MoveSpeed(v) => self.move_speed = v,
            GuiControllerProp::Acceleration(v) => self.acceleration = v,
            GuiControllerProp::JumpStrength(v) => self.jump_strength = v,
            GuiControllerProp::WaypointRadius(v) => self.waypoint_radius = v,
        }
        Ok(prop)
    }
}

/// An op on a GUI controller (addressed by its body's handle).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum GuiControllerOp {
    /// Binds a controller to the object (locks its rotation). `uncontrolled` marks an NPC
    /// controller (`NewUncontrolled`): it also steers vertically toward waypoints when its
    /// body feels no gravity.
    Create {
        /// `NewUncontrolled` rather than `NewController`.
        uncontrolled: bool,
        /// Tunables applied after the defaults.
        props: Vec<GuiControllerProp>,
    },
    /// Changes a tunable.
    Set(GuiControllerProp),
    /// The desired direction; each component is clamped to [-1, 1] when it is used.
    Move(Vec2),
    /// Jumps at the next tick if on the ground (the request is cleared either way).
    Jump,
    /// Replaces the path (seeks each point in order).
    SetWaypoints(Vec<Vec2>),
    /// Drops the path; the body keeps its velocity.
    ClearWaypoints,
    /// Everything about the controller. Replies [`GuiReply::Controller`].
    Info,
    /// Removes the controller and its body.
    Destroy,
}

impl GuiControllerOp {
    /// The op with its values checked, or an error naming the field and the value.
    pub fn checked(self) -> Result<GuiControllerOp, CommandError> {
        Ok(match self {
            GuiControllerOp::Create {
                uncontrolled,
                props,
            } => GuiControllerOp::Create {
                uncontrolled,
                props: props
                    .into_iter()
                    .map(GuiControllerProp::checked)
                    .collect::<Result<_, _>>()?,
            },
            GuiControllerOp::Set(p) => GuiControllerOp::Set(p.checked()?),
            GuiControllerOp::Move(d) => GuiControllerOp::Move(finite2("MoveDirection", d)?),
            GuiControllerOp::SetWaypoints(points) => {
                if points.len() > MAX_WAYPOINTS {
                    return Err(CommandError::invalid_field(
                        "Waypoints",
                        format!(
                            "a path holds at most {MAX_WAYPOINTS} waypoints, got {}",
                            points.len()
                        ),
                    ));
                }
                for (i, p) in points.iter().enumerate() {
                    finite2(&format!("Waypoints[{}]", i + 1), *p)?;
                }
                GuiControllerOp::SetWaypoints(points)
            }
            other => other,
        })
    }
}

/// Checks a ray of [`GuiOp::Raycast`]; returns the unit direction.
pub fn check_ray(from: Vec2, dir: Vec2, max_distance: Option<f32>) -> Result<Vec2, CommandError> {
    finite2("from", from)?;
    let dir = finite2("dir", dir)?;
    let len = (dir[0] * dir[0] + dir[1] * dir[1]).sqrt();
    if len <= 1e-12 || !len.is_finite() {
        return Err(CommandError::invalid_field(
            "dir",
            format!("dir must be a non-zero Dim, got {dir:?}"),
        ));
    }
    if let Some(d) = max_distance {
        if finite("maxDistance", d)? < 0.0 {
            return Err(CommandError::invalid_field(
                "maxDistance",
                format!("maxDistance must be >= 0, got {d}"),
            ));
        }
    }
    Ok([dir[0] / len, dir[1] / len])
}

/// A ray hit on a GUI plane.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct GuiHit {
    /// The body hit.
    pub handle: Handle,
    /// Distance along the ray (px).
    pub distance: f32,
    /// Where the ray met the body (px).
    pub position: Vec2,
    /// Unit surface normal there.
    pub normal: Vec2,
}

/// What the daemon knows about a GUI plane.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GuiPlaneInfo {
    /// The plane's id.
    pub id: u32,
    /// Every option as set.
    pub settings: GuiPlaneSettings,
    /// Ticks stepped so far.
    pub tick: u64,
    /// Live objects (controllers' bodies included).
    pub object_count: u32,
    /// Live controllers.
    pub controller_count: u32,
}

impl std::ops::Deref for GuiPlaneInfo {
    type Target = GuiPlaneSettings;
    fn deref(&self) -> &GuiPlaneSettings {
        &self.settings
    }
}

/// Every property of a GUI object.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GuiObjectInfo {
    /// The object's handle.
    pub handle: Handle,
    /// Its shape.
    pub shape: GuiShape,
    /// The stored properties.
    pub settings: GuiObjectSettings,
    /// Position (px).
    pub position: Vec2,
    /// Velocity (px/s).
    pub velocity: Vec2,
    /// Rotation (degrees).
    pub rotation: f32,
    /// Angular velocity (degrees/s).
    pub angular_velocity: f32,
    /// Asleep now.
    pub sleeping: bool,
    /// A controller drives it.
    pub controlled: bool,
}

impl std::ops::Deref for GuiObjectInfo {
    type Target = GuiObjectSettings;
    fn deref(&self) -> &GuiObjectSettings {
        &self.settings
    }
}

/// Everything about a GUI controller.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GuiControllerInfo {
    /// Its body.
    pub handle: Handle,
    /// Tunables.
    pub settings: GuiControllerSettings,
    /// Created by `NewUncontrolled`.
    pub uncontrolled: bool,
    /// The last `Move` direction.
    pub move_direction: Vec2,
    /// The foot probe touches a collidable body on the same ZIndex.
    pub on_ground: bool,
    /// The current path.
    pub waypoints: Vec<Vec2>,
    /// 0-based index of the waypoint it seeks (= waypoints.len() when done).
    pub next_waypoint: u32,
}

impl std::ops::Deref for GuiControllerInfo {
    type Target = GuiControllerSettings;
    fn deref(&self) -> &GuiControllerSettings {
        &self.settings
    }
}

/// Replies of GUI ops that carry data.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum GuiReply {
    /// [`GuiOp::Info`].
    Plane(GuiPlaneInfo),
    /// [`GuiObjectOp::Info`].
    Object(Box<GuiObjectInfo>),
    /// [`GuiControllerOp::Info`].
    Controller(Box<GuiControllerInfo>),
    /// [`GuiOp::Raycast`].
    Hit(Option<GuiHit>),
}

impl GuiOp {
    /// Bytes of path the op may add (8 a waypoint), for the per-client quotas.
    pub fn path_bytes(&self) -> u64 {
        match self {
            GuiOp::Controller {
                op: GuiControllerOp::SetWaypoints(points),
                ..
            } => 8 * points.len() as u64,
            _ => 0,
        }
    }

    /// Whether the op only reads.
    pub fn is_read_only(&self) -> bool {
        matches!(
            self,
            GuiOp::Info
                | GuiOp::Raycast { .. }
                | GuiOp::Object {
                    op: GuiObjectOp::Info,
                    ..
                }
                | GuiOp::Controller {
                    op: GuiControllerOp::Info,
                    ..
                }
        )
    }
}

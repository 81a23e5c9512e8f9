//! Character controllers: what a client asks of the controllers of a plane. A controller is
//! an object of its plane (a kinematic capsule, published like any body, so its part's
//! CFrame reads zero-copy) that the plane moves every tick from its settings, its motion
//! intent and its path.

use serde::{Deserialize, Serialize};

use crate::error::CommandError;
use crate::geometry::{Pose, Vec3};
use crate::ids::Handle;
use crate::settings::{ControllerProp, ControllerSettings};
use crate::validate::{bounded3, pose, size, MAX_COORDINATE};

/// Most waypoints one path may hold.
pub const MAX_WAYPOINTS: usize = 65_536;

/// An op on the controllers of a plane.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum ControllerOp {
    /// Makes a controller for a part of full `size` at `pose`; replies with its object
    /// handle. `controlled`: NewControlledController (LookWhereMoving off by default).
    Create {
        /// The part's pose (only its yaw is kept: the capsule stays upright).
        pose: Pose,
        /// The part's full size (the capsule's defaults come from it).
        size: Vec3,
        /// NewControlledController.
        controlled: bool,
        /// Options applied after the defaults.
        props: Vec<ControllerProp>,
    },
    /// Sets one property.
    Set {
        /// The controller.
        handle: Handle,
        /// The property.
        prop: ControllerProp,
    },
    /// Describes the controller.
    Info {
        /// The controller.
        handle: Handle,
    },
    /// Replaces the path (WalkTo is a path of one point).
    SetPath {
        /// The controller.
        handle: Handle,
        /// Waypoints in order (at most [`MAX_WAYPOINTS`]).
        waypoints: Vec<Vec3>,
    },
    /// Adds a waypoint at the end of the path.
    AppendWaypoint {
        /// The controller.
        handle: Handle,
        /// The waypoint.
        point: Vec3,
    },
    /// Clears the path and the motion intent.
    StopWalking {
        /// The controller.
        handle: Handle,
    },
    /// Jumps if on the ground; the reply says whether it launched.
    Jump {
        /// The controller.
        handle: Handle,
    },
    /// Sets position and facing, clears velocity and path.
    Teleport {
        /// The controller.
        handle: Handle,
        /// Where to (only the yaw of the rotation is kept).
        pose: Pose,
    },
    /// Removes the controller and its body.
    Destroy {
        /// The controller.
        handle: Handle,
    },
}

/// What the daemon knows about a controller.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ControllerInfo {
    /// Its object handle.
    pub handle: Handle,
    /// Settings as set.
    pub settings: ControllerSettings,
    /// Its own velocity (units/s).
    pub velocity: Vec3,
    /// Facing, Euler radians (yaw in Y).
    pub rotation: Vec3,
    /// On the ground after the last tick.
    pub on_ground: bool,
    /// The motion intent (local x, z).
    pub move_vector: [f32; 2],
    /// Waypoints in the path.
    pub path_length: u32,
    /// Index (1-based) of the waypoint being walked to; 0 without a path.
    pub path_index: u32,
    /// Unit normal of the wall beside the capsule where the last tick's move left it (a
    /// surface steeper than MaxSlope, not a ceiling, touching or within a small skin of its
    /// side), probed when this info is asked for; zero when there is none (`OnWall` false).
    pub wall_normal: Vec3,
}

impl std::ops::Deref for ControllerInfo {
    type Target = ControllerSettings;
    fn deref(&self) -> &ControllerSettings {
        &self.settings
    }
}

impl ControllerOp {
    /// The op with its values checked, or an error naming the field and the value.
    pub fn checked(self) -> Result<ControllerOp, CommandError> {
        let point = |f: &str, p: Vec3| bounded3(f, p, MAX_COORDINATE);
        Ok(match self {
            ControllerOp::Create {
                pose: p,
                size: s,
                controlled,
                props,
            } => ControllerOp::Create {
                pose: pose("CFrame", p)?,
                size: size("Size", s)?,
                controlled,
                props: props
                    .into_iter()
                    .map(ControllerProp::checked)
                    .collect::<Result<_, _>>()?,
            },
            ControllerOp::Set { handle, prop } => ControllerOp::Set {
                handle,
                prop: prop.checked()?,
            },
            ControllerOp::SetPath { handle, waypoints } => {
                if waypoints.len() > MAX_WAYPOINTS {
                    return Err(CommandError::invalid_field(
                        "waypoints",
                        format!(
                            "waypoints must hold at most {MAX_WAYPOINTS} points, got {}",
                            waypoints.len()
                        ),
                    ));
                }
                for (i, w) in waypoints.iter().enumerate() {
                    point(&format!("waypoints[{}]", i + 1), *w)?;
                }
                ControllerOp::SetPath { handle, waypoints }
            }
            ControllerOp::AppendWaypoint { handle, point: p } => ControllerOp::AppendWaypoint {
                handle,
                point: point("waypoint", p)?,
            },
            ControllerOp::Teleport { handle, pose: p } => ControllerOp::Teleport {
                handle,
                pose: pose("target", p)?,
            },
            other => other,
        })
    }
}

//! Controller properties. Position, Rotation, Velocity and OnGround read the newest tick in
//! shared memory (no request); settings and path state read back from the daemon
//! (`controller.info()`, one round trip). Every write is one `ControllerProp`; the writable
//! rows are also the options of `plane:NewController(part, opts)`.

use client_sdk::{ControllerInfo, ControllerProp};
use mlua::{Error as LuaError, Value};

use super::LuaController;
use crate::props::{Get, Kind, Props, Row, Set};
use crate::values::{new_vector, sdk_error};

/// The controller's settings and state as the daemon holds them (one round trip).
fn info(c: &LuaController, what: &str) -> Result<ControllerInfo, LuaError> {
    c.live(what)?
        .info()
        .map_err(|e| sdk_error(&format!("Controller.{what}"), e))
}

/// A number setting read back from the daemon.
macro_rules! number_row {
    ($name:literal, $kind:expr, $field:ident, $prop:path) => {
        Row {
            name: $name,
            kind: $kind,
            get: Get::Fn(|_, c| Ok(crate::values::lua_number(info(c, $name)?.$field))),
            set: Set::Prop(|a| Ok($prop(a.number()? as f32))),
        }
    };
}

/// A boolean setting read back from the daemon.
macro_rules! bool_row {
    ($name:literal, $field:ident, $prop:path) => {
        Row {
            name: $name,
            kind: Kind::Boolean,
            get: Get::Fn(|_, c| Ok(Value::Boolean(info(c, $name)?.$field))),
            set: Set::Prop(|a| Ok($prop(a.bool()?))),
        }
    };
}

/// A signal of the controller (created on first access).
macro_rules! signal_row {
    ($name:literal) => {
        Row {
            name: $name,
            kind: Kind::String,
            get: Get::Fn(|lua, c| Ok(Value::UserData(c.0.signal($name).userdata(lua)?))),
            set: Set::ReadOnly,
        }
    };
}

const SPEED: Kind = Kind::Number {
    min: 0.0,
    max: 10_000.0,
};

/// The rows of `Controller`.
pub static CONTROLLER: Props<LuaController> = Props {
    owner: "Controller",
    rows: &[
        Row {
            name: "Position",
            kind: Kind::Vector,
            get: Get::Fn(|_, c| Ok(new_vector(c.state("Position")?.position))),
            set: Set::Prop(|a| Ok(ControllerProp::Position(a.vector()?))),
        },
        Row {
            name: "Velocity",
            kind: Kind::Vector,
            get: Get::Fn(|_, c| Ok(new_vector(c.state("Velocity")?.linear_velocity))),
            set: Set::Prop(|a| Ok(ControllerProp::Velocity(a.vector()?))),
        },
        Row {
            name: "Rotation",
            kind: Kind::Vector,
            get: Get::Fn(|_, c| Ok(new_vector([0.0, c.yaw("Rotation")?, 0.0]))),
            set: Set::Prop(|a| Ok(ControllerProp::Rotation(a.vector()?))),
        },
        number_row!("WalkSpeed", SPEED, walk_speed, ControllerProp::WalkSpeed),
        number_row!("JumpPower", SPEED, jump_power, ControllerProp::JumpPower),
        number_row!(
            "TurnSpeed",
            Kind::Number {
                min: 0.0,
                max: 10_000.0
            },
            turn_speed,
            ControllerProp::TurnSpeed
        ),
        number_row!(
            "Gravity",
            Kind::Number {
                min: -100_000.0,
                max: 100_000.0
            },
            gravity,
            ControllerProp::Gravity
        ),
        bool_row!(
            "UsePlaneGravity",
            use_plane_gravity,
            ControllerProp::UsePlaneGravity
        ),
        number_row!(
            "MaxSlope",
            Kind::Number {
                min: 0.0,
                max: 89.0
            },
            max_slope,
            ControllerProp::MaxSlope
        ),
        Row {
            name: "GroundY",
            kind: Kind::OptionalNumber,
            get: Get::Fn(|_, c| {
                Ok(info(c, "GroundY")?
                    .ground_y
                    .map_or(Value::Nil, crate::values::lua_number))
            }),
            // nil clears it (no floor).
            set: Set::Prop(|a| {
                Ok(ControllerProp::GroundY(
                    a.optional_number()?.map(|y| y as f32),
                ))
            }),
        },
        number_row!(
            "CapsuleRadius",
            Kind::Number {
                min: 0.001,
                max: 100_000.0
            },
            capsule_radius,
            ControllerProp::CapsuleRadius
        ),
        number_row!(
            "CapsuleHalfHeight",
            Kind::Number {
                min: 0.0,
                max: 100_000.0
            },
            capsule_half_height,
            ControllerProp::CapsuleHalfHeight
        ),
        number_row!(
            "WaypointThreshold",
            Kind::Number {
                min: 0.001,
                max: 100_000.0
            },
            waypoint_threshold,
            ControllerProp::WaypointThreshold
        ),
        bool_row!(
            "LookWhereMoving",
            look_where_moving,
            ControllerProp::LookWhereMoving
        ),
        number_row!(
            "StepHeight",
            Kind::Number {
                min: 0.0,
                max: 100_000.0
            },
            step_height,
            ControllerProp::StepHeight
        ),
        number_row!(
            "Acceleration",
            Kind::Number {
                min: 0.0,
                max: 10_000.0
            },
            acceleration,
            ControllerProp::Acceleration
        ),
        number_row!(
            "Friction",
            Kind::Number {
                min: 0.0,
                max: 10_000.0
            },
            friction,
            ControllerProp::Friction
        ),
        number_row!(
            "AirControl",
            Kind::UNIT,
            air_control,
            ControllerProp::AirControl
        ),
        number_row!(
            "PushStrength",
            Kind::NON_NEGATIVE,
            push_strength,
            ControllerProp::PushStrength
        ),
        Row {
            name: "OnGround",
            kind: Kind::Boolean,
            get: Get::Fn(|_, c| {
                Ok(Value::Boolean(
                    c.state("OnGround")?.flags & client_sdk::FLAG_ON_GROUND != 0,
                ))
            }),
            set: Set::ReadOnly,
        },
        Row {
            name: "Controlled",
            kind: Kind::Boolean,
            get: Get::Fn(|_, c| Ok(Value::Boolean(info(c, "Controlled")?.controlled))),
            set: Set::ReadOnly,
        },
        Row {
            name: "PathLength",
            kind: Kind::ANY_INTEGER,
            get: Get::Fn(|_, c| {
                Ok(crate::values::lua_number(
                    info(c, "PathLength")?.path_length,
                ))
            }),
            set: Set::ReadOnly,
        },
        Row {
            name: "PathIndex",
            kind: Kind::ANY_INTEGER,
            get: Get::Fn(|_, c| Ok(crate::values::lua_number(info(c, "PathIndex")?.path_index))),
            set: Set::ReadOnly,
        },
        Row {
            name: "Alive",
            kind: Kind::Boolean,
            get: Get::Fn(|_, c| Ok(Value::Boolean(c.live("Alive").is_ok()))),
            set: Set::ReadOnly,
        },
        signal_row!("Jumped"),
        signal_row!("Landed"),
        signal_row!("Moved"),
        signal_row!("WaypointReached"),
        signal_row!("PathFinished"),
        Row {
            name: "WallNormal",
            kind: Kind::Vector,
            get: Get::Fn(|_, c| Ok(new_vector(info(c, "WallNormal")?.wall_normal))),
            set: Set::ReadOnly,
        },
        Row {
            name: "OnWall",
            kind: Kind::Boolean,
            get: Get::Fn(|_, c| Ok(Value::Boolean(info(c, "OnWall")?.wall_normal != [0.0; 3]))),
            set: Set::ReadOnly,
        },
    ],
};

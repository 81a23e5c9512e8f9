//! Controller properties. Position, Rotation, Velocity and OnGround read the newest tick in
//! shared memory (no request); settings and path state read back from the daemon
//! (`controller.info()`, one round trip). The plain settings (WalkSpeed, JumpPower, ...) are
//! not listed here: they are the controller settings table's rows flagged `lua`
//! (the `table` of [`CONTROLLER`]), their ranges taken from the table. Every write is one
//! `ControllerProp`; the writable rows are also the options of `plane:NewController(part,
//! opts)`.

use client_sdk::{ControllerInfo, ControllerProp};
use mlua::{Error as LuaError, Value};

use super::state::LuaController;
use crate::props::{Get, Kind, Props, Row, Set, Table, Target};
use crate::values::{new_vector, sdk_error};

/// The controller's settings and state as the daemon holds them (one round trip).
fn info(c: &LuaController, what: &str) -> Result<ControllerInfo, LuaError> {
    c.live(what)?
        .info()
        .map_err(|e| sdk_error(&format!("Controller.{what}"), e))
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

/// The rows of `Controller`.
pub static CONTROLLER: Props<LuaController> = Props {
    owner: "Controller",
    table: Some(Table::new(
        ControllerProp::ROWS,
        |c, name, index| Ok(info(c, name)?.settings.get(index)),
        ControllerProp::from_any,
    )),
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

impl Target for LuaController {
    type Prop = ControllerProp;

    fn write(&self, name: &str, prop: ControllerProp) -> mlua::Result<()> {
        self.live(name)?
            .set(prop)
            .map_err(|e| sdk_error(&format!("Controller.{name}"), e))
    }
}

//! PhysicsGuiObject properties: rows on the shared row system (`crate::props`), like
//! `PhysicsObject`'s. Position, Rotation, their velocities, Anchored and Sleeping read the
//! SDK's read-your-writes view of the newest tick (no request); ImpulseDirection reads the
//! daemon's info; ZIndex, Size and Shape mirror the primitive (set them there). The plain
//! stored settings (Mass, Friction, ...) are not listed here: they are the GUI object
//! settings table's rows flagged `lua` (the `table` of [`GUI_OBJECT`]). Every write is one
//! `GuiObjectProp`.

use client_sdk::{GuiObjectInfo, GuiObjectProp};
use mlua::{Error as LuaError, Lua, Value};

use crate::api::gui_plane::state::PhysicsGuiObject;
use crate::props::{Get, Kind, Props, Row, Set, Table, Target};
use crate::values::{lua_number, new_dim, sdk_error};

impl Target for PhysicsGuiObject {
    type Prop = GuiObjectProp;

    fn write(&self, name: &str, prop: GuiObjectProp) -> mlua::Result<()> {
        let what = format!("PhysicsGuiObject.{name}");
        self.check_alive(&what)?;
        self.object.set(prop).map_err(|e| sdk_error(&what, e))
    }
}

/// `what` for messages, after checking the object is alive.
fn live(o: &PhysicsGuiObject, name: &str) -> Result<String, LuaError> {
    let what = format!("PhysicsGuiObject.{name}");
    o.check_alive(&what)?;
    Ok(what)
}

fn info(o: &PhysicsGuiObject, name: &str) -> Result<GuiObjectInfo, LuaError> {
    let what = live(o, name)?;
    o.object.info().map_err(|e| sdk_error(&what, e))
}

fn dim_value(lua: &Lua, d: [f32; 2]) -> Result<Value, LuaError> {
    Ok(Value::UserData(lua.create_userdata(new_dim(d))?))
}

/// A property read from the newest tick through an SDK getter.
macro_rules! from_tick {
    ($name:literal, $getter:ident, $out:expr) => {
        Get::Fn(|lua, o| {
            let what = live(o, $name)?;
            let v = o.object.$getter().map_err(|e| sdk_error(&what, e))?;
            $out(lua, v)
        })
    };
}

/// A setting read from the daemon's info.
macro_rules! from_info {
    ($name:literal, $field:ident, $out:expr) => {
        Get::Fn(|lua, o| $out(lua, info(o, $name)?.$field))
    };
}

fn number(_: &Lua, x: f32) -> Result<Value, LuaError> {
    Ok(lua_number(x))
}

fn boolean(_: &Lua, x: bool) -> Result<Value, LuaError> {
    Ok(Value::Boolean(x))
}

/// The rows of `PhysicsGuiObject`.
pub static GUI_OBJECT: Props<PhysicsGuiObject> = Props {
    owner: "PhysicsGuiObject",
    table: Some(Table::new(
        GuiObjectProp::ROWS,
        |o, name, index| Ok(info(o, name)?.settings.get(index)),
        GuiObjectProp::from_any,
    )),
    rows: &[
        Row {
            name: "Position",
            kind: Kind::Dim,
            get: from_tick!("Position", position, dim_value),
            set: Set::Prop(|a| Ok(GuiObjectProp::Position(a.dim()?))),
        },
        Row {
            name: "Velocity",
            kind: Kind::Dim,
            get: from_tick!("Velocity", velocity, dim_value),
            set: Set::Prop(|a| Ok(GuiObjectProp::Velocity(a.dim()?))),
        },
        Row {
            name: "Rotation",
            kind: Kind::ANY_NUMBER,
            get: from_tick!("Rotation", rotation, number),
            set: Set::Prop(|a| Ok(GuiObjectProp::Rotation(a.number()? as f32))),
        },
        Row {
            name: "AngularVelocity",
            kind: Kind::ANY_NUMBER,
            get: from_tick!("AngularVelocity", angular_velocity, number),
            set: Set::Prop(|a| Ok(GuiObjectProp::AngularVelocity(a.number()? as f32))),
        },
        Row {
            name: "ImpulseDirection",
            kind: Kind::Dim,
            get: from_info!("ImpulseDirection", impulse_direction, dim_value),
            set: Set::Prop(|a| Ok(GuiObjectProp::ImpulseDirection(a.dim()?))),
        },
        Row {
            name: "Anchored",
            kind: Kind::Boolean,
            get: from_tick!("Anchored", is_anchored, boolean),
            set: Set::Prop(|a| Ok(GuiObjectProp::Anchored(a.bool()?))),
        },
        Row {
            name: "Sleeping",
            kind: Kind::Boolean,
            get: from_tick!("Sleeping", is_sleeping, boolean),
            set: Set::ReadOnly,
        },
        // Mirrors of the primitive's (set them on the primitive).
        Row {
            name: "ZIndex",
            kind: Kind::ANY_INTEGER,
            get: Get::Fn(|_, o| {
                live(o, "ZIndex")?;
                Ok(Value::Integer(o.prim.z_index() as i64))
            }),
            set: Set::ReadOnly,
        },
        Row {
            name: "Size",
            kind: Kind::Dim,
            get: Get::Fn(|lua, o| {
                live(o, "Size")?;
                dim_value(lua, o.prim.size())
            }),
            set: Set::ReadOnly,
        },
        Row {
            name: "Shape",
            kind: Kind::String,
            get: Get::Fn(|lua, o| {
                live(o, "Shape")?;
                Ok(Value::String(lua.create_string(o.prim.shape.name())?))
            }),
            set: Set::ReadOnly,
        },
        Row {
            name: "Alive",
            kind: Kind::Boolean,
            get: Get::Fn(|_, o| Ok(Value::Boolean(o.alive()))),
            set: Set::ReadOnly,
        },
    ],
};

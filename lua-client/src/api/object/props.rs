//! PhysicsObject properties. Pose, velocities and Anchored read the SDK's read-your-writes
//! view of the newest tick in shared memory (no request); the other properties read the
//! SDK's property mirror (`object.properties()`: a local lookup after the object's first
//! read, one round trip then); Size reads through to the wrapped part.
//! Every SDK write is one `ObjectProp`. The stored properties with a plain value (Weight,
//! Friction, ...) are not listed here: they are the object settings table's rows flagged
//! `lua` (the `table` of [`OBJECT`]: read from the same mirror, written as one `ObjectProp`).

use client_sdk::{BodyState, ObjectInfo, ObjectProp};
use mlua::{Error as LuaError, Value};

use super::state::PhysicsObject;
use crate::props::{Get, Kind, Props, Row, Set, Table, Target};
use crate::values::{new_vector, sdk_error, CFrame};

/// The object's properties (the SDK's mirror; one round trip the first time).
fn info(o: &PhysicsObject, what: &str) -> Result<ObjectInfo, LuaError> {
    o.live_for(|| format!("PhysicsObject.{what}"))?
        .properties()
        .map_err(|e| sdk_error(&format!("PhysicsObject.{what}"), e))
}

/// The object's published state: the newest tick with this process's unconfirmed writes on
/// top (no request).
fn state(o: &PhysicsObject, what: &str) -> Result<BodyState, LuaError> {
    o.live_for(|| format!("PhysicsObject.{what}"))?
        .state()
        .map_err(|e| sdk_error(&format!("PhysicsObject.{what}"), e))
}

/// A property of the published state (read-your-writes, no request): `$read` maps the
/// object's `BodyState` to a Lua value, `$write` the converted argument to the property.
macro_rules! state_row {
    ($name:literal, $kind:expr, |$lua:tt, $s:ident| $read:expr, |$a:ident| $write:expr) => {
        Row {
            name: $name,
            kind: $kind,
            get: Get::Fn(|$lua, o| {
                let $s = state(o, $name)?;
                Ok($read)
            }),
            set: Set::Prop(|$a| Ok($write)),
        }
    };
}

/// The rows of `PhysicsObject`.
pub static OBJECT: Props<PhysicsObject> = Props {
    owner: "PhysicsObject",
    table: Some(Table::new(
        ObjectProp::ROWS,
        |o, name, index| Ok(info(o, name)?.settings.get(index)),
        ObjectProp::from_any,
    )),
    rows: &[
        // The part's CFrame value is reused while the pose is the same (as `part.CFrame`).
        Row {
            name: "CFrame",
            kind: Kind::named(ObjectProp::ROWS, "CFrame"),
            get: Get::Fn(|lua, o| {
                let s = state(o, "CFrame")?;
                let cf = CFrame::from_pose(s.pose());
                o.part.cframe_value(lua, cf)
            }),
            set: Set::Prop(|a| Ok(ObjectProp::Pose(a.cframe()?.pose()))),
        },
        state_row!(
            "Velocity",
            Kind::named(ObjectProp::ROWS, "Velocity"),
            |_, s| new_vector(s.linear_velocity),
            |a| ObjectProp::Velocity(a.vector()?)
        ),
        state_row!(
            "AngularVelocity",
            Kind::named(ObjectProp::ROWS, "AngularVelocity"),
            |_, s| new_vector(s.angular_velocity),
            |a| ObjectProp::AngularVelocity(a.vector()?)
        ),
        state_row!(
            "Anchored",
            Kind::named(ObjectProp::ROWS, "Anchored"),
            |_, s| Value::Boolean(s.is_anchored()),
            |a| ObjectProp::Anchored(a.bool()?)
        ),
        Row {
            // The published sleeping flag (no request): true once the engine put the body
            // to rest; `Wake()` or any write wakes it.
            name: "Sleeping",
            kind: Kind::Boolean,
            get: Get::Fn(|_, o| Ok(Value::Boolean(state(o, "Sleeping")?.is_sleeping()))),
            set: Set::ReadOnly,
        },
        Row {
            name: "Alive",
            kind: Kind::Boolean,
            get: Get::Fn(|_, o| Ok(Value::Boolean(o.alive()))),
            set: Set::ReadOnly,
        },
        Row {
            // Reads through to the wrapped part; writing resizes the part and its body.
            name: "Size",
            kind: Kind::named(ObjectProp::ROWS, "Size"),
            get: Get::Fn(|_, o| Ok(new_vector(o.part.size()))),
            set: Set::Fn(|lua, o, a| {
                o.live("PhysicsObject.Size")?;
                o.part.resize(lua, "PhysicsObject.Size", a.vector()?)
            }),
        },
        // A registered collision group's name (PhysicsService:RegisterCollisionGroup).
        Row {
            name: "CollisionGroup",
            kind: Kind::String,
            get: Get::Fn(|lua, o| {
                let id = info(o, "CollisionGroup")?.collision_group;
                let name = o.body.object.plane().client().collision_group_name(id);
                Ok(Value::String(lua.create_string(name)?))
            }),
            set: Set::Fn(|lua, o, a| {
                o.live("PhysicsObject.CollisionGroup")?;
                let ctx = crate::api::plane::context::context(lua);
                ctx.set_collision_group(&o.part, "PhysicsObject.CollisionGroup", a.string()?)
            }),
        },
        // The density in effect (the explicit value, or Weight ÷ volume), not the stored
        // setting the table's generic row would read.
        Row {
            name: "Density",
            kind: Kind::named(ObjectProp::ROWS, "Density"),
            get: Get::Fn(|_, o| Ok(crate::values::lua_number(info(o, "Density")?.density))),
            set: Set::Prop(|a| Ok(ObjectProp::Density(a.number()? as f32))),
        },
    ],
};

impl Target for PhysicsObject {
    type Prop = ObjectProp;

    fn write(&self, name: &str, prop: ObjectProp) -> mlua::Result<()> {
        let what = || format!("PhysicsObject.{name}");
        self.live_for(what)?
            .set(prop)
            .map_err(|e| sdk_error(&what(), e))
    }
}

//! PhysicsObject properties. Pose, velocities and Anchored read the SDK's read-your-writes
//! view of the newest tick in shared memory (no request); the other properties read the
//! SDK's property mirror (`object.properties()`: a local lookup after the object's first
//! read, one round trip then); Size reads through to the wrapped part.
//! Every SDK write is one `ObjectProp`.

use client_sdk::validate::MAX_HIT_BOX_QUALITY;
use client_sdk::{BodyState, ObjectInfo, ObjectProp, Pose};
use mlua::{Error as LuaError, Value};

use super::{Get, Kind, Props, Row, Set};
use crate::api::object::PhysicsObject;
use crate::api::part::PartState;
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

/// A property read back from the daemon: `$read` maps the info to a Lua value, `$write` the
/// converted argument to the property.
macro_rules! info_row {
    ($name:literal, $kind:expr, |$i:ident| $read:expr, |$a:ident| $write:expr) => {
        Row {
            name: $name,
            kind: $kind,
            get: Get::Fn(|_, o| {
                let $i = info(o, $name)?;
                Ok($read)
            }),
            set: Set::Prop(|$a| Ok($write)),
        }
    };
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
    rows: &[
        // The part's CFrame value is reused while the pose is the same (as `part.CFrame`).
        Row {
            name: "CFrame",
            kind: Kind::CFrame,
            get: Get::Fn(|lua, o| {
                let s = state(o, "CFrame")?;
                let cf = CFrame::from_pose(Pose {
                    position: s.position,
                    rotation: s.rotation,
                });
                o.part.cframe_value(lua, cf)
            }),
            set: Set::Prop(|a| Ok(ObjectProp::Pose(a.cframe()?.pose()))),
        },
        state_row!(
            "Velocity",
            Kind::Vector,
            |_, s| new_vector(s.linear_velocity),
            |a| ObjectProp::Velocity(a.vector()?)
        ),
        state_row!(
            "AngularVelocity",
            Kind::Vector,
            |_, s| new_vector(s.angular_velocity),
            |a| ObjectProp::AngularVelocity(a.vector()?)
        ),
        state_row!(
            "Anchored",
            Kind::Boolean,
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
            kind: Kind::PositiveVector,
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
                let ctx = crate::api::plane::context(lua);
                PartState::set_collision_group(
                    &o.part,
                    &ctx,
                    "PhysicsObject.CollisionGroup",
                    a.string()?,
                )
            }),
        },
        info_row!(
            "ImpulseDirection",
            Kind::Vector,
            |i| new_vector(i.impulse_direction),
            |a| ObjectProp::ImpulseDirection(a.vector()?)
        ),
        info_row!(
            "ConstantForce",
            Kind::Vector,
            |i| new_vector(i.constant_force),
            |a| ObjectProp::ConstantForce(a.vector()?)
        ),
        info_row!(
            "Weight",
            Kind::Number {
                // validate::MIN_MASS, written as the decimal Lua users see in errors.
                min: 1e-4,
                max: f64::INFINITY,
            },
            |i| crate::values::lua_number(i.weight),
            |a| ObjectProp::Weight(a.number()? as f32)
        ),
        info_row!(
            "Density",
            Kind::NON_NEGATIVE,
            |i| crate::values::lua_number(i.density),
            |a| ObjectProp::Density(a.number()? as f32)
        ),
        // Documented as clamped to [0, 1]: any finite number is accepted.
        info_row!(
            "Bounciness",
            Kind::ANY_NUMBER,
            |i| crate::values::lua_number(i.bounciness),
            |a| ObjectProp::Bounciness(a.number()? as f32)
        ),
        info_row!(
            "Friction",
            Kind::UNIT,
            |i| crate::values::lua_number(i.friction),
            |a| ObjectProp::Friction(a.number()? as f32)
        ),
        info_row!(
            "CanCollide",
            Kind::Boolean,
            |i| Value::Boolean(i.can_collide),
            |a| ObjectProp::CanCollide(a.bool()?)
        ),
        // Documented as clamped to [1, 32]: any integer is accepted.
        info_row!(
            "HitBoxQuality",
            Kind::ANY_INTEGER,
            |i| crate::values::lua_number(i.hit_box_quality),
            |a| ObjectProp::HitBoxQuality(a.integer()?.clamp(1, MAX_HIT_BOX_QUALITY as i64) as u32)
        ),
        info_row!(
            "CenterOfMass",
            Kind::Vector,
            |i| new_vector(i.center_of_mass),
            |a| ObjectProp::CenterOfMass(a.vector()?)
        ),
    ],
};

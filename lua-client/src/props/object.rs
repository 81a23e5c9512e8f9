//! PhysicsObject properties. Pose and velocities read zero-copy from shared memory; the
//! other properties are read back from the daemon (`object.info()`, one round trip).

use client_sdk::validate::MAX_HIT_BOX_QUALITY;
use client_sdk::{ObjectInfo, ObjectProp};
use mlua::{Error as LuaError, Value};

use super::{Get, Kind, Props, Row, Set};
use crate::api::object::PhysicsObject;
use crate::values::{new_vector, sdk_error};

fn info(o: &PhysicsObject, what: &str) -> Result<ObjectInfo, LuaError> {
    o.live(what)?
        .info()
        .map_err(|e| sdk_error(&format!("PhysicsObject.{what}"), e))
}

fn set(o: &PhysicsObject, what: &str, prop: ObjectProp) -> Result<(), LuaError> {
    o.live(what)?
        .set(prop)
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
            set: Set::Fn(|_, o, $a| set(o, $name, $write)),
        }
    };
}

pub static OBJECT: Props<PhysicsObject> = Props {
    owner: "PhysicsObject",
    rows: &[
        Row {
            name: "CFrame",
            kind: Kind::CFrame,
            get: Get::Fn(|lua, o| {
                let pose = o
                    .live("CFrame")?
                    .pose()
                    .map_err(|e| sdk_error("PhysicsObject.CFrame", e))?;
                Ok(Value::UserData(
                    lua.create_userdata(crate::values::CFrame::from_pose(pose))?,
                ))
            }),
            set: Set::Fn(|_, o, a| {
                o.live("CFrame")?
                    .set_pose(a.cframe()?.pose())
                    .map_err(|e| sdk_error("PhysicsObject.CFrame", e))
            }),
        },
        Row {
            name: "Velocity",
            kind: Kind::Vector,
            get: Get::Fn(|_, o| {
                let v = o.live("Velocity")?.velocity();
                Ok(new_vector(
                    v.map_err(|e| sdk_error("PhysicsObject.Velocity", e))?,
                ))
            }),
            set: Set::Fn(|_, o, a| {
                o.live("Velocity")?
                    .set_velocity(a.vector()?)
                    .map_err(|e| sdk_error("PhysicsObject.Velocity", e))
            }),
        },
        Row {
            name: "AngularVelocity",
            kind: Kind::Vector,
            get: Get::Fn(|_, o| {
                let w = o.live("AngularVelocity")?.angular_velocity();
                Ok(new_vector(w.map_err(|e| {
                    sdk_error("PhysicsObject.AngularVelocity", e)
                })?))
            }),
            set: Set::Fn(|_, o, a| {
                o.live("AngularVelocity")?
                    .set_angular_velocity(a.vector()?)
                    .map_err(|e| sdk_error("PhysicsObject.AngularVelocity", e))
            }),
        },
        Row {
            name: "Anchored",
            kind: Kind::Boolean,
            get: Get::Fn(|_, o| {
                let a = o.live("Anchored")?.is_anchored();
                Ok(Value::Boolean(
                    a.map_err(|e| sdk_error("PhysicsObject.Anchored", e))?,
                ))
            }),
            set: Set::Fn(|_, o, a| {
                o.live("Anchored")?.set_anchored(a.bool()?);
                Ok(())
            }),
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
                let size = a.vector()?;
                set(o, "Size", ObjectProp::Size(size))?;
                o.part.set_size(size);
                o.part.changed(lua, "Size", new_vector(size))
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
            |i| Value::Number(i.weight as f64),
            |a| ObjectProp::Weight(a.number()? as f32)
        ),
        info_row!(
            "Density",
            Kind::NON_NEGATIVE,
            |i| Value::Number(i.density as f64),
            |a| ObjectProp::Density(a.number()? as f32)
        ),
        // Documented as clamped to [0, 1]: any finite number is accepted.
        info_row!(
            "Bounciness",
            Kind::ANY_NUMBER,
            |i| Value::Number(i.bounciness as f64),
            |a| ObjectProp::Bounciness(a.number()? as f32)
        ),
        info_row!(
            "Friction",
            Kind::UNIT,
            |i| Value::Number(i.friction as f64),
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
            Kind::Integer {
                min: i64::MIN,
                max: i64::MAX,
            },
            |i| Value::Number(i.hit_box_quality as f64),
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

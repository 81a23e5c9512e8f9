//! PhysicsObject properties. Rows marked `not_yet` are documented but not in the SDK yet.

use mlua::Value;

use super::{Get, Kind, Props, Row, Set};
use crate::convert::{new_vector, sdk_error};
use crate::object::PhysicsObject;

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
                Ok(Value::UserData(lua.create_userdata(
                    crate::primitives::CFrame::from_pose(pose),
                )?))
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
            // Reads through to the wrapped part; resizing a body needs the SDK first.
            name: "Size",
            kind: Kind::PositiveVector,
            get: Get::Fn(|_, o| Ok(new_vector(o.part.size()))),
            set: Set::NotYet,
        },
        Row::not_yet("ImpulseDirection", Kind::Vector),
        Row::not_yet("ConstantForce", Kind::Vector),
        Row::not_yet(
            "Weight",
            Kind::Number {
                min: 1e-4,
                max: f64::INFINITY,
            },
        ),
        Row::not_yet("Density", Kind::NON_NEGATIVE),
        Row::not_yet("Bounciness", Kind::UNIT),
        Row::not_yet("Friction", Kind::UNIT),
        Row::not_yet("CanCollide", Kind::Boolean),
        Row::not_yet("HitBoxQuality", Kind::Integer { min: 1, max: 32 }),
        Row::not_yet("CenterOfMass", Kind::Vector),
    ],
};

/// Documented methods the SDK cannot do yet.
pub const NOT_YET_METHODS: &[&str] = &[
    "FieldRestraint",
    "RotateTo",
    "StopRotateTo",
    "SetPin",
    "RecalculateCenterOfMass",
];

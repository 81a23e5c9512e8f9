//! `joint:SetAxisMotor(axis, opts?)` and `joint:SetAxisSpring(axis, stiffness, damping,
//! restPosition?)` on SixDof joints: a motor or spring per axis ("X", "Y", "Z", "RotX",
//! "RotY", "RotZ", the names of `Joint.Axes`). `opts` is `{TargetVelocity, TargetPosition,
//! Stiffness, Damping, MaxForce}`, every key optional; nil removes the axis's motor.

use client_sdk::axis_motor::axis_index;
use client_sdk::AxisMotor;
use mlua::{UserDataMethods, Value};

use super::joint::state::LuaJoint;
use crate::values::{describe, expected, finite_number, sdk_error};

/// The option names of SetAxisMotor.
const OPTIONS: [&str; 5] = [
    "TargetVelocity",
    "TargetPosition",
    "Stiffness",
    "Damping",
    "MaxForce",
];

fn axis(what: &str, v: &Value) -> mlua::Result<u8> {
    match v {
        Value::String(s) => axis_index(&s.to_string_lossy()),
        _ => None,
    }
    .ok_or_else(|| {
        expected(
            &format!("{what} axis"),
            "\"X\", \"Y\", \"Z\", \"RotX\", \"RotY\" or \"RotZ\"",
            v,
        )
    })
}

fn number(what: &str, key: &str, v: &Value) -> mlua::Result<f32> {
    finite_number(&format!("{what} {key}"), v).map(|n| n as f32)
}

fn motor(what: &str, opts: &Value) -> mlua::Result<Option<AxisMotor>> {
    let t = match opts {
        Value::Nil => return Ok(None),
        Value::Table(t) => t,
        v => return Err(expected(what, "an options table or nil", v)),
    };
    let mut m = AxisMotor::default();
    for pair in t.pairs::<Value, Value>() {
        let (k, v) = pair?;
        let key = match &k {
            Value::String(s) => s.to_string_lossy(),
            other => return Err(expected(&format!("{what} option key"), "a string", other)),
        };
        match key.as_str() {
            "TargetVelocity" => m.target_velocity = number(what, &key, &v)?,
            "TargetPosition" => m.target_position = Some(number(what, &key, &v)?),
            "Stiffness" => m.stiffness = number(what, &key, &v)?,
            "Damping" => m.damping = number(what, &key, &v)?,
            "MaxForce" => m.max_force = number(what, &key, &v)?,
            _ => {
                return Err(mlua::Error::runtime(format!(
                    "{what}: unknown option {} (expected one of {})",
                    describe(&k),
                    OPTIONS.join(", ")
                )))
            }
        }
    }
    Ok(Some(m))
}

/// Registers SetAxisMotor and SetAxisSpring on Joint.
pub fn add_methods<M: UserDataMethods<LuaJoint>>(methods: &mut M) {
    methods.add_method("SetAxisMotor", |_, j, (a, opts): (Value, Value)| {
        let what = "Joint:SetAxisMotor";
        let joint = j.live(what)?;
        let axis = axis(what, &a)?;
        let m = motor(what, &opts)?;
        joint
            .set_axis_motor(axis, m)
            .map_err(|e| sdk_error(what, e))
    });
    methods.add_method(
        "SetAxisSpring",
        |_, j, (a, k, c, rest): (Value, Value, Value, Value)| {
            let what = "Joint:SetAxisSpring";
            let joint = j.live(what)?;
            let axis = axis(what, &a)?;
            let k = number(what, "stiffness", &k)?;
            let c = number(what, "damping", &c)?;
            let rest = match rest {
                Value::Nil => 0.0,
                v => number(what, "restPosition", &v)?,
            };
            joint
                .set_axis_spring(axis, k, c, rest)
                .map_err(|e| sdk_error(what, e))
        },
    );
}

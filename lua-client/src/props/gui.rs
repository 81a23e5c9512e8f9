//! The property rows of the GUI types: `GuiPhysicsPlane` options (also the options of
//! `PhysicsService.NewGUI`) and `PhysicsGuiObject` properties. One row per property: its
//! name, what it takes, where it reads from (the daemon's info, or the newest tick for pose
//! and velocities) and the SDK write it becomes.

use client_sdk::validate::MAX_TICK_RATE;
use client_sdk::{GuiObjectProp, GuiPlaneProp, PlaneProp};
use mlua::{Lua, Value};

use crate::api::gui_basic::{dim_arg, new_dim};
use crate::api::gui_object::PhysicsGuiObject;
use crate::api::gui_plane::GuiPlaneState;
use crate::values::{describe, expected, number, sdk_error};

/// What a GUI row takes.
#[derive(Clone, Copy)]
enum Takes {
    Dim,
    Number(f64, f64),
    Integer(i64, i64),
    Bool,
}

fn convert(what: &str, takes: Takes, v: &Value) -> mlua::Result<Value> {
    let ok = match takes {
        Takes::Dim => {
            dim_arg(what, v)?;
            true
        }
        Takes::Number(lo, hi) => number(v).is_some_and(|n| n.is_finite() && n >= lo && n <= hi),
        Takes::Integer(lo, hi) => {
            number(v).is_some_and(|n| n.fract() == 0.0 && n >= lo as f64 && n <= hi as f64)
        }
        Takes::Bool => matches!(v, Value::Boolean(_)),
    };
    if ok {
        return Ok(v.clone());
    }
    let want = match takes {
        Takes::Dim => "a Dim".to_string(),
        Takes::Number(lo, hi) if hi.is_infinite() && lo.is_infinite() => "a finite number".into(),
        Takes::Number(lo, hi) if hi.is_infinite() => format!("a finite number >= {lo}"),
        Takes::Number(lo, hi) => format!("a number in [{lo}, {hi}]"),
        Takes::Integer(lo, hi) => format!("an integer in [{lo}, {hi}]"),
        Takes::Bool => "a boolean".into(),
    };
    Err(expected(what, &want, v))
}

fn num(v: &Value) -> f32 {
    number(v).unwrap_or(0.0) as f32
}

fn dim(v: &Value) -> [f32; 2] {
    dim_arg("", v).unwrap_or([0.0; 2])
}

fn flag(v: &Value) -> bool {
    matches!(v, Value::Boolean(true))
}

/// A GuiPhysicsPlane row.
pub(crate) struct PlaneRow {
    pub(crate) name: &'static str,
    takes: Takes,
    prop: fn(&Value) -> PlaneProp,
    get: fn(&Lua, &client_sdk::GuiPlaneInfo) -> mlua::Result<Value>,
}

macro_rules! gui_row {
    ($name:literal, $takes:expr, $variant:ident, $conv:ident, $field:ident, $out:expr) => {
        PlaneRow {
            name: $name,
            takes: $takes,
            prop: |v| PlaneProp::Gui(GuiPlaneProp::$variant($conv(v))),
            get: |lua, i| $out(lua, i.$field),
        }
    };
}

fn out_num(_: &Lua, x: f32) -> mlua::Result<Value> {
    Ok(crate::values::lua_number(x))
}
fn out_int(_: &Lua, x: u32) -> mlua::Result<Value> {
    Ok(Value::Integer(x as i64))
}
fn out_bool(_: &Lua, x: bool) -> mlua::Result<Value> {
    Ok(Value::Boolean(x))
}
fn out_dim(lua: &Lua, x: [f32; 2]) -> mlua::Result<Value> {
    Ok(Value::UserData(lua.create_userdata(new_dim(x))?))
}
fn count(v: &Value) -> u32 {
    num(v) as u32
}

const NON_NEG: Takes = Takes::Number(0.0, f64::INFINITY);

/// The rows of `GuiPhysicsPlane` (options of `NewGUI` as well).
pub(crate) static GUI_PLANE_ROWS: &[PlaneRow] = &[
    gui_row!("Gravity", Takes::Dim, Gravity, dim, gravity, out_dim),
    gui_row!(
        "LinearDamping",
        NON_NEG,
        LinearDamping,
        num,
        linear_damping,
        out_num
    ),
    gui_row!(
        "AngularDamping",
        NON_NEG,
        AngularDamping,
        num,
        angular_damping,
        out_num
    ),
    gui_row!("Drag", NON_NEG, Drag, num, drag, out_num),
    gui_row!(
        "ConstantForce",
        Takes::Dim,
        ConstantForce,
        dim,
        constant_force,
        out_dim
    ),
    gui_row!(
        "RestThreshold",
        NON_NEG,
        RestThreshold,
        num,
        rest_threshold,
        out_num
    ),
    gui_row!(
        "SolverIterations",
        Takes::Integer(i64::MIN, i64::MAX),
        SolverIterations,
        count,
        solver_iterations,
        out_int
    ),
    gui_row!(
        "NeverSleep",
        Takes::Bool,
        NeverSleep,
        flag,
        never_sleep,
        out_bool
    ),
    PlaneRow {
        name: "Enabled",
        takes: Takes::Bool,
        prop: |v| PlaneProp::Enabled(flag(v)),
        get: |_, i| Ok(Value::Boolean(i.enabled)),
    },
    PlaneRow {
        name: "TickRate",
        takes: Takes::Number(0.0, MAX_TICK_RATE as f64),
        prop: |v| PlaneProp::TickRate(num(v)),
        get: |_, i| Ok(crate::values::lua_number(i.tick_rate)),
    },
];

fn key_name(key: &Value) -> String {
    match key {
        Value::String(s) => s.to_string_lossy(),
        other => describe(other),
    }
}

fn row(key: &Value) -> Option<&'static PlaneRow> {
    let Value::String(s) = key else { return None };
    GUI_PLANE_ROWS
        .iter()
        .find(|r| r.name.as_bytes() == &*s.as_bytes())
}

/// `key = value` of `NewGUI`'s options as the SDK option it stands for.
pub fn gui_plane_option(what: &str, key: &Value, value: &Value) -> mlua::Result<PlaneProp> {
    let r = row(key).ok_or_else(|| {
        mlua::Error::runtime(format!(
            "{what}: unknown option {} (given {})",
            describe(key),
            describe(value)
        ))
    })?;
    convert(&format!("{what} option {}", r.name), r.takes, value)?;
    Ok((r.prop)(value))
}

/// Reads a GuiPhysicsPlane property.
pub fn plane_get(lua: &Lua, p: &GuiPlaneState, key: &Value) -> mlua::Result<Value> {
    let name = key_name(key);
    match name.as_str() {
        "Alive" => return Ok(Value::Boolean(p.alive())),
        "ObjectCount" if !p.alive() => return Ok(Value::Integer(0)),
        _ => {}
    }
    let info = |what: &str| {
        p.check_alive(what)?;
        p.plane
            .info()
            .map_err(|e| sdk_error(&format!("GuiPhysicsPlane.{what}"), e))
    };
    match name.as_str() {
        "ObjectCount" => {
            p.check_alive("ObjectCount")?;
            let n = p
                .plane
                .object_count()
                .map_err(|e| sdk_error("GuiPhysicsPlane.ObjectCount", e))?;
            Ok(Value::Integer(n as i64))
        }
        "BoundsMin" | "BoundsMax" => match info(&name)?.bounds {
            Some((min, max)) => out_dim(lua, if name == "BoundsMin" { min } else { max }),
            None => Ok(Value::Nil),
        },
        _ => match row(key) {
            Some(r) => (r.get)(lua, &info(r.name)?),
            None => Err(mlua::Error::runtime(format!(
                "GuiPhysicsPlane has no property \"{name}\""
            ))),
        },
    }
}

/// Writes a GuiPhysicsPlane property.
pub fn plane_set(p: &GuiPlaneState, key: &Value, value: &Value) -> mlua::Result<()> {
    let name = key_name(key);
    let Some(r) = row(key) else {
        let why = match name.as_str() {
            "BoundsMin" | "BoundsMax" => "is construction-only (give it to PhysicsService.NewGUI)",
            "ObjectCount" | "Alive" => "is read-only",
            _ => {
                return Err(mlua::Error::runtime(format!(
                    "GuiPhysicsPlane has no property \"{name}\" (assigned {})",
                    describe(value)
                )))
            }
        };
        return Err(mlua::Error::runtime(format!(
            "GuiPhysicsPlane.{name} {why} (assigned {})",
            describe(value)
        )));
    };
    p.check_alive(r.name)?;
    let what = format!("GuiPhysicsPlane.{}", r.name);
    convert(&what, r.takes, value)?;
    match (r.prop)(value) {
        PlaneProp::Gui(g) => p.plane.set(g),
        other => p.plane.set_common(other),
    }
    .map_err(|e| sdk_error(&what, e))
}

/// A PhysicsGuiObject row.
pub(crate) struct ObjectRow {
    pub(crate) name: &'static str,
    takes: Takes,
    prop: fn(&Value) -> GuiObjectProp,
}

pub(crate) static GUI_OBJECT_ROWS: &[ObjectRow] = &[
    ObjectRow {
        name: "Position",
        takes: Takes::Dim,
        prop: |v| GuiObjectProp::Position(dim(v)),
    },
    ObjectRow {
        name: "Velocity",
        takes: Takes::Dim,
        prop: |v| GuiObjectProp::Velocity(dim(v)),
    },
    ObjectRow {
        name: "Rotation",
        takes: Takes::Number(f64::NEG_INFINITY, f64::INFINITY),
        prop: |v| GuiObjectProp::Rotation(num(v)),
    },
    ObjectRow {
        name: "AngularVelocity",
        takes: Takes::Number(f64::NEG_INFINITY, f64::INFINITY),
        prop: |v| GuiObjectProp::AngularVelocity(num(v)),
    },
    ObjectRow {
        name: "ImpulseDirection",
        takes: Takes::Dim,
        prop: |v| GuiObjectProp::ImpulseDirection(dim(v)),
    },
    ObjectRow {
        name: "ConstantForce",
        takes: Takes::Dim,
        prop: |v| GuiObjectProp::ConstantForce(dim(v)),
    },
    ObjectRow {
        name: "Mass",
        takes: Takes::Number(0.0001, f64::INFINITY),
        prop: |v| GuiObjectProp::Mass(num(v)),
    },
    ObjectRow {
        name: "Bounciness",
        takes: Takes::Number(0.0, 1.0),
        prop: |v| GuiObjectProp::Bounciness(num(v)),
    },
    ObjectRow {
        name: "Friction",
        takes: Takes::Number(0.0, 4.0),
        prop: |v| GuiObjectProp::Friction(num(v)),
    },
    ObjectRow {
        name: "Anchored",
        takes: Takes::Bool,
        prop: |v| GuiObjectProp::Anchored(flag(v)),
    },
    ObjectRow {
        name: "CanCollide",
        takes: Takes::Bool,
        prop: |v| GuiObjectProp::CanCollide(flag(v)),
    },
    ObjectRow {
        name: "GravityScale",
        takes: Takes::Number(f64::NEG_INFINITY, f64::INFINITY),
        prop: |v| GuiObjectProp::GravityScale(num(v)),
    },
    ObjectRow {
        name: "LockedX",
        takes: Takes::Bool,
        prop: |v| GuiObjectProp::LockedX(flag(v)),
    },
    ObjectRow {
        name: "LockedY",
        takes: Takes::Bool,
        prop: |v| GuiObjectProp::LockedY(flag(v)),
    },
    ObjectRow {
        name: "LockedRotation",
        takes: Takes::Bool,
        prop: |v| GuiObjectProp::LockedRotation(flag(v)),
    },
];

/// Reads a PhysicsGuiObject property.
pub fn object_get(lua: &Lua, o: &PhysicsGuiObject, key: &Value) -> mlua::Result<Value> {
    let name = key_name(key);
    if name == "Alive" {
        return Ok(Value::Boolean(o.alive()));
    }
    let what = format!("PhysicsGuiObject.{name}");
    o.check_alive(&what)?;
    let sdk = |e| sdk_error(&what, e);
    let b = &o.object;
    let info = || b.info().map_err(sdk);
    Ok(match name.as_str() {
        "Position" => out_dim(lua, b.position().map_err(sdk)?)?,
        "Velocity" => out_dim(lua, b.velocity().map_err(sdk)?)?,
        "Rotation" => crate::values::lua_number(b.rotation().map_err(sdk)?),
        "AngularVelocity" => crate::values::lua_number(b.angular_velocity().map_err(sdk)?),
        "Anchored" => Value::Boolean(b.is_anchored().map_err(sdk)?),
        "Sleeping" => Value::Boolean(b.is_sleeping().map_err(sdk)?),
        "ImpulseDirection" => out_dim(lua, info()?.impulse_direction)?,
        "ConstantForce" => out_dim(lua, info()?.constant_force)?,
        "Mass" => crate::values::lua_number(info()?.mass),
        "Bounciness" => crate::values::lua_number(info()?.bounciness),
        "Friction" => crate::values::lua_number(info()?.friction),
        "CanCollide" => Value::Boolean(info()?.can_collide),
        "GravityScale" => crate::values::lua_number(info()?.gravity_scale),
        "LockedX" => Value::Boolean(info()?.locked_x),
        "LockedY" => Value::Boolean(info()?.locked_y),
        "LockedRotation" => Value::Boolean(info()?.locked_rotation),
        "ZIndex" => Value::Integer(o.prim.z_index() as i64),
        "Size" => out_dim(lua, o.prim.size())?,
        "Shape" => Value::String(lua.create_string(o.prim.shape.name())?),
        _ => {
            return Err(mlua::Error::runtime(format!(
                "PhysicsGuiObject has no property \"{name}\""
            )))
        }
    })
}

/// Writes a PhysicsGuiObject property.
pub fn object_set(o: &PhysicsGuiObject, key: &Value, value: &Value) -> mlua::Result<()> {
    let name = key_name(key);
    let Some(r) = GUI_OBJECT_ROWS.iter().find(|r| r.name == name.as_str()) else {
        let why = match name.as_str() {
            "ZIndex" | "Size" | "Shape" => {
                "is read-only (a mirror of the primitive's: set it on the primitive)"
            }
            "Sleeping" | "Alive" => "is read-only",
            _ => {
                return Err(mlua::Error::runtime(format!(
                    "PhysicsGuiObject has no property \"{name}\" (assigned {})",
                    describe(value)
                )))
            }
        };
        return Err(mlua::Error::runtime(format!(
            "PhysicsGuiObject.{name} {why} (assigned {})",
            describe(value)
        )));
    };
    let what = format!("PhysicsGuiObject.{}", r.name);
    o.check_alive(&what)?;
    convert(&what, r.takes, value)?;
    o.object
        .set((r.prop)(value))
        .map_err(|e| sdk_error(&what, e))
}

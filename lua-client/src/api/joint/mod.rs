//! `plane:NewJoint(kind, objA, objB?, opts?)` and the `Joint` it returns; `plane:LoadMap`
//! (its `Map` lives in `map.rs`) and `plane:LoadProp`.
//! Options are the SDK's `JointProp`s by name; reads (`Error`, `Broken`, `Force`, options)
//! ask the daemon (one round trip).

pub(crate) mod state;

use std::rc::Rc;

use client_sdk::{AxisMode, JointInfo, JointKind, JointProp, MapOptions, Object};
use mlua::{Lua, MetaMethod, Table, UserData, UserDataMethods, Value};

use super::axis_motor;
use super::contacts::joint_broke_signal;
use super::object::state::PhysicsObject;
use super::part::state::PartState;
use super::plane::add;
use super::plane::state::PhysicsPlane;
use crate::values::CFrame;
use crate::values::{describe, expected, finite_number, finite_vector, new_vector, sdk_error};
use state::LuaJoint;

/// The option names `NewJoint` and the Joint's properties accept.
const OPTIONS: [&str; 18] = [
    "AnchorA",
    "AnchorB",
    "Axis",
    "LowerAngle",
    "UpperAngle",
    "SwingLimit",
    "TwistLimit",
    "LowerDistance",
    "UpperDistance",
    "RestLength",
    "Stiffness",
    "Damping",
    "MotorSpeed",
    "MotorTarget",
    "MotorMaxForce",
    "Axes",
    "BreakForce",
    "CollideConnected",
];

/// One option from its name and Lua value; errors name the option and the value.
fn joint_prop(name: &str, value: &Value) -> mlua::Result<JointProp> {
    // nil removes a limit or motor (its type is `number?`).
    if let (Value::Nil, Some(o)) = (value, client_sdk::OptionalJointProp::from_name(name)) {
        return Ok(JointProp::Unset(o));
    }
    let what = format!("Joint.{name}");
    let num = || finite_number(&what, value).map(|v| v as f32);
    let vec = || finite_vector(&what, value);
    Ok(match name {
        "AnchorA" => JointProp::AnchorA(vec()?),
        "AnchorB" => JointProp::AnchorB(vec()?),
        "Axis" => JointProp::Axis(vec()?),
        "LowerAngle" => JointProp::LowerAngle(num()?),
        "UpperAngle" => JointProp::UpperAngle(num()?),
        "SwingLimit" => JointProp::SwingLimit(num()?),
        "TwistLimit" => JointProp::TwistLimit(num()?),
        "LowerDistance" => JointProp::LowerDistance(num()?),
        "UpperDistance" => JointProp::UpperDistance(num()?),
        "RestLength" => JointProp::RestLength(num()?),
        "Stiffness" => JointProp::Stiffness(num()?),
        "Damping" => JointProp::Damping(num()?),
        "MotorSpeed" => JointProp::MotorSpeed(num()?),
        "MotorTarget" => JointProp::MotorTarget(num()?),
        "MotorMaxForce" => JointProp::MotorMaxForce(num()?),
        "BreakForce" => JointProp::BreakForce(num()?),
        "CollideConnected" => match value {
            Value::Boolean(b) => JointProp::CollideConnected(*b),
            v => return Err(expected(&what, "a boolean", v)),
        },
        "Axes" => {
            let Value::Table(t) = value else {
                return Err(expected(
                    &what,
                    "a table {X = \"Locked\", ..., RotZ = ...}",
                    value,
                ));
            };
            let mut axes = [AxisMode::Locked; 6];
            for pair in t.pairs::<Value, Value>() {
                let (k, v) = pair?;
                let key = match &k {
                    Value::String(s) => s.to_string_lossy(),
                    other => describe(other),
                };
                let Some(i) = shm_axis(&key) else {
                    return Err(mlua::Error::runtime(format!(
                        "Joint.Axes: unknown axis \"{key}\" (expected X, Y, Z, RotX, RotY, RotZ)"
                    )));
                };
                let mode = match &v {
                    Value::String(s) => AxisMode::from_name(&s.to_string_lossy()),
                    _ => None,
                };
                axes[i] = mode.ok_or_else(|| {
                    expected(
                        &format!("Joint.Axes.{key}"),
                        "\"Locked\", \"Limited\" or \"Free\"",
                        &v,
                    )
                })?;
            }
            JointProp::Axes(axes)
        }
        _ => {
            return Err(mlua::Error::runtime(format!(
                "Joint: unknown option \"{name}\" (expected one of {})",
                OPTIONS.join(", ")
            )))
        }
    })
}

fn shm_axis(name: &str) -> Option<usize> {
    ["X", "Y", "Z", "RotX", "RotY", "RotZ"]
        .iter()
        .position(|a| *a == name)
}

fn object_of(what: &str, v: &Value) -> mlua::Result<Object> {
    match v {
        Value::UserData(ud) => {
            let o = ud
                .borrow::<PhysicsObject>()
                .map_err(|_| expected(what, "a PhysicsObject", v))?;
            Ok(o.live(what)?.clone())
        }
        _ => Err(expected(what, "a PhysicsObject", v)),
    }
}

fn info_value(lua: &Lua, info: &JointInfo, key: &str) -> mlua::Result<Value> {
    let s = &info.settings;
    let opt = |v: Option<f32>| v.map_or(Value::Nil, crate::values::lua_number);
    Ok(match key {
        "Error" => crate::values::lua_number(info.error),
        "AngularError" => crate::values::lua_number(info.angular_error),
        "Broken" => Value::Boolean(info.broken),
        "Force" => crate::values::lua_number(info.force),
        "Position" => crate::values::lua_number(info.position),
        "Kind" => Value::String(lua.create_string(info.kind.name())?),
        "AnchorA" => new_vector(s.anchor_a),
        "AnchorB" => new_vector(s.anchor_b),
        "Axis" => new_vector(s.axis),
        "LowerAngle" => opt(s.lower_angle),
        "UpperAngle" => opt(s.upper_angle),
        "SwingLimit" => opt(s.swing_limit),
        "TwistLimit" => opt(s.twist_limit),
        "LowerDistance" => opt(s.lower_distance),
        "UpperDistance" => opt(s.upper_distance),
        "RestLength" => crate::values::lua_number(s.rest_length),
        "Stiffness" => crate::values::lua_number(s.stiffness),
        "Damping" => crate::values::lua_number(s.damping),
        "MotorSpeed" => opt(s.motor_speed),
        "MotorTarget" => opt(s.motor_target),
        "MotorMaxForce" => crate::values::lua_number(s.motor_max_force),
        "BreakForce" => crate::values::lua_number(s.break_force),
        "CollideConnected" => Value::Boolean(s.collide_connected),
        _ => {
            return Err(mlua::Error::runtime(format!(
                "Joint.{key} is not a valid member of Joint"
            )))
        }
    })
}

impl UserData for LuaJoint {
    fn add_methods<M: UserDataMethods<Self>>(methods: &mut M) {
        // Destroying a destroyed joint (or one removed with its object) does nothing, as
        // for objects and controllers.
        methods.add_method("Destroy", |_, j, ()| {
            if j.2.get() {
                return Ok(());
            }
            j.1.contacts.forget_joint(j.0.handle());
            match j.0.destroy() {
                Ok(()) => {
                    j.2.set(true);
                    Ok(())
                }
                Err(_) if j.0.info().is_err() => {
                    j.2.set(true);
                    Ok(())
                }
                Err(e) => Err(sdk_error("Joint:Destroy", e)),
            }
        });
        methods.add_meta_method(MetaMethod::Index, |lua, j, key: String| {
            if key == "Alive" {
                return Ok(Value::Boolean(j.alive()));
            }
            if j.2.get() {
                return Err(mlua::Error::runtime(format!(
                    "Joint.{key}: {} (read Alive to check)",
                    j.name()
                )));
            }
            if key == "Broke" {
                let signal = joint_broke_signal(&j.1, j.0.handle(), &j.3, &j.name());
                return Ok(Value::UserData(signal.userdata(lua)?));
            }
            let info =
                j.0.info()
                    .map_err(|e| sdk_error(&format!("Joint.{key}"), e))?;
            info_value(lua, &info, &key)
        });
        methods.add_meta_method(
            MetaMethod::NewIndex,
            |_, j, (key, value): (String, Value)| {
                let prop = joint_prop(&key, &value)?;
                j.0.set(prop)
                    .map_err(|e| sdk_error(&format!("Joint.{key}"), e))
            },
        );
        methods.add_meta_method(MetaMethod::ToString, |_, j, ()| Ok(j.name()));
        axis_motor::add_methods(methods);
    }
}

fn options(what: &str, opts: &Value) -> mlua::Result<Vec<(String, Value)>> {
    match opts {
        Value::Nil => Ok(Vec::new()),
        Value::Table(t) => t
            .pairs::<Value, Value>()
            .map(|p| {
                let (k, v) = p?;
                match k {
                    Value::String(s) => Ok((s.to_string_lossy(), v)),
                    other => Err(expected(&format!("{what} option key"), "a string", &other)),
                }
            })
            .collect(),
        v => Err(expected(what, "an options table", v)),
    }
}

fn new_joint(
    plane: &PhysicsPlane,
    (kind, a, b, opts): (Value, Value, Value, Value),
) -> mlua::Result<LuaJoint> {
    let what = "PhysicsPlane:NewJoint";
    let kind = match &kind {
        Value::String(s) => JointKind::from_name(&s.to_string_lossy()),
        _ => None,
    }
    .ok_or_else(|| {
        expected(
            what,
            "a joint kind (\"Ball\", \"Hinge\", \"ConeTwist\", \"SixDof\", \"Fixed\", \"Prismatic\", \"Rope\", \"Spring\")",
            &kind,
        )
    })?;
    let a = object_of(&format!("{what} objA"), &a)?;
    let b = match &b {
        Value::Nil => None,
        v => Some(object_of(&format!("{what} objB"), v)?),
    };
    let props = options(what, &opts)?
        .iter()
        .map(|(k, v)| joint_prop(k, v))
        .collect::<mlua::Result<Vec<_>>>()?;
    plane
        .0
        .plane
        .joint(kind, &a, b.as_ref(), &props)
        .map(|j| LuaJoint::new(j, plane.0.clone(), &a, b.as_ref()))
        .map_err(|e| sdk_error(what, e))
}

fn map_options(what: &str, opts: &Value) -> mlua::Result<MapOptions> {
    let mut o = MapOptions::default();
    for (k, v) in options(what, opts)? {
        match k.as_str() {
            "Position" => o.pose.position = finite_vector(&format!("{what} Position"), &v)?,
            "Rotation" => {
                let e = finite_vector(&format!("{what} Rotation"), &v)?;
                o.pose.rotation = crate::values::rotation::from_euler(e);
            }
            "Scale" => {
                o.scale = match &v {
                    Value::Number(_) | Value::Integer(_) => {
                        [finite_number(&format!("{what} Scale"), &v)? as f32; 3]
                    }
                    _ => finite_vector(&format!("{what} Scale"), &v)?,
                }
            }
            other => {
                return Err(mlua::Error::runtime(format!(
                    "{what}: unknown option \"{other}\" (expected Position, Rotation, Scale)"
                )))
            }
        }
    }
    Ok(o)
}

/// `plane:LoadMap(path, opts?)`: the map's `Map` (see `map.rs`).
fn load_map(
    lua: &Lua,
    plane: &PhysicsPlane,
    (path, opts): (String, Value),
) -> mlua::Result<mlua::AnyUserData> {
    let what = "PhysicsPlane:LoadMap";
    super::query::live(&plane.0, what)?;
    let o = map_options(what, &opts)?;
    let resolved = crate::host::assets::resolve(lua, what, &path)?;
    let map = plane
        .0
        .plane
        .load_map(&resolved, &o)
        .map_err(|e| sdk_error(what, e))?;
    super::map::new_map(lua, plane, map, &path)
}

/// `plane:LoadProp(path, cframe, opts?)`: the .glb as one dynamic mesh part (the convex
/// hull of all its vertices) placed by `cframe`, or with `Decompose = true` one mesh part
/// per mesh of the file welded to the first by Fixed joints. `Scale` (number or vector)
/// scales the file's coordinates. Returns the first PhysicsObject and an array of all.
fn load_prop(
    lua: &Lua,
    plane: &PhysicsPlane,
    (path, cframe, opts): (String, Value, Value),
) -> mlua::Result<(mlua::AnyUserData, Table)> {
    let what = "PhysicsPlane:LoadProp";
    let cf = CFrame::from_value(&cframe)
        .ok_or_else(|| expected(&format!("{what} cframe"), "a CFrame", &cframe))?;
    let (mut scale, mut decompose) = ([1.0f32; 3], false);
    for (k, v) in options(what, &opts)? {
        match k.as_str() {
            "Scale" => {
                let w = format!("{what} Scale");
                scale = match &v {
                    Value::Number(_) | Value::Integer(_) => [finite_number(&w, &v)? as f32; 3],
                    _ => finite_vector(&w, &v)?,
                };
                if scale.iter().any(|c| *c <= 0.0) {
                    return Err(expected(&w, "positive scale factors", &v));
                }
            }
            "Decompose" => {
                decompose = match v {
                    Value::Boolean(b) => b,
                    other => {
                        return Err(expected(&format!("{what} Decompose"), "a boolean", &other))
                    }
                }
            }
            other => {
                return Err(mlua::Error::runtime(format!(
                    "{what}: unknown option \"{other}\" (expected Scale, Decompose)"
                )))
            }
        }
    }
    let meshes = client_sdk::map::read_meshes(&crate::host::assets::resolve(lua, what, &path)?)
        .map_err(|e| sdk_error(what, e))?;
    let scaled = |m: &client_sdk::MapMesh| -> Vec<[f32; 3]> {
        m.vertices
            .iter()
            .map(|v| std::array::from_fn(|k| v[k] * scale[k]))
            .collect()
    };
    // (vertices, triangles) of each part.
    type Group = (Vec<[f32; 3]>, Vec<[u32; 3]>);
    let groups: Vec<Group> = if decompose {
        meshes
            .iter()
            .map(|m| (scaled(m), m.triangles.clone()))
            .collect()
    } else {
        let mut all = (Vec::new(), Vec::new());
        for m in &meshes {
            let base = all.0.len() as u32;
            all.1
                .extend(m.triangles.iter().map(|t| t.map(|i| i + base)));
            all.0.extend(scaled(m));
        }
        vec![all]
    };
    if groups.is_empty() || groups.iter().all(|g| g.0.is_empty()) {
        return Err(mlua::Error::runtime(format!("{what}: {path} has no mesh")));
    }
    let mut objects: Vec<PhysicsObject> = Vec::new();
    for (i, (vertices, triangles)) in groups.into_iter().enumerate() {
        if vertices.len() < 4 {
            return Err(mlua::Error::runtime(format!(
                "{what}: {path}: mesh {i} has {} vertices (a solid needs at least 4)",
                vertices.len()
            )));
        }
        let part = Rc::new(PartState::mesh(vertices, triangles, cf));
        let ud = super::part::part_ud(lua, &part)?;
        let obj = add(&plane.0, Value::UserData(ud))?;
        if let Some(first) = objects.first() {
            // Same rotation for every part: A's local anchor is the centres' difference.
            let a = first.part.cframe().position;
            let b = obj.part.cframe().position;
            let d = crate::values::rotation::rotate(
                crate::values::rotation::conjugate(cf.rotation),
                std::array::from_fn(|k| b[k] - a[k]),
            );
            plane
                .0
                .plane
                .joint(
                    JointKind::Fixed,
                    &first.body.object,
                    Some(&obj.body.object),
                    &[JointProp::AnchorA(d), JointProp::AnchorB([0.0; 3])],
                )
                .map_err(|e| sdk_error(what, e))?;
        }
        objects.push(obj);
    }
    let all = lua.create_table()?;
    for o in objects {
        all.push(super::object::object_ud(lua, o)?)?;
    }
    Ok((all.get(1)?, all))
}

/// Registers `NewJoint`, `LoadMap` and `LoadProp` on PhysicsPlane.
pub fn add_methods<M: UserDataMethods<PhysicsPlane>>(methods: &mut M) {
    methods.add_method("NewJoint", |_, p, args: (Value, Value, Value, Value)| {
        new_joint(p, args)
    });
    methods.add_method("LoadMap", |lua, p, (path, opts): (Value, Value)| {
        load_map(lua, p, (path_arg("PhysicsPlane:LoadMap", &path)?, opts))
    });
    methods.add_method(
        "LoadProp",
        |lua, p, (path, cframe, opts): (Value, Value, Value)| {
            load_prop(
                lua,
                p,
                (path_arg("PhysicsPlane:LoadProp", &path)?, cframe, opts),
            )
        },
    );
}

/// A file path argument, or an error naming the call and what was given.
fn path_arg(what: &str, v: &Value) -> mlua::Result<String> {
    match v {
        Value::String(s) => Ok(s.to_str()?.to_string()),
        other => Err(expected(what, "a file path (a string)", other)),
    }
}

//! The Lua side of a `CFrame` value: its members, methods and operators (the metatable
//! `cframe_ud` installs), the constructors `CFrame.new` and `CFrame.Angles`, and CFrame
//! arguments.

use mlua::{Lua, Table, Value, Variadic};

use super::cframe::CFrame;
use super::cframe_ud::cframe_of_userdata;
use super::convert::{new_vector, number, vector};
use super::describe::{describe, expected, finite_number, finite_vector};
use super::rotation::{self, V3};

impl CFrame {
    fn axis(&self, v: V3) -> Value {
        new_vector(rotation::rotate(self.rotation, v))
    }
}

/// A CFrame argument of a method, or an error naming the method.
fn cframe_arg(what: &str, value: &Value) -> mlua::Result<CFrame> {
    CFrame::from_value(value).ok_or_else(|| expected(what, "a CFrame", value))
}

/// The members of a CFrame value, in the order error messages list them.
const MEMBERS: &str = "Position, Rotation, X, Y, Z, LookVector, RightVector, UpVector, \
                       ToWorldSpace, ToObjectSpace, PointToWorldSpace, PointToObjectSpace, Inverse";

/// The metatable of CFrame values (see `cframe_ud`): `__index` answers the members and the
/// methods (its C front answers Position and the components), and the operators.
pub fn metatable(lua: &Lua) -> mlua::Result<Table> {
    let methods = lua.create_table()?;
    // With no argument the frame itself is the world-space pose (as `Right:ToWorldSpace()`).
    methods.raw_set(
        "ToWorldSpace",
        lua.create_function(|_, (this, other): (Value, Value)| {
            let cf = cframe_arg("CFrame:ToWorldSpace self", &this)?;
            match other {
                Value::Nil => Ok(cf),
                v => Ok(cf.compose(&cframe_arg("CFrame:ToWorldSpace", &v)?)),
            }
        })?,
    )?;
    methods.raw_set(
        "ToObjectSpace",
        lua.create_function(|_, (this, other): (Value, Value)| {
            let cf = cframe_arg("CFrame:ToObjectSpace self", &this)?;
            Ok(cf
                .inverse()
                .compose(&cframe_arg("CFrame:ToObjectSpace", &other)?))
        })?,
    )?;
    methods.raw_set(
        "PointToWorldSpace",
        lua.create_function(|_, (this, v): (Value, Value)| {
            let cf = cframe_arg("CFrame:PointToWorldSpace self", &this)?;
            let v = finite_vector("CFrame:PointToWorldSpace", &v)?;
            Ok(new_vector(cf.point_to_world(v)))
        })?,
    )?;
    methods.raw_set(
        "PointToObjectSpace",
        lua.create_function(|_, (this, v): (Value, Value)| {
            let cf = cframe_arg("CFrame:PointToObjectSpace self", &this)?;
            let v = finite_vector("CFrame:PointToObjectSpace", &v)?;
            Ok(new_vector(cf.inverse().point_to_world(v)))
        })?,
    )?;
    methods.raw_set(
        "Inverse",
        lua.create_function(|_, this: Value| {
            Ok(cframe_arg("CFrame:Inverse self", &this)?.inverse())
        })?,
    )?;
    methods.set_readonly(true);

    let mt = lua.create_table()?;
    mt.raw_set(
        "__index",
        lua.create_function(move |_, (this, key): (Value, Value)| {
            let cf = cframe_arg("CFrame member read", &this)?;
            let name = match &key {
                Value::String(s) => s.as_bytes().to_vec(),
                _ => Vec::new(),
            };
            match name.as_slice() {
                b"Position" => Ok(new_vector(cf.position)),
                b"Rotation" => Ok(new_vector(rotation::to_euler(cf.rotation))),
                b"X" => Ok(Value::Number(f64::from(cf.position[0]))),
                b"Y" => Ok(Value::Number(f64::from(cf.position[1]))),
                b"Z" => Ok(Value::Number(f64::from(cf.position[2]))),
                b"LookVector" => Ok(cf.axis([0.0, 0.0, -1.0])),
                b"RightVector" => Ok(cf.axis([1.0, 0.0, 0.0])),
                b"UpVector" => Ok(cf.axis([0.0, 1.0, 0.0])),
                _ => match methods.raw_get::<Value>(key.clone())? {
                    f @ Value::Function(_) => Ok(f),
                    _ => Err(mlua::Error::runtime(format!(
                        "CFrame has no member {} (members: {MEMBERS})",
                        describe(&key)
                    ))),
                },
            }
        })?,
    )?;
    mt.raw_set(
        "__mul",
        lua.create_function(|lua, (a, b): (Value, Value)| {
            let lhs = cframe_arg("CFrame * ...", &a)?;
            match &b {
                Value::Vector(_) => Ok(new_vector(
                    lhs.point_to_world(finite_vector("CFrame * Vector", &b)?),
                )),
                _ => lhs
                    .compose(&cframe_arg("CFrame * CFrame", &b)?)
                    .into_value(lua),
            }
        })?,
    )?;
    mt.raw_set(
        "__add",
        lua.create_function(|_, (a, b): (Value, Value)| {
            let mut cf = cframe_arg("CFrame + Vector", &a)?;
            let v = finite_vector("CFrame + Vector", &b)?;
            cf.position = [0, 1, 2].map(|i| cf.position[i] + v[i]);
            Ok(cf)
        })?,
    )?;
    mt.raw_set(
        "__sub",
        lua.create_function(|_, (a, b): (Value, Value)| {
            let mut cf = cframe_arg("CFrame - Vector", &a)?;
            let v = finite_vector("CFrame - Vector", &b)?;
            cf.position = [0, 1, 2].map(|i| cf.position[i] - v[i]);
            Ok(cf)
        })?,
    )?;
    mt.raw_set(
        "__eq",
        lua.create_function(|_, (a, b): (Value, Value)| {
            Ok(matches!(
                (CFrame::from_value(&a), CFrame::from_value(&b)),
                (Some(a), Some(b)) if a == b
            ))
        })?,
    )?;
    mt.raw_set(
        "__tostring",
        lua.create_function(|_, this: Value| {
            Ok(cframe_arg("tostring(CFrame)", &this)?.to_string())
        })?,
    )?;
    mt.raw_set("__type", "CFrame")?;
    Ok(mt)
}

/// Components of `args` as numbers, or None when any is not a number.
fn numbers(args: &[Value]) -> Option<Vec<f32>> {
    args.iter().map(|v| number(v).map(|n| n as f32)).collect()
}

/// `CFrame.new()`, `CFrame.new(position)`, `CFrame.new(position, rotation)` (rotation in Euler
/// radians), `CFrame.new(x, y, z)` and `CFrame.new(x, y, z, rx, ry, rz)`.
pub fn new(_: &Lua, args: Variadic<Value>) -> mlua::Result<CFrame> {
    let bad = || {
        let given: Vec<String> = args.iter().map(describe).collect();
        mlua::Error::runtime(format!(
            "CFrame.new expects (), (position: Vector, rotation: Vector?), (x, y, z) or \
             (x, y, z, rx, ry, rz), got ({})",
            given.join(", ")
        ))
    };
    let (position, euler) = match args.len() {
        0 => ([0.0; 3], [0.0; 3]),
        1 | 2 => {
            let p = vector(&args[0]).ok_or_else(bad)?;
            let r = match args.get(1) {
                None | Some(Value::Nil) => [0.0; 3],
                Some(v) => vector(v).ok_or_else(bad)?,
            };
            (p, r)
        }
        3 => {
            let n = numbers(&args).ok_or_else(bad)?;
            ([n[0], n[1], n[2]], [0.0; 3])
        }
        6 => {
            let n = numbers(&args).ok_or_else(bad)?;
            ([n[0], n[1], n[2]], [n[3], n[4], n[5]])
        }
        _ => return Err(bad()),
    };
    if !position.iter().chain(&euler).all(|c| c.is_finite()) {
        return Err(mlua::Error::runtime(format!(
            "CFrame.new expects finite components, got position {position:?}, rotation {euler:?}"
        )));
    }
    Ok(CFrame {
        position,
        rotation: rotation::from_euler(euler),
    })
}

/// `CFrame.Angles(rx, ry, rz)`: a pure rotation.
pub fn angles(_: &Lua, (rx, ry, rz): (Value, Value, Value)) -> mlua::Result<CFrame> {
    let mut e = [0.0f32; 3];
    for (i, (v, name)) in [(rx, "rx"), (ry, "ry"), (rz, "rz")].iter().enumerate() {
        e[i] = finite_number(&format!("CFrame.Angles {name}"), v)? as f32;
    }
    Ok(CFrame {
        position: [0.0; 3],
        rotation: rotation::from_euler(e),
    })
}

impl mlua::FromLua for CFrame {
    fn from_lua(value: Value, _: &Lua) -> mlua::Result<Self> {
        match &value {
            Value::UserData(ud) => cframe_of_userdata(ud),
            _ => None,
        }
        .ok_or_else(|| expected("a CFrame argument", "a CFrame", &value))
    }
}

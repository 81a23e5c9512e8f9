//! `Vector`: Luau's native vector type (so `vector.create` values are Vectors too), with the
//! members the host adds through the vector type's metatable.

use mlua::{Lua, Table, Value};

use super::convert::{lua_number, new_vector, vector};
use super::describe::{expected, finite_number};

/// Builds the `Primitives.Vector` table and installs the vector metatable.
pub fn module(lua: &Lua) -> mlua::Result<Table> {
    install_metatable(lua)?;
    let vector_mod = lua.create_table()?;
    vector_mod.set(
        "new",
        lua.create_function(|_, (x, y, z): (Value, Value, Value)| {
            let comp = |name: &str, v: &Value| match v {
                Value::Nil => Ok(0.0),
                v => finite_number(&format!("Vector.new {name}"), v).map(|n| n as f32),
            };
            Ok(new_vector([comp("x", &x)?, comp("y", &y)?, comp("z", &z)?]))
        })?,
    )?;
    vector_mod.set("zero", new_vector([0.0; 3]))?;
    vector_mod.set("one", new_vector([1.0; 3]))?;
    Ok(vector_mod)
}

/// `.X/.Y/.Z` (any case) and arithmetic are native to Luau vectors; this adds `Magnitude`,
/// `Unit`, `:Dot`, `:Cross` and `:Lerp` through the vector type's metatable, and the
/// components for keys that are not constants (`v[name]`).
fn install_metatable(lua: &Lua) -> mlua::Result<()> {
    let dot = lua.create_function(|_, (a, b): (Value, Value)| {
        let (a, b) = (vec_arg("Vector:Dot", &a)?, vec_arg("Vector:Dot", &b)?);
        Ok(a[0] * b[0] + a[1] * b[1] + a[2] * b[2])
    })?;
    let cross = lua.create_function(|_, (a, b): (Value, Value)| {
        let (a, b) = (vec_arg("Vector:Cross", &a)?, vec_arg("Vector:Cross", &b)?);
        Ok(new_vector([
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]))
    })?;
    let lerp = lua.create_function(|_, (a, b, t): (Value, Value, Value)| {
        let (a, b) = (vec_arg("Vector:Lerp", &a)?, vec_arg("Vector:Lerp", &b)?);
        let t = finite_number("Vector:Lerp alpha", &t)? as f32;
        Ok(new_vector([0, 1, 2].map(|i| a[i] + (b[i] - a[i]) * t)))
    })?;
    let index = lua.create_function(move |_, (v, key): (Value, mlua::String)| {
        let v = vec_arg("Vector", &v)?;
        let len = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        match &*key.as_bytes() {
            // `v.X` is native (the VM reads the component, the f32 widened); `v["X"]` (a
            // key that is not a constant) comes here, and reads the same number.
            b"X" | b"x" => Ok(Value::Number(f64::from(v[0]))),
            b"Y" | b"y" => Ok(Value::Number(f64::from(v[1]))),
            b"Z" | b"z" => Ok(Value::Number(f64::from(v[2]))),
            b"Magnitude" => Ok(lua_number(len)),
            b"Unit" if len > 0.0 => Ok(new_vector(v.map(|c| c / len))),
            b"Unit" => Ok(new_vector([0.0; 3])),
            b"Dot" => Ok(Value::Function(dot.clone())),
            b"Cross" => Ok(Value::Function(cross.clone())),
            b"Lerp" => Ok(Value::Function(lerp.clone())),
            other => Err(mlua::Error::runtime(format!(
                "Vector has no member \"{}\" (members: X, Y, Z, Magnitude, Unit, Dot, Cross, Lerp)",
                String::from_utf8_lossy(other)
            ))),
        }
    })?;
    let mt = lua.create_table()?;
    mt.set("__index", index)?;
    lua.set_type_metatable::<mlua::Vector>(Some(mt));
    Ok(())
}

fn vec_arg(what: &str, v: &Value) -> mlua::Result<[f32; 3]> {
    vector(v).ok_or_else(|| expected(what, "a Vector", v))
}

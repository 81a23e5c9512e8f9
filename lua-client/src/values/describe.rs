//! The error messages that name what was expected and what was given, and the finite
//! number and vector arguments checked with them.

use mlua::{AnyUserData, Error as LuaError, Function, Value};

use super::cframe_ud::cframe_of_userdata;
use super::convert::{number, vector};
use super::dim::Dim;

/// The metatable field of a userdata type that describes its values in error messages: a
/// function of the value returning a string (e.g. `BasePart "Ball"`). Types without one are
/// described by their type name.
pub const DESCRIBE: &str = "__describe";

/// What a userdata type's [`DESCRIBE`] entry says about `ud`, if it has one.
fn described(ud: &AnyUserData) -> Option<String> {
    let describe = ud
        .metatable()
        .ok()?
        .get::<Option<Function>>(DESCRIBE)
        .ok()??;
    describe.call::<String>(ud.clone()).ok()
}

/// A short description of a Lua value for error messages: its type and, when small, itself.
pub fn describe(value: &Value) -> String {
    match value {
        Value::Nil => "nil".into(),
        Value::Boolean(b) => format!("boolean {b}"),
        Value::Integer(i) => format!("number {i}"),
        Value::Number(n) => format!("number {n}"),
        Value::Vector(v) => format!("Vector({}, {}, {})", v.x(), v.y(), v.z()),
        Value::String(s) => {
            let s = s.to_string_lossy();
            if s.chars().count() > 40 {
                let short: String = s.chars().take(40).collect();
                format!("string \"{short}…\"")
            } else {
                format!("string \"{s}\"")
            }
        }
        Value::Table(_) => "table".into(),
        Value::Function(_) => "function".into(),
        Value::Thread(_) => "thread".into(),
        Value::UserData(ud) => {
            if let Some(cf) = cframe_of_userdata(ud) {
                cf.to_string()
            } else if let Ok(d) = ud.borrow::<Dim>() {
                d.to_string()
            } else if let Some(text) = described(ud) {
                text
            } else {
                match ud.type_name() {
                    Ok(Some(name)) => name,
                    _ => "userdata".into(),
                }
            }
        }
        other => other.type_name().to_string(),
    }
}

/// `"{what} expects {expected}, got {value}"`.
pub fn expected(what: &str, expected: &str, got: &Value) -> LuaError {
    LuaError::runtime(format!("{what} expects {expected}, got {}", describe(got)))
}

/// A finite vector, or an error naming `what`.
pub fn finite_vector(what: &str, value: &Value) -> Result<[f32; 3], LuaError> {
    match vector(value) {
        Some(v) if v.iter().all(|c| c.is_finite()) => Ok(v),
        Some(_) => Err(expected(what, "a Vector with finite components", value)),
        None => Err(expected(what, "a Vector", value)),
    }
}

/// A finite number, or an error naming `what`.
pub fn finite_number(what: &str, value: &Value) -> Result<f64, LuaError> {
    match number(value) {
        Some(n) if n.is_finite() => Ok(n),
        _ => Err(expected(what, "a finite number", value)),
    }
}

//! Lua values to Rust values, and the error messages that name what was expected and what
//! was given.

use mlua::{AnyUserData, Error as LuaError, Function, Value};

use super::Dim;

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
            if let Some(cf) = super::cframe_ud::cframe_of_userdata(ud) {
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

/// A Lua number (integer or float) as `f64`.
pub fn number(value: &Value) -> Option<f64> {
    match *value {
        Value::Number(n) => Some(n),
        Value::Integer(i) => Some(i as f64),
        _ => None,
    }
}

/// A native Luau vector (what `Vector.new` and `vector.create` both make).
pub fn vector(value: &Value) -> Option<[f32; 3]> {
    match value {
        Value::Vector(v) => Some([v.x(), v.y(), v.z()]),
        _ => None,
    }
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

/// A Rust error from the SDK as a Lua error, prefixed by what was being done.
pub fn sdk_error(what: &str, e: client_sdk::Error) -> LuaError {
    LuaError::runtime(format!("{what}: {e}"))
}

/// A native Luau vector of `v`.
pub fn new_vector(v: [f32; 3]) -> Value {
    Value::Vector(mlua::Vector::new(v[0], v[1], v[2]))
}

/// A number the daemon keeps as `f32` or as an integer, as a Lua number that reads back
/// what a script wrote: an `f32` becomes the double nearest its shortest decimal form
/// (`0.7f32` reads `0.7`, not `0.699999988`), so `obj.Bounciness = 0.7` then
/// `obj.Bounciness == 0.7` holds, and documented defaults read as written.
pub fn lua_number<T: LuaNumber>(x: T) -> mlua::Value {
    mlua::Value::Number(x.to_lua_f64())
}

/// Numbers [`lua_number`] takes.
pub trait LuaNumber {
    /// The Lua number for `self`.
    fn to_lua_f64(self) -> f64;
}

impl LuaNumber for f32 {
    fn to_lua_f64(self) -> f64 {
        let wide = self as f64;
        if !self.is_finite() {
            return wide;
        }
        if wide.abs() >= 16_777_216.0 {
            // Past 2^24 an f32 is an integer that need not be the one written.
            return self.to_string().parse().unwrap_or(wide);
        }
        // The fewest decimal places that still read back as this f32 (a multiply and a
        // division per place, no formatting), nearest to it; Rust's shortest printing for
        // what needs more.
        let mut scale = 1.0f64;
        for _ in 0..=12 {
            let r = (wide * scale).round() / scale;
            if r as f32 == self {
                return r;
            }
            scale *= 10.0;
        }
        self.to_string().parse().unwrap_or(wide)
    }
}

impl LuaNumber for f64 {
    fn to_lua_f64(self) -> f64 {
        self
    }
}

macro_rules! lua_integer {
    ($($t:ty),*) => {$(
        impl LuaNumber for $t {
            fn to_lua_f64(self) -> f64 {
                self as f64
            }
        }
    )*};
}
lua_integer!(u8, u16, u32, u64, i32, i64, usize);

#[cfg(test)]
mod lua_number_tests {
    use super::*;

    #[test]
    fn f32_values_read_back_as_written() {
        for (x, want) in [
            (0.7f32, 0.7f64),
            (1.1, 1.1),
            (0.1, 0.1),
            (16.0, 16.0),
            (1e-4, 1e-4),
        ] {
            assert_eq!(x.to_lua_f64(), want, "{x}");
        }
        assert_eq!(u32::MAX.to_lua_f64(), u32::MAX as f64);
        assert!(f32::NAN.to_lua_f64().is_nan());
        // Every f32 reads as the value Rust's shortest printing gives.
        for bits in (0..u32::MAX).step_by(65_537) {
            let x = f32::from_bits(bits);
            if x.is_finite() {
                let shortest: f64 = x.to_string().parse().unwrap();
                assert_eq!(x.to_lua_f64(), shortest, "{x:e}");
            }
        }
    }
}

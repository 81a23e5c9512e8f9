//! Lua values to Rust values and back: numbers and vectors.

use mlua::{Error as LuaError, Value};

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
mod tests {
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

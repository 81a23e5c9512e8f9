//! The property layer: each Lua-visible property is one row (name → expected Lua type with
//! its converter → SDK read / write). A documented property the SDK cannot do yet is a row
//! marked `NotYet`, so wiring it later is editing one row, and using it meanwhile is a clear
//! error instead of a silent no-op.

pub mod object;
pub mod part;
pub mod plane;

use mlua::{Error as LuaError, Lua, Value};

use crate::values::{describe, number, vector, CFrame};

/// The Lua type a property takes, with its accepted range.
#[derive(Debug, Clone, Copy)]
pub enum Kind {
    Number {
        min: f64,
        max: f64,
    },
    Integer {
        min: i64,
        max: i64,
    },
    Boolean,
    Vector,
    /// A Vector whose components are all > 0 (sizes).
    PositiveVector,
    CFrame,
    String,
}

impl Kind {
    pub const ANY_NUMBER: Kind = Kind::Number {
        min: f64::NEG_INFINITY,
        max: f64::INFINITY,
    };
    pub const NON_NEGATIVE: Kind = Kind::Number {
        min: 0.0,
        max: f64::INFINITY,
    };
    pub const UNIT: Kind = Kind::Number { min: 0.0, max: 1.0 };

    /// What the error message says was expected.
    pub fn expected(&self) -> String {
        match *self {
            Kind::Number { min, max } => match (min.is_finite(), max.is_finite()) {
                (false, false) => "a finite number".into(),
                (true, false) => format!("a finite number >= {min}"),
                (false, true) => format!("a finite number <= {max}"),
                (true, true) => format!("a number in [{min}, {max}]"),
            },
            Kind::Integer { min, max } => format!("an integer in [{min}, {max}]"),
            Kind::Boolean => "a boolean".into(),
            Kind::Vector => "a Vector with finite components".into(),
            Kind::PositiveVector => "a Vector with finite components > 0".into(),
            Kind::CFrame => "a CFrame".into(),
            Kind::String => "a string".into(),
        }
    }

    /// Converts `value`, or says which property wanted what and what it got.
    pub fn convert(&self, what: &str, value: &Value) -> Result<Arg, LuaError> {
        let bad = || {
            LuaError::runtime(format!(
                "{what} expects {}, got {}",
                self.expected(),
                describe(value)
            ))
        };
        match *self {
            Kind::Number { min, max } => match number(value) {
                Some(n) if n.is_finite() && n >= min && n <= max => Ok(Arg::Number(n)),
                _ => Err(bad()),
            },
            Kind::Integer { min, max } => match number(value) {
                Some(n) if n.fract() == 0.0 && n >= min as f64 && n <= max as f64 => {
                    Ok(Arg::Integer(n as i64))
                }
                _ => Err(bad()),
            },
            Kind::Boolean => match value {
                Value::Boolean(b) => Ok(Arg::Bool(*b)),
                _ => Err(bad()),
            },
            Kind::Vector => match vector(value) {
                Some(v) if v.iter().all(|c| c.is_finite()) => Ok(Arg::Vector(v)),
                _ => Err(bad()),
            },
            Kind::PositiveVector => match vector(value) {
                Some(v) if v.iter().all(|c| c.is_finite() && *c > 0.0) => Ok(Arg::Vector(v)),
                _ => Err(bad()),
            },
            Kind::CFrame => match value {
                Value::UserData(ud) => ud
                    .borrow::<CFrame>()
                    .map(|cf| Arg::CFrame(*cf))
                    .map_err(|_| bad()),
                _ => Err(bad()),
            },
            Kind::String => match value {
                Value::String(s) => Ok(Arg::String(s.to_string_lossy())),
                _ => Err(bad()),
            },
        }
    }
}

/// A converted property value. Each variant is what one `Kind` produces.
#[derive(Debug, Clone)]
pub enum Arg {
    Number(f64),
    Integer(i64),
    Bool(bool),
    Vector([f32; 3]),
    CFrame(CFrame),
    String(String),
}

fn mismatch(arg: &Arg, want: &str) -> LuaError {
    // Unreachable while every row's setter matches its kind; an error, never a panic.
    LuaError::runtime(format!(
        "internal: property converter gave {arg:?} where {want} was expected"
    ))
}

impl Arg {
    pub fn number(&self) -> Result<f64, LuaError> {
        match *self {
            Arg::Number(n) => Ok(n),
            Arg::Integer(i) => Ok(i as f64),
            _ => Err(mismatch(self, "a number")),
        }
    }
    pub fn integer(&self) -> Result<i64, LuaError> {
        match *self {
            Arg::Integer(i) => Ok(i),
            _ => Err(mismatch(self, "an integer")),
        }
    }
    pub fn bool(&self) -> Result<bool, LuaError> {
        match *self {
            Arg::Bool(b) => Ok(b),
            _ => Err(mismatch(self, "a boolean")),
        }
    }
    pub fn vector(&self) -> Result<[f32; 3], LuaError> {
        match *self {
            Arg::Vector(v) => Ok(v),
            _ => Err(mismatch(self, "a Vector")),
        }
    }
    pub fn cframe(&self) -> Result<CFrame, LuaError> {
        match *self {
            Arg::CFrame(cf) => Ok(cf),
            _ => Err(mismatch(self, "a CFrame")),
        }
    }
    pub fn string(self) -> Result<String, LuaError> {
        match self {
            Arg::String(s) => Ok(s),
            other => Err(mismatch(&other, "a string")),
        }
    }
}

pub type Getter<T> = fn(&Lua, &T) -> Result<Value, LuaError>;
pub type Setter<T> = fn(&Lua, &T, Arg) -> Result<(), LuaError>;

pub enum Get<T> {
    Fn(Getter<T>),
    /// Documented, but the SDK cannot read it yet.
    NotYet,
}

pub enum Set<T> {
    Fn(Setter<T>),
    ReadOnly,
    /// Documented, but the SDK cannot write it yet.
    NotYet,
}

pub struct Row<T: 'static> {
    pub name: &'static str,
    pub kind: Kind,
    pub get: Get<T>,
    pub set: Set<T>,
}

impl<T> Row<T> {
    /// A documented property the SDK does not support yet (neither read nor write).
    pub const fn not_yet(name: &'static str, kind: Kind) -> Row<T> {
        Row {
            name,
            kind,
            get: Get::NotYet,
            set: Set::NotYet,
        }
    }
}

/// A table of rows for one Lua type (`owner` is its Lua name, e.g. "PhysicsObject").
pub struct Props<T: 'static> {
    pub owner: &'static str,
    pub rows: &'static [Row<T>],
}

fn key_text(key: &Value) -> String {
    match key {
        Value::String(s) => s.to_string_lossy(),
        other => describe(other),
    }
}

impl<T> Props<T> {
    pub fn row(&self, key: &Value) -> Option<&'static Row<T>> {
        let Value::String(s) = key else {
            return None;
        };
        let key = s.as_bytes();
        self.rows.iter().find(|r| r.name.as_bytes() == &*key)
    }

    pub fn not_supported(&self, name: &str) -> LuaError {
        LuaError::runtime(format!("{}.{name} is not supported yet", self.owner))
    }

    pub fn unknown(&self, key: &Value) -> LuaError {
        LuaError::runtime(format!(
            "{} has no property \"{}\"",
            self.owner,
            key_text(key)
        ))
    }

    pub fn get(&self, lua: &Lua, target: &T, key: &Value) -> Result<Value, LuaError> {
        let row = self.row(key).ok_or_else(|| self.unknown(key))?;
        match row.get {
            Get::Fn(f) => f(lua, target),
            Get::NotYet => Err(self.not_supported(row.name)),
        }
    }

    pub fn set(&self, lua: &Lua, target: &T, key: &Value, value: &Value) -> Result<(), LuaError> {
        let Some(row) = self.row(key) else {
            return Err(LuaError::runtime(format!(
                "{} has no property \"{}\" (assigned {})",
                self.owner,
                key_text(key),
                describe(value)
            )));
        };
        match row.set {
            Set::Fn(f) => {
                let arg = row
                    .kind
                    .convert(&format!("{}.{}", self.owner, row.name), value)?;
                f(lua, target, arg)
            }
            Set::ReadOnly => Err(LuaError::runtime(format!(
                "{}.{} is read-only (assigned {})",
                self.owner,
                row.name,
                describe(value)
            ))),
            Set::NotYet => Err(match row.get {
                Get::Fn(_) => LuaError::runtime(format!(
                    "setting {}.{} is not supported yet (assigned {})",
                    self.owner,
                    row.name,
                    describe(value)
                )),
                Get::NotYet => self.not_supported(row.name),
            }),
        }
    }
}

/// Registers documented methods the SDK cannot do yet: calling one is a clear error.
pub fn not_yet_methods<T, M: mlua::UserDataMethods<T>>(
    methods: &mut M,
    owner: &'static str,
    names: &[&'static str],
) {
    for &name in names {
        methods.add_function(name, move |_, _: mlua::MultiValue| -> mlua::Result<()> {
            Err(LuaError::runtime(format!(
                "{owner}:{name} is not supported yet"
            )))
        });
    }
}

//! The property layer: each Lua-visible property is one row (name → expected Lua type with
//! its converter → one read source → the write). Adding a property is adding one row.
//!
//! - A row reads from one place: the daemon's info, the SDK's read-your-writes view of the
//!   newest tick (pose, velocities, Anchored), or the state the host itself owns (a part's
//!   name). No row keeps a script-side copy of what another row reads from the daemon.
//! - A writable row turns the converted value into one SDK property write ([`Set::Prop`]),
//!   which is also what the type's creation options use (`PhysicsService.New(opts)`); a row
//!   flagged [`Set::CreationOnly`] (`Threads`) is an option of the creation call and
//!   read-only afterwards. Rows with work beyond one SDK write are [`Set::Fn`].
//! - A documented property the SDK cannot do yet is a row marked `NotYet`, so wiring it later
//!   is editing one row, and using it meanwhile is a clear error instead of a silent no-op.

use std::sync::OnceLock;

use client_sdk::settings::table::{AnyValue, PropKind, PropRow, Range};
use mlua::{Error as LuaError, Lua, Value};

use crate::values::{describe, lua_number, new_dim, new_vector, number, vector, CFrame, Dim};

/// A Lua type whose properties are rows, and how one of its property writes reaches the SDK.
pub trait Target: 'static {
    /// One property write as the SDK takes it (`PlaneProp`, `ObjectProp`); a type with no SDK
    /// writes of its own uses [`std::convert::Infallible`].
    type Prop;

    /// Sends (queues) one property write; `name` is the property, for error messages.
    fn write(&self, name: &str, prop: Self::Prop) -> Result<(), LuaError>;
}

/// Reads the stored value of a settings-table row (`name` the property, for the read's
/// errors; `index` the row) from where `T` keeps its settings: `None` when the row has no
/// plain value.
pub type TableGet<T> = fn(&T, &str, usize) -> Result<Option<AnyValue>, LuaError>;
/// The property write of a settings-table row (`index`) with value `v`, `None` when the row
/// cannot take it.
pub type TableProp<T> = fn(usize, AnyValue) -> Option<<T as Target>::Prop>;

/// The rows a Lua type takes from its settings table (shm-layout's rows flagged `lua`),
/// looked up after its own rows: each reads the stored value and writes one property of
/// its row.
pub struct Table<T: Target> {
    /// The settings table's rows.
    pub rows: &'static [PropRow],
    /// Where the stored values are read.
    pub get: TableGet<T>,
    /// How a value becomes a write.
    pub prop: TableProp<T>,
    /// The Lua rows, made on first use.
    lua_rows: OnceLock<Vec<Row<T>>>,
}

impl<T: Target> Table<T> {
    /// The rows of the settings table `rows`, read through `get` and written through `prop`.
    pub const fn new(rows: &'static [PropRow], get: TableGet<T>, prop: TableProp<T>) -> Table<T> {
        Table {
            rows,
            get,
            prop,
            lua_rows: OnceLock::new(),
        }
    }
}

/// The Lua type a property takes, with its accepted range.
#[derive(Debug, Clone, Copy)]
pub enum Kind {
    /// A finite number in `[min, max]`.
    Number {
        /// Smallest accepted value (may be -inf: no bound).
        min: f64,
        /// Largest accepted value (may be inf: no bound).
        max: f64,
    },
    /// A finite number > 0 (limits that cannot be zero).
    Positive,
    /// A whole number in `[min, max]`.
    Integer {
        /// Smallest accepted value (`i64::MIN`: no bound).
        min: i64,
        /// Largest accepted value (`i64::MAX`: no bound).
        max: i64,
    },
    /// `true` or `false`.
    Boolean,
    /// A Vector with finite components.
    Vector,
    /// A Vector whose components are all > 0 (sizes).
    PositiveVector,
    /// A CFrame userdata.
    CFrame,
    /// A Lua string.
    String,
    /// A finite number, or nil for none (an optional setting such as `GroundY`).
    OptionalNumber,
    /// A Dim with finite components (GUI planes: pixels).
    Dim,
}

impl Kind {
    /// Any finite number.
    pub const ANY_NUMBER: Kind = Kind::Number {
        min: f64::NEG_INFINITY,
        max: f64::INFINITY,
    };
    /// A finite number >= 0.
    pub const NON_NEGATIVE: Kind = Kind::Number {
        min: 0.0,
        max: f64::INFINITY,
    };
    /// A number in [0, 1].
    pub const UNIT: Kind = Kind::Number { min: 0.0, max: 1.0 };
    /// Any whole number (rows that clamp it themselves).
    pub const ANY_INTEGER: Kind = Kind::Integer {
        min: i64::MIN,
        max: i64::MAX,
    };

    /// What the error message says was expected.
    pub fn expected(&self) -> String {
        /// A bound as written in the settings table: the shortest decimal of the `f32` it
        /// came from (1e-4, not 0.00009999999747378752).
        fn shortest(x: f64) -> String {
            let narrow = x as f32;
            if narrow as f64 == x {
                narrow.to_string()
            } else {
                x.to_string()
            }
        }
        match *self {
            Kind::Number { min, max } => {
                let (lo, hi) = (shortest(min), shortest(max));
                match (min.is_finite(), max.is_finite()) {
                    (false, false) => "a finite number".into(),
                    (true, false) => format!("a finite number >= {lo}"),
                    (false, true) => format!("a finite number <= {hi}"),
                    (true, true) => format!("a number in [{lo}, {hi}]"),
                }
            }
            Kind::Positive => "a finite number > 0".into(),
            Kind::Integer { min, max } => match (min > i64::MIN, max < i64::MAX) {
                (false, false) => "an integer".into(),
                (true, false) => format!("an integer >= {min}"),
                (false, true) => format!("an integer <= {max}"),
                (true, true) => format!("an integer in [{min}, {max}]"),
            },
            Kind::Boolean => "a boolean".into(),
            Kind::Vector => "a Vector with finite components".into(),
            Kind::PositiveVector => "a Vector with finite components > 0".into(),
            Kind::CFrame => "a CFrame".into(),
            Kind::String => "a string".into(),
            Kind::OptionalNumber => "a finite number or nil".into(),
            Kind::Dim => "a Dim with finite components".into(),
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
            Kind::OptionalNumber => match (value, number(value)) {
                (Value::Nil, _) => Ok(Arg::Nil),
                (_, Some(n)) if n.is_finite() => Ok(Arg::Number(n)),
                _ => Err(bad()),
            },
            Kind::Positive => match number(value) {
                Some(n) if n.is_finite() && n > 0.0 => Ok(Arg::Number(n)),
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
            Kind::CFrame => CFrame::from_value(value).map(Arg::CFrame).ok_or_else(bad),
            Kind::String => match value {
                Value::String(s) => Ok(Arg::String(s.to_string_lossy())),
                _ => Err(bad()),
            },
            Kind::Dim => match value {
                Value::UserData(ud) => match ud.borrow::<Dim>() {
                    Ok(d) if d.x.is_finite() && d.y.is_finite() => {
                        Ok(Arg::Dim([d.x as f32, d.y as f32]))
                    }
                    _ => Err(bad()),
                },
                _ => Err(bad()),
            },
        }
    }
}

/// A converted property value. Each variant is what one `Kind` produces.
#[derive(Debug, Clone)]
pub enum Arg {
    /// From [`Kind::Number`] and [`Kind::Positive`].
    Number(f64),
    /// From [`Kind::Integer`].
    Integer(i64),
    /// From [`Kind::Boolean`].
    Bool(bool),
    /// From [`Kind::Vector`] and [`Kind::PositiveVector`].
    Vector([f32; 3]),
    /// From [`Kind::CFrame`].
    CFrame(CFrame),
    /// From [`Kind::String`].
    String(String),
    /// Nil, from [`Kind::OptionalNumber`].
    Nil,
    /// From [`Kind::Dim`].
    Dim([f32; 2]),
}

fn mismatch(arg: &Arg, want: &str) -> LuaError {
    // Unreachable while every row's setter matches its kind; an error, never a panic.
    LuaError::runtime(format!(
        "internal: property converter gave {arg:?} where {want} was expected"
    ))
}

impl Arg {
    /// The number (integers too).
    pub fn number(&self) -> Result<f64, LuaError> {
        match *self {
            Arg::Number(n) => Ok(n),
            Arg::Integer(i) => Ok(i as f64),
            _ => Err(mismatch(self, "a number")),
        }
    }
    /// The number, or `None` for nil.
    pub fn optional_number(&self) -> Result<Option<f64>, LuaError> {
        match *self {
            Arg::Nil => Ok(None),
            _ => self.number().map(Some),
        }
    }
    /// The integer.
    #[allow(dead_code)] // table rows convert integers themselves; kept for hand rows
    pub fn integer(&self) -> Result<i64, LuaError> {
        match *self {
            Arg::Integer(i) => Ok(i),
            _ => Err(mismatch(self, "an integer")),
        }
    }
    /// The boolean.
    pub fn bool(&self) -> Result<bool, LuaError> {
        match *self {
            Arg::Bool(b) => Ok(b),
            _ => Err(mismatch(self, "a boolean")),
        }
    }
    /// The vector.
    pub fn vector(&self) -> Result<[f32; 3], LuaError> {
        match *self {
            Arg::Vector(v) => Ok(v),
            _ => Err(mismatch(self, "a Vector")),
        }
    }
    /// The CFrame.
    pub fn cframe(&self) -> Result<CFrame, LuaError> {
        match *self {
            Arg::CFrame(cf) => Ok(cf),
            _ => Err(mismatch(self, "a CFrame")),
        }
    }
    /// The Dim, as pixels.
    pub fn dim(&self) -> Result<[f32; 2], LuaError> {
        match *self {
            Arg::Dim(d) => Ok(d),
            _ => Err(mismatch(self, "a Dim")),
        }
    }
    /// The string.
    pub fn string(self) -> Result<String, LuaError> {
        match self {
            Arg::String(s) => Ok(s),
            other => Err(mismatch(&other, "a string")),
        }
    }
}

/// Reads a property of `T`.
pub type Getter<T> = fn(&Lua, &T) -> Result<Value, LuaError>;
/// Writes a property of `T` with work beyond one SDK write.
pub type Setter<T> = fn(&Lua, &T, Arg) -> Result<(), LuaError>;
/// The SDK property write a converted value stands for.
pub type ToProp<T> = fn(Arg) -> Result<<T as Target>::Prop, LuaError>;

/// How a row reads.
pub enum Get<T> {
    /// Read through this function (from the row's one source).
    Fn(Getter<T>),
    /// Documented, but the SDK cannot read it yet (no row needs it today).
    #[allow(dead_code)]
    NotYet,
    /// The stored value of the settings-table row at this index ([`Table::get`]).
    Table(usize),
}

/// How a row writes.
pub enum Set<T: Target> {
    /// Writable: the value becomes one SDK property write, at any time and as a creation
    /// option.
    Prop(ToProp<T>),
    /// The creation-only flag: an option of the creation call (`PhysicsService.New`), which
    /// writes it as part of the creation request; read-only afterwards.
    #[allow(dead_code)] // the table's `creation_only` rows use `Table`; kept for hand rows
    CreationOnly(ToProp<T>),
    /// Writable, with work beyond one SDK write (the host's own state, change signals).
    /// Not a creation option.
    Fn(Setter<T>),
    /// Never written by scripts.
    ReadOnly,
    /// Documented, but the SDK cannot write it yet (no row needs it today).
    #[allow(dead_code)]
    NotYet,
    /// The settings-table row at `index` ([`Table::prop`]): writable, or an option
    /// of the creation call only when the row is `creation_only`.
    Table {
        /// The row's index in its table (its wire index).
        index: usize,
        /// Only the creation call may set it.
        creation_only: bool,
    },
}

/// One property of a Lua type.
pub struct Row<T: Target> {
    /// The Lua name.
    pub name: &'static str,
    /// What a write takes.
    pub kind: Kind,
    /// How it reads.
    pub get: Get<T>,
    /// How it writes.
    pub set: Set<T>,
}

impl<T: Target> Row<T> {
    /// A documented property the SDK does not support yet (neither read nor write).
    #[allow(dead_code)]
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
pub struct Props<T: Target> {
    /// The Lua type's name, as error messages spell it.
    pub owner: &'static str,
    /// One row per property.
    pub rows: &'static [Row<T>],
    /// The rows from its settings table, if it has one.
    pub table: Option<Table<T>>,
}

fn key_text(key: &Value) -> String {
    match key {
        Value::String(s) => s.to_string_lossy(),
        other => describe(other),
    }
}

impl<T: Target> Props<T> {
    /// The rows from the type's settings table (none without one).
    pub fn table_rows(&self) -> &[Row<T>] {
        match &self.table {
            Some(t) => t.lua_rows.get_or_init(|| table_rows(t.rows)),
            None => &[],
        }
    }

    /// The stored value of the settings-table row at `index` (`name` its property).
    fn table_get(&self, target: &T, name: &str, index: usize) -> Result<AnyValue, LuaError> {
        let what = format!("{}.{name}", self.owner);
        let Some(t) = &self.table else {
            return Err(LuaError::runtime(format!("{what} has no settings table")));
        };
        (t.get)(target, name, index)?
            .ok_or_else(|| LuaError::runtime(format!("{what} has no plain value")))
    }

    /// The write of value `v` to the settings-table row at `index` (`what` names it).
    fn table_prop(&self, what: &str, index: usize, v: AnyValue) -> Result<T::Prop, LuaError> {
        let Some(t) = &self.table else {
            return Err(LuaError::runtime(format!("{what} has no settings table")));
        };
        (t.prop)(index, v).ok_or_else(|| LuaError::runtime(format!("{what} cannot take {v:?}")))
    }

    /// The row named by `key`, if `key` is one of its property names.
    pub fn row(&self, key: &Value) -> Option<&Row<T>> {
        let Value::String(s) = key else {
            return None;
        };
        let key = s.as_bytes();
        self.rows
            .iter()
            .chain(self.table_rows())
            .find(|r| r.name.as_bytes() == &*key)
    }

    /// The error for a documented property the SDK cannot do yet.
    pub fn not_supported(&self, name: &str) -> LuaError {
        LuaError::runtime(format!("{}.{name} is not supported yet", self.owner))
    }

    /// The error for reading a property the type does not have.
    pub fn unknown(&self, key: &Value) -> LuaError {
        LuaError::runtime(format!(
            "{} has no property \"{}\"",
            self.owner,
            key_text(key)
        ))
    }

    /// Reads the property `key` of `target`.
    pub fn get(&self, lua: &Lua, target: &T, key: &Value) -> Result<Value, LuaError> {
        let row = self.row(key).ok_or_else(|| self.unknown(key))?;
        self.read(lua, target, row)
    }

    /// Reads the property of `row` (one of this table's rows) of `target`.
    pub fn read(&self, lua: &Lua, target: &T, row: &Row<T>) -> Result<Value, LuaError> {
        match row.get {
            Get::Fn(f) => f(lua, target),
            Get::NotYet => Err(self.not_supported(row.name)),
            Get::Table(index) => any_to_lua(lua, self.table_get(target, row.name, index)?),
        }
    }

    /// Writes `value` to the property `key` of `target` (script assignment).
    pub fn set(&self, lua: &Lua, target: &T, key: &Value, value: &Value) -> Result<(), LuaError> {
        let Some(row) = self.row(key) else {
            return Err(LuaError::runtime(format!(
                "{} has no property \"{}\" (assigned {})",
                self.owner,
                key_text(key),
                describe(value)
            )));
        };
        let arg = || {
            row.kind
                .convert(&format!("{}.{}", self.owner, row.name), value)
        };
        match row.set {
            Set::Prop(to_prop) => target.write(row.name, to_prop(arg()?)?),
            Set::Fn(f) => f(lua, target, arg()?),
            Set::Table {
                index,
                creation_only: false,
            } => {
                let what = format!("{}.{}", self.owner, row.name);
                target.write(
                    row.name,
                    self.table_prop(&what, index, arg_to_any(arg()?)?)?,
                )
            }
            Set::ReadOnly | Set::CreationOnly(_) | Set::Table { .. } => {
                Err(LuaError::runtime(format!(
                    "{}.{} is read-only (assigned {})",
                    self.owner,
                    row.name,
                    describe(value)
                )))
            }
            Set::NotYet => Err(match row.get {
                Get::Fn(_) => LuaError::runtime(format!(
                    "setting {}.{} is not supported yet (assigned {})",
                    self.owner,
                    row.name,
                    describe(value)
                )),
                Get::NotYet | Get::Table(_) => self.not_supported(row.name),
            }),
        }
    }

    /// `key = value` of a creation call's options (`what` names the call, e.g.
    /// `PhysicsService.New`) as the SDK write the creation request carries. Every writable
    /// row and every creation-only row is an option.
    pub fn option(&self, what: &str, key: &Value, value: &Value) -> Result<T::Prop, LuaError> {
        let not_an_option = |name: &str, why: &str| {
            LuaError::runtime(format!("{what}: {name} {why} (given {})", describe(value)))
        };
        let Some(row) = self.row(key) else {
            return Err(LuaError::runtime(format!(
                "{what}: unknown option {} (given {})",
                describe(key),
                describe(value)
            )));
        };
        let to_prop = match row.set {
            Set::Prop(f) | Set::CreationOnly(f) => f,
            Set::Table { index, .. } => {
                let what = format!("{what} option {}", row.name);
                let arg = row.kind.convert(&what, value)?;
                return self.table_prop(&what, index, arg_to_any(arg)?);
            }
            Set::NotYet => return Err(self.not_supported(row.name)),
            Set::ReadOnly => return Err(not_an_option(row.name, "is read-only, not an option")),
            Set::Fn(_) => return Err(not_an_option(row.name, "cannot be given at creation")),
        };
        to_prop(
            row.kind
                .convert(&format!("{what} option {}", row.name), value)?,
        )
    }
}

impl Kind {
    /// The Lua kind of a settings-table row: its range as the values a script may write
    /// (a clamped row takes any finite value and the daemon clamps it).
    pub const fn of(row: &PropRow) -> Kind {
        match (row.kind, row.range) {
            (PropKind::Bool, _) => Kind::Boolean,
            (PropKind::Float, Range::NonNegative) => Kind::NON_NEGATIVE,
            (PropKind::Float, Range::Positive) => Kind::Positive,
            (PropKind::Float, Range::AtLeast(min)) => Kind::Number {
                min,
                max: f64::INFINITY,
            },
            (PropKind::Float, Range::Within(min, max)) => Kind::Number { min, max },
            (PropKind::Float, _) => Kind::ANY_NUMBER,
            (PropKind::Integer { .. }, Range::Within(min, max)) => Kind::Integer {
                min: min as i64,
                max: max as i64,
            },
            (PropKind::Integer { .. }, Range::Clamped(..)) => Kind::ANY_INTEGER,
            (PropKind::Integer { min, max }, _) => Kind::Integer { min, max },
            (PropKind::Vector, Range::Extent) => Kind::PositiveVector,
            (PropKind::Vector, _) => Kind::Vector,
            (PropKind::Vector2, _) => Kind::Dim,
            (PropKind::Pose, _) => Kind::CFrame,
            // Structured values have rows of their own (methods or custom rows).
            (PropKind::Other, _) => Kind::String,
        }
    }

    /// The Lua kind of the row of `T`'s settings table named `name`.
    pub const fn named(rows: &'static [PropRow], name: &str) -> Kind {
        let mut i = 0;
        while i < rows.len() {
            if client_sdk::settings::table::same_name(rows[i].name, name) {
                return Kind::of(&rows[i]);
            }
            i += 1;
        }
        panic!("no such settings row")
    }
}

/// The Lua rows of a settings table: one per row flagged `lua`, reading the stored value
/// and writing one property of that row.
fn table_rows<T: Target>(rows: &'static [PropRow]) -> Vec<Row<T>> {
    rows.iter()
        .enumerate()
        .filter(|(_, r)| r.lua && r.stored)
        .map(|(index, r)| Row {
            name: r.name,
            kind: Kind::of(r),
            get: Get::Table(index),
            set: Set::Table {
                index,
                creation_only: r.creation_only,
            },
        })
        .collect()
}

/// A converted Lua value as a settings-table value.
fn arg_to_any(arg: Arg) -> Result<AnyValue, LuaError> {
    Ok(match arg {
        Arg::Number(n) => AnyValue::Float(n as f32),
        Arg::Integer(i) => AnyValue::Integer(i),
        Arg::Bool(b) => AnyValue::Bool(b),
        Arg::Vector(v) => AnyValue::Vector(v),
        Arg::Dim(d) => AnyValue::Vector2(d),
        other => return Err(mismatch(&other, "a number, boolean, Vector or Dim")),
    })
}

/// A stored settings value as a Lua value (an `f32` reads back as written).
fn any_to_lua(lua: &Lua, v: AnyValue) -> Result<Value, LuaError> {
    Ok(match v {
        AnyValue::Bool(b) => Value::Boolean(b),
        AnyValue::Float(x) => lua_number(x),
        AnyValue::Integer(i) => Value::Number(i as f64),
        AnyValue::Vector(v) => new_vector(v),
        AnyValue::Vector2(d) => Value::UserData(lua.create_userdata(new_dim(d))?),
    })
}

//! The settings table: one declarative row per property, from which
//! [`settings_table!`](crate::settings_table) derives everything that used to be restated per
//! property: the wire enum (variant order is row order, so the postcard variant indices stay what
//! they were), the settings struct with its defaults, the store into it, the check (errors name the
//! property and the value), and a const slice of [`PropRow`] metadata (name, kind, range, flags,
//! doc) that the SDK's mirror, the Lua property rows, the fuzzer and the definitions test read
//! instead of restating ranges and names.
//!
//! A row reads
//!
//! ```text
//! /// Doc.
//! Weight(f32) "Weight" = 1.0, range: Range::AtLeast(1e-4), field: weight, flags: [derived, lua];
//! ```
//!
//! - `Variant(Type) "Name" = default`: the wire variant, its payload, the API name and the
//!   documented default (a const expression). A struct variant `Variant { a: A, b: B }`
//!   (a pair such as a GUI plane's `Bounds { min, max }`) takes the tuple `(A, B)` as its
//!   payload wherever a row's value is handled (range, check, store, default).
//! - `range: Range::…` (default [`Range::Any`]): checked by the payload's [`PropValue::check`];
//!   the same range gives the Lua row its accepted values.
//! - `check: path`: a further check `fn(T) -> Result<T, CommandError>` after the range.
//! - `field: name` stores the value in the settings struct; `field: name via f => Type =
//!   default` stores it through `f(&mut field, value)` into a field of another type. Rows
//!   without a field live in the engine (poses, velocities, sizes).
//! - `flags: [..]`: the [`PropRow`] booleans that are true for this row.
//!
//! The settings struct may list fields of its own after the rows' fields
//! (`pub struct S { /// doc \n tick_rate: f32 = 60.0 };`), kept and defaulted with them.
//!
//! After the rows, `options: { struct }` also declares the options struct of a creation
//! call: the fields given, then one `Option` per stored row, with `props()`, `set(prop)` and
//! `with(prop)` (plane options).

use crate::{CommandError, Pose, Vec3};

/// What kind of value a property takes (for the Lua rows and the definitions check).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PropKind {
    /// `true` / `false`.
    Bool,
    /// An `f32`.
    Float,
    /// A whole number within the payload type's bounds.
    Integer {
        /// Smallest value of the type.
        min: i64,
        /// Largest value of the type.
        max: i64,
    },
    /// Three `f32` components.
    Vector,
    /// Two `f32` components (GUI planes: pixels).
    Vector2,
    /// A position and a rotation (a CFrame).
    Pose,
    /// A structured value (a restraint, a controller, a GUI option) with its own API.
    Other,
}

/// The values a property accepts. Numbers and vectors are always finite.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Range {
    /// Any value of the type (numbers and vector components finite).
    Any,
    /// A number >= 0.
    NonNegative,
    /// A number > 0.
    Positive,
    /// A number > 0 and at least this.
    AtLeast(f64),
    /// Within `[lo, hi]`, refused outside.
    Within(f64, f64),
    /// Clamped into `[lo, hi]` (what the API documents as clamped); any finite value accepted.
    Clamped(f64, f64),
    /// Vector components within `[-max, max]`.
    Bounded(f64),
    /// Vector components that are part extents (within `[MIN_SIZE, MAX_SIZE]`; errors name
    /// the axis).
    Extent,
    /// Two components in `[-1, 1]` (a motion intent); errors name the axis by these names.
    UnitAxes(&'static str, &'static str),
}

/// One row of a settings table: what every consumer may read about a property.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PropRow {
    /// The property's name in the API (`"CFrame"`, `"SetPin"`, `"TickRate"`).
    pub name: &'static str,
    /// Its documentation (the row's doc comment).
    pub doc: &'static str,
    /// The kind of value it takes.
    pub kind: PropKind,
    /// The values it accepts.
    pub range: Range,
    /// Kept in the family's settings struct (otherwise it lives in the engine).
    pub stored: bool,
    /// A plain Lua property of the type that reads the stored value back.
    pub lua: bool,
    /// Changes what a published body state shows (a client's read-your-writes overlay).
    pub published: bool,
    /// Changes a value the daemon derives (mass, effective iterations): a client's mirror
    /// must read back instead of storing the write.
    pub derived: bool,
    /// Only the creation request may set it.
    pub creation_only: bool,
    /// Changes the forces on resting bodies (which must then wake up).
    pub changes_forces: bool,
    /// The GPU path cannot honour a value other than the default.
    pub cpu_only: bool,
}

impl PropRow {
    /// Every flag false; rows start from it.
    pub const BASE: PropRow = PropRow {
        name: "",
        doc: "",
        kind: PropKind::Other,
        range: Range::Any,
        stored: false,
        lua: false,
        published: false,
        derived: false,
        creation_only: false,
        changes_forces: false,
        cpu_only: false,
    };
}

/// A stored property value as a generic reader (a Lua row) takes it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum AnyValue {
    /// A boolean.
    Bool(bool),
    /// An `f32`.
    Float(f32),
    /// A whole number.
    Integer(i64),
    /// A vector.
    Vector(Vec3),
    /// A 2D vector (GUI planes).
    Vector2([f32; 2]),
}

/// A payload type of a settings row: its kind, its check against a [`Range`], and its
/// conversion to and from [`AnyValue`].
pub trait PropValue: Sized + Copy + PartialEq + std::fmt::Debug {
    /// The kind of value.
    const KIND: PropKind;
    /// The value as the daemon applies it (clamped where `range` says so), or an error
    /// naming `name` and the value.
    fn check(self, name: &str, range: &Range) -> Result<Self, CommandError>;
    /// The value for messages.
    fn text(&self) -> String {
        format!("{self:?}")
    }
    /// The value for a generic reader, if it has a plain form.
    fn to_any(&self) -> Option<AnyValue> {
        None
    }
    /// The value from a generic writer, if `v` is of this kind.
    fn from_any(_v: AnyValue) -> Option<Self> {
        None
    }
}

fn not_in_range(name: &str, range: &Range, value: &dyn std::fmt::Debug) -> CommandError {
    // A row whose range does not fit its type: a table mistake, reported, never a panic.
    CommandError::invalid_field(
        name,
        format!("{name}: range {range:?} does not apply to {value:?}"),
    )
}

impl PropValue for f32 {
    const KIND: PropKind = PropKind::Float;
    fn check(self, name: &str, range: &Range) -> Result<f32, CommandError> {
        use crate::validate::{clamped, finite, in_range, non_negative, positive};
        match *range {
            Range::Any => finite(name, self),
            Range::NonNegative => non_negative(name, self),
            Range::Positive => positive(name, self),
            Range::AtLeast(min) => {
                let v = positive(name, self)?;
                if v < min as f32 {
                    return Err(CommandError::invalid_field(
                        name,
                        format!("{name} must be at least {}, got {v}", min as f32),
                    ));
                }
                Ok(v)
            }
            Range::Within(lo, hi) => in_range(name, self, lo as f32, hi as f32),
            Range::Clamped(lo, hi) => clamped(name, self, lo as f32, hi as f32),
            Range::Bounded(_) | Range::Extent | Range::UnitAxes(..) => {
                Err(not_in_range(name, range, &self))
            }
        }
    }
    fn text(&self) -> String {
        self.to_string()
    }
    fn to_any(&self) -> Option<AnyValue> {
        Some(AnyValue::Float(*self))
    }
    fn from_any(v: AnyValue) -> Option<f32> {
        match v {
            AnyValue::Float(x) => Some(x),
            AnyValue::Integer(i) => Some(i as f32),
            _ => None,
        }
    }
}

/// Checks and converts the whole-number payloads.
macro_rules! integer_value {
    ($t:ty) => {
        impl PropValue for $t {
            const KIND: PropKind = PropKind::Integer {
                min: <$t>::MIN as i64,
                max: <$t>::MAX as i64,
            };
            fn check(self, name: &str, range: &Range) -> Result<$t, CommandError> {
                match *range {
                    Range::Any => Ok(self),
                    Range::Within(lo, hi) => {
                        let (lo, hi) = (lo as $t, hi as $t);
                        if (lo..=hi).contains(&self) {
                            Ok(self)
                        } else {
                            Err(CommandError::invalid_field(
                                name,
                                format!("{name} must be within [{lo}, {hi}], got {self}"),
                            ))
                        }
                    }
                    Range::Clamped(lo, hi) => Ok(self.clamp(lo as $t, hi as $t)),
                    _ => Err(not_in_range(name, range, &self)),
                }
            }
            fn text(&self) -> String {
                self.to_string()
            }
            fn to_any(&self) -> Option<AnyValue> {
                Some(AnyValue::Integer(*self as i64))
            }
            /// Saturates to the type's bounds: a clamped row then clamps as documented.
            fn from_any(v: AnyValue) -> Option<$t> {
                match v {
                    AnyValue::Integer(i) => Some(i.clamp(<$t>::MIN as i64, <$t>::MAX as i64) as $t),
                    _ => None,
                }
            }
        }
    };
}

integer_value!(u32);
integer_value!(u8);
integer_value!(i32);

impl PropValue for bool {
    const KIND: PropKind = PropKind::Bool;
    fn check(self, _name: &str, _range: &Range) -> Result<bool, CommandError> {
        Ok(self)
    }
    fn text(&self) -> String {
        self.to_string()
    }
    fn to_any(&self) -> Option<AnyValue> {
        Some(AnyValue::Bool(*self))
    }
    fn from_any(v: AnyValue) -> Option<bool> {
        match v {
            AnyValue::Bool(b) => Some(b),
            _ => None,
        }
    }
}

impl PropValue for Vec3 {
    const KIND: PropKind = PropKind::Vector;
    fn check(self, name: &str, range: &Range) -> Result<Vec3, CommandError> {
        use crate::validate::{bounded3, finite3, size};
        match *range {
            Range::Any => finite3(name, self),
            Range::Bounded(max) => bounded3(name, self, max as f32),
            Range::Extent => size(name, self),
            _ => Err(not_in_range(name, range, &self)),
        }
    }
    fn to_any(&self) -> Option<AnyValue> {
        Some(AnyValue::Vector(*self))
    }
    fn from_any(v: AnyValue) -> Option<Vec3> {
        match v {
            AnyValue::Vector(v) => Some(v),
            _ => None,
        }
    }
}

impl PropValue for [f32; 2] {
    const KIND: PropKind = PropKind::Vector2;
    fn check(self, name: &str, range: &Range) -> Result<[f32; 2], CommandError> {
        use crate::validate::{extent, finite};
        match *range {
            Range::Any => super::gui_plane::finite2(name, self),
            Range::Extent => Ok([
                extent(&format!("{name}.X"), self[0])?,
                extent(&format!("{name}.Y"), self[1])?,
            ]),
            Range::UnitAxes(a, b) => {
                let unit = |axis: &str, c: f32| {
                    let field = format!("{name}.{axis}");
                    crate::validate::in_range(&field, finite(&field, c)?, -1.0, 1.0)
                };
                Ok([unit(a, self[0])?, unit(b, self[1])?])
            }
            _ => Err(not_in_range(name, range, &self)),
        }
    }
    fn to_any(&self) -> Option<AnyValue> {
        Some(AnyValue::Vector2(*self))
    }
    fn from_any(v: AnyValue) -> Option<[f32; 2]> {
        match v {
            AnyValue::Vector2(v) => Some(v),
            _ => None,
        }
    }
}

impl PropValue for Pose {
    const KIND: PropKind = PropKind::Pose;
    /// A bounded position and a normalised rotation, whatever the range.
    fn check(self, name: &str, _range: &Range) -> Result<Pose, CommandError> {
        crate::validate::pose(name, self)
    }
}

/// Structured payloads: their rows check them with a `check:` function.
macro_rules! structured_value {
    ($($t:ty),*) => {
        $(
            impl PropValue for $t {
                const KIND: PropKind = PropKind::Other;
                fn check(self, _name: &str, _range: &Range) -> Result<$t, CommandError> {
                    Ok(self)
                }
            }
        )*
    };
}

structured_value!(
    (super::gui_plane::Vec2, super::gui_plane::Vec2),
    super::object::Restraint,
    Option<super::object::RotateTo>,
    Option<super::object::Pin>,
    super::gui_plane::GuiPlaneProp,
    Option<f32>
);

/// The payload type of a row's variant: `(T)` gives `T`, `{ a: A, b: B }` gives `(A, B)`.
#[doc(hidden)]
#[macro_export]
macro_rules! __table_ty {
    (($t:ty)) => {
        $t
    };
    ({ $($(#[$m:meta])* $f:ident : $ft:ty),+ $(,)? }) => {
        ($($ft),+)
    };
}

/// A pattern of a row's variant binding its payload: `$v` for a tuple variant, the
/// fields by their names for a struct variant (see [`__table_payload`]).
#[doc(hidden)]
#[macro_export]
macro_rules! __table_pat {
    ($E:ident :: $V:ident ($t:ty); $v:ident) => {
        $E::$V($v)
    };
    ($E:ident :: $V:ident { $($(#[$m:meta])* $f:ident : $ft:ty),+ $(,)? }; $v:ident) => {
        $E::$V { $($f),+ }
    };
}

/// A pattern of a row's variant that binds nothing.
#[doc(hidden)]
#[macro_export]
macro_rules! __table_pat_any {
    ($E:ident :: $V:ident ($t:ty)) => {
        $E::$V(..)
    };
    ($E:ident :: $V:ident { $($body:tt)* }) => {
        $E::$V { .. }
    };
}

/// The payload bound by [`__table_pat`], as one value.
#[doc(hidden)]
#[macro_export]
macro_rules! __table_payload {
    (($t:ty); $v:ident) => {
        $v
    };
    ({ $($(#[$m:meta])* $f:ident : $ft:ty),+ $(,)? }; $v:ident) => {
        ($($f),+)
    };
}

/// The row's variant holding the payload `$v`.
#[doc(hidden)]
#[macro_export]
macro_rules! __table_build {
    ($E:ident :: $V:ident ($t:ty); $v:expr) => {
        $E::$V($v)
    };
    ($E:ident :: $V:ident { $($(#[$m:meta])* $f:ident : $ft:ty),+ $(,)? }; $v:expr) => {{
        let ($($f),+) = $v;
        $E::$V { $($f),+ }
    }};
}

/// Declares the prop enum from its rows' variants (tuple or struct variants).
#[doc(hidden)]
#[macro_export]
macro_rules! __table_enum {
    ([$(#[$m:meta])*] $E:ident [$($done:tt)*]) => {
        $(#[$m])*
        pub enum $E {
            $($done)*
        }
    };
    ($meta:tt $E:ident [$($done:tt)*] [$(#[doc = $doc:literal])*] $V:ident $shape:tt $($rest:tt)*) => {
        $crate::__table_enum! { $meta $E [$($done)* $(#[doc = $doc])* $V $shape,] $($rest)* }
    };
}

/// `$a` when given, else `$b` (a type).
#[doc(hidden)]
#[macro_export]
macro_rules! __table_pick_ty {
    ([] $b:ty) => {
        $b
    };
    ([$a:ty] $b:ty) => {
        $a
    };
}

/// `$a` when given, else `$b` (an expression).
#[doc(hidden)]
#[macro_export]
macro_rules! __table_pick {
    ([] $b:expr) => {
        $b
    };
    ([$a:expr] $b:expr) => {
        $a
    };
}

/// Whether a row has a field.
#[doc(hidden)]
#[macro_export]
macro_rules! __table_has {
    ([]) => {
        false
    };
    ([$($t:tt)+]) => {
        true
    };
}

/// Stores `$v` into the row's field, or reports that the row lives in the engine.
#[doc(hidden)]
#[macro_export]
macro_rules! __table_store {
    ($s:ident, $v:ident;) => {{
        let _ = $v;
        return false;
    }};
    ($s:ident, $v:ident; $field:ident) => {
        $s.$field = $v
    };
    ($s:ident, $v:ident; $field:ident via $via:path) => {
        $via(&mut $s.$field, $v)
    };
}

/// Whether the row's field holds its default.
#[doc(hidden)]
#[macro_export]
macro_rules! __table_is_default {
    ($s:ident, $default:expr;) => {
        true
    };
    ($s:ident, $default:expr; $field:ident) => {
        $s.$field == $default
    };
    ($s:ident, $default:expr; $field:ident via $via:path, $fdefault:expr) => {
        $s.$field == $fdefault
    };
}

/// Reads the row's field for a generic reader (fields stored in another form have none).
#[doc(hidden)]
#[macro_export]
macro_rules! __table_get {
    ($s:ident;) => {
        None
    };
    ($s:ident; $field:ident) => {
        $crate::settings::table::PropValue::to_any(&$s.$field)
    };
    ($s:ident; $field:ident via $via:path) => {
        None
    };
}

/// The options struct of a creation call (see [`settings_table!`]'s `options:`): one
/// `Option` per stored row (`None` keeps the default) after the fields given, with a builder
/// over the prop enum.
#[doc(hidden)]
#[macro_export]
macro_rules! __table_options {
    ([] $($rest:tt)*) => {};
    (
        [{
            $(#[$ometa:meta])*
            pub struct $Options:ident { $($extra:tt)* }
        }]
        $Enum:ident;
        $([$Variant:ident($ty:ty) $name:literal $($field:ident)?])*
    ) => {
        $(#[$ometa])*
        pub struct $Options {
            $($extra)*
            $($(
                #[doc = concat!("`", $name, "` (see [`", stringify!($Enum), "::",
                    stringify!($Variant), "`]); `None` keeps the default.")]
                pub $field: Option<$ty>,
            )?)*
        }

        impl $Options {
            /// The options set, as the creation request carries them (in row order).
            pub fn props(&self) -> Vec<$Enum> {
                let mut props = Vec::new();
                $($(
                    if let Some(v) = self.$field {
                        props.push($Enum::$Variant(v));
                    }
                )?)*
                props
            }

            /// Sets the option `prop` stands for; false (and nothing set) for a prop that is
            /// not an option of this call.
            pub fn set(&mut self, prop: $Enum) -> bool {
                match prop {
                    $(
                        $Enum::$Variant(v) => {
                            $(
                                self.$field = Some(v);
                                return true;
                            )?
                            #[allow(unreachable_code)]
                            {
                                let _ = v;
                                false
                            }
                        }
                    )*
                }
            }

            /// Builder form of [`Self::set`]: `PlaneOptions::manual().with(PlaneProp::Drag(0.1))`.
            pub fn with(mut self, prop: $Enum) -> Self {
                self.set(prop);
                self
            }
        }
    };
}

/// Declares one settings family from its rows (see the [module docs](self)): the prop
/// enum, the settings struct with [`Default`], and on the enum `ROWS`, `DEFAULTS`, `index`,
/// `row`, `checked`, `is_default`, `value_text` and `from_any`; on the struct `store` and
/// `get`.
#[macro_export]
macro_rules! settings_table {
    (
        $(#[$emeta:meta])*
        pub enum $Enum:ident;
        $(#[$smeta:meta])*
        pub struct $Settings:ident
            $({ $($(#[doc = $xdoc:literal])* $xfield:ident : $xty:ty = $xdefault:expr),* $(,)? })?;
        rows {
            $(
                $(#[doc = $doc:literal])*
                $Variant:ident $shape:tt $name:literal = $default:expr
                    $(, range: $range:expr)?
                    $(, check: $check:path)?
                    $(, field: $field:ident $(via $via:path => $fty:ty = $fdefault:expr)?)?
                    $(, flags: [$($flag:ident),* $(,)?])?
                ;
            )*
        }
        $(options: $options:tt)?
    ) => {
        $crate::__table_options! {
            [$($options)?] $Enum;
            $([$Variant($crate::__table_ty!($shape)) $name $($field)?])*
        }

        $crate::__table_enum! {
            [$(#[$emeta])*] $Enum []
            $([$(#[doc = $doc])*] $Variant $shape)*
        }

        $(#[$smeta])*
        pub struct $Settings {
            $($(
                #[doc = concat!("`", $name, "` (see [`", stringify!($Enum), "::",
                    stringify!($Variant), "`]).")]
                pub $field: $crate::__table_pick_ty!([$($fty)?] $crate::__table_ty!($shape)),
            )?)*
            $($(
                $(#[doc = $xdoc])*
                pub $xfield: $xty,
            )*)?
        }

        impl Default for $Settings {
            fn default() -> Self {
                $Settings {
                    $($(
                        $field: $crate::__table_pick!([$($fdefault)?] $default),
                    )?)*
                    $($(
                        $xfield: $xdefault,
                    )*)?
                }
            }
        }

        impl $Settings {
            /// Stores a checked property. Returns false for the properties that live in
            /// the engine instead, leaving the settings unchanged.
            pub fn store(&mut self, prop: &$Enum) -> bool {
                match *prop {
                    $(
                        $crate::__table_pat!($Enum::$Variant $shape; v) => {
                            let v = $crate::__table_payload!($shape; v);
                            $crate::__table_store!(self, v; $($field $(via $via)?)?)
                        }
                    )*
                }
                true
            }

            /// Whether the row at `index` of the prop enum's `ROWS` holds its default (rows
            /// that live in the engine always do).
            #[allow(unused_assignments)]
            pub fn is_default_at(&self, index: usize) -> bool {
                let mut i = 0;
                $(
                    if i == index {
                        return $crate::__table_is_default!(self, $default;
                            $($field $(via $via, $fdefault)?)?);
                    }
                    i += 1;
                )*
                true
            }

            /// The stored value of the row at `index` of the prop enum's `ROWS`, for a
            /// generic reader; `None` for rows not stored plainly.
            #[allow(unused_assignments)]
            pub fn get(&self, index: usize) -> Option<$crate::settings::table::AnyValue> {
                let mut i = 0;
                $(
                    if i == index {
                        return $crate::__table_get!(self; $($field $(via $via)?)?);
                    }
                    i += 1;
                )*
                None
            }
        }

        impl $Enum {
            /// One row per variant, in variant order.
            pub const ROWS: &'static [$crate::settings::table::PropRow] = &[
                $(
                    $crate::settings::table::PropRow {
                        name: $name,
                        doc: concat!($($doc, "\n"),*),
                        kind: <$crate::__table_ty!($shape) as $crate::settings::table::PropValue>::KIND,
                        range: $crate::__table_pick!([$($range)?]
                            $crate::settings::table::Range::Any),
                        stored: $crate::__table_has!([$($field)?]),
                        $($($flag: true,)*)?
                        ..$crate::settings::table::PropRow::BASE
                    },
                )*
            ];

            /// Every variant at its documented default, in variant order.
            pub const DEFAULTS: &'static [$Enum] =
                &[$($crate::__table_build!($Enum::$Variant $shape; $default),)*];

            /// The variant's position in [`Self::ROWS`] (its wire index).
            pub const fn index(&self) -> usize {
                #[allow(dead_code, clippy::enum_variant_names)]
                enum Index {
                    $($Variant,)*
                }
                match self {
                    $($crate::__table_pat_any!($Enum::$Variant $shape) => Index::$Variant as usize,)*
                }
            }

            /// The variant's row.
            pub const fn row(&self) -> &'static $crate::settings::table::PropRow {
                &Self::ROWS[self.index()]
            }

            /// The row named `name` (a compile error in a const context when none is).
            pub const fn row_named(name: &str) -> &'static $crate::settings::table::PropRow {
                let mut i = 0;
                while i < Self::ROWS.len() {
                    if $crate::settings::table::same_name(Self::ROWS[i].name, name) {
                        return &Self::ROWS[i];
                    }
                    i += 1;
                }
                panic!("no such property row")
            }

            /// Whether the value is the row's documented default.
            pub fn is_default(&self) -> bool {
                match *self {
                    $($crate::__table_pat!($Enum::$Variant $shape; v) => {
                        $crate::__table_payload!($shape; v) == $default
                    })*
                }
            }

            /// The value for messages.
            pub fn value_text(&self) -> String {
                match *self {
                    $($crate::__table_pat!($Enum::$Variant $shape; v) => {
                        $crate::settings::table::PropValue::text(
                            &$crate::__table_payload!($shape; v),
                        )
                    })*
                }
            }

            /// The property as the daemon applies it (its range, then its own check), or an
            /// error naming it and the value.
            pub fn checked(self) -> Result<$Enum, $crate::CommandError> {
                Ok(match self {
                    $(
                        $crate::__table_pat!($Enum::$Variant $shape; v) => {
                            let v = $crate::settings::table::PropValue::check(
                                $crate::__table_payload!($shape; v),
                                $name,
                                &$crate::__table_pick!([$($range)?]
                                    $crate::settings::table::Range::Any),
                            )?;
                            $(let v = $check(v)?;)?
                            $crate::__table_build!($Enum::$Variant $shape; v)
                        }
                    )*
                })
            }

            /// The property of the row at `index` with the value `v` from a generic writer
            /// (unchecked), or `None` when `v` is not of the row's kind.
            #[allow(unused_assignments)]
            pub fn from_any(index: usize, v: $crate::settings::table::AnyValue) -> Option<$Enum> {
                let mut i = 0;
                $(
                    if i == index {
                        return <$crate::__table_ty!($shape) as $crate::settings::table::PropValue>::from_any(v)
                            .map(|v| $crate::__table_build!($Enum::$Variant $shape; v));
                    }
                    i += 1;
                )*
                None
            }
        }
    };
}

/// Byte equality of two names, usable in const contexts.
pub const fn same_name(a: &str, b: &str) -> bool {
    let (a, b) = (a.as_bytes(), b.as_bytes());
    if a.len() != b.len() {
        return false;
    }
    let mut i = 0;
    while i < a.len() {
        if a[i] != b[i] {
            return false;
        }
        i += 1;
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{ObjectProp, ObjectSettings, PlaneProp, PlaneSettings};

    /// The wire index of each variant is its row's index, and the rows keep the order the
    /// wire had before the table (a reordering would change every encoded command).
    #[test]
    fn wire_order_is_row_order() {
        // New rows go last: only the prefix that existed is pinned.
        let names: Vec<&str> = ObjectProp::ROWS.iter().map(|r| r.name).collect();
        assert_eq!(
            names[..20],
            [
                "CFrame",
                "Velocity",
                "AngularVelocity",
                "Anchored",
                "ReportContacts",
                "Weight",
                "Density",
                "Bounciness",
                "Friction",
                "CanCollide",
                "HitBoxQuality",
                "Size",
                "CenterOfMass",
                "ImpulseDirection",
                "ConstantForce",
                "FieldRestraint",
                "RotateTo",
                "SetPin",
                "CollisionGroup",
                "Held",
            ]
        );
        let names: Vec<&str> = PlaneProp::ROWS.iter().map(|r| r.name).collect();
        assert_eq!(
            names[..19],
            [
                "Gravity",
                "Threads",
                "TickRate",
                "Enabled",
                "LinearDamping",
                "AngularDamping",
                "Drag",
                "Buoyancy",
                "ConstantForce",
                "RestThreshold",
                "SolverIterations",
                "LoopSolver",
                "NeverSleep",
                "Shared",
                "MaxLinearSpeed",
                "MaxAngularSpeed",
                "DeferGpu",
                "Gui",
                "SharedObjectLimit",
            ]
        );
        for (i, p) in ObjectProp::DEFAULTS.iter().enumerate() {
            assert_eq!(p.index(), i);
            assert_eq!(postcard::to_allocvec(p).unwrap()[0] as usize, i, "{p:?}");
        }
        for (i, p) in PlaneProp::DEFAULTS.iter().enumerate() {
            assert_eq!(p.index(), i);
            assert_eq!(postcard::to_allocvec(p).unwrap()[0] as usize, i, "{p:?}");
        }
    }

    /// The defaults of the rows are valid, unchanged by their check, and what the settings
    /// struct's `Default` holds.
    #[test]
    fn row_defaults_are_valid_and_match_the_settings_defaults() {
        let mut s = ObjectSettings::default();
        for p in ObjectProp::DEFAULTS {
            assert_eq!(p.checked().unwrap(), *p);
            assert!(p.is_default());
            assert_eq!(s.store(p), p.row().stored, "{p:?}");
        }
        assert_eq!(s, ObjectSettings::default());
        let mut s = PlaneSettings::default();
        for p in PlaneProp::DEFAULTS {
            assert_eq!(p.checked().unwrap(), *p);
            assert_eq!(s.store(p), p.row().stored, "{p:?}");
        }
        assert_eq!(s, PlaneSettings::default());
    }

    /// A generic reader gets back what a generic writer stored, for every plain row.
    #[test]
    fn generic_values_round_trip() {
        let mut s = ObjectSettings::default();
        let friction = ObjectProp::Friction(0.0).index();
        assert_eq!(ObjectProp::row_named("Friction").kind, PropKind::Float);
        let p = ObjectProp::from_any(friction, AnyValue::Float(0.25)).unwrap();
        assert_eq!(p, ObjectProp::Friction(0.25));
        s.store(&p);
        assert_eq!(s.get(p.index()), Some(AnyValue::Float(0.25)));
        // A value of another kind makes no property.
        assert_eq!(ObjectProp::from_any(p.index(), AnyValue::Bool(true)), None);
        // Integers saturate to the payload type; the row's clamp then applies.
        let q = ObjectProp::from_any(ObjectProp::HitBoxQuality(1).index(), AnyValue::Integer(-5))
            .unwrap();
        assert_eq!(q.checked().unwrap(), ObjectProp::HitBoxQuality(1));
        // Rows stored in another form have no plain value.
        assert_eq!(
            s.get(ObjectProp::FieldRestraint(Restraint::KEEP).index()),
            None
        );
        assert!(ObjectProp::row_named("SetPin").cpu_only);
    }

    use crate::settings::Restraint;

    /// `PlaneOptions` has one option per stored plane row, and its builder over `PlaneProp`
    /// and its struct literal make the same creation request.
    #[test]
    fn plane_options_are_a_builder_over_plane_props() {
        use crate::PlaneOptions;
        let mut all = PlaneOptions::default();
        for p in PlaneProp::DEFAULTS {
            assert_eq!(all.set(*p), p.row().stored, "{p:?}");
        }
        let stored: Vec<PlaneProp> = PlaneProp::DEFAULTS
            .iter()
            .copied()
            .filter(|p| p.row().stored)
            .collect();
        assert_eq!(all.props(), stored);
        let built = PlaneOptions::manual()
            .with(PlaneProp::Drag(0.25))
            .with(PlaneProp::Threads(2));
        let literal = PlaneOptions {
            tick_rate: Some(0.0),
            drag: Some(0.25),
            threads: Some(2),
            ..Default::default()
        };
        assert_eq!(built.props(), literal.props());
        assert_eq!(
            built.props(),
            [
                PlaneProp::Threads(2),
                PlaneProp::TickRate(0.0),
                PlaneProp::Drag(0.25)
            ]
        );
        assert!(!PlaneOptions::default().set(PlaneProp::Gui(crate::GuiPlaneProp::NeverSleep(true))));
    }
}

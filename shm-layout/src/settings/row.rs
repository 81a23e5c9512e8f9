//! What one row of a settings table says about its property ([`PropRow`]: name, kind,
//! range, flags, doc), and the payload types a row may take ([`PropValue`]: their kind,
//! their check against a [`Range`], their conversion to and from [`AnyValue`]). The table
//! machinery that declares the rows is [`super::table`].

use crate::error::CommandError;
use crate::geometry::{Pose, Vec3};

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
    /// A map (a static triangle mesh) may change it; maps refuse every other property.
    pub on_maps: bool,
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
        on_maps: false,
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
        use crate::validate::{extent, finite, finite2};
        match *range {
            Range::Any => finite2(name, self),
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

/// Structured payloads: their rows check them with a `check:` function (the families'
/// own types implement [`PropValue`] through it in their files).
macro_rules! structured_value {
    ($($t:ty),*) => {
        $(
            impl $crate::settings::row::PropValue for $t {
                const KIND: $crate::settings::row::PropKind = $crate::settings::row::PropKind::Other;
                fn check(
                    self,
                    _name: &str,
                    _range: &$crate::settings::row::Range,
                ) -> Result<$t, $crate::error::CommandError> {
                    Ok(self)
                }
            }
        )*
    };
}
pub(crate) use structured_value;

structured_value!(Option<f32>);

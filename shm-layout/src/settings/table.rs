//! The settings table: one declarative row per property, from which
//! `settings_table!` derives everything that used to be restated per
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

pub use super::row::{AnyValue, PropKind, PropRow, PropValue, Range};

/// The payload type of a row's variant: `(T)` gives `T`, `{ a: A, b: B }` gives `(A, B)`.
macro_rules! __table_ty {
    (($t:ty)) => {
        $t
    };
    ({ $($(#[$m:meta])* $f:ident : $ft:ty),+ $(,)? }) => {
        ($($ft),+)
    };
}
pub(crate) use __table_ty;

/// A pattern of a row's variant binding its payload: `$v` for a tuple variant, the
/// fields by their names for a struct variant (see [`__table_payload`]).
macro_rules! __table_pat {
    ($E:ident :: $V:ident ($t:ty); $v:ident) => {
        $E::$V($v)
    };
    ($E:ident :: $V:ident { $($(#[$m:meta])* $f:ident : $ft:ty),+ $(,)? }; $v:ident) => {
        $E::$V { $($f),+ }
    };
}
pub(crate) use __table_pat;

/// A pattern of a row's variant that binds nothing.
macro_rules! __table_pat_any {
    ($E:ident :: $V:ident ($t:ty)) => {
        $E::$V(..)
    };
    ($E:ident :: $V:ident { $($body:tt)* }) => {
        $E::$V { .. }
    };
}
pub(crate) use __table_pat_any;

/// The payload bound by [`__table_pat`], as one value.
macro_rules! __table_payload {
    (($t:ty); $v:ident) => {
        $v
    };
    ({ $($(#[$m:meta])* $f:ident : $ft:ty),+ $(,)? }; $v:ident) => {
        ($($f),+)
    };
}
pub(crate) use __table_payload;

/// The row's variant holding the payload `$v`.
macro_rules! __table_build {
    ($E:ident :: $V:ident ($t:ty); $v:expr) => {
        $E::$V($v)
    };
    ($E:ident :: $V:ident { $($(#[$m:meta])* $f:ident : $ft:ty),+ $(,)? }; $v:expr) => {{
        let ($($f),+) = $v;
        $E::$V { $($f),+ }
    }};
}
pub(crate) use __table_build;

/// Declares the prop enum from its rows' variants (tuple or struct variants).
macro_rules! __table_enum {
    ([$(#[$m:meta])*] $E:ident [$($done:tt)*]) => {
        $(#[$m])*
        pub enum $E {
            $($done)*
        }
    };
    ($meta:tt $E:ident [$($done:tt)*] [$(#[doc = $doc:literal])*] $V:ident $shape:tt $($rest:tt)*) => {
        $crate::settings::table::__table_enum! { $meta $E [$($done)* $(#[doc = $doc])* $V $shape,] $($rest)* }
    };
}
pub(crate) use __table_enum;

/// `$a` when given, else `$b` (a type).
macro_rules! __table_pick_ty {
    ([] $b:ty) => {
        $b
    };
    ([$a:ty] $b:ty) => {
        $a
    };
}
pub(crate) use __table_pick_ty;

/// `$a` when given, else `$b` (an expression).
macro_rules! __table_pick {
    ([] $b:expr) => {
        $b
    };
    ([$a:expr] $b:expr) => {
        $a
    };
}
pub(crate) use __table_pick;

/// Whether a row has a field.
macro_rules! __table_has {
    ([]) => {
        false
    };
    ([$($t:tt)+]) => {
        true
    };
}
pub(crate) use __table_has;

/// Stores `$v` into the row's field, or reports that the row lives in the engine.
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
pub(crate) use __table_store;

/// Whether the row's field holds its default.
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
pub(crate) use __table_is_default;

/// Reads the row's field for a generic reader (fields stored in another form have none).
macro_rules! __table_get {
    ($s:ident;) => {
        None
    };
    ($s:ident; $field:ident) => {
        $crate::settings::row::PropValue::to_any(&$s.$field)
    };
    ($s:ident; $field:ident via $via:path) => {
        None
    };
}
pub(crate) use __table_get;

/// The options struct of a creation call (see [`settings_table!`]'s `options:`): one
/// `Option` per stored row (`None` keeps the default) after the fields given, with a builder
/// over the prop enum.
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
pub(crate) use __table_options;

/// Declares one settings family from its rows (see the [module docs](self)): the prop
/// enum, the settings struct with [`Default`], and on the enum `ROWS`, `DEFAULTS`, `index`,
/// `row`, `checked`, `is_default`, `value_text` and `from_any`; on the struct `store` and
/// `get`.
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
        $crate::settings::table::__table_options! {
            [$($options)?] $Enum;
            $([$Variant($crate::settings::table::__table_ty!($shape)) $name $($field)?])*
        }

        $crate::settings::table::__table_enum! {
            [$(#[$emeta])*] $Enum []
            $([$(#[doc = $doc])*] $Variant $shape)*
        }

        $(#[$smeta])*
        pub struct $Settings {
            $($(
                #[doc = concat!("`", $name, "` (see [`", stringify!($Enum), "::",
                    stringify!($Variant), "`]).")]
                pub $field: $crate::settings::table::__table_pick_ty!([$($fty)?] $crate::settings::table::__table_ty!($shape)),
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
                        $field: $crate::settings::table::__table_pick!([$($fdefault)?] $default),
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
                        $crate::settings::table::__table_pat!($Enum::$Variant $shape; v) => {
                            let v = $crate::settings::table::__table_payload!($shape; v);
                            $crate::settings::table::__table_store!(self, v; $($field $(via $via)?)?)
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
                        return $crate::settings::table::__table_is_default!(self, $default;
                            $($field $(via $via, $fdefault)?)?);
                    }
                    i += 1;
                )*
                true
            }

            /// The stored value of the row at `index` of the prop enum's `ROWS`, for a
            /// generic reader; `None` for rows not stored plainly.
            #[allow(unused_assignments)]
            pub fn get(&self, index: usize) -> Option<$crate::settings::row::AnyValue> {
                let mut i = 0;
                $(
                    if i == index {
                        return $crate::settings::table::__table_get!(self; $($field $(via $via)?)?);
                    }
                    i += 1;
                )*
                None
            }
        }

        impl $Enum {
            /// One row per variant, in variant order.
            pub const ROWS: &'static [$crate::settings::row::PropRow] = &[
                $(
                    $crate::settings::row::PropRow {
                        name: $name,
                        doc: concat!($($doc, "\n"),*),
                        kind: <$crate::settings::table::__table_ty!($shape) as $crate::settings::row::PropValue>::KIND,
                        range: $crate::settings::table::__table_pick!([$($range)?]
                            $crate::settings::row::Range::Any),
                        stored: $crate::settings::table::__table_has!([$($field)?]),
                        $($($flag: true,)*)?
                        ..$crate::settings::row::PropRow::BASE
                    },
                )*
            ];

            /// Every variant at its documented default, in variant order.
            pub const DEFAULTS: &'static [$Enum] =
                &[$($crate::settings::table::__table_build!($Enum::$Variant $shape; $default),)*];

            /// The variant's position in [`Self::ROWS`] (its wire index).
            pub const fn index(&self) -> usize {
                #[allow(dead_code, clippy::enum_variant_names)]
                enum Index {
                    $($Variant,)*
                }
                match self {
                    $($crate::settings::table::__table_pat_any!($Enum::$Variant $shape) => Index::$Variant as usize,)*
                }
            }

            /// The variant's row.
            pub const fn row(&self) -> &'static $crate::settings::row::PropRow {
                &Self::ROWS[self.index()]
            }

            /// The row named `name` (a compile error in a const context when none is).
            pub const fn row_named(name: &str) -> &'static $crate::settings::row::PropRow {
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
                    $($crate::settings::table::__table_pat!($Enum::$Variant $shape; v) => {
                        $crate::settings::table::__table_payload!($shape; v) == $default
                    })*
                }
            }

            /// The value for messages.
            pub fn value_text(&self) -> String {
                match *self {
                    $($crate::settings::table::__table_pat!($Enum::$Variant $shape; v) => {
                        $crate::settings::row::PropValue::text(
                            &$crate::settings::table::__table_payload!($shape; v),
                        )
                    })*
                }
            }

            /// The property as the daemon applies it (its range, then its own check), or an
            /// error naming it and the value.
            pub fn checked(self) -> Result<$Enum, $crate::error::CommandError> {
                Ok(match self {
                    $(
                        $crate::settings::table::__table_pat!($Enum::$Variant $shape; v) => {
                            let v = $crate::settings::row::PropValue::check(
                                $crate::settings::table::__table_payload!($shape; v),
                                $name,
                                &$crate::settings::table::__table_pick!([$($range)?]
                                    $crate::settings::row::Range::Any),
                            )?;
                            $(let v = $check(v)?;)?
                            $crate::settings::table::__table_build!($Enum::$Variant $shape; v)
                        }
                    )*
                })
            }

            /// The property of the row at `index` with the value `v` from a generic writer
            /// (unchecked), or `None` when `v` is not of the row's kind.
            #[allow(unused_assignments)]
            pub fn from_any(index: usize, v: $crate::settings::row::AnyValue) -> Option<$Enum> {
                let mut i = 0;
                $(
                    if i == index {
                        return <$crate::settings::table::__table_ty!($shape) as $crate::settings::row::PropValue>::from_any(v)
                            .map(|v| $crate::settings::table::__table_build!($Enum::$Variant $shape; v));
                    }
                    i += 1;
                )*
                None
            }
        }
    };
}
pub(crate) use settings_table;

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

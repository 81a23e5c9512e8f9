//! GUI plane options (`PhysicsService.NewGUI`): the wire variant, the defaults and the checks
//! of each. They travel as [`PlaneProp::Gui`](crate::PlaneProp::Gui) next to the options every
//! plane kind takes (`TickRate`, `Enabled`, `Shared`). Units are pixels and seconds, +Y down.
//! One row each in the GUI plane settings table (`settings_table!`): wire variant, name,
//! default, range, stored field, flags; the Lua rows of `GuiPhysicsPlane` come from it.

use serde::{Deserialize, Serialize};

use super::row::{structured_value, Range};
use crate::error::CommandError;

pub use crate::geometry::Vec2;
pub use crate::validate::finite2;

/// Largest `SolverIterations` of a GUI plane (the reference clamps to 1..32).
pub const MAX_GUI_SOLVER_ITERATIONS: u32 = 32;

super::table::settings_table! {
    /// An option of a GUI plane.
    #[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
    pub enum GuiPlaneProp;
    /// Every option of a GUI plane, as set. [`Default`] holds the documented defaults.
    #[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
    pub struct GuiPlaneSettings {
        /// `TickRate` (the common plane option), default 60; 0 = manual.
        tick_rate: f32 = 60.0,
        /// `Enabled` (the common plane option), default true.
        enabled: bool = true,
        /// `Shared` (the common plane option), default false.
        shared: bool = false,
    };
    rows {
        /// Acceleration of every non-anchored body (px/s², +Y down). Default (0, 980).
        Gravity(Vec2) "Gravity" = [0.0, 980.0], field: gravity, flags: [changes_forces, lua];
        /// Per-second linear damping: each tick `v *= max(0, 1 - k·dt)`. Default 0.05.
        LinearDamping(f32) "LinearDamping" = 0.05, range: Range::NonNegative,
            field: linear_damping, flags: [lua];
        /// The same for angular velocity. Default 0.10.
        AngularDamping(f32) "AngularDamping" = 0.10, range: Range::NonNegative,
            field: angular_damping, flags: [lua];
        /// Quadratic drag coefficient: `F = -Drag·|v|·v`. Default 0.
        Drag(f32) "Drag" = 0.0, range: Range::NonNegative, field: drag, flags: [lua];
        /// Force on every non-anchored body (px·mass/s²). Default (0, 0).
        ConstantForce(Vec2) "ConstantForce" = [0.0; 2], field: constant_force,
            flags: [changes_forces, lua];
        /// Speed (px/s) below which a body's sleep timer runs; after 0.5 s it sleeps. 0
        /// disables sleeping. Default 0.25.
        RestThreshold(f32) "RestThreshold" = 0.25, range: Range::NonNegative,
            field: rest_threshold, flags: [lua];
        /// Solver iterations per tick, clamped to [1, 32]. Default 4.
        SolverIterations(u32) "SolverIterations" = 4,
            range: Range::Clamped(1.0, MAX_GUI_SOLVER_ITERATIONS as f64),
            field: solver_iterations, flags: [lua];
        /// Keeps every body awake. Default false.
        NeverSleep(bool) "NeverSleep" = false, field: never_sleep, flags: [lua];
        /// Creation only: bodies are kept inside the rectangle `min`..`max` and bounce off
        /// its sides with their own Bounciness. None by default (unbounded; the row's default
        /// pair is no valid rectangle).
        Bounds {
            /// Top-left corner.
            min: Vec2,
            /// Bottom-right corner.
            max: Vec2,
        } "Bounds" = ([0.0; 2], [0.0; 2]), check: check_bounds,
            field: bounds via store_bounds => Option<(Vec2, Vec2)> = None,
            flags: [creation_only];
    }
}

// Structured payloads: their rows check them with a `check:` function.
structured_value!((Vec2, Vec2), GuiPlaneProp);

/// `Bounds`: both corners finite, `max` at least 1 px right of and below `min`.
fn check_bounds((min, max): (Vec2, Vec2)) -> Result<(Vec2, Vec2), CommandError> {
    let min = finite2("BoundsMin", min)?;
    let max = finite2("BoundsMax", max)?;
    if max[0] - min[0] < 1.0 || max[1] - min[1] < 1.0 {
        return Err(CommandError::invalid_field(
            "BoundsMax",
            format!(
                "BoundsMax must be at least 1 px right of and below BoundsMin, got BoundsMin \
                 Dim({}, {}), BoundsMax Dim({}, {})",
                min[0], min[1], max[0], max[1]
            ),
        ));
    }
    Ok((min, max))
}

/// Stores `Bounds` (the settings hold `None` while unbounded).
fn store_bounds(field: &mut Option<(Vec2, Vec2)>, v: (Vec2, Vec2)) {
    *field = Some(v);
}

/// Seconds a body must stay below `RestThreshold` before it sleeps.
pub const GUI_TIME_UNTIL_SLEEP: f32 = 0.5;

impl GuiPlaneSettings {
    /// Checks `prop` and stores it; `creating` allows `Bounds`. Returns the option as stored.
    pub fn apply(
        &mut self,
        prop: GuiPlaneProp,
        creating: bool,
    ) -> Result<GuiPlaneProp, CommandError> {
        let prop = prop.checked()?;
        if let GuiPlaneProp::Bounds { min, max } = prop {
            if !creating {
                return Err(CommandError::invalid_field(
                    "Bounds",
                    format!(
                        "BoundsMin / BoundsMax are construction-only (tried to set \
                         Dim({}, {}) to Dim({}, {}))",
                        min[0], min[1], max[0], max[1]
                    ),
                ));
            }
        }
        self.store(&prop);
        Ok(prop)
    }
}

impl GuiPlaneProp {
    /// The option's name in the API.
    pub fn name(&self) -> &'static str {
        self.row().name
    }

    /// Options that change the forces on resting bodies (which must then wake up).
    pub fn changes_forces(&self) -> bool {
        self.row().changes_forces
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_and_checks() {
        let mut s = GuiPlaneSettings::default();
        assert_eq!(s.gravity, [0.0, 980.0]);
        assert!(s.apply(GuiPlaneProp::Drag(f32::NAN), false).is_err());
        let e = s
            .apply(GuiPlaneProp::Gravity([0.0, f32::INFINITY]), false)
            .unwrap_err();
        assert!(e.message.contains("Gravity.Y"), "{}", e.message);
        assert_eq!(
            s.apply(GuiPlaneProp::SolverIterations(99), false).unwrap(),
            GuiPlaneProp::SolverIterations(32)
        );
        let bounds = GuiPlaneProp::Bounds {
            min: [0.0, 0.0],
            max: [100.0, 100.0],
        };
        assert!(s.apply(bounds, false).is_err());
        assert!(s.apply(bounds, true).is_ok());
        assert!(GuiPlaneProp::Bounds {
            min: [10.0, 0.0],
            max: [5.0, 100.0]
        }
        .checked()
        .is_err());
    }

    /// The table keeps the wire: variant indices, the struct variant's fields, and the
    /// settings' fields in the order (and with the defaults) they had before the table.
    #[test]
    fn the_table_keeps_the_wire_and_the_defaults() {
        let names: Vec<&str> = GuiPlaneProp::ROWS.iter().map(|r| r.name).collect();
        assert_eq!(
            names,
            [
                "Gravity",
                "LinearDamping",
                "AngularDamping",
                "Drag",
                "ConstantForce",
                "RestThreshold",
                "SolverIterations",
                "NeverSleep",
                "Bounds"
            ]
        );
        for (i, p) in GuiPlaneProp::DEFAULTS.iter().enumerate() {
            assert_eq!(postcard::to_allocvec(p).unwrap()[0] as usize, i, "{p:?}");
        }
        let bounds = GuiPlaneProp::Bounds {
            min: [1.0, 2.0],
            max: [300.0, 400.0],
        };
        let pair = (8u8, [1.0f32, 2.0], [300.0f32, 400.0]);
        assert_eq!(
            postcard::to_allocvec(&bounds).unwrap(),
            postcard::to_allocvec(&pair).unwrap()
        );
        let s = GuiPlaneSettings::default();
        let fields = (
            (
                [0.0f32, 980.0],
                0.05f32,
                0.10f32,
                0.0f32,
                [0.0f32; 2],
                0.25f32,
                4u32,
                false,
            ),
            (None::<(Vec2, Vec2)>, 60.0f32, true, false),
        );
        assert_eq!(
            postcard::to_allocvec(&s).unwrap(),
            postcard::to_allocvec(&fields).unwrap()
        );
        // Bounds is stored as a pair, and only at creation.
        let mut s = GuiPlaneSettings::default();
        assert_eq!(s.apply(bounds, true).unwrap(), bounds);
        assert_eq!(s.bounds, Some(([1.0, 2.0], [300.0, 400.0])));
        let e = s.apply(bounds, false).unwrap_err();
        assert!(e.message.contains("construction-only"), "{e}");
        assert!(GuiPlaneProp::row_named("Bounds").creation_only);
        assert_eq!(
            GuiPlaneProp::row_named("Bounds").kind,
            super::super::table::PropKind::Other
        );
        assert!(GuiPlaneProp::Gravity([0.0; 2]).changes_forces());
        assert_eq!(bounds.name(), "Bounds");
        // Generic reads and writes of the plain rows.
        let drag = GuiPlaneProp::Drag(0.0).index();
        let p = GuiPlaneProp::from_any(drag, super::super::table::AnyValue::Float(0.5)).unwrap();
        s.store(&p);
        assert_eq!(s.get(drag), Some(super::super::table::AnyValue::Float(0.5)));
        assert_eq!(s.get(bounds.index()), None, "a pair has no plain value");
        let e = GuiPlaneProp::Drag(-1.0).checked().unwrap_err();
        assert!(
            e.message.contains("Drag") && e.message.contains("-1"),
            "{e}"
        );
    }
}

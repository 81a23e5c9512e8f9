//! GUI plane options (`PhysicsService.NewGUI`): the wire variant, the defaults and the checks
//! of each. They travel as [`PlaneProp::Gui`](crate::PlaneProp::Gui) next to the options every
//! plane kind takes (`TickRate`, `Enabled`, `Shared`). Units are pixels and seconds, +Y down.

use serde::{Deserialize, Serialize};

use crate::validate::{non_negative, MAX_COORDINATE};
use crate::CommandError;

/// A 2D vector on the wire (pixels, pixels/s, ...).
pub type Vec2 = [f32; 2];

/// Largest `SolverIterations` of a GUI plane (the reference clamps to 1..32).
pub const MAX_GUI_SOLVER_ITERATIONS: u32 = 32;

/// An option of a GUI plane.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum GuiPlaneProp {
    /// Acceleration of every non-anchored body (px/s², +Y down). Default (0, 980).
    Gravity(Vec2),
    /// Per-second linear damping: each tick `v *= max(0, 1 - k·dt)`. Default 0.05.
    LinearDamping(f32),
    /// The same for angular velocity. Default 0.10.
    AngularDamping(f32),
    /// Quadratic drag coefficient: `F = -Drag·|v|·v`. Default 0.
    Drag(f32),
    /// Force on every non-anchored body (px·mass/s²). Default (0, 0).
    ConstantForce(Vec2),
    /// Speed (px/s) below which a body's sleep timer runs; after 0.5 s it sleeps. 0 disables
    /// sleeping. Default 0.25.
    RestThreshold(f32),
    /// Solver iterations per tick, clamped to [1, 32]. Default 4.
    SolverIterations(u32),
    /// Keeps every body awake. Default false.
    NeverSleep(bool),
    /// Creation only: bodies are kept inside the rectangle `min`..`max` and bounce off its
    /// sides with their own Bounciness.
    Bounds {
        /// Top-left corner.
        min: Vec2,
        /// Bottom-right corner.
        max: Vec2,
    },
}

/// Every option of a GUI plane, as set. [`Default`] holds the documented defaults.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct GuiPlaneSettings {
    /// `Gravity`, default (0, 980).
    pub gravity: Vec2,
    /// `LinearDamping`, default 0.05.
    pub linear_damping: f32,
    /// `AngularDamping`, default 0.10.
    pub angular_damping: f32,
    /// `Drag`, default 0.
    pub drag: f32,
    /// `ConstantForce`, default (0, 0).
    pub constant_force: Vec2,
    /// `RestThreshold`, default 0.25 px/s.
    pub rest_threshold: f32,
    /// `SolverIterations` (clamped to [1, 32]), default 4.
    pub solver_iterations: u32,
    /// `NeverSleep`, default false.
    pub never_sleep: bool,
    /// `BoundsMin` / `BoundsMax`, none by default (unbounded).
    pub bounds: Option<(Vec2, Vec2)>,
    /// `TickRate` (the common plane option), default 60; 0 = manual.
    pub tick_rate: f32,
    /// `Enabled` (the common plane option), default true.
    pub enabled: bool,
    /// `Shared` (the common plane option), default false.
    pub shared: bool,
}

/// Seconds a body must stay below `RestThreshold` before it sleeps.
pub const GUI_TIME_UNTIL_SLEEP: f32 = 0.5;

impl Default for GuiPlaneSettings {
    fn default() -> Self {
        GuiPlaneSettings {
            gravity: [0.0, 980.0],
            linear_damping: 0.05,
            angular_damping: 0.10,
            drag: 0.0,
            constant_force: [0.0; 2],
            rest_threshold: 0.25,
            solver_iterations: 4,
            never_sleep: false,
            bounds: None,
            tick_rate: 60.0,
            enabled: true,
            shared: false,
        }
    }
}

/// Checks a 2D value: both components finite (and within the coordinate range).
pub fn finite2(field: &str, v: Vec2) -> Result<Vec2, CommandError> {
    for (c, axis) in v.iter().zip(["X", "Y"]) {
        if !c.is_finite() || c.abs() > MAX_COORDINATE {
            return Err(CommandError::invalid_field(
                format!("{field}.{axis}"),
                format!("{field}.{axis} must be a finite number within ±{MAX_COORDINATE}, got {c}"),
            ));
        }
    }
    Ok(v)
}

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
                        "BoundsMin / BoundsMax are construction-only (tried to set {min:?} .. \
                         {max:?})"
                    ),
                ));
            }
        }
        match prop {
            GuiPlaneProp::Gravity(g) => self.gravity = g,
            GuiPlaneProp::LinearDamping(k) => self.linear_damping = k,
            GuiPlaneProp::AngularDamping(k) => self.angular_damping = k,
            GuiPlaneProp::Drag(k) => self.drag = k,
            GuiPlaneProp::ConstantForce(f) => self.constant_force = f,
            GuiPlaneProp::RestThreshold(v) => self.rest_threshold = v,
            GuiPlaneProp::SolverIterations(n) => self.solver_iterations = n,
            GuiPlaneProp::NeverSleep(on) => self.never_sleep = on,
            GuiPlaneProp::Bounds { min, max } => self.bounds = Some((min, max)),
        }
        Ok(prop)
    }
}

impl GuiPlaneProp {
    /// The option's name in the API.
    pub fn name(&self) -> &'static str {
        match self {
            GuiPlaneProp::Gravity(_) => "Gravity",
            GuiPlaneProp::LinearDamping(_) => "LinearDamping",
            GuiPlaneProp::AngularDamping(_) => "AngularDamping",
            GuiPlaneProp::Drag(_) => "Drag",
            GuiPlaneProp::ConstantForce(_) => "ConstantForce",
            GuiPlaneProp::RestThreshold(_) => "RestThreshold",
            GuiPlaneProp::SolverIterations(_) => "SolverIterations",
            GuiPlaneProp::NeverSleep(_) => "NeverSleep",
            GuiPlaneProp::Bounds { .. } => "Bounds",
        }
    }

    /// Options that change the forces on resting bodies (which must then wake up).
    pub fn changes_forces(&self) -> bool {
        matches!(
            self,
            GuiPlaneProp::Gravity(_) | GuiPlaneProp::ConstantForce(_)
        )
    }

    /// The option as the daemon applies it, or an error naming it and the value.
    pub fn checked(self) -> Result<GuiPlaneProp, CommandError> {
        use GuiPlaneProp::*;
        Ok(match self {
            Gravity(g) => Gravity(finite2("Gravity", g)?),
            LinearDamping(k) => LinearDamping(non_negative("LinearDamping", k)?),
            AngularDamping(k) => AngularDamping(non_negative("AngularDamping", k)?),
            Drag(k) => Drag(non_negative("Drag", k)?),
            ConstantForce(f) => ConstantForce(finite2("ConstantForce", f)?),
            RestThreshold(v) => RestThreshold(non_negative("RestThreshold", v)?),
            SolverIterations(n) => SolverIterations(n.clamp(1, MAX_GUI_SOLVER_ITERATIONS)),
            NeverSleep(on) => NeverSleep(on),
            Bounds { min, max } => {
                let min = finite2("BoundsMin", min)?;
                let max = finite2("BoundsMax", max)?;
                if max[0] - min[0] < 1.0 || max[1] - min[1] < 1.0 {
                    return Err(CommandError::invalid_field(
                        "BoundsMax",
                        format!(
                            "BoundsMax must be at least 1 px right of and below BoundsMin, got \
                             BoundsMin {min:?}, BoundsMax {max:?}"
                        ),
                    ));
                }
                Bounds { min, max }
            }
        })
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
}

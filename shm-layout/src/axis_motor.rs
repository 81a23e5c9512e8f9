//! Per-axis motors and springs of a SixDof joint: each of its six axes (X, Y, Z, RotX,
//! RotY, RotZ of the joint frame) may drive toward a target velocity, a target position, or
//! both (a damped spring), with a force cap. Carried by [`crate::JointProp::AxisMotor`] and
//! stored in [`crate::JointSettings::axis_motors`].

use serde::{Deserialize, Serialize};

use crate::error::CommandError;
use crate::joint_limits::{AXIS_NAMES, MAX_ANGLE, MAX_JOINT_VALUE};
use crate::validate::{finite, non_negative, MAX_COORDINATE};

/// A motor on one axis of a SixDof joint.
///
/// With `stiffness` or `damping` set (> 0) the motor applies the force (torque about a
/// rotation axis) `stiffness · (target_position − x) + damping · (target_velocity − v)`,
/// capped at `max_force`: a spring of stiffness k on a free mass m oscillates with period
/// 2π√(m/k). With both 0 it is a stiff drive that holds `target_velocity` (and, with a
/// `target_position`, goes there) within a few ticks whatever the mass, still capped at
/// `max_force`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct AxisMotor {
    /// Velocity the motor drives toward (units/s, or rad/s about a rotation axis).
    pub target_velocity: f32,
    /// Position the motor pulls toward (units, or radians), if any.
    pub target_position: Option<f32>,
    /// Force per unit of distance from `target_position` (0: no spring).
    pub stiffness: f32,
    /// Force per unit of velocity off `target_velocity`.
    pub damping: f32,
    /// Most force (torque) the motor applies.
    pub max_force: f32,
}

impl Default for AxisMotor {
    fn default() -> Self {
        AxisMotor {
            target_velocity: 0.0,
            target_position: None,
            stiffness: 0.0,
            damping: 0.0,
            max_force: f32::MAX,
        }
    }
}

impl AxisMotor {
    /// A spring toward `rest` of `stiffness` and `damping` (no velocity target, no cap).
    pub fn spring(stiffness: f32, damping: f32, rest: f32) -> AxisMotor {
        AxisMotor {
            target_position: Some(rest),
            stiffness,
            damping,
            ..AxisMotor::default()
        }
    }

    /// Whether the motor is force-based (a spring or damper of the given strength) rather
    /// than the stiff default drive.
    pub fn force_based(&self) -> bool {
        self.stiffness > 0.0 || self.damping > 0.0
    }

    /// Every value checked for the axis `axis` (0..6): finite and in range; the message
    /// names the axis and the value (`AxisMotor.RotY.Stiffness must be ≥ 0, got -1`).
    pub fn checked(self, axis: u8) -> Result<AxisMotor, CommandError> {
        let Some(axis_name) = AXIS_NAMES.get(axis as usize) else {
            return Err(CommandError::invalid_field(
                "AxisMotor",
                format!("AxisMotor axis must be 0 to 5 (X, Y, Z, RotX, RotY, RotZ), got {axis}"),
            ));
        };
        let field = |what: &str| format!("AxisMotor.{axis_name}.{what}");
        let bounded = |what: &str, v: f32, limit: f32| {
            let name = field(what);
            let v = finite(&name, v)?;
            if v.abs() > limit {
                return Err(CommandError::invalid_field(
                    &name,
                    format!("{name} must be within ±{limit}, got {v}"),
                ));
            }
            Ok(v)
        };
        let amount = |what: &str, v: f32| {
            let name = field(what);
            let v = non_negative(&name, v)?;
            if v > MAX_JOINT_VALUE && !(what == "MaxForce" && v == f32::MAX) {
                return Err(CommandError::invalid_field(
                    &name,
                    format!("{name} must be at most {MAX_JOINT_VALUE}, got {v}"),
                ));
            }
            Ok(v)
        };
        let position_limit = if axis < 3 { MAX_COORDINATE } else { MAX_ANGLE };
        Ok(AxisMotor {
            target_velocity: bounded("TargetVelocity", self.target_velocity, MAX_JOINT_VALUE)?,
            target_position: self
                .target_position
                .map(|p| bounded("TargetPosition", p, position_limit))
                .transpose()?,
            stiffness: amount("Stiffness", self.stiffness)?,
            damping: amount("Damping", self.damping)?,
            max_force: amount("MaxForce", self.max_force)?,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bad_values_name_the_axis_and_the_value() {
        let e = AxisMotor {
            stiffness: -1.0,
            ..AxisMotor::default()
        }
        .checked(4)
        .unwrap_err();
        assert_eq!(e.field.as_deref(), Some("AxisMotor.RotY.Stiffness"));
        assert!(e.message.contains("-1"), "{}", e.message);
        let e = AxisMotor {
            target_velocity: f32::NAN,
            ..AxisMotor::default()
        }
        .checked(0)
        .unwrap_err();
        assert_eq!(e.field.as_deref(), Some("AxisMotor.X.TargetVelocity"));
        let e = AxisMotor::spring(1.0, 0.0, 100.0).checked(3).unwrap_err();
        assert_eq!(e.field.as_deref(), Some("AxisMotor.RotX.TargetPosition"));
        assert!(AxisMotor::default().checked(6).is_err());
        assert!(AxisMotor::spring(50.0, 0.0, 0.5).checked(0).is_ok());
    }
}

//! SixDof per-axis motors and springs onto rapier's `GenericJoint` motors (one per axis).
//!
//! A motor with a stiffness or damping is force-based: rapier applies
//! `stiffness · (target − x) + damping · (target_velocity − v)` as a force (torque), so a
//! spring of stiffness k on a mass m oscillates with period 2π√(m/k). Without either it is
//! the joints' stiff default drive (acceleration-based, the same gains as a Hinge motor's):
//! it holds its target velocity within a few ticks whatever the mass. `max_force` caps the
//! impulse per step at `max_force · dt`.

use rapier3d::prelude::*;
use shm_layout::JointSettings;

use crate::rapier3d::joints::table::{
    POSITION_MOTOR_DAMPING, POSITION_MOTOR_STIFFNESS, VELOCITY_MOTOR_GAIN,
};

/// The joint frame's axes in `AXIS_NAMES` order.
const AXES: [JointAxis; 6] = [
    JointAxis::LinX,
    JointAxis::LinY,
    JointAxis::LinZ,
    JointAxis::AngX,
    JointAxis::AngY,
    JointAxis::AngZ,
];

/// Sets the motors of `s.axis_motors` on `j` (a SixDof joint's rapier joint).
pub(crate) fn apply(j: &mut GenericJoint, s: &JointSettings) {
    for (axis, motor) in AXES.iter().zip(&s.axis_motors) {
        let Some(m) = motor else {
            continue;
        };
        if m.force_based() {
            // No rest point, no spring: stiffness alone means nothing without a target.
            let stiffness = if m.target_position.is_some() {
                m.stiffness
            } else {
                0.0
            };
            j.set_motor_model(*axis, MotorModel::ForceBased);
            j.set_motor(
                *axis,
                m.target_position.unwrap_or(0.0),
                m.target_velocity,
                stiffness,
                m.damping,
            );
        } else if let Some(target) = m.target_position {
            j.set_motor(
                *axis,
                target,
                m.target_velocity,
                POSITION_MOTOR_STIFFNESS,
                POSITION_MOTOR_DAMPING,
            );
        } else {
            j.set_motor_velocity(*axis, m.target_velocity, VELOCITY_MOTOR_GAIN);
        }
        j.set_motor_max_force(*axis, m.max_force);
    }
}

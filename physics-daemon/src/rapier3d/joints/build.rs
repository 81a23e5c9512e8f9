//! Building a rapier joint from a joint's kind and settings, and the angle and limit
//! arithmetic the error figures share.

use rapier3d::prelude::*;
use shm_layout::joint_op::{AxisMode, JointKind, JointSettings};

use crate::rapier3d::joints::table::{
    POSITION_MOTOR_DAMPING, POSITION_MOTOR_STIFFNESS, VELOCITY_MOTOR_GAIN,
};

pub(in crate::rapier3d::joints) const LIN: [JointAxis; 3] =
    [JointAxis::LinX, JointAxis::LinY, JointAxis::LinZ];
pub(in crate::rapier3d::joints) const ANG: [JointAxis; 3] =
    [JointAxis::AngX, JointAxis::AngY, JointAxis::AngZ];

pub(in crate::rapier3d::joints) fn vec(v: [f32; 3]) -> Vector {
    Vector::from(v)
}

/// The rapier joint for `kind` with `s`; `rel` turns frame A into frame B.
pub(in crate::rapier3d::joints) fn build(
    kind: JointKind,
    s: &JointSettings,
    rel: Rotation,
) -> GenericJoint {
    let frame_rot = GenericJoint::complete_ang_frame(vec(s.axis));
    let mut j = GenericJoint::new(JointAxesMask::empty());
    j.set_local_frame1(Pose::from_parts(vec(s.anchor_a), frame_rot));
    j.set_local_frame2(Pose::from_parts(vec(s.anchor_b), rel * frame_rot));
    j.set_contacts_enabled(s.collide_connected);
    let angle_limits = |lo: Option<f32>, hi: Option<f32>| {
        [
            lo.unwrap_or(-shm_layout::joint_op::MAX_ANGLE),
            hi.unwrap_or(shm_layout::joint_op::MAX_ANGLE),
        ]
    };
    let distance_limits =
        |lo: Option<f32>, hi: Option<f32>| [lo.unwrap_or(-f32::MAX), hi.unwrap_or(f32::MAX)];
    let cone = |j: &mut GenericJoint| {
        if let Some(t) = s.twist_limit {
            j.set_limits(JointAxis::AngX, [-t, t]);
        }
        if let Some(w) = s.swing_limit {
            j.set_limits(JointAxis::AngY, [-w, w]);
            j.set_limits(JointAxis::AngZ, [-w, w]);
        }
    };
    let motor = |j: &mut GenericJoint, axis: JointAxis| {
        if let Some(target) = s.motor_target {
            if s.stiffness > 0.0 {
                j.set_motor_model(axis, MotorModel::ForceBased);
                j.set_motor(
                    axis,
                    target,
                    s.motor_speed.unwrap_or(0.0),
                    s.stiffness,
                    s.damping,
                );
            } else {
                j.set_motor(
                    axis,
                    target,
                    s.motor_speed.unwrap_or(0.0),
                    POSITION_MOTOR_STIFFNESS,
                    POSITION_MOTOR_DAMPING,
                );
            }
        } else if let Some(speed) = s.motor_speed {
            let gain = if s.damping > 0.0 {
                s.damping
            } else {
                VELOCITY_MOTOR_GAIN
            };
            j.set_motor_velocity(axis, speed, gain);
        }
        if s.motor_speed.is_some() || s.motor_target.is_some() {
            j.set_motor_max_force(axis, s.motor_max_force);
        }
    };
    match kind {
        JointKind::Ball | JointKind::ConeTwist => {
            j.lock_axes(JointAxesMask::LIN_AXES);
            cone(&mut j);
        }
        JointKind::Fixed => {
            j.lock_axes(JointAxesMask::LIN_AXES | JointAxesMask::ANG_AXES);
        }
        JointKind::Hinge => {
            j.lock_axes(JointAxesMask::LIN_AXES | JointAxesMask::ANG_Y | JointAxesMask::ANG_Z);
            if s.lower_angle.is_some() || s.upper_angle.is_some() {
                j.set_limits(JointAxis::AngX, angle_limits(s.lower_angle, s.upper_angle));
            }
            motor(&mut j, JointAxis::AngX);
        }
        JointKind::Prismatic => {
            j.lock_axes(JointAxesMask::LIN_Y | JointAxesMask::LIN_Z | JointAxesMask::ANG_AXES);
            if s.lower_distance.is_some() || s.upper_distance.is_some() {
                j.set_limits(
                    JointAxis::LinX,
                    distance_limits(s.lower_distance, s.upper_distance),
                );
            }
            motor(&mut j, JointAxis::LinX);
        }
        JointKind::SixDof => {
            let mut locked = JointAxesMask::empty();
            for (i, mode) in s.axes.iter().enumerate() {
                let axis = if i < 3 { LIN[i] } else { ANG[i - 3] };
                match mode {
                    AxisMode::Locked => locked |= axis.into(),
                    AxisMode::Free => {}
                    AxisMode::Limited if i < 3 => {
                        j.set_limits(axis, distance_limits(s.lower_distance, s.upper_distance));
                    }
                    AxisMode::Limited => {
                        j.set_limits(axis, angle_limits(s.lower_angle, s.upper_angle));
                    }
                }
            }
            j.lock_axes(locked);
            crate::rapier3d::joints::axis_motors::apply(&mut j, s);
        }
        JointKind::Rope => {
            j.coupled_axes = JointAxesMask::LIN_AXES;
            j.set_limits(
                JointAxis::LinX,
                [0.0, s.upper_distance.unwrap_or(s.rest_length)],
            );
        }
        JointKind::Spring => {
            j.coupled_axes = JointAxesMask::LIN_AXES;
            j.set_motor_model(JointAxis::LinX, MotorModel::ForceBased);
            j.set_motor_position(JointAxis::LinX, s.rest_length, s.stiffness, s.damping);
        }
    }
    j
}

/// The signed angle of a relative rotation about one of its frame's axes (the angle
/// rapier's limits compare), in (-π, π].
pub(in crate::rapier3d::joints) fn axis_angle(q: Rotation, i: usize) -> f32 {
    let q = if q.w < 0.0 { -q } else { q };
    let imag = [q.x, q.y, q.z];
    2.0 * imag[i].atan2(q.w)
}

pub(in crate::rapier3d::joints) fn overshoot(v: f32, lo: f32, hi: f32) -> f32 {
    (lo - v).max(v - hi).max(0.0)
}

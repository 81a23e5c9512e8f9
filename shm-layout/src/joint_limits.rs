//! The axes of a joint frame and the largest values joint options and axis motors accept.

/// The axis names of [`JointProp::Axes`](crate::joint_op::JointProp::Axes), in order.
pub const AXIS_NAMES: [&str; 6] = ["X", "Y", "Z", "RotX", "RotY", "RotZ"];

/// Largest angle limit (radians): a few turns, beyond which a limit means nothing.
pub const MAX_ANGLE: f32 = 4.0 * std::f32::consts::PI;
/// Largest force, stiffness, damping or motor value accepted.
pub const MAX_JOINT_VALUE: f32 = 1e12;

//! Joints: every [`JointKind`] is one rapier `GenericJoint` built from the joint's
//! [`JointSettings`] (locked, limited, coupled and motorised axes of the joint frame, whose
//! X axis is `Axis`). After each step the plane measures every joint's positional and
//! angular error (the tick header's `max_joint_error`), its constraint force, and breaks
//! the joints whose force exceeded `BreakForce` (an `EVENT_JOINT_BROKE` event).
//!
//! Joint frames: frame A is `AnchorA` on A with X along `Axis`; frame B is `AnchorB` on B
//! with the rotation that makes the two frames coincide in the pose the bodies had when
//! the joint was made, so every angle (hinge angle, limits, motor targets) is measured from
//! the creation pose.
//!
//! Files: the joint table (`table`), building a rapier joint from a joint's
//! settings (`build`, `axis_motors`), articulated trees (`articulations`). `ops.rs` (joint
//! ops) and `step.rs` (before and after each step) are the plane's `impl Plane` side; the
//! others know no plane.
//!
//! [`JointKind`]: shm_layout::joint_op::JointKind
//! [`JointSettings`]: shm_layout::joint_op::JointSettings

pub(super) mod articulations;
mod axis_motors;
mod build;
#[cfg(test)]
mod edge_tests;
mod ops;
mod step;
pub(super) mod table;
#[cfg(test)]
mod tests;

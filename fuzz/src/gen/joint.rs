//! Joint ops and joint options, valid or wild.

use shm_layout::{AxisMode, JointKind, JointOp, JointProp, OptionalJointProp, PlaneId};

use super::Gen;
use crate::rng::Rng;

impl Gen<'_> {
    /// A joint op: creation between live objects (or the world) with valid or wild options,
    /// and Set / Info / List / Destroy on handles that may or may not be joints.
    pub(super) fn joint_op(&mut self, wild: bool, id: PlaneId) -> JointOp {
        let joint = self.handle(true, id);
        // Joints count against the objects quota and few destroys find one: creating them
        // rarely keeps valid commands from flooding the quota.
        match self.rng.below(100) {
            0..=14 => {
                let kind = *self.rng.pick(&JointKind::ALL);
                let a = self.handle(wild, id);
                let b = if self.rng.chance(0.3) {
                    None
                } else {
                    Some(self.handle(wild, id))
                };
                let props = (0..self.rng.below(5))
                    .map(|_| self.joint_prop(wild))
                    .collect();
                JointOp::Create { kind, a, b, props }
            }
            15..=59 => JointOp::Set {
                joint,
                prop: self.joint_prop(wild),
            },
            60..=74 => JointOp::Info { joint },
            // Pages of the joint list, from a joint's slot; wild limits include 0 (refused)
            // and more than a page holds (cut).
            75..=79 => JointOp::List {
                after: joint.slot,
                limit: match wild {
                    true => *self.rng.pick(&[0, 1, 4_096, 4_097, u32::MAX]),
                    false => 1 + self.rng.below(8) as u32,
                },
            },
            _ => JointOp::Destroy { joint },
        }
    }

    pub(super) fn joint_prop(&mut self, wild: bool) -> JointProp {
        let f = |r: &mut Rng, sane: f32| r.maybe_wild(wild, sane);
        let angle = f(self.rng, 1.5);
        let dist = f(self.rng, 3.0);
        let v = self.rng.vec3(wild, 2.0);
        match self.rng.below(19) {
            0 => JointProp::AnchorA(v),
            1 => JointProp::AnchorB(v),
            2 => JointProp::Axis(v),
            3 => JointProp::LowerAngle(-angle.abs()),
            4 => JointProp::UpperAngle(angle.abs()),
            5 => JointProp::SwingLimit(angle.abs()),
            6 => JointProp::TwistLimit(angle.abs()),
            7 => JointProp::LowerDistance(-dist.abs()),
            8 => JointProp::UpperDistance(dist.abs()),
            9 => JointProp::RestLength(dist.abs()),
            10 => JointProp::Stiffness(f(self.rng, 100.0).abs()),
            11 => JointProp::Damping(f(self.rng, 10.0).abs()),
            12 => JointProp::MotorSpeed(f(self.rng, 5.0)),
            13 => JointProp::MotorTarget(angle),
            14 => JointProp::MotorMaxForce(f(self.rng, 100.0).abs()),
            15 => {
                let modes = [AxisMode::Locked, AxisMode::Limited, AxisMode::Free];
                JointProp::Axes(std::array::from_fn(|_| *self.rng.pick(&modes)))
            }
            16 => JointProp::BreakForce(f(self.rng, 500.0).abs()),
            17 => JointProp::Unset(*self.rng.pick(&OptionalJointProp::ALL)),
            _ => JointProp::CollideConnected(self.rng.chance(0.5)),
        }
    }
}

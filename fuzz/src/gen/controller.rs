//! Character-controller ops, on live handles that may or may not be controllers.

use shm_layout::{ControllerOp, ControllerProp, PlaneId};

use super::Gen;
use crate::rng::Rng;

impl Gen<'_> {
    /// Any controller op, on a live handle mostly (which may or may not be a controller).
    pub(super) fn controller_op(&mut self, wild: bool, id: PlaneId) -> ControllerOp {
        let handle = self.handle(wild, id);
        let r = &mut *self.rng;
        let f = |r: &mut Rng, lo: f32, hi: f32| {
            let v = r.f32_in(lo, hi);
            r.maybe_wild(wild, v)
        };
        let prop = |r: &mut Rng| match r.below(12) {
            0 => ControllerProp::WalkSpeed(f(r, 0.0, 40.0)),
            1 => ControllerProp::JumpPower(f(r, 0.0, 60.0)),
            2 => ControllerProp::Gravity(f(r, -50.0, 100.0)),
            3 => ControllerProp::MaxSlope(f(r, 0.0, 95.0)),
            4 => ControllerProp::GroundY(r.chance(0.7).then(|| f(r, -20.0, 5.0))),
            5 => ControllerProp::CapsuleRadius(f(r, 0.05, 3.0)),
            6 => ControllerProp::CapsuleHalfHeight(f(r, 0.0, 3.0)),
            7 => ControllerProp::StepHeight(f(r, 0.0, 2.0)),
            8 => ControllerProp::MoveVector([f(r, -1.2, 1.2), f(r, -1.2, 1.2)]),
            9 => ControllerProp::Velocity(r.vec3(wild, 30.0)),
            10 => ControllerProp::Position(r.vec3(wild, 30.0)),
            _ => ControllerProp::Rotation(r.vec3(wild, 4.0)),
        };
        match r.below(9) {
            0 | 1 => ControllerOp::Create {
                pose: r.pose(wild, 20.0),
                size: [f(r, 0.5, 3.0), f(r, 1.0, 6.0), f(r, 0.5, 3.0)],
                controlled: r.chance(0.5),
                props: (0..r.below(3)).map(|_| prop(r)).collect(),
            },
            2 | 3 => ControllerOp::Set {
                handle,
                prop: prop(r),
            },
            4 => ControllerOp::Info { handle },
            5 => ControllerOp::SetPath {
                handle,
                waypoints: (0..r.below(5)).map(|_| r.vec3(wild, 30.0)).collect(),
            },
            6 => ControllerOp::Jump { handle },
            7 => ControllerOp::Teleport {
                handle,
                pose: r.pose(wild, 20.0),
            },
            _ => match r.below(3) {
                0 => ControllerOp::AppendWaypoint {
                    handle,
                    point: r.vec3(wild, 30.0),
                },
                1 => ControllerOp::StopWalking { handle },
                _ => ControllerOp::Destroy { handle },
            },
        }
    }
}

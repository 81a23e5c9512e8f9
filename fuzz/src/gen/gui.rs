//! GUI planes: their options, their object properties and their ops.

use shm_layout::{
    GuiControllerOp, GuiControllerProp, GuiObjectOp, GuiObjectProp, GuiOp, GuiPlaneProp, GuiShape,
    PlaneId,
};

use super::Gen;
use crate::rng::Rng;

impl Gen<'_> {
    /// Any GUI-plane option with a valid or wild value.
    pub(super) fn gui_plane_prop(&mut self, wild: bool) -> GuiPlaneProp {
        let r = &mut *self.rng;
        let f = |r: &mut Rng, lo: f32, hi: f32| {
            let v = r.f32_in(lo, hi);
            r.maybe_wild(wild, v)
        };
        match r.below(9) {
            0 => GuiPlaneProp::Gravity([f(r, -100.0, 100.0), f(r, 0.0, 1500.0)]),
            1 => GuiPlaneProp::LinearDamping(f(r, 0.0, 2.0)),
            2 => GuiPlaneProp::AngularDamping(f(r, 0.0, 2.0)),
            3 => GuiPlaneProp::Drag(f(r, 0.0, 0.01)),
            4 => GuiPlaneProp::ConstantForce([f(r, -50.0, 50.0), f(r, -50.0, 50.0)]),
            5 => GuiPlaneProp::RestThreshold(f(r, 0.0, 2.0)),
            6 => GuiPlaneProp::SolverIterations(if wild {
                r.special_u32()
            } else {
                r.below(40) as u32
            }),
            7 => GuiPlaneProp::NeverSleep(r.chance(0.5)),
            _ => GuiPlaneProp::Bounds {
                min: [f(r, -10.0, 0.0), f(r, -10.0, 0.0)],
                max: [f(r, 200.0, 1000.0), f(r, 200.0, 1000.0)],
            },
        }
    }

    /// Any GUI object property with a valid or wild value.
    pub(super) fn gui_object_prop(&mut self, wild: bool) -> GuiObjectProp {
        let r = &mut *self.rng;
        let f = |r: &mut Rng, lo: f32, hi: f32| {
            let v = r.f32_in(lo, hi);
            r.maybe_wild(wild, v)
        };
        match r.below(17) {
            0 => GuiObjectProp::Position([f(r, 0.0, 500.0), f(r, 0.0, 500.0)]),
            1 => GuiObjectProp::Velocity([f(r, -300.0, 300.0), f(r, -300.0, 300.0)]),
            2 => GuiObjectProp::Rotation(f(r, -360.0, 360.0)),
            3 => GuiObjectProp::AngularVelocity(f(r, -360.0, 360.0)),
            4 => GuiObjectProp::ImpulseDirection([f(r, -100.0, 100.0), f(r, -100.0, 100.0)]),
            5 => GuiObjectProp::ConstantForce([f(r, -100.0, 100.0), f(r, -100.0, 100.0)]),
            6 => GuiObjectProp::Mass(f(r, 0.01, 10.0)),
            7 => GuiObjectProp::Bounciness(f(r, 0.0, 1.2)),
            8 => GuiObjectProp::Friction(f(r, 0.0, 4.5)),
            9 => GuiObjectProp::Anchored(r.chance(0.2)),
            10 => GuiObjectProp::CanCollide(r.chance(0.8)),
            11 => GuiObjectProp::GravityScale(f(r, -1.0, 2.0)),
            12 => GuiObjectProp::LockedX(r.chance(0.2)),
            13 => GuiObjectProp::LockedY(r.chance(0.2)),
            14 => GuiObjectProp::LockedRotation(r.chance(0.3)),
            15 => GuiObjectProp::ZIndex(if wild {
                r.u32() as i32
            } else {
                r.below(3) as i32
            }),
            _ => GuiObjectProp::Size([f(r, 2.0, 80.0), f(r, 2.0, 80.0)]),
        }
    }

    /// Any GUI-plane op (sent to any plane: 3D planes refuse it).
    pub(super) fn gui_op(&mut self, wild: bool, id: PlaneId) -> GuiOp {
        let handle = self.handle(wild, id);
        let shapes = GuiShape::ALL;
        match self.rng.below(10) {
            0 => GuiOp::Info,
            1..=3 => {
                let shape = *self.rng.pick(&shapes);
                let r = &mut *self.rng;
                let size = [r.f32_in(4.0, 60.0), r.f32_in(4.0, 60.0)];
                let size = [r.maybe_wild(wild, size[0]), size[1]];
                let position = [r.f32_in(0.0, 400.0), r.f32_in(0.0, 400.0)];
                let props = (0..self.rng.below(3))
                    .map(|_| self.gui_object_prop(wild))
                    .collect();
                GuiOp::Add {
                    shape,
                    size,
                    position,
                    props,
                }
            }
            4..=6 => {
                let op = match self.rng.below(8) {
                    0..=3 => GuiObjectOp::Set(self.gui_object_prop(wild)),
                    4 => GuiObjectOp::ApplyImpulse(
                        self.rng.vec3(wild, 100.0)[..2]
                            .try_into()
                            .unwrap_or([0.0; 2]),
                    ),
                    5 => GuiObjectOp::Wake,
                    6 => GuiObjectOp::Info,
                    _ => GuiObjectOp::Destroy,
                };
                GuiOp::Object { handle, op }
            }
            7..=8 => {
                let r = &mut *self.rng;
                let prop = match r.below(4) {
                    0 => GuiControllerProp::MoveSpeed(r.f32_in(0.0, 400.0)),
                    1 => GuiControllerProp::Acceleration(r.f32_in(0.0, 3000.0)),
                    2 => GuiControllerProp::JumpStrength(r.f32_in(0.0, 900.0)),
                    _ => GuiControllerProp::WaypointRadius(r.f32_in(0.0, 20.0)),
                };
                let prop = if wild && r.chance(0.3) {
                    GuiControllerProp::MoveSpeed(r.special_f32())
                } else {
                    prop
                };
                let op = match r.below(8) {
                    0 => GuiControllerOp::Create {
                        uncontrolled: r.chance(0.5),
                        props: vec![prop],
                    },
                    1 => GuiControllerOp::Set(prop),
                    2 => GuiControllerOp::Move([r.f32_in(-1.0, 1.0), r.f32_in(-1.0, 1.0)]),
                    3 => GuiControllerOp::Jump,
                    4 => GuiControllerOp::SetWaypoints(
                        (0..r.below(5))
                            .map(|_| [r.f32_in(0.0, 400.0), r.f32_in(0.0, 400.0)])
                            .collect(),
                    ),
                    5 => GuiControllerOp::ClearWaypoints,
                    6 => GuiControllerOp::Info,
                    _ => GuiControllerOp::Destroy,
                };
                GuiOp::Controller { handle, op }
            }
            _ => {
                let r = &mut *self.rng;
                GuiOp::Raycast {
                    from: [r.f32_in(0.0, 400.0), r.f32_in(0.0, 400.0)],
                    dir: [r.maybe_wild(wild, 1.0), r.f32_in(-1.0, 1.0)],
                    max_distance: r.chance(0.5).then(|| r.f32_in(0.0, 500.0)),
                }
            }
        }
    }
}

//! Plane options and object properties with valid or wild values, and collision-group
//! tables.

use shm_layout::{CollisionGroups, ObjectProp, Pin, PlaneProp, Restraint, RotateTo};

use super::Gen;
use crate::rng::Rng;

impl Gen<'_> {
    /// Any plane option with a valid or wild value; creation-only ones too.
    pub(super) fn plane_prop(&mut self, wild: bool, creating: bool) -> PlaneProp {
        let r = &mut *self.rng;
        let any_u32 = |r: &mut Rng, lo: usize, hi: usize| {
            if wild && r.chance(0.5) {
                r.special_u32()
            } else {
                r.range(lo, hi) as u32
            }
        };
        // Every row of the plane settings table (GUI options have their own generator); a
        // row with no tuned values below goes out at its default.
        let mut row = *r.pick(PlaneProp::DEFAULTS);
        if let PlaneProp::Gui(_) = row {
            row = PlaneProp::Shared(false);
        }
        match row {
            PlaneProp::Gravity(_) => PlaneProp::Gravity(if r.chance(0.3) {
                [0.0, -50.0, 0.0]
            } else {
                r.vec3(wild, 100.0)
            }),
            PlaneProp::Threads(_) => PlaneProp::Threads(if creating && !wild {
                r.range(1, 3) as u32
            } else {
                any_u32(r, 1, 3)
            }),
            PlaneProp::TickRate(_) => PlaneProp::TickRate(if wild {
                *r.pick(&[
                    f32::NAN,
                    f32::INFINITY,
                    -60.0,
                    1e-45,
                    1e-3,
                    0.009_999,
                    0.01,
                    10_000.0,
                    10_000.001,
                    1e38,
                ])
            } else {
                *r.pick(&[0.0, 0.0, 0.0, 30.0, 60.0, 240.0])
            }),
            PlaneProp::Enabled(_) => PlaneProp::Enabled(r.chance(0.85)),
            PlaneProp::LinearDamping(_) => {
                let k = r.f32_in(0.0, 5.0);
                PlaneProp::LinearDamping(r.maybe_wild(wild, k))
            }
            PlaneProp::AngularDamping(_) => {
                let k = r.f32_in(0.0, 5.0);
                PlaneProp::AngularDamping(r.maybe_wild(wild, k))
            }
            PlaneProp::Drag(_) => {
                let k = r.f32_in(0.0, 2.0);
                PlaneProp::Drag(r.maybe_wild(wild, k))
            }
            PlaneProp::Buoyancy(_) => {
                let b = r.f32_in(-100.0, 100.0);
                PlaneProp::Buoyancy(r.maybe_wild(wild, b))
            }
            PlaneProp::ConstantForce(_) => PlaneProp::ConstantForce(r.vec3(wild, 50.0)),
            PlaneProp::RestThreshold(_) => {
                let v = r.f32_in(0.0, 5.0);
                PlaneProp::RestThreshold(r.maybe_wild(wild, v))
            }
            PlaneProp::SolverIterations(_) => PlaneProp::SolverIterations(any_u32(r, 1, 16)),
            PlaneProp::LoopSolver(_) => PlaneProp::LoopSolver(r.chance(0.1)),
            PlaneProp::NeverSleep(_) => PlaneProp::NeverSleep(r.chance(0.3)),
            PlaneProp::MaxLinearSpeed(_) => {
                let v = r.f32_in(1.0, 20_000.0);
                PlaneProp::MaxLinearSpeed(r.maybe_wild(wild, v))
            }
            PlaneProp::MaxAngularSpeed(_) => {
                let w = r.f32_in(0.5, 2_000.0);
                PlaneProp::MaxAngularSpeed(r.maybe_wild(wild, w))
            }
            PlaneProp::Shared(_) => PlaneProp::Shared(r.chance(0.5)),
            other => other,
        }
    }

    /// Any object property with a valid or wild value.
    pub(super) fn object_prop(&mut self, wild: bool) -> ObjectProp {
        let r = &mut *self.rng;
        let f = |r: &mut Rng, lo: f32, hi: f32| {
            let v = r.f32_in(lo, hi);
            r.maybe_wild(wild, v)
        };
        // Every row of the object settings table; a row with no tuned values below goes
        // out at its default.
        match *r.pick(ObjectProp::DEFAULTS) {
            ObjectProp::Held(_) => ObjectProp::Held(r.chance(0.5)),
            ObjectProp::CollisionGroup(_) => {
                ObjectProp::CollisionGroup(if wild { r.byte() } else { r.below(3) as u8 })
            }
            ObjectProp::Pose(_) => ObjectProp::Pose(r.pose(wild, 30.0)),
            ObjectProp::Velocity(_) => ObjectProp::Velocity(r.vec3(wild, 20.0)),
            ObjectProp::AngularVelocity(_) => ObjectProp::AngularVelocity(r.vec3(wild, 10.0)),
            ObjectProp::Anchored(_) => ObjectProp::Anchored(r.chance(0.15)),
            ObjectProp::ReportContacts(_) => ObjectProp::ReportContacts(r.chance(0.5)),
            ObjectProp::Weight(_) => {
                let w = r.log_f32(1e-3, 1e3);
                ObjectProp::Weight(r.maybe_wild(wild, w))
            }
            ObjectProp::Density(_) => {
                let d = if r.chance(0.3) {
                    0.0
                } else {
                    r.log_f32(0.01, 100.0)
                };
                ObjectProp::Density(r.maybe_wild(wild, d))
            }
            ObjectProp::Bounciness(_) => ObjectProp::Bounciness(f(r, -0.5, 1.5)),
            ObjectProp::Friction(_) => ObjectProp::Friction(f(r, 0.0, 1.0)),
            ObjectProp::CanCollide(_) => ObjectProp::CanCollide(r.chance(0.8)),
            ObjectProp::HitBoxQuality(_) => ObjectProp::HitBoxQuality(if wild && r.chance(0.5) {
                r.special_u32()
            } else {
                *r.pick(&[1, 1, 2, 4, 8, 32])
            }),
            ObjectProp::Size(_) => ObjectProp::Size([0; 3].map(|_| f(r, 0.1, 4.0))),
            ObjectProp::CenterOfMass(_) => ObjectProp::CenterOfMass(if r.chance(0.3) {
                [0.0; 3]
            } else {
                r.vec3(wild, 0.5)
            }),
            ObjectProp::ImpulseDirection(_) => ObjectProp::ImpulseDirection(r.vec3(wild, 20.0)),
            ObjectProp::ConstantForce(_) => ObjectProp::ConstantForce(r.vec3(wild, 50.0)),
            ObjectProp::FieldRestraint(_) => {
                let mut flag = || match r.below(3) {
                    0 => None,
                    1 => Some(false),
                    _ => Some(true),
                };
                ObjectProp::FieldRestraint(Restraint {
                    lock_x: flag(),
                    lock_y: flag(),
                    lock_z: flag(),
                    lock_rot_x: flag(),
                    lock_rot_y: flag(),
                    lock_rot_z: flag(),
                })
            }
            ObjectProp::RotateTo(_) => ObjectProp::RotateTo(if r.chance(0.2) {
                None
            } else {
                Some(RotateTo {
                    target: r.quat(wild),
                    strength: f(r, 0.0, 20.0),
                })
            }),
            ObjectProp::Pin(_) => ObjectProp::Pin(if r.chance(0.2) {
                None
            } else {
                Some(Pin {
                    force: f(r, 0.0, 1_000.0),
                    relative: r.vec3(wild, 1.0),
                    target: r.pose(wild, 20.0),
                })
            }),
            // Rows added to the table later, until they get tuned values here.
            #[allow(unreachable_patterns)]
            other => other,
        }
    }

    /// A collision-group table: a valid one, or (wild) a forged one.
    pub(super) fn collision_groups(&mut self, wild: bool) -> CollisionGroups {
        let mut table = CollisionGroups::default();
        for i in 0..self.rng.below(if wild { 40 } else { 4 }) {
            let _ = table.register(&format!("G{i}"));
        }
        let registered: Vec<String> = table.registered().map(|(_, n, _)| n.to_string()).collect();
        for _ in 0..self.rng.below(4) {
            let a = self.rng.pick(&registered).clone();
            let b = self.rng.pick(&registered).clone();
            let _ = table.set_collidable(&a, &b, self.rng.chance(0.5));
        }
        if wild && self.rng.chance(0.5) {
            // Forged bytes: decode a mangled encoding, or fall back to the valid table.
            let mut bytes = postcard::to_allocvec(&table).unwrap_or_default();
            if !bytes.is_empty() {
                let i = self.rng.below(bytes.len());
                bytes[i] = self.rng.byte();
            }
            if let Ok(forged) = postcard::from_bytes(&bytes) {
                return forged;
            }
        }
        table
    }
}

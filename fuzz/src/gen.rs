//! Structured input: batches of commands of every `Command`, `PlaneOp` and `ObjectOp`
//! variant with every `PlaneProp` and `ObjectProp`. Each command is drawn either *valid*
//! (realistic values on a plane and an object the client owns, so it gets past validation
//! and runs the engine) or *wild* (fields replaced by NaN, infinities, zeros, subnormals,
//! huge values, random bits; stale, random and out-of-range handles; unknown plane ids;
//! degenerate meshes and bad triangle indices).

use shm_layout::{
    AxisMode, CollisionGroups, Command, ControllerOp, ControllerProp, FilterType, GuiControllerOp,
    GuiControllerProp, GuiObjectOp, GuiObjectProp, GuiOp, GuiPlaneProp, GuiShape, Handle,
    JointKind, JointOp, JointProp, MapOp, ObjectOp, ObjectProp, OptionalJointProp, Pin, PlaneId,
    PlaneKind, PlaneOp, PlaneProp, Pose, QueryFilter, QueryOp, Ray, Restraint, RotateTo, Shape,
    TransferOp, Vec3, CRATE_VERSION,
};

use super::rng::Rng;
use super::world::World;

/// Own planes a client keeps at most (valid creations beyond it destroy one instead).
const MAX_OWN_PLANES: usize = 6;
/// Objects valid adds put into one plane at most, so steps stay cheap.
const MAX_VALID_OBJECTS: usize = 120;
/// Share of commands drawn wild.
const WILD: f64 = 0.35;

/// Draws commands for one client from the seeded stream and the world it learned.
pub struct Gen<'a> {
    rng: &'a mut Rng,
    world: &'a World,
    client: usize,
    /// Planes and objects earlier commands of this batch destroy: valid commands leave
    /// them alone (the world learns of it only from the reply).
    dropped_planes: Vec<PlaneId>,
    dropped_handles: Vec<Handle>,
}

impl<'a> Gen<'a> {
    /// Commands for `client`, drawn from `rng`, aimed with what `world` knows.
    pub fn new(rng: &'a mut Rng, world: &'a World, client: usize) -> Gen<'a> {
        Gen {
            rng,
            world,
            client,
            dropped_planes: Vec::new(),
            dropped_handles: Vec::new(),
        }
    }

    /// A batch of 1 to 1,000 commands (mostly short), led by a `Hello` when the client is
    /// not connected.
    pub fn batch(&mut self) -> Vec<Command> {
        let n = match self.rng.unit() {
            u if u < 0.5 => self.rng.range(1, 4),
            u if u < 0.85 => self.rng.range(5, 32),
            u if u < 0.98 => self.rng.range(33, 200),
            _ => self.rng.range(201, 1_000),
        };
        let mut batch = Vec::with_capacity(n + 1);
        if !self.world.connected[self.client] {
            batch.push(hello());
            // A read-only listing, once per (re)connection: outside the random stream, so
            // every other command comes out as it would without it.
            batch.push(Command::ListPlanes);
        }
        for _ in 0..n {
            let command = self.command();
            match &command {
                Command::Plane {
                    plane,
                    op: PlaneOp::Destroy,
                } => self.dropped_planes.push(*plane),
                Command::Plane {
                    op:
                        PlaneOp::Object {
                            handle,
                            op: ObjectOp::Destroy,
                        },
                    ..
                } => self.dropped_handles.push(*handle),
                _ => {}
            }
            batch.push(command);
        }
        batch
    }

    /// The client's planes not destroyed earlier in this batch.
    fn own_planes(&self) -> Vec<PlaneId> {
        let mut own = self.world.own_planes(self.client);
        own.retain(|id| !self.dropped_planes.contains(id));
        own
    }

    /// The plane's live objects not destroyed earlier in this batch.
    fn live(&self, id: PlaneId) -> Vec<Handle> {
        self.world.planes.get(&id).map_or_else(Vec::new, |p| {
            p.live
                .iter()
                .filter(|h| !self.dropped_handles.contains(h))
                .copied()
                .collect()
        })
    }

    /// One command.
    pub fn command(&mut self) -> Command {
        let wild = self.rng.chance(WILD);
        let own = self.own_planes();
        let u = self.rng.unit();
        if u < 0.0003 {
            return Command::Goodbye;
        }
        if u < 0.005 {
            return if self.rng.chance(0.5) {
                hello()
            } else {
                Command::Hello {
                    crate_version: self.text(),
                    pid: self.rng.u32(),
                }
            };
        }
        if u < 0.04 || (own.is_empty() && !wild && self.rng.chance(0.7)) {
            if own.len() >= MAX_OWN_PLANES && !wild {
                let id = *self.rng.pick(&own);
                return Command::plane(id, PlaneOp::Destroy);
            }
            return self.create_plane(wild);
        }
        if u < 0.045 {
            return Command::Transfer(self.transfer_op());
        }
        let plane = self.plane_id(wild, &own);
        let op = self.plane_op(wild, plane);
        Command::Plane { plane, op }
    }

    /// A snapshot transfer op: opens of any size, pieces with made-up numbers, offsets and
    /// totals (the daemon must refuse each by name and hold nothing for long).
    fn transfer_op(&mut self) -> TransferOp {
        let transfer = self.rng.range(0, 64) as u32;
        let total = *self.rng.pick(&[0, 1, 100, 5 << 20, u64::MAX]);
        let offset = *self.rng.pick(&[0, 1, 100, u64::MAX]);
        match self.rng.range(0, 4) {
            0 => TransferOp::Open { total },
            1 => TransferOp::Put {
                transfer,
                total,
                offset,
                bytes: (0..self.rng.range(0, 200))
                    .map(|_| self.rng.u32() as u8)
                    .collect(),
            },
            2 => TransferOp::Get { transfer, offset },
            _ => TransferOp::Close { transfer },
        }
    }

    fn create_plane(&mut self, wild: bool) -> Command {
        let mut props = Vec::new();
        if !wild || self.rng.chance(0.5) {
            // Mostly manual: automatic planes tick on their own and compete for the daemon.
            props.push(PlaneProp::TickRate(if self.rng.chance(0.85) {
                0.0
            } else {
                *self.rng.pick(&[30.0, 60.0, 120.0])
            }));
        }
        for _ in 0..self.rng.below(5) {
            props.push(self.plane_prop(wild, true));
        }
        // Now and then a 2D GUI plane (its own options; 3D options are refused there).
        if self.rng.chance(0.2) {
            let mut props = vec![PlaneProp::TickRate(0.0)];
            for _ in 0..self.rng.below(3) {
                props.push(PlaneProp::Gui(self.gui_plane_prop(wild)));
            }
            return Command::CreatePlane {
                kind: PlaneKind::Gui2d,
                props,
            };
        }
        Command::CreatePlane {
            kind: PlaneKind::Rapier3d,
            props,
        }
    }

    /// An own plane mostly; sometimes another client's, a gone one or one never created.
    fn plane_id(&mut self, wild: bool, own: &[PlaneId]) -> PlaneId {
        let u = self.rng.unit();
        if !own.is_empty() && (u < 0.8 || !wild && u < 0.95) {
            return *self.rng.pick(own);
        }
        let foreign = self.world.foreign_planes(self.client);
        if !foreign.is_empty() && u < 0.9 {
            return *self.rng.pick(&foreign);
        }
        match self.rng.below(5) {
            0 if !self.world.gone.is_empty() => *self.rng.pick(&self.world.gone),
            1 => self.world.max_id + 1 + self.rng.below(3) as u32,
            2 => self.rng.special_u32(),
            _ => self.rng.u32(),
        }
    }

    fn plane_op(&mut self, wild: bool, id: PlaneId) -> PlaneOp {
        let live = self.live(id).len();
        let mut u = self.rng.unit();
        // Valid commands need something to act on, and keep planes small.
        if !wild && live == 0 && u >= 0.45 {
            u = 0.3;
        }
        if !wild && live >= MAX_VALID_OBJECTS && (0.25..0.45).contains(&u) {
            u = 0.5;
        }
        match u {
            u if u < 0.03 => PlaneOp::Info,
            u if u < 0.10 => PlaneOp::Set(self.plane_prop(wild, false)),
            u if u < 0.24 => PlaneOp::Step { dt: self.dt(wild) },
            u if u < 0.25 => {
                if wild || self.rng.chance(0.3) {
                    PlaneOp::Destroy
                } else {
                    PlaneOp::Info
                }
            }
            u if u < 0.45 => self.add_object(wild),
            // The newer op families take small slices, so object ops (mostly applied) keep
            // their share and a run still exercises the engine, not only the checks.
            u if u < 0.475 => PlaneOp::Query(self.query(wild, id)),
            u if u < 0.48 => PlaneOp::Explode(self.explosion(wild, id)),
            u if u < 0.485 => PlaneOp::CollisionGroups(self.collision_groups(wild)),
            u if u < 0.51 => PlaneOp::Controller(self.controller_op(wild, id)),
            u if u < 0.53 => PlaneOp::Gui(self.gui_op(wild, id)),
            u if u < 0.555 => PlaneOp::Joint(self.joint_op(wild, id)),
            u if u < 0.565 => PlaneOp::Map(self.map_op(wild)),
            u if u < 0.57 => self.snapshot_op(wild),
            _ => {
                let handle = self.handle(wild, id);
                PlaneOp::Object {
                    handle,
                    op: self.object_op(wild),
                }
            }
        }
    }

    /// A snapshot (valid), or a restore of forged bytes: random, or a snapshot's start
    /// followed by random bytes (the daemon must refuse both by name and keep the plane).
    fn snapshot_op(&mut self, wild: bool) -> PlaneOp {
        if !wild {
            return PlaneOp::Snapshot;
        }
        let mut bytes = Vec::new();
        if self.rng.chance(0.5) {
            bytes.extend_from_slice(&shm_layout::snapshot::SNAPSHOT_MAGIC);
            bytes.extend_from_slice(&(self.rng.range(0, 64) as u32).to_le_bytes());
        }
        for _ in 0..self.rng.range(0, 256) {
            bytes.push(self.rng.u32() as u8);
        }
        if self.rng.chance(0.2) {
            return PlaneOp::RestoreUploaded {
                transfer: self.rng.range(0, 64) as u32,
                overrides: Vec::new(),
            };
        }
        PlaneOp::Restore {
            bytes,
            overrides: Vec::new(),
        }
    }

    /// A step length: the usual 1/60 s, anything from 1 µs to the 1 s limit, or (wild)
    /// NaN, infinities, zero, negative, subnormal, just past the limit.
    fn dt(&mut self, wild: bool) -> f32 {
        if wild && self.rng.chance(0.6) {
            return *self.rng.pick(&[
                f32::NAN,
                f32::INFINITY,
                f32::NEG_INFINITY,
                0.0,
                -0.0,
                -1.0 / 60.0,
                1e-45,
                1e-38,
                1e-12,
                1.000_000_1,
                2.0,
                1e38,
                f32::MAX,
            ]);
        }
        if self.rng.chance(0.5) {
            1.0 / 60.0
        } else {
            self.rng.log_f32(1e-6, 1.0)
        }
    }

    /// Any scene query, with valid or wild rays, shapes, filters and groups.
    fn query(&mut self, wild: bool, id: PlaneId) -> QueryOp {
        let filter = QueryFilter {
            filter_type: if self.rng.chance(0.5) {
                FilterType::Exclude
            } else {
                FilterType::Include
            },
            list: (0..self.rng.below(4))
                .map(|_| self.handle(wild, id))
                .collect(),
            collision_group: self
                .rng
                .chance(0.3)
                .then(|| self.rng.below(if wild { 256 } else { 3 }) as u8),
            respect_can_collide: self.rng.chance(0.5),
        };
        let r = &mut *self.rng;
        let radius = {
            let v = r.log_f32(0.01, 5.0);
            r.maybe_wild(wild, v)
        };
        match r.below(11) {
            0 => QueryOp::Raycast {
                rays: (0..r.below(70))
                    .map(|_| Ray {
                        origin: r.vec3(wild, 30.0),
                        direction: r.vec3(wild, 60.0),
                    })
                    .collect(),
                filter,
            },
            1 => QueryOp::Spherecast {
                origin: r.vec3(wild, 30.0),
                radius,
                direction: r.vec3(wild, 60.0),
                filter,
            },
            2 => QueryOp::Blockcast {
                pose: r.pose(wild, 30.0),
                size: [radius, 1.0, 2.0],
                direction: r.vec3(wild, 60.0),
                filter,
            },
            3 => QueryOp::Shapecast {
                object: self.handle(wild, id),
                direction: self.rng.vec3(wild, 60.0),
                filter,
            },
            4 => QueryOp::BoundsInRadius {
                position: r.vec3(wild, 30.0),
                radius,
                filter,
            },
            5 => QueryOp::BoundsInBox {
                pose: r.pose(wild, 30.0),
                size: [radius, 2.0, 1.0],
                filter,
            },
            6 => QueryOp::InPart {
                object: self.handle(wild, id),
                filter,
            },
            7 => QueryOp::ProbeGround {
                position: r.vec3(wild, 30.0),
                radius,
                max_distance: r.maybe_wild(wild, 20.0),
                max_slope: r.maybe_wild(wild, 45.0),
                filter,
            },
            8 => QueryOp::ClosestPoint {
                position: r.vec3(wild, 30.0),
                max_distance: r.maybe_wild(wild, 50.0),
                filter,
            },
            9 => QueryOp::Clearance {
                shape: Shape::Capsule {
                    size: [radius, radius * 3.0, radius],
                },
                pose: r.pose(wild, 30.0),
                max_distance: r.maybe_wild(wild, 50.0),
                own: None,
                filter,
            },
            _ => QueryOp::ProbeWall {
                pose: r.pose(wild, 30.0),
                radius,
                height: r.maybe_wild(wild, 3.0),
                max_distance: r.maybe_wild(wild, 1.0),
                max_slope: r.maybe_wild(wild, 45.0),
                filter,
            },
        }
    }

    /// An explosion with valid or wild numbers and filter.
    fn explosion(&mut self, wild: bool, id: PlaneId) -> shm_layout::Explosion {
        let filter = QueryFilter {
            list: (0..self.rng.below(3))
                .map(|_| self.handle(wild, id))
                .collect(),
            ..QueryFilter::default()
        };
        let r = &mut *self.rng;
        shm_layout::Explosion {
            center: r.vec3(wild, 30.0),
            radius: r.maybe_wild(wild, 8.0),
            impulse: r.maybe_wild(wild, 20.0),
            falloff: *r.pick(&[
                shm_layout::Falloff::Linear,
                shm_layout::Falloff::None,
                shm_layout::Falloff::InverseSquare,
            ]),
            filter,
        }
    }

    /// Any controller op, on a live handle mostly (which may or may not be a controller).
    fn controller_op(&mut self, wild: bool, id: PlaneId) -> ControllerOp {
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

    /// Any GUI-plane option with a valid or wild value.
    fn gui_plane_prop(&mut self, wild: bool) -> GuiPlaneProp {
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
    fn gui_object_prop(&mut self, wild: bool) -> GuiObjectProp {
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
    fn gui_op(&mut self, wild: bool, id: PlaneId) -> GuiOp {
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

    /// A collision-group table: a valid one, or (wild) a forged one.
    fn collision_groups(&mut self, wild: bool) -> CollisionGroups {
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

    fn add_object(&mut self, wild: bool) -> PlaneOp {
        let shape = self.shape(wild);
        let pose = self.rng.pose(wild, 30.0);
        let props = (0..self.rng.below(4))
            .map(|_| self.object_prop(wild))
            .collect();
        PlaneOp::AddObject { shape, pose, props }
    }

    /// A live handle of the plane mostly; a stale one, a neighbour's generation or a bogus
    /// one otherwise.
    fn handle(&mut self, wild: bool, id: PlaneId) -> Handle {
        let live = self.live(id);
        let u = self.rng.unit();
        if let Some(p) = self.world.planes.get(&id) {
            if !live.is_empty() && (u < 0.75 || !wild && u < 0.97) {
                return *self.rng.pick(&live);
            }
            if !p.stale.is_empty() && u < 0.85 {
                return *self.rng.pick(&p.stale);
            }
            if !live.is_empty() && u < 0.9 {
                let h = *self.rng.pick(&live);
                return Handle {
                    slot: h.slot,
                    generation: h.generation.wrapping_add(1),
                };
            }
        }
        self.rng.bogus_handle()
    }

    /// A joint op: creation between live objects (or the world) with valid or wild options,
    /// and Set / Info / Destroy on handles that may or may not be joints.
    fn joint_op(&mut self, wild: bool, id: PlaneId) -> JointOp {
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
            60..=79 => JointOp::Info { joint },
            _ => JointOp::Destroy { joint },
        }
    }

    fn joint_prop(&mut self, wild: bool) -> JointProp {
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

    /// A map op: small uploads (valid grids, or wild: NaN vertices, indices past the end,
    /// degenerate triangles), builds at valid or wild poses and scales, discards.
    fn map_op(&mut self, wild: bool) -> MapOp {
        match self.rng.below(100) {
            0..=59 => {
                let n = self.rng.range(1, 6);
                let mut vertices = Vec::new();
                for i in 0..=n {
                    for j in 0..=n {
                        vertices.push([i as f32, 0.0, j as f32]);
                    }
                }
                let mut triangles = Vec::new();
                let w = n as u32 + 1;
                for i in 0..n as u32 {
                    for j in 0..n as u32 {
                        let a = i * w + j;
                        triangles.push([a, a + 1, a + w]);
                        triangles.push([a + 1, a + w + 1, a + w]);
                    }
                }
                if wild {
                    match self.rng.below(4) {
                        0 => vertices[0] = self.rng.vec3(true, 1.0),
                        1 => triangles.push([0, 0, self.rng.special_u32()]),
                        2 => triangles.push([0, 0, 1]),
                        _ => triangles.clear(),
                    }
                }
                MapOp::Upload {
                    vertices,
                    triangles,
                }
            }
            60..=89 => MapOp::Build {
                pose: self.rng.pose(wild, 30.0),
                scale: if wild && self.rng.chance(0.5) {
                    self.rng.vec3(true, 1.0)
                } else {
                    [self.rng.f32_in(0.5, 2.0); 3]
                },
                vertices: if wild { self.rng.u64() % 100 } else { 0 },
                triangles: if wild { self.rng.u64() % 100 } else { 0 },
            },
            _ => MapOp::Discard,
        }
    }

    fn object_op(&mut self, wild: bool) -> ObjectOp {
        match self.rng.below(100) {
            0..=54 => ObjectOp::Set(self.object_prop(wild)),
            55..=66 => ObjectOp::ApplyImpulse(self.rng.vec3(wild, 20.0)),
            67..=76 => ObjectOp::Info,
            77..=81 => ObjectOp::RecalculateCenterOfMass,
            82..=89 => ObjectOp::Wake,
            _ => ObjectOp::Destroy,
        }
    }

    /// A shape: cube, sphere, capsule, cylinder, wedge or mesh.
    fn shape(&mut self, wild: bool) -> Shape {
        match self.rng.below(100) {
            0..=29 => Shape::Cube {
                size: self.size(wild),
            },
            30..=39 => Shape::Capsule {
                size: self.size(wild),
            },
            40..=49 => Shape::Cylinder {
                size: self.size(wild),
            },
            50..=59 => Shape::Wedge {
                size: self.size(wild),
            },
            60..=79 => {
                let r = self.rng.f32_in(0.05, 2.0);
                Shape::Sphere {
                    radius: self.rng.maybe_wild(wild, r),
                }
            }
            _ => self.mesh(wild),
        }
    }

    fn size(&mut self, wild: bool) -> Vec3 {
        [0; 3].map(|_| {
            let s = self.rng.f32_in(0.1, 4.0);
            self.rng.maybe_wild(wild, s)
        })
    }

    /// A mesh part: a valid point cloud with valid triangles, or (wild) too few vertices,
    /// coplanar, collinear or coincident points, non-finite, huge or tiny coordinates, bad
    /// triangle indices, or many vertices.
    fn mesh(&mut self, wild: bool) -> Shape {
        let cloud = |rng: &mut Rng, n: usize, scale: f32| -> Vec<Vec3> {
            (0..n)
                .map(|_| [0; 3].map(|_| rng.f32_in(-scale, scale)))
                .collect()
        };
        let n = self.rng.range(4, 32);
        let mut vertices = cloud(self.rng, n, 1.0);
        let mut triangles = self.triangles(vertices.len(), 0);
        if wild {
            match self.rng.below(11) {
                0 => vertices.truncate(self.rng.below(4)),
                1 => vertices.iter_mut().for_each(|v| v[2] = 0.0),
                2 => vertices
                    .iter_mut()
                    .for_each(|v| *v = [v[0], 2.0 * v[0], -v[0]]),
                3 => {
                    let p = vertices[0];
                    vertices.iter_mut().for_each(|v| *v = p);
                }
                4 => {
                    let i = self.rng.below(vertices.len());
                    vertices[i][self.rng.below(3)] = self.rng.special_f32();
                }
                5 => {
                    let scale = *self.rng.pick(&[1e20, 1e30, 1e38]);
                    vertices = cloud(self.rng, n, scale);
                }
                6 => {
                    let scale = *self.rng.pick(&[1e-20, 1e-30, 1e-38]);
                    vertices = cloud(self.rng, n, scale);
                }
                7 => {
                    let bad = 1 + self.rng.below(3);
                    triangles = self.triangles(vertices.len(), bad);
                }
                8 => {
                    let n = self.rng.range(1_000, 4_000);
                    vertices = cloud(self.rng, n, 3.0);
                    triangles = self.triangles(n, 0);
                }
                9 => vertices.iter_mut().for_each(|v| v[2] *= 1e-7),
                _ => {
                    // More triangles than any real part, all in range.
                    let m = self.rng.range(1_000, 20_000);
                    triangles = (0..m)
                        .map(|_| [0; 3].map(|_| self.rng.below(n) as u32))
                        .collect();
                }
            }
        }
        Shape::Mesh {
            vertices,
            triangles,
        }
    }

    /// Up to 16 triangles over `n` vertices, `bad` of them with an index out of range.
    fn triangles(&mut self, n: usize, bad: usize) -> Vec<[u32; 3]> {
        let mut t: Vec<[u32; 3]> = (0..self.rng.below(17))
            .map(|_| [0; 3].map(|_| self.rng.below(n) as u32))
            .collect();
        for _ in 0..bad {
            let k = *self.rng.pick(&[n as u32, n as u32 + 1, u32::MAX, 1 << 31]);
            let tri = [self.rng.below(n.max(1)) as u32, k, 0];
            let at = self.rng.below(t.len() + 1);
            t.insert(at, tri);
        }
        t
    }

    /// Any plane option with a valid or wild value; creation-only ones too.
    fn plane_prop(&mut self, wild: bool, creating: bool) -> PlaneProp {
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
    fn object_prop(&mut self, wild: bool) -> ObjectProp {
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

    /// A short string: empty, a near-miss version, or random (possibly invalid-looking)
    /// characters.
    fn text(&mut self) -> String {
        match self.rng.below(4) {
            0 => String::new(),
            1 => format!("{CRATE_VERSION}-x"),
            2 => "9.9.9".into(),
            _ => (0..self.rng.below(40))
                .map(|_| char::from_u32(self.rng.below(0x3000) as u32).unwrap_or('?'))
                .collect(),
        }
    }
}

/// The handshake a client of this build sends.
pub fn hello() -> Command {
    Command::Hello {
        crate_version: CRATE_VERSION.to_string(),
        pid: std::process::id(),
    }
}

/// `count` points on a unit sphere (golden-angle spiral): a mesh whose hull keeps them all.
pub fn sphere_points(count: usize) -> Vec<Vec3> {
    (0..count)
        .map(|i| {
            let t = i as f32 * 2.399_963;
            let y = 1.0 - 2.0 * (i as f32 + 0.5) / count as f32;
            let r = (1.0 - y * y).max(0.0).sqrt();
            [r * t.cos(), y, r * t.sin()]
        })
        .collect()
}

/// A small valid box at `at`, for the quota rounds.
pub fn small_cube(at: Vec3) -> PlaneOp {
    PlaneOp::AddObject {
        shape: Shape::Cube { size: [0.5; 3] },
        pose: Pose::at(at),
        props: vec![ObjectProp::Anchored(true)],
    }
}

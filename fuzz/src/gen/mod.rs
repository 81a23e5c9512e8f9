//! Structured input: batches of commands of every `Command`, `PlaneOp` and `ObjectOp`
//! variant with every `PlaneProp` and `ObjectProp`. Each command is drawn either *valid*
//! (realistic values on a plane and an object the client owns, so it gets past validation
//! and runs the engine) or *wild* (fields replaced by NaN, infinities, zeros, subnormals,
//! huge values, random bits; stale, random and out-of-range handles; unknown plane ids;
//! degenerate meshes and bad triangle indices).
//!
//! This file holds the generator, the batch, the command and plane-op dispatch, handles and
//! the snapshot ops; each family of ops or values draws in a file of its own (`props`,
//! `shape`, `query`, `controller`, `gui`, `joint`, `map`, `record`), adding methods to [`Gen`].

mod controller;
mod gui;
mod joint;
mod map;
mod props;
mod query;
mod record;
mod shape;

use shm_layout::{
    Command, Handle, ObjectOp, ObjectProp, PlaneId, PlaneKind, PlaneOp, PlaneProp, Pose, Shape,
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
            u if u < 0.573 => self.record_op(wild),
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

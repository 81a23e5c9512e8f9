//! Commands (client → daemon) and replies (daemon → client).
//!
//! Planes and objects are created with a list of properties rather than a fixed struct, so a
//! new property is one new enum variant on each side, not a new command.

use serde::{Deserialize, Serialize};

use crate::records::Handle;

pub type PlaneId = u32;
pub type Vec3 = [f32; 3];

/// Position plus unit quaternion `[x, y, z, w]`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Pose {
    pub position: Vec3,
    pub rotation: [f32; 4],
}

impl Pose {
    pub const IDENTITY: Pose = Pose {
        position: [0.0; 3],
        rotation: [0.0, 0.0, 0.0, 1.0],
    };

    pub fn at(position: Vec3) -> Pose {
        Pose {
            position,
            ..Pose::IDENTITY
        }
    }
}

impl Default for Pose {
    fn default() -> Self {
        Pose::IDENTITY
    }
}

/// Collision shape of an object.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum Shape {
    /// A box with the given full size along x, y, z.
    Cube { size: Vec3 },
    /// A sphere with the given radius.
    Sphere { radius: f32 },
    /// A part that carries a mesh (body-local vertices, triangles as vertex indices). It
    /// collides as the convex hull of its vertices.
    Mesh {
        vertices: Vec<Vec3>,
        triangles: Vec<[u32; 3]>,
    },
}

/// The kind of an object's shape, as reported back.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum ShapeKind {
    Cube,
    Sphere,
    Mesh,
}

impl Shape {
    pub fn kind(&self) -> ShapeKind {
        match self {
            Shape::Cube { .. } => ShapeKind::Cube,
            Shape::Sphere { .. } => ShapeKind::Sphere,
            Shape::Mesh { .. } => ShapeKind::Mesh,
        }
    }
}

/// `FieldRestraint`: which axes an object may move along / rotate around. `None` leaves a
/// flag as it is.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Restraint {
    pub lock_x: Option<bool>,
    pub lock_y: Option<bool>,
    pub lock_z: Option<bool>,
    pub lock_rot_x: Option<bool>,
    pub lock_rot_y: Option<bool>,
    pub lock_rot_z: Option<bool>,
}

impl Restraint {
    /// The flags in the order LockX, LockY, LockZ, LockRotX, LockRotY, LockRotZ.
    pub fn flags(&self) -> [Option<bool>; 6] {
        [
            self.lock_x,
            self.lock_y,
            self.lock_z,
            self.lock_rot_x,
            self.lock_rot_y,
            self.lock_rot_z,
        ]
    }
}

/// `RotateTo`: a proportional controller driving the angular velocity toward `target`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct RotateTo {
    /// Target orientation, unit quaternion `[x, y, z, w]`.
    pub target: [f32; 4],
    /// Gain (1/s): the orientation error decays as `exp(-strength·t)`.
    pub strength: f32,
}

/// `SetPin`: pulls the body-local point `relative` toward `target.position` and turns the
/// body toward `target.rotation`, with a force capped at `force`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Pin {
    pub force: f32,
    pub relative: Vec3,
    pub target: Pose,
}

/// A plane option. Options marked "creation only" are rejected by `SetPlane`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum PlaneProp {
    /// Acceleration applied to every non-anchored object (units/s²).
    Gravity(Vec3),
    /// Worker threads; a rayon pool is built only when > 1. Creation only.
    Threads(u32),
    /// Ticks per second of wall time; 0 = manual (only `Step` advances the plane).
    TickRate(f32),
    /// When false the plane does not advance.
    Enabled(bool),
    /// Per-second linear damping: each tick `v *= max(0, 1 - k·dt)`. Default 0.10.
    LinearDamping(f32),
    /// The same for angular velocity. Default 0.30.
    AngularDamping(f32),
    /// Quadratic drag coefficient: `F = -Drag·|v|·v`. Default 0.
    Drag(f32),
    /// Upward acceleration on every dynamic body. Default 0.
    Buoyancy(f32),
    /// World-space force on every dynamic body (heavier bodies accelerate less).
    ConstantForce(Vec3),
    /// Normal approach speed below which a contact does not bounce. Default 0.5.
    RestThreshold(f32),
    /// Solver iterations per tick, clamped to [1, 64]. Default 4.
    SolverIterations(u32),
    /// Pins the solver at 64 iterations.
    LoopSolver(bool),
    /// Keeps every body awake.
    NeverSleep(bool),
}

/// An object property.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum ObjectProp {
    /// Teleports the object.
    Pose(Pose),
    Velocity(Vec3),
    AngularVelocity(Vec3),
    /// Anchored objects do not move; setting it zeroes both velocities.
    Anchored(bool),
    /// Report contact started / stopped events for this object.
    ReportContacts(bool),
    /// Mass used when `Density` is 0 (impulses divide by it; free fall ignores it). Default 1.
    Weight(f32),
    /// When > 0, mass = Density × volume (wins over Weight). 0 returns to Weight.
    Density(f32),
    /// Restitution, clamped to [0, 1]; a pair uses the higher value. Default 0.
    Bounciness(f32),
    /// Coulomb friction in [0, 1]; a pair uses `sqrt(a·b)`. Default 0.5.
    Friction(f32),
    /// When false the object passes through everything.
    CanCollide(bool),
    /// Fidelity dial, clamped to [1, 32]. Default 1.
    HitBoxQuality(u32),
    /// Full size of the object's box (a sphere takes the smallest half-extent as radius; a
    /// mesh is scaled to it).
    Size(Vec3),
    /// Body-local centre of mass; non-zero switches to the real inertia of the shape.
    CenterOfMass(Vec3),
    /// Persistent acceleration applied every tick.
    ImpulseDirection(Vec3),
    /// Persistent world-space force applied every tick.
    ConstantForce(Vec3),
    FieldRestraint(Restraint),
    /// `None` stops the controller (angular velocity is left as it is).
    RotateTo(Option<RotateTo>),
    /// `None` releases the pin.
    Pin(Option<Pin>),
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum Command {
    /// Must be the first command of a client: identifies it and checks versions.
    Hello {
        crate_version: String,
        pid: u32,
    },
    /// Creates a plane with defaults, then applies `props` in order. Owned by the sender.
    CreatePlane {
        props: Vec<PlaneProp>,
    },
    /// Describes a plane (any client may ask; used to attach to planes of other clients).
    PlaneInfo {
        plane: PlaneId,
    },
    SetPlane {
        plane: PlaneId,
        prop: PlaneProp,
    },
    /// Advances the plane by `dt` seconds; the reply comes after the new tick is published.
    Step {
        plane: PlaneId,
        dt: f32,
    },
    /// Removes the plane and all its objects.
    DestroyPlane {
        plane: PlaneId,
    },
    AddObject {
        plane: PlaneId,
        shape: Shape,
        pose: Pose,
        props: Vec<ObjectProp>,
    },
    SetObject {
        plane: PlaneId,
        object: Handle,
        prop: ObjectProp,
    },
    /// Velocity-space impulse (`Δv = impulse / mass`).
    ApplyImpulse {
        plane: PlaneId,
        object: Handle,
        impulse: Vec3,
    },
    DestroyObject {
        plane: PlaneId,
        object: Handle,
    },
    /// Every property of an object.
    ObjectInfo {
        plane: PlaneId,
        object: Handle,
    },
    /// Sets the centre of mass to the vertex centroid of the object's mesh (no-op for a cube
    /// or sphere); replies with the centre of mass in effect.
    RecalculateCenterOfMass {
        plane: PlaneId,
        object: Handle,
    },
    /// Orderly goodbye: the daemon releases the client's planes.
    Goodbye,
}

/// What the daemon knows about a plane.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PlaneInfo {
    pub id: PlaneId,
    pub gravity: Vec3,
    pub threads: u32,
    pub tick_rate: f32,
    pub enabled: bool,
    pub tick: u64,
    pub object_count: u32,
    pub linear_damping: f32,
    pub angular_damping: f32,
    pub drag: f32,
    pub buoyancy: f32,
    pub constant_force: Vec3,
    pub rest_threshold: f32,
    /// As set (clamped to [1, 64]).
    pub solver_iterations: u32,
    pub loop_solver: bool,
    pub never_sleep: bool,
    /// Iterations the solver runs now: LoopSolver, SolverIterations and HitBoxQuality scaling.
    pub effective_solver_iterations: u32,
    /// Largest HitBoxQuality among the plane's objects (1 when empty).
    pub max_hit_box_quality: u32,
}

/// Every property of an object, as the daemon holds it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ObjectInfo {
    pub handle: Handle,
    pub shape: ShapeKind,
    pub size: Vec3,
    pub anchored: bool,
    pub weight: f32,
    /// The density in effect: the explicit value, or Weight ÷ volume.
    pub density: f32,
    /// The mass in effect.
    pub mass: f32,
    pub bounciness: f32,
    pub friction: f32,
    pub can_collide: bool,
    pub hit_box_quality: u32,
    pub center_of_mass: Vec3,
    pub impulse_direction: Vec3,
    pub constant_force: Vec3,
    /// LockX, LockY, LockZ, LockRotX, LockRotY, LockRotZ as set by FieldRestraint.
    pub locks: [bool; 6],
    /// Rotation locked because the object is a low-quality non-sphere without CenterOfMass.
    pub rotation_locked_by_quality: bool,
    pub ccd: bool,
    pub rotate_to: Option<RotateTo>,
    pub pin: Option<Pin>,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum Reply {
    Done,
    Welcome {
        daemon_pid: u32,
        daemon_node_id: u128,
        crate_version: String,
    },
    Plane(PlaneInfo),
    /// A new object, and the plane tick after which published samples include it.
    Object {
        handle: Handle,
        tick: u64,
    },
    /// An object mutation was applied after `tick`: samples newer than `tick` reflect it.
    Applied {
        tick: u64,
    },
    /// The tick number now visible in shared memory.
    Stepped {
        tick: u64,
    },
    ObjectInfo(Box<ObjectInfo>),
    /// The centre of mass in effect, body-local.
    CenterOfMass(Vec3),
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum ErrorKind {
    /// A field has a value outside its domain (NaN, negative size, ...).
    InvalidValue,
    UnknownPlane,
    /// The handle's slot is empty or holds a newer generation.
    StaleHandle,
    /// The request bytes could not be decoded.
    Malformed,
    /// Layout or crate versions of client and daemon differ.
    VersionMismatch,
    /// A command came before `Hello`.
    NotConnected,
    /// The daemon could not do it (resource exhaustion, shared-memory failure).
    Internal,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CommandError {
    pub kind: ErrorKind,
    pub message: String,
}

impl CommandError {
    pub fn new(kind: ErrorKind, message: impl Into<String>) -> Self {
        CommandError {
            kind,
            message: message.into(),
        }
    }
    pub fn invalid(message: impl Into<String>) -> Self {
        Self::new(ErrorKind::InvalidValue, message)
    }
}

impl core::fmt::Display for CommandError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(f, "{:?}: {}", self.kind, self.message)
    }
}

impl std::error::Error for CommandError {}

pub type CommandResult = Result<Reply, CommandError>;

/// One request: a batch of commands from one client. The client's iceoryx2 node id travels
/// in the request's user header, so even an undecodable request can be answered.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Request {
    pub commands: Vec<Command>,
}

/// The answer to one request: one result per command, in order, or the rejection of the
/// whole request when it could not be decoded.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum Response {
    Results(Vec<CommandResult>),
    Rejected(CommandError),
}

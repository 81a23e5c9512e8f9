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
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum Shape {
    /// A box with the given full size along x, y, z.
    Cube { size: Vec3 },
    /// A sphere with the given radius.
    Sphere { radius: f32 },
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

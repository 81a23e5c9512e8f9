//! Commands (client → daemon) and replies (daemon → client).
//!
//! Commands are nested by target: a [`Command`] names a plane, a [`PlaneOp`] names what to
//! do to it (or to one of its objects, through [`ObjectOp`]). The server resolves the plane
//! and hands the op to it; a new family of ops (controllers, joints, queries) is a new
//! sub-enum in a file of its own, not a new server branch.

use serde::{Deserialize, Serialize};

pub use crate::geometry::{Pose, Vec3};
pub use crate::ids::PlaneId;

use crate::error::CommandError;
use crate::ids::Handle;
use crate::joint_op::JointInfo;
use crate::map_op::MapInfo;
use crate::object_op::ObjectOp;
use crate::plane_op::{PlaneKind, PlaneOp};
use crate::query::Hit;
use crate::settings::{ObjectSettings, PlaneProp, PlaneSettings};
use crate::shape::ShapeKind;

/// One command of a request.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum Command {
    /// Must be the first command of a client: identifies it and checks versions.
    Hello {
        /// The client's crate version.
        crate_version: String,
        /// The client's process id.
        pid: u32,
    },
    /// Creates a plane of `kind` with defaults, then applies `props` in order. Owned by the
    /// sender.
    CreatePlane {
        /// Which backend simulates the plane.
        kind: PlaneKind,
        /// Options applied after the defaults.
        props: Vec<PlaneProp>,
    },
    /// Something done to an existing plane or to something in it.
    Plane {
        /// The plane.
        plane: PlaneId,
        /// What to do.
        op: PlaneOp,
    },
    /// Orderly goodbye: the daemon releases the client's planes.
    Goodbye,
    /// Lists the ids of every plane of the daemon (any client may ask; read-only).
    /// Replies [`Reply::PlaneIds`].
    ListPlanes,
    /// Lists the named planes of the daemon ([`crate::NamedPlane`]: name, id, kind,
    /// persistent, tick), by name. Replies [`Reply::NamedPlanes`].
    ListNamedPlanes,
    /// Attaches to the named plane `name`: an orphaned plane (a persistent plane whose owner
    /// left, or one restored from the state directory) becomes the sender's. Replies
    /// [`Reply::Opened`].
    OpenPlane {
        /// The plane's name.
        name: String,
    },
    /// An op on a snapshot transfer of this connection (snapshots in pieces,
    /// [`crate::snapshot_transfer`]). Replies [`Reply::Transfer`].
    Transfer(crate::snapshot_transfer::TransferOp),
}

impl Command {
    /// `op` on `plane`.
    pub fn plane(plane: PlaneId, op: PlaneOp) -> Command {
        Command::Plane { plane, op }
    }

    /// `op` on the object `handle` of `plane`.
    pub fn object(plane: PlaneId, handle: Handle, op: ObjectOp) -> Command {
        Command::Plane {
            plane,
            op: PlaneOp::Object { handle, op },
        }
    }
}

/// What the daemon knows about a plane: its options as set (read through `Deref`, so
/// `info.gravity` works) and the figures the plane computes.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PlaneInfo {
    /// The plane's id.
    pub id: PlaneId,
    /// Which backend simulates it.
    pub kind: PlaneKind,
    /// Every option as set.
    pub settings: PlaneSettings,
    /// Ticks stepped so far.
    pub tick: u64,
    /// Live objects.
    pub object_count: u32,
    /// Iterations the solver runs now: LoopSolver, SolverIterations and HitBoxQuality scaling.
    pub effective_solver_iterations: u32,
    /// Largest HitBoxQuality among the plane's objects (1 when empty).
    pub max_hit_box_quality: u32,
}

impl std::ops::Deref for PlaneInfo {
    type Target = PlaneSettings;
    fn deref(&self) -> &PlaneSettings {
        &self.settings
    }
}

/// Every property of an object, as the daemon holds it: the stored settings (read through
/// `Deref`) and what lives in the engine or is derived.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ObjectInfo {
    /// The object's handle.
    pub handle: Handle,
    /// Its shape.
    pub shape: ShapeKind,
    /// The stored properties as set (`settings.density` is the Density as set).
    pub settings: ObjectSettings,
    /// `Size`.
    pub size: Vec3,
    /// `Anchored`.
    pub anchored: bool,
    /// Asleep in the engine now.
    pub sleeping: bool,
    /// The density in effect: the explicit value, or Weight ÷ volume.
    pub density: f32,
    /// The mass in effect.
    pub mass: f32,
    /// Rotation locked because the object is a low-quality non-sphere without CenterOfMass.
    pub rotation_locked_by_quality: bool,
    /// Continuous collision detection is on.
    pub ccd: bool,
}

impl std::ops::Deref for ObjectInfo {
    type Target = ObjectSettings;
    fn deref(&self) -> &ObjectSettings {
        &self.settings
    }
}

/// The successful result of one command.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum Reply {
    /// Done; nothing to report.
    Done,
    /// The handshake succeeded.
    Welcome {
        /// The daemon's process id.
        daemon_pid: u32,
        /// The daemon's iceoryx2 node id (for liveness checks).
        daemon_node_id: u128,
        /// The daemon's crate version.
        crate_version: String,
    },
    /// A plane's description.
    Plane(PlaneInfo),
    /// A new object, and the plane tick after which published samples include it.
    Object {
        /// The new object's handle.
        handle: Handle,
        /// Samples newer than this tick include it.
        tick: u64,
    },
    /// An object mutation was applied after `tick`: samples newer than `tick` reflect it.
    Applied {
        /// Samples newer than this tick reflect the change.
        tick: u64,
    },
    /// The tick number now visible in shared memory.
    Stepped {
        /// The tick now published.
        tick: u64,
    },
    /// An object's description.
    ObjectInfo(Box<ObjectInfo>),
    /// The centre of mass in effect, body-local.
    CenterOfMass(Vec3),
    /// One optional hit per ray or sweep of a query, in order.
    Hits(Vec<Option<Hit>>),
    /// The objects an overlap query found.
    Objects(Vec<Handle>),
    /// A controller's description.
    Controller(Box<crate::controller_op::ControllerInfo>),
    /// A yes / no answer (whether a jump launched).
    Flag(bool),
    /// The answer of a GUI-plane op that carries data.
    Gui(crate::gui_op::GuiReply),
    /// A new joint, and the tick after which it acts.
    Joint {
        /// The joint's handle.
        handle: Handle,
        /// Steps after this tick include it.
        tick: u64,
    },
    /// A joint's description.
    JointInfo(Box<JointInfo>),
    /// A built map.
    Map(Box<MapInfo>),
    /// The ids of every plane of the daemon, ascending ([`Command::ListPlanes`]).
    PlaneIds(Vec<PlaneId>),
    /// An impulse was applied after `tick`: the object's linear velocity right after it
    /// (what the script reads back until a newer sample shows the stepped value).
    Velocity {
        /// Samples newer than this tick reflect the change.
        tick: u64,
        /// The linear velocity after the impulse (a GUI plane's has z = 0).
        linear: Vec3,
    },
    /// What a proximity query found (`None`: nothing within its reach).
    Probe(Option<crate::probe::ProbeHit>),
    /// The objects an object touches now, with their contact points ([`ObjectOp::Contacts`]).
    Contacts(Vec<crate::contact_points::ContactInfo>),
    /// A page of an overlap query's objects, ascending slots: the answer of a
    /// [`crate::QueryOp::Page`], and of an overlap query that found more than
    /// [`crate::query::MAX_QUERY_RESULTS`].
    ObjectPage {
        /// The objects of this page.
        objects: Vec<Handle>,
        /// More objects match after the last one (ask for the page after its slot).
        truncated: bool,
    },
    /// A plane's whole state ([`PlaneOp::Snapshot`]): bytes framed by
    /// [`crate::snapshot`] (header readable with [`crate::snapshot::header`]).
    Snapshot(Vec<u8>),
    /// The named planes, by name ([`Command::ListNamedPlanes`]).
    NamedPlanes(Vec<crate::plane_name::NamedPlane>),
    /// A named plane opened ([`Command::OpenPlane`]).
    Opened(crate::plane_name::OpenedPlane),
    /// A persistent plane was written to its file ([`PlaneOp::Save`]) at this tick.
    Saved {
        /// The tick the file holds.
        tick: u64,
    },
    /// A snapshot transfer's answer ([`Command::Transfer`], or a snapshot too large for one
    /// reply).
    Transfer(crate::snapshot_transfer::TransferReply),
    /// The plane moved ([`PlaneOp::MoveTo`]): where it lives now, and the key its owner
    /// claims it with there ([`PlaneOp::ClaimMoved`]; 0 when it did not move).
    Moved {
        /// The daemon it lives on.
        daemon: String,
        /// Its id there.
        plane: PlaneId,
        /// The claim key.
        key: u128,
        /// The cluster.
        cluster: String,
        /// An endpoint of the cluster that routes for clients (the old daemon's).
        endpoint: String,
        /// The tick the plane stopped at (its last on the old daemon; the new one steps
        /// the next).
        tick: u64,
    },
    /// A recording started or stopped ([`PlaneOp::Record`]): its file and what it holds.
    Recording(crate::record_op::RecordingInfo),
    /// A page of a plane's joints, ascending slots ([`crate::joint_op::JointOp::List`]).
    Joints(Vec<JointInfo>),
}

/// The result of one command.
pub type CommandResult = Result<Reply, CommandError>;

/// One request: a batch of commands from one client. The client's iceoryx2 node id travels
/// in the request's user header, so even an undecodable request can be answered.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Request {
    /// The commands, applied in order.
    pub commands: Vec<Command>,
}

/// The answer to one request: one result per command, in order, or the rejection of the
/// whole request when it could not be decoded.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum Response {
    /// One result per command.
    Results(Vec<CommandResult>),
    /// The request as a whole was refused.
    Rejected(CommandError),
}

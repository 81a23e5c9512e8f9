//! Rust API for game processes talking to the physics daemon.
//!
//! - [`Client`]: the connection (handshake, batched commands, daemon liveness).
//! - [`Plane`]: one simulation plane; zero-copy [`Snapshot`]s of its newest tick.
//! - [`Object`]: one body; reads index into the newest sample, writes join the batch.
//! - [`cluster`]: the daemons of a physics cluster on Zenoh and their load.
//!
//! Writes are queued and sent as one request per [`Client::flush`] (or when a call needs an
//! answer); reads see your own writes until the daemon's samples reflect them.
//!
//! Every port is reached through one module (`transport`): this host's iceoryx2 ports, built
//! by the `local-transport` crate, or a cluster member's relay; the other modules hold what
//! it returns.

#![deny(missing_docs)]

pub mod axis_motor;
mod client;
pub mod cluster;
mod collision_groups;
mod contact_points;
mod controller;
mod error;
mod events;
mod failover_switch;
mod gui;
mod inspect;
mod joint;
pub mod map;
mod members;
mod mirror;
mod moving;
mod named_plane;
mod object;
mod overlay;
mod plane;
mod plane_shared;
mod plane_snapshot;
mod probe;
mod query;
pub mod ragdoll;
pub mod recording;
pub mod remote;
mod replay_check;
mod snapshot_transfer;
mod spawn;
pub mod spin;
mod transport;

pub use client::{
    Client, ConnectOptions, DaemonHealth, HUNG_AFTER, MAX_IN_FLIGHT, STALL_AFTER, WATCH_STALL_AFTER,
};
pub use collision_groups::CollisionGroup;
pub use controller::Controller;
pub use error::Error;
pub use events::{Contact, Events, EVENT_BUFFER_TICKS};
pub use gui::{GuiController, GuiEvent, GuiObject, GuiPlane, GuiPlaneOptions};
pub use joint::{Joint, JointBroke};
pub use map::{Map, MapMesh, MapOptions};
pub use named_plane::OpenedPlane;
pub use object::Object;
pub use plane::{Plane, PlaneOptions, Snapshot};
pub use plane_snapshot::PlaneSnapshot;
pub use probe::{Explosion, Falloff, ProbeHit, DEFAULT_MAX_SLOPE};
pub use query::{Found, QueryParams};
pub use ragdoll::{Bone, Ragdoll, RagdollDesc};
pub use recording::{load_recording, Advanced, Divergence, Recording, Replay};
pub use replay_check::{first_difference, FieldDifference};
/// The collision group every object starts in ("Default").
pub use shm_layout::collision_groups::DEFAULT_GROUP;
pub use shm_layout::gui_op::{GuiControllerInfo, GuiObjectInfo, GuiPlaneInfo};
/// The settings tables: each property's name, default, range and flags, declared once.
pub use shm_layout::settings;
/// The limits and checks the daemon applies, for callers that want to check early.
pub use shm_layout::validate;
pub use shm_layout::RecordingInfo;
pub use shm_layout::{
    AxisMode, BodyState, CollisionGroups, CommandError, ControllerInfo, ControllerProp,
    ControllerSettings, ErrorKind, EventRecord, FilterType, GuiControllerProp, GuiHit,
    GuiObjectProp, GuiPlaneProp, GuiShape, Handle, Hit, JointInfo, JointKind, JointProp,
    JointSettings, MapReport, ObjectInfo, ObjectOp, ObjectProp, ObjectSettings, OptionalJointProp,
    Pin, PlaneId, PlaneInfo, PlaneKind, PlaneOp, PlaneProp, PlaneSettings, Pose, Ray, Restraint,
    RotateTo, Shape, ShapeKind, StateHasher, TickHeader, Vec2, Vec3, EVENT_CONTROLLER_JUMPED,
    EVENT_CONTROLLER_LANDED, EVENT_CONTROLLER_MOVED, EVENT_PATH_FINISHED, EVENT_WAYPOINT_REACHED,
    FLAG_ON_GROUND,
};
pub use shm_layout::{AxisMotor, ContactInfo, ContactPoint, MAX_CONTACT_POINTS};
pub use shm_layout::{NamedPlane, PlaneName};
pub use spawn::{
    connect_or_start, daemon_executable, interrupt_child, sibling_executable, start_daemon,
    start_daemon_with, DaemonChild, Session,
};
pub use transport::quiet_transport_logs;

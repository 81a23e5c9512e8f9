//! The wire between the physics daemon and its clients.
//!
//! - [`records`]: `#[repr(C)]` zero-copy records published every tick in shared memory.
//! - [`command`]: the request / reply enums carried over request-response, nested by target:
//!   [`Command`] → [`PlaneOp`] ([`plane_op`]) → [`ObjectOp`] ([`object_op`]).
//! - [`settings`]: every plane option and object property with its default and its check,
//!   defined once for the SDK and the daemon.
//! - [`query`]: scene queries (rays, sweeps, overlaps); [`probe`]: proximity queries and
//!   explosions; [`collision_groups`]: named groups
//!   and which pairs collide.
//! - [`shape`]: collision shapes; [`error`]: command errors that name their field.
//! - [`codec`]: framing of those enums into bytes (version header + postcard body).
//! - [`names`]: domain validation and the iceoryx2 service names of one deployment.
//! - [`validate`]: the checks and limits shared by both sides.
//!
//! No simulation code and no I/O live here, so both sides agree on one definition.

#![deny(missing_docs)]

pub mod axis_motor;
pub mod cluster;
pub mod codec;
pub mod collision_groups;
pub mod command;
pub mod contact_points;
pub mod controller_op;
pub mod error;
pub mod gui_op;
pub mod joint_op;
pub mod map_op;
pub mod migrate;
pub mod names;
pub mod object_op;
pub mod object_op_of;
pub mod plane_name;
pub mod plane_op;
pub mod probe;
pub mod query;
pub mod records;
pub mod remote;
pub mod settings;
pub mod shape;
pub mod snapshot;
pub mod snapshot_transfer;
pub mod validate;

pub use axis_motor::AxisMotor;
pub use codec::{DecodeError, Frame};
pub use collision_groups::CollisionGroups;
pub use command::*;
pub use contact_points::{ContactInfo, ContactPoint, MAX_CONTACT_POINTS};
pub use controller_op::{ControllerInfo, ControllerOp};
pub use error::{CommandError, ErrorKind};
pub use gui_op::{GuiControllerOp, GuiControllerProp, GuiHit, GuiObjectOp, GuiOp, GuiReply};
pub use joint_op::{
    AxisMode, JointInfo, JointKind, JointOp, JointProp, JointSettings, OptionalJointProp,
};
pub use map_op::{MapInfo, MapOp, MapReport};
pub use object_op::ObjectOp;
pub use object_op_of::ObjectOpOf;
pub use plane_name::{NamedPlane, OpenedPlane, PlaneName};
pub use plane_op::{OpCost, PlaneKind, PlaneOp};
pub use probe::{Explosion, Falloff, ProbeHit};
pub use query::{FilterType, Hit, QueryFilter, QueryOp, Ray};
pub use records::*;
pub use settings::{
    ControllerProp, ControllerSettings, GuiObjectProp, GuiPlaneProp, GuiShape, ObjectProp,
    ObjectSettings, Pin, PlaneOptions, PlaneProp, PlaneSettings, Restraint, RotateTo, Vec2,
};
pub use shape::{Shape, ShapeKind};
pub use snapshot::SnapshotHeader;
pub use snapshot_transfer::{TransferOp, TransferReply};

/// Bumped whenever a record layout or the command encoding changes. Client and daemon must
/// agree on it; the handshake reports both values when they differ.
pub const LAYOUT_VERSION: u32 = 11;

/// The crate version both sides were built from; also checked by the handshake.
pub const CRATE_VERSION: &str = env!("CARGO_PKG_VERSION");

//! The wire between the physics daemon and its clients.
//!
//! Layered bottom to top (each file imports only files below it; this file only declares
//! and re-exports):
//!
//! - primitives: [`geometry`] (vectors, poses), [`ids`] (plane ids, handles), [`version`],
//!   [`error`] (command errors that name their field), [`plane_kind`], [`joint_limits`],
//!   [`validate`] (the checks and limits shared by both sides).
//! - [`settings`]: every plane option and object property with its default and its check,
//!   defined once for the SDK and the daemon ([`settings::row`]: what a row says,
//!   [`settings::table`]: the table machinery, then one file per family of rows).
//! - [`records`]: `#[repr(C)]` zero-copy records published every tick in shared memory.
//! - the op families: [`object_op`], [`joint_op`], [`controller_op`], [`gui_op`],
//!   [`map_op`]; [`query`]: scene queries (rays, sweeps, overlaps); [`probe`]: proximity
//!   queries and explosions; [`collision_groups`]: named groups and which pairs collide;
//!   [`shape`]: collision shapes.
//! - [`command`]: the request / reply enums carried over request-response, nested by target:
//!   [`Command`] → [`PlaneOp`] ([`plane_op`]) → [`ObjectOp`] ([`object_op`]).
//! - [`codec`]: framing of those enums into bytes (version header + postcard body);
//!   [`snapshot`]: the framing of a plane's saved state.
//! - [`names`]: domain validation and the iceoryx2 service names of one deployment.
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
pub mod geometry;
pub mod gui_op;
pub mod ids;
pub mod joint_limits;
pub mod joint_op;
pub mod map_op;
pub mod migrate;
pub mod names;
pub mod object_op;
pub mod object_op_of;
pub mod plane_kind;
pub mod plane_name;
pub mod plane_op;
pub mod probe;
pub mod query;
pub mod record_op;
pub mod recording;
pub mod records;
pub mod remote;
pub mod settings;
pub mod shape;
pub mod snapshot;
pub mod snapshot_transfer;
pub mod validate;
pub mod version;

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
pub use record_op::{RecordOp, RecordingInfo};
pub use records::*;
pub use settings::{
    ControllerProp, ControllerSettings, GuiObjectProp, GuiPlaneProp, GuiShape, ObjectProp,
    ObjectSettings, Pin, PlaneOptions, PlaneProp, PlaneSettings, Restraint, RotateTo, Vec2,
};
pub use shape::{Shape, ShapeKind};
pub use snapshot::SnapshotHeader;
pub use snapshot_transfer::{TransferOp, TransferReply};
pub use version::{CRATE_VERSION, LAYOUT_VERSION};

//! What a command does to a plane: the ops every kind understands (the kinds themselves
//! are [`crate::plane_kind`]).
//! The server handles only the lifecycle ops (`Step`, `Destroy`); everything else is handed
//! to the plane's backend unread.

use serde::{Deserialize, Serialize};

pub use crate::plane_kind::PlaneKind;

use crate::collision_groups::CollisionGroups;
use crate::controller_op::ControllerOp;
use crate::geometry::Pose;
use crate::gui_op::GuiOp;
use crate::ids::Handle;
use crate::joint_op::JointOp;
use crate::map_op::MapOp;
use crate::object_op::ObjectOp;
use crate::query::QueryOp;
use crate::settings::{ObjectProp, PlaneProp};
use crate::shape::Shape;

/// An op on one plane.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum PlaneOp {
    /// Describes the plane (any client may ask; used to attach to planes of other clients).
    Info,
    /// Changes one option.
    Set(PlaneProp),
    /// Advances the plane by `dt` seconds; the reply comes after the new tick is published.
    Step {
        /// Seconds to advance.
        dt: f32,
    },
    /// Removes the plane and all its objects.
    Destroy,
    /// Adds an object.
    AddObject {
        /// Its shape.
        shape: Shape,
        /// Where it starts.
        pose: Pose,
        /// Properties applied after the defaults.
        props: Vec<ObjectProp>,
    },
    /// An op on one object of the plane.
    Object {
        /// The object.
        handle: Handle,
        /// What to do to it.
        op: ObjectOp,
    },
    /// A scene query on the latest tick (objects added or moved since are included).
    Query(QueryOp),
    /// Replaces the plane's collision-group table; objects in a group no longer registered
    /// return to "Default".
    CollisionGroups(CollisionGroups),
    /// An op on the plane's character controllers.
    Controller(ControllerOp),
    /// An op of the 2D GUI plane (objects, controllers, rays); other kinds refuse it.
    Gui(GuiOp),
    /// An op on the plane's joints.
    Joint(JointOp),
    /// An op on the plane's triangle-mesh map upload.
    Map(MapOp),
    /// Pushes dynamic objects and controllers away from a point; replies
    /// [`crate::Reply::Objects`] (what it affected).
    Explode(crate::probe::Explosion),
    /// The plane's whole state as it is between ticks; replies [`crate::Reply::Snapshot`].
    Snapshot,
    /// The plane becomes exactly the state of a snapshot of the same kind (same objects
    /// under the same handles, same tick), then `overrides` apply as at creation (a plane
    /// started from a snapshot with another TickRate or Threads); refused, the plane stays
    /// as it was. Replies [`crate::Reply::Applied`] with the restored tick.
    Restore {
        /// The snapshot ([`crate::snapshot`] framing).
        bytes: Vec<u8>,
        /// Options applied after the state (DeferGpu excluded).
        overrides: Vec<PlaneProp>,
    },
    /// Goes back this many ticks (at most `RollbackTicks`): the plane becomes its state
    /// after that tick. Replies [`crate::Reply::Applied`] with the tick gone back to.
    Rewind(u32),
    /// Writes a persistent plane to its file in the daemon's state directory now (atomically)
    /// and replies [`crate::Reply::Saved`] once the file is on disk. Owner only.
    Save,
    /// [`PlaneOp::Restore`] from the bytes of upload `transfer` of the sending connection
    /// ([`crate::snapshot_transfer`]): the daemon takes the finished upload and restores
    /// from it as from `Restore` (the transfer is gone after, refused or not).
    RestoreUploaded {
        /// The upload.
        transfer: u32,
        /// Options applied after the state, as for `Restore`.
        overrides: Vec<PlaneProp>,
    },
    /// Moves the plane to another daemon of the cluster (owner only, 3D planes only): it
    /// stops at a tick boundary here and goes on from the same tick there, same objects,
    /// same handles ([`crate::migrate`]). Replies [`crate::Reply::Moved`].
    MoveTo {
        /// The target daemon's name (`--name`).
        daemon: String,
    },
    /// Claims a plane that arrived by [`PlaneOp::MoveTo`] with the key its old owner got:
    /// the sender becomes its owner. Replies [`crate::Reply::Done`].
    ClaimMoved {
        /// The key of [`crate::Reply::Moved`].
        key: u128,
    },
    /// Pins the plane to its daemon (owner only): `--rebalance` never moves it (a plane
    /// placed on a daemon by name). `MoveTo` still does. Replies [`crate::Reply::Done`].
    Pin,
    /// Starts or stops recording the plane to a file (owner only; [`crate::record_op`]).
    Record(crate::record_op::RecordOp),
}

/// What an op may add to a plane, for the daemon's per-client quotas.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct OpCost {
    /// Objects the op adds.
    pub objects: u32,
    /// Mesh vertices the op adds.
    pub mesh_vertices: u64,
    /// Bytes of other state the op may add (controller paths: 12 bytes a 3D waypoint, 8 a
    /// GUI one).
    pub state_bytes: u64,
}

impl PlaneOp {
    /// Whether the op only reads (allowed to any client on any plane).
    pub fn is_read_only(&self) -> bool {
        matches!(
            self,
            PlaneOp::Info
                | PlaneOp::Query(_)
                | PlaneOp::Snapshot
                | PlaneOp::Controller(ControllerOp::Info { .. })
                | PlaneOp::Joint(JointOp::Info { .. })
                | PlaneOp::Joint(JointOp::List { .. })
                | PlaneOp::Object {
                    op: ObjectOp::Info,
                    ..
                }
                | PlaneOp::Object {
                    op: ObjectOp::Contacts,
                    ..
                }
        ) || matches!(self, PlaneOp::Gui(op) if op.is_read_only())
    }

    /// What the op may add to the plane.
    pub fn cost(&self) -> OpCost {
        match self {
            PlaneOp::AddObject { shape, .. } => OpCost {
                objects: 1,
                mesh_vertices: shape.mesh_vertices() as u64,
                ..OpCost::default()
            },
            PlaneOp::Controller(ControllerOp::Create { .. }) | PlaneOp::Gui(GuiOp::Add { .. }) => {
                OpCost {
                    objects: 1,
                    ..OpCost::default()
                }
            }
            // A joint counts as an object; map pieces count vertices + triangles.
            PlaneOp::Joint(JointOp::Create { .. }) => OpCost {
                objects: 1,
                ..OpCost::default()
            },
            PlaneOp::Map(op) => OpCost {
                mesh_vertices: op.cost(),
                ..OpCost::default()
            },
            PlaneOp::Controller(ControllerOp::SetPath { waypoints, .. }) => OpCost {
                state_bytes: 12 * waypoints.len() as u64,
                ..OpCost::default()
            },
            PlaneOp::Controller(ControllerOp::AppendWaypoint { .. }) => OpCost {
                state_bytes: 12,
                ..OpCost::default()
            },
            // What the snapshot's header says it holds (the plane refuses a body that
            // holds more).
            PlaneOp::Restore { bytes, .. } => match crate::snapshot::header(bytes) {
                Ok((h, _)) => OpCost {
                    objects: h.objects.min(u32::MAX as u64) as u32,
                    mesh_vertices: h.mesh_vertices,
                    state_bytes: h.state_bytes,
                },
                Err(_) => OpCost::default(),
            },
            PlaneOp::Gui(op) => OpCost {
                state_bytes: op.path_bytes(),
                ..OpCost::default()
            },
            _ => OpCost::default(),
        }
    }
}

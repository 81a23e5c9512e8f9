//! The plane's objects: the slot table's entries (`body`), their parts and how a part maps
//! onto rapier (`part`), the tallies over the parts (`tally`), the per-body pass before each
//! step (`body_pass`: forces, speed limits, contact prediction) and triangle-mesh maps
//! (`maps`, `map_store`). [`Objects`] is the part's state (the slot table, the tallies,
//! the pass's buffers and the pending map); `ops.rs`, `properties.rs`, `maps_ops.rs` and
//! `stepping.rs` are the plane's `impl Plane` side; the others know no plane.

pub(super) mod body_pass;
pub(super) mod forces;
pub(super) mod limits;
pub(super) mod map_store;
pub(super) mod maps;
mod maps_ops;
pub(super) mod object;
mod ops;
pub(super) mod part;
mod properties;
mod stepping;
pub(super) mod tally;

use rapier3d::prelude::{PhysicsWorld, RigidBodyHandle};

use crate::backend::SlotTable;
use crate::rapier3d::objects::body_pass::{Inputs, Scratch};
use crate::rapier3d::objects::maps::PendingMap;
use crate::rapier3d::objects::object::{Object, MAX_SLOTS};
use crate::rapier3d::objects::tally::Tally;

/// The objects' part of the plane: the slot table, the tallies over its parts, the body
/// pass's buffers and the map pieces uploaded since the last build. The slot table and the
/// tallies' kept half are snapshot state (named in the plane's `plane_state!`, so reached
/// from there); the pass and the pending map are private to this part.
pub(crate) struct Objects {
    /// The objects by slot (snapshot state).
    pub(in crate::rapier3d) bodies: SlotTable<Object>,
    /// Tallies over the objects' parts: per quality, driven, mesh vertices (its `kept` is
    /// snapshot state).
    pub(in crate::rapier3d) tally: Tally,
    /// Buffers of the per-body passes.
    pass: Scratch,
    /// Map pieces uploaded since the last build (see `maps`).
    map_pending: PendingMap,
}

impl Default for Objects {
    fn default() -> Self {
        Objects {
            bodies: SlotTable::tracked("object", MAX_SLOTS),
            tally: Tally::default(),
            pass: Scratch::default(),
            map_pending: PendingMap::default(),
        }
    }
}

impl Objects {
    /// Before a step: forces, angular speed caps and contact prediction for every body the
    /// step will move (see `body_pass`).
    pub(crate) fn prepare_bodies(&mut self, world: &mut PhysicsWorld, inputs: &Inputs) {
        self.pass.prepare_bodies(world, &self.bodies, inputs);
    }

    /// After a step: caps the angular speed of the awake bodies at `max`.
    pub(crate) fn cap_angular_speeds(&mut self, world: &mut PhysicsWorld, max: f32) {
        self.pass.cap_angular_speeds(world, max);
    }

    /// The bodies the last body pass visited (those awake before the step).
    pub(crate) fn passed(&self) -> &[RigidBodyHandle] {
        &self.pass.handles
    }

    /// The map pieces uploaded since the last build.
    pub(crate) fn pending_map(&self) -> &PendingMap {
        &self.map_pending
    }

    /// The map pieces uploaded since the last build, to add to.
    pub(crate) fn pending_map_mut(&mut self) -> &mut PendingMap {
        &mut self.map_pending
    }

    /// Takes the map pieces uploaded since the last build, leaving none.
    pub(crate) fn take_pending_map(&mut self) -> PendingMap {
        std::mem::take(&mut self.map_pending)
    }
}

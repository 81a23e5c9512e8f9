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
use shm_layout::{CommandError, Handle};

use crate::backend::SlotTable;
use crate::rapier3d::objects::body_pass::{Inputs, Scratch};
use crate::rapier3d::objects::maps::PendingMap;
use crate::rapier3d::objects::object::{Object, MAX_SLOTS};
use crate::rapier3d::objects::tally::Tally;

/// The objects' part of the plane: the slot table, the tallies over its parts, the body
/// pass's buffers and the map pieces uploaded since the last build. Everything goes through
/// its methods but the plane's `plane_state!`, which names the slot table, the tallies'
/// kept half and the bodies the last pass left a force on (snapshot state) as fields.
pub(crate) struct Objects {
    /// The objects by slot (snapshot state: only `plane_state!` reaches the field).
    pub(in crate::rapier3d) bodies: SlotTable<Object>,
    /// Tallies over the objects' parts: per quality, driven, mesh vertices (its `kept` is
    /// snapshot state: only `plane_state!` reaches the field).
    pub(in crate::rapier3d) tally: Tally,
    /// Buffers of the per-body passes (the bodies the last pass left a force on are
    /// snapshot state: only `plane_state!` reaches that field).
    pub(in crate::rapier3d) pass: Scratch,
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

    /// The slot table, read-only (for the passes over every slot: publishing, hashing).
    pub(crate) fn table(&self) -> &SlotTable<Object> {
        &self.bodies
    }

    /// The object of `handle`.
    pub(crate) fn get(&self, handle: Handle) -> Result<&Object, CommandError> {
        self.bodies.get(handle)
    }

    /// The object of `handle`, to change (its slot is marked).
    pub(crate) fn get_mut(&mut self, handle: Handle) -> Result<&mut Object, CommandError> {
        self.bodies.get_mut(handle)
    }

    /// The live object in `slot`.
    pub(crate) fn at(&self, slot: usize) -> Option<&Object> {
        self.bodies.at(slot)
    }

    /// The live object in `slot`, to change (for the plane's own passes: not marked).
    pub(crate) fn at_mut(&mut self, slot: usize) -> Option<&mut Object> {
        self.bodies.at_mut(slot)
    }

    /// The handle of the live object in `slot`.
    pub(crate) fn handle_at(&self, slot: usize) -> Option<Handle> {
        self.bodies.handle_at(slot)
    }

    /// The generation of `slot`.
    pub(crate) fn generation(&self, slot: usize) -> u32 {
        self.bodies.generation(slot)
    }

    /// The slot the next insert takes (none when the table is full).
    pub(crate) fn next_slot(&self) -> Option<u32> {
        self.bodies.next_slot()
    }

    /// Adds `object`; its handle.
    pub(crate) fn insert(&mut self, object: Object) -> Result<Handle, CommandError> {
        self.bodies.insert(object)
    }

    /// Removes the object of `handle`.
    pub(crate) fn remove(&mut self, handle: Handle) -> Result<Object, CommandError> {
        self.bodies.remove(handle)
    }

    /// The live objects in slot order.
    #[cfg(test)]
    pub(crate) fn iter(&self) -> impl Iterator<Item = (Handle, &Object)> + '_ {
        self.bodies.iter()
    }

    /// Length of the published body array.
    pub(crate) fn slot_count(&self) -> usize {
        self.bodies.slot_count()
    }

    /// Live objects.
    pub(crate) fn live(&self) -> u32 {
        self.bodies.live()
    }

    /// How many marks the table has made (see `SlotTable::marks_made`).
    #[cfg(test)]
    pub(crate) fn marks_made(&self) -> u64 {
        self.bodies.marks_made()
    }

    /// Marks every slot changed.
    pub(crate) fn mark_all(&mut self) {
        self.bodies.mark_all();
    }

    /// The slots marked since the last step.
    pub(crate) fn since_step(&self) -> &[u32] {
        self.bodies.since_step()
    }

    /// A step happened: the marks since the step start over.
    pub(crate) fn stepped(&mut self) {
        self.bodies.stepped();
    }

    /// Moves the marked slots into `into` (see `SlotTable::drain_marks`).
    pub(crate) fn drain_marks(&mut self, into: &mut Vec<u32>) -> bool {
        self.bodies.drain_marks(into)
    }

    /// Hands this table's marks to `restored`, the table about to replace it.
    pub(crate) fn hand_marks_to(&mut self, restored: &mut SlotTable<Object>) {
        restored.take_marks_of(&mut self.bodies);
    }

    /// The tallies over the objects' parts.
    pub(crate) fn tally(&self) -> &Tally {
        &self.tally
    }

    /// The tallies, to keep in step with a part added, changed or removed.
    pub(crate) fn tally_mut(&mut self) -> &mut Tally {
        &mut self.tally
    }

    /// Counts the objects per HitBoxQuality again from the parts (after a restore).
    pub(crate) fn recount_qualities(&mut self) {
        let qualities = self.bodies.iter().map(|(_, b)| b.part.hit_box_quality);
        self.tally.recount_qualities(qualities);
    }
}

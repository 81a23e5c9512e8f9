//! Scene queries of the plane: rays, sweeps and overlaps with their filters (`ops`), the
//! character probes built on them (`probes`), explosions (`explode`) and the plane's
//! collision-group table (`collision_groups`). All of it is the plane's `impl Plane` side
//! but [`Queries`], the part's state (the group table and the bodies queries must first
//! bring up to date), whose fields only these files reach.

mod collision_groups;
mod explode;
pub(super) mod ops;
pub(super) mod probes;

use rapier3d::prelude::RigidBodyHandle;
use shm_layout::CollisionGroups;

use crate::backend::Marks;

/// The queries' part of the plane (snapshot state: both fields, in this order).
#[derive(Clone, Default, serde::Serialize, serde::Deserialize)]
pub(crate) struct Queries {
    /// The collision-group table objects' CollisionGroup indexes into.
    groups: CollisionGroups,
    /// Bodies an op added, moved or reshaped since the last step: a query first brings their
    /// colliders' poses and broad-phase boxes up to date, so it sees the change.
    stale: Marks<RigidBodyHandle>,
}

impl Queries {
    /// The collision-group table in effect.
    pub(crate) fn groups(&self) -> &CollisionGroups {
        &self.groups
    }

    /// An op added, moved or reshaped body `h`: the next query brings its colliders up to date.
    pub(crate) fn mark_stale(&mut self, h: RigidBodyHandle) {
        self.stale.push(h);
    }

    /// A step brought every collider up to date.
    pub(crate) fn step_done(&mut self) {
        self.stale.clear();
    }

    /// How many bodies are marked for the next query.
    #[cfg(test)]
    pub(crate) fn stale_count(&self) -> usize {
        self.stale.len()
    }
}

//! The plane's collision-group table: which groups collide, mapped onto rapier's interaction
//! groups (membership = the object's group bit, filter = that group's mask).

use shm_layout::{CollisionGroups, CommandError};

use crate::rapier3d::plane::Plane;

impl Plane {
    /// Replaces the table (checked: a forged table is refused whole). Objects in a group no
    /// longer registered return to "Default"; every collider takes its new filter.
    pub fn set_collision_groups(&mut self, table: CollisionGroups) -> Result<(), CommandError> {
        self.queries.groups = table.checked()?;
        for i in 0..self.objects.slot_count() {
            let Some(body) = self.objects.at_mut(i) else {
                continue;
            };
            let part = &mut body.part;
            if !self.queries.groups.is_registered(part.collision_group) {
                part.settings.collision_group = 0;
            }
            let groups = part.interaction_groups(&self.queries.groups);
            if let Some(rb) = self.world.bodies.get(body.handle) {
                for c in rb.colliders() {
                    self.world.colliders[*c].set_collision_groups(groups);
                }
            }
        }
        // Pairs that collide now must meet at the next step, including resting ones.
        self.world.wake_up_all(true);
        // Every body's sleep flag may have changed: the last step's copy of the states is no
        // longer theirs.
        self.history.forget_poses();
        Ok(())
    }

    /// The table in effect.
    pub fn collision_groups(&self) -> &CollisionGroups {
        &self.queries.groups
    }
}

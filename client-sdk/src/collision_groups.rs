//! Collision groups (Roblox's `PhysicsService` collision-group API): a table per client,
//! sent whole to every plane the client creates, so objects and queries name groups.

use shm_layout::collision_groups::{CollisionGroups, MAX_COLLISION_GROUPS};
use shm_layout::ObjectProp;

use crate::{client::Client, error::Error, object::Object};

/// One registered group, as `GetRegisteredCollisionGroups` lists it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CollisionGroup {
    /// Its name.
    pub name: String,
    /// Its index (bit `id` of every mask stands for it).
    pub id: u8,
    /// Which groups it collides with, one bit per group id.
    pub mask: u32,
}

impl Client {
    /// Registers a group that collides with every group (registering it again is a no-op).
    /// At most 32 groups, "Default" included.
    pub fn register_collision_group(&self, name: &str) -> Result<(), Error> {
        self.change_groups(|g| g.register(name).map(|_| ()))
    }

    /// Removes a group; objects in it return to "Default".
    pub fn unregister_collision_group(&self, name: &str) -> Result<(), Error> {
        self.change_groups(|g| g.unregister(name))
    }

    /// Renames a group (its objects and collisions stay).
    pub fn rename_collision_group(&self, from: &str, to: &str) -> Result<(), Error> {
        self.change_groups(|g| g.rename(from, to))
    }

    /// Makes groups `a` and `b` collide or not, both ways, on every plane of this client.
    pub fn collision_group_set_collidable(
        &self,
        a: &str,
        b: &str,
        collidable: bool,
    ) -> Result<(), Error> {
        self.change_groups(|g| g.set_collidable(a, b, collidable))
    }

    /// Whether groups `a` and `b` collide.
    pub fn collision_groups_are_collidable(&self, a: &str, b: &str) -> Result<bool, Error> {
        self.groups(|g| g.collidable(a, b))
            .map_err(Error::invalid_value)
    }

    /// Whether `name` is registered.
    pub fn is_collision_group_registered(&self, name: &str) -> bool {
        self.groups(|g| g.index_of(name).is_some())
    }

    /// The registered groups, by id.
    pub fn registered_collision_groups(&self) -> Vec<CollisionGroup> {
        self.groups(|g| {
            g.registered()
                .map(|(id, name, mask)| CollisionGroup {
                    name: name.to_string(),
                    id,
                    mask,
                })
                .collect()
        })
    }

    /// The most groups a client may register, "Default" included (32).
    pub fn max_collision_groups(&self) -> usize {
        MAX_COLLISION_GROUPS
    }

    /// The id of a registered group, or an error naming it.
    pub fn collision_group_id(&self, name: &str) -> Result<u8, Error> {
        self.groups(|g| g.require(name))
            .map_err(Error::invalid_value)
    }

    /// The name of group `id` in this client's table ("Default" for an id it does not know).
    pub fn collision_group_name(&self, id: u8) -> String {
        self.groups(|g| {
            g.name_of(id)
                .unwrap_or(shm_layout::collision_groups::DEFAULT_GROUP)
                .to_string()
        })
    }

    /// A copy of the table.
    pub fn collision_group_table(&self) -> CollisionGroups {
        self.groups(CollisionGroups::clone)
    }
}

impl Object {
    /// Puts the object in a registered collision group.
    pub fn set_collision_group(&self, name: &str) -> Result<(), Error> {
        let id = self.plane().client().collision_group_id(name)?;
        self.set(ObjectProp::CollisionGroup(id))
    }

    /// The object's collision group, by name (one round trip).
    pub fn collision_group(&self) -> Result<String, Error> {
        let id = self.info()?.collision_group;
        Ok(self.plane().client().collision_group_name(id))
    }
}

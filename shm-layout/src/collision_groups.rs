//! Collision groups, after Roblox's `PhysicsService` API: named groups (at most 32, "Default"
//! always among them) and a symmetric table of which pairs collide. A client keeps its table
//! and sends it to its planes whole; objects and query filters name a group by its index.

use serde::{Deserialize, Serialize};

use crate::error::CommandError;

/// Most groups a table holds, "Default" included (Roblox's limit).
pub const MAX_COLLISION_GROUPS: usize = 32;
/// Longest group name in bytes (Roblox's limit is 100 characters).
pub const MAX_GROUP_NAME: usize = 100;
/// The group every object starts in; index 0, never removed or renamed.
pub const DEFAULT_GROUP: &str = "Default";

/// Registered groups and which pairs collide. New groups collide with every group.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct CollisionGroups {
    /// Group names by index; `None` is a free index.
    names: Vec<Option<String>>,
    /// Per index: bit `j` set when this group collides with group `j`.
    masks: Vec<u32>,
}

impl Default for CollisionGroups {
    fn default() -> Self {
        CollisionGroups {
            names: vec![Some(DEFAULT_GROUP.to_string())],
            masks: vec![u32::MAX],
        }
    }
}

fn unknown(name: &str) -> CommandError {
    CommandError::invalid_field(
        "CollisionGroup",
        format!("collision group \"{name}\" is not registered"),
    )
}

impl CollisionGroups {
    /// The index of `name`, if registered.
    pub fn index_of(&self, name: &str) -> Option<u8> {
        self.names
            .iter()
            .position(|n| n.as_deref() == Some(name))
            .map(|i| i as u8)
    }

    /// The index of `name`, or an error naming it.
    pub fn require(&self, name: &str) -> Result<u8, CommandError> {
        self.index_of(name).ok_or_else(|| unknown(name))
    }

    /// The name at `index`, if registered.
    pub fn name_of(&self, index: u8) -> Option<&str> {
        self.names.get(index as usize)?.as_deref()
    }

    /// Whether `index` names a registered group.
    pub fn is_registered(&self, index: u8) -> bool {
        self.name_of(index).is_some()
    }

    /// Which groups `index` collides with (bit per index); 0 for a free index.
    pub fn mask(&self, index: u8) -> u32 {
        match self.is_registered(index) {
            true => self.masks[index as usize],
            false => 0,
        }
    }

    /// Registered groups as (index, name, mask), by index.
    pub fn registered(&self) -> impl Iterator<Item = (u8, &str, u32)> + '_ {
        self.names
            .iter()
            .enumerate()
            .filter_map(|(i, n)| Some((i as u8, n.as_deref()?, self.masks[i])))
    }

    /// Registers `name` (colliding with every group) and returns its index. Registering a
    /// registered name again is allowed and changes nothing.
    pub fn register(&mut self, name: &str) -> Result<u8, CommandError> {
        check_name(name)?;
        if let Some(i) = self.index_of(name) {
            return Ok(i);
        }
        let i = match self.names.iter().position(Option::is_none) {
            Some(i) => i,
            None if self.names.len() < MAX_COLLISION_GROUPS => {
                self.names.push(None);
                self.masks.push(0);
                self.names.len() - 1
            }
            None => {
                return Err(CommandError::invalid_field(
                    "name",
                    format!(
                        "cannot register collision group \"{name}\": all \
                         {MAX_COLLISION_GROUPS} groups are in use"
                    ),
                ))
            }
        };
        self.names[i] = Some(name.to_string());
        self.masks[i] = u32::MAX;
        for m in &mut self.masks {
            *m |= 1 << i;
        }
        Ok(i as u8)
    }

    /// Removes `name`; objects in it return to "Default". "Default" cannot be removed.
    pub fn unregister(&mut self, name: &str) -> Result<(), CommandError> {
        let i = self.require(name)?;
        if i == 0 {
            return Err(CommandError::invalid_field(
                "name",
                "the \"Default\" collision group cannot be removed",
            ));
        }
        self.names[i as usize] = None;
        Ok(())
    }

    /// Renames group `from` to `to` (its index and collisions stay).
    pub fn rename(&mut self, from: &str, to: &str) -> Result<(), CommandError> {
        check_name(to)?;
        let i = self.require(from)?;
        if i == 0 {
            return Err(CommandError::invalid_field(
                "name",
                "the \"Default\" collision group cannot be renamed",
            ));
        }
        if self.index_of(to).is_some_and(|j| j != i) {
            return Err(CommandError::invalid_field(
                "name",
                format!("collision group \"{to}\" is already registered"),
            ));
        }
        self.names[i as usize] = Some(to.to_string());
        Ok(())
    }

    /// Makes groups `a` and `b` collide or not (both ways).
    pub fn set_collidable(&mut self, a: &str, b: &str, on: bool) -> Result<(), CommandError> {
        let (i, j) = (self.require(a)? as usize, self.require(b)? as usize);
        let set = |m: &mut u32, bit: usize| match on {
            true => *m |= 1 << bit,
            false => *m &= !(1 << bit),
        };
        set(&mut self.masks[i], j);
        set(&mut self.masks[j], i);
        Ok(())
    }

    /// Whether groups `a` and `b` collide.
    pub fn collidable(&self, a: &str, b: &str) -> Result<bool, CommandError> {
        let (i, j) = (self.require(a)?, self.require(b)?);
        Ok(self.mask(i) & (1 << j) != 0)
    }

    /// The table as a daemon accepts it from a client: at most 32 groups, "Default" at 0,
    /// valid names, no name twice, a symmetric collision table.
    pub fn checked(self) -> Result<CollisionGroups, CommandError> {
        let bad = |message: String| CommandError::invalid_field("CollisionGroups", message);
        if self.names.len() > MAX_COLLISION_GROUPS || self.names.len() != self.masks.len() {
            return Err(bad(format!(
                "a collision-group table holds at most {MAX_COLLISION_GROUPS} groups with one \
                 mask each, got {} names and {} masks",
                self.names.len(),
                self.masks.len()
            )));
        }
        if self.name_of(0) != Some(DEFAULT_GROUP) {
            return Err(bad(format!(
                "group 0 must be \"{DEFAULT_GROUP}\", got {:?}",
                self.names.first()
            )));
        }
        for (i, name, _) in self.registered() {
            check_name(name)?;
            if self.index_of(name) != Some(i) {
                return Err(bad(format!("group \"{name}\" is registered twice")));
            }
        }
        for (i, _, _) in self.registered() {
            for (j, _, _) in self.registered() {
                if (self.mask(i) >> j & 1) != (self.mask(j) >> i & 1) {
                    return Err(bad(format!(
                        "the collision table is not symmetric between groups {i} and {j}"
                    )));
                }
            }
        }
        Ok(self)
    }
}

fn check_name(name: &str) -> Result<(), CommandError> {
    if name.is_empty() || name.len() > MAX_GROUP_NAME || name.chars().any(char::is_control) {
        return Err(CommandError::invalid_field(
            "name",
            format!(
                "a collision group name must be 1 to {MAX_GROUP_NAME} bytes without control \
                 characters, got {name:?}"
            ),
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn groups_collide_with_everything_until_told_otherwise() {
        let mut g = CollisionGroups::default();
        let a = g.register("A").unwrap();
        g.register("B").unwrap();
        assert_eq!(a, 1);
        assert!(g.collidable("A", "B").unwrap());
        assert!(g.collidable("A", "Default").unwrap());
        g.set_collidable("A", "B", false).unwrap();
        assert!(!g.collidable("B", "A").unwrap());
        assert!(g.collidable("A", "A").unwrap());
        assert_eq!(g.clone().checked().unwrap(), g);
    }

    #[test]
    fn the_33rd_group_is_refused_and_a_freed_index_is_reused_fresh() {
        let mut g = CollisionGroups::default();
        for i in 1..MAX_COLLISION_GROUPS {
            g.register(&format!("G{i}")).unwrap();
        }
        let e = g.register("one too many").unwrap_err();
        assert!(e.message.contains("32"), "{}", e.message);
        g.set_collidable("G5", "G6", false).unwrap();
        g.unregister("G5").unwrap();
        assert_eq!(g.register("again").unwrap(), 5);
        assert!(g.collidable("again", "G6").unwrap());
        assert!(g.unregister("Default").is_err());
        assert!(g.collidable("nope", "Default").is_err());
    }

    #[test]
    fn forged_tables_are_refused() {
        let mut g = CollisionGroups::default();
        g.register("A").unwrap();
        let mut forged = g.clone();
        forged.masks[1] &= !1; // A ignores Default, Default does not ignore A
        assert!(forged.checked().is_err());
        let mut forged = g.clone();
        forged.names[0] = Some("X".into());
        assert!(forged.checked().is_err());
        let mut forged = g;
        forged.names[1] = Some("Default".into());
        assert!(forged.checked().is_err());
    }
}

//! The connection's collision groups (named groups and which collide), read and changed
//! under one borrow.

use shm_layout::{CollisionGroups, Command, CommandError, PlaneOp};

use crate::error::Error;

use super::Client;

impl Client {
    /// Reads the collision-group table.
    pub(crate) fn groups<R>(&self, f: impl FnOnce(&CollisionGroups) -> R) -> R {
        f(&self.inner.state.borrow().groups)
    }

    /// Changes the collision-group table through `f`; when it changed, every plane this
    /// client created gets the new table with the next request.
    pub(crate) fn change_groups<R>(
        &self,
        f: impl FnOnce(&mut CollisionGroups) -> Result<R, CommandError>,
    ) -> Result<R, Error> {
        let (result, table, owned) = {
            let mut state = self.inner.state.borrow_mut();
            let before = state.groups.clone();
            let result = f(&mut state.groups).map_err(Error::invalid_value)?;
            if state.groups == before {
                return Ok(result);
            }
            (result, state.groups.clone(), state.owned.clone())
        };
        for id in owned {
            self.queue(
                Command::plane(id, PlaneOp::CollisionGroups(table.clone())),
                None,
            );
        }
        Ok(result)
    }
}

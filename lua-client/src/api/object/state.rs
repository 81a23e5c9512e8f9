//! The state behind a `PhysicsObject`: the body a part has in a plane, as scripts hold it.

use std::rc::Rc;

use client_sdk::Object;
use mlua::AnyUserData;

use crate::api::part::state::{Ended, PartObject, PartState};

/// A part's body in a plane, as scripts hold it.
pub struct PhysicsObject {
    /// The body `plane:Add` made; it ends (and this object goes stale) on Unlink, Destroy
    /// or the plane's Destroy, and is never replaced.
    pub body: Rc<PartObject>,
    /// The wrapped part.
    pub part: Rc<PartState>,
    /// The wrapped part's own userdata, so `obj:BasePart() == part`.
    pub part_ud: AnyUserData,
}

impl PhysicsObject {
    /// The body, while it is still the part's; else an error for `what` (the property or
    /// method, e.g. `PhysicsObject.Velocity`) naming the object and what happened to it.
    pub fn live(&self, what: &str) -> mlua::Result<&Object> {
        self.live_for(|| what.to_string())
    }

    /// [`live`](Self::live), naming `what` only when it fails.
    pub fn live_for(&self, what: impl FnOnce() -> String) -> mlua::Result<&Object> {
        match self.body.ended() {
            None => Ok(&self.body.object),
            Some(ended) => Err(mlua::Error::runtime(format!(
                "{}: {} {}",
                what(),
                self.describe(),
                ended.says()
            ))),
        }
    }

    /// Whether the body still exists and is still the part's.
    pub fn alive(&self) -> bool {
        self.body.ended().is_none() && self.body.object.is_alive().unwrap_or(false)
    }

    /// `PhysicsObject "Name"`: how `tostring` and error messages show the object.
    pub fn describe(&self) -> String {
        format!("PhysicsObject \"{}\"", self.part.name())
    }

    /// What `tostring` shows: [`describe`](Self::describe), then "(destroyed)" once the
    /// object was destroyed (itself, its part or its plane) or "(unlinked)" once unlinked,
    /// as a destroyed joint, plane or map shows.
    pub fn tostring(&self) -> String {
        match self.body.ended() {
            None => self.describe(),
            Some(Ended::Unlinked) => format!("{} (unlinked)", self.describe()),
            Some(_) => format!("{} (destroyed)", self.describe()),
        }
    }
}

//! The Lua handle of a joint ([`LuaJoint`]), shared by its methods (`joint/mod.rs`) and its
//! axis motors (`axis_motor.rs`).

use std::rc::Rc;

use client_sdk::{Joint, Object};

use crate::api::plane::state::PlaneState;

/// The Lua handle of a joint, with its plane (for its Broke signal), whether this script
/// destroyed it, and the objects it joins (it goes with either).
pub struct LuaJoint(
    pub Joint,
    pub Rc<PlaneState>,
    pub(crate) std::cell::Cell<bool>,
    pub(crate) Vec<client_sdk::Handle>,
);

impl LuaJoint {
    /// The handle of `joint`, a joint of `plane` between `a` and `b` (`None`: the world).
    pub fn new(joint: Joint, plane: Rc<PlaneState>, a: &Object, b: Option<&Object>) -> LuaJoint {
        let ends = std::iter::once(a).chain(b).map(Object::handle).collect();
        LuaJoint(joint, plane, std::cell::Cell::new(false), ends)
    }

    /// What `tostring` and messages call it: its kind, and "(destroyed)" once it is.
    pub(crate) fn name(&self) -> String {
        let gone = if self.2.get() { " (destroyed)" } else { "" };
        format!("Joint {}{gone}", self.0.kind().name())
    }

    /// Whether the joint still exists: not destroyed by this script, nor removed by the
    /// daemon with one of its objects.
    pub(crate) fn alive(&self) -> bool {
        !self.2.get() && self.0.info().is_ok()
    }

    /// The joint, unless this script destroyed it (then an error for `what`, the method).
    pub(crate) fn live(&self, what: &str) -> mlua::Result<&Joint> {
        if self.2.get() {
            return Err(mlua::Error::runtime(format!(
                "{what}: {} (read Alive to check)",
                self.name()
            )));
        }
        Ok(&self.0)
    }
}

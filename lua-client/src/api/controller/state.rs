//! The Lua handle of a character controller ([`LuaController`]) and what its state does:
//! its signals and the reads and writes its methods and rows share. The state itself
//! (`ControllerState`) is kept by its plane (`plane/state.rs`).

use std::rc::Rc;

use client_sdk::{BodyState, Controller, ControllerProp};
use mlua::{Lua, MultiValue};

use crate::api::plane::state::ControllerState;
use crate::host::signal::Signal;
use crate::values::sdk_error;

/// The Lua handle of a controller.
#[derive(Clone)]
pub struct LuaController(pub Rc<ControllerState>);

impl ControllerState {
    /// The signal `name`, created on first use (Moved asks the daemon for Moved events only
    /// while it has handlers).
    pub fn signal(self: &Rc<Self>, name: &'static str) -> Signal {
        let mut signals = self.signals.borrow_mut();
        if let Some((_, s)) = signals.iter().find(|(n, _)| *n == name) {
            return s.clone();
        }
        let s = Signal::new(format!("Controller.{name}"));
        let me = Rc::downgrade(self);
        s.on_listeners(move |n| {
            let Some(me) = me.upgrade() else {
                return;
            };
            if me.body.ended().is_some() {
                return;
            }
            if n > 0 {
                if let Some(plane) = me.plane.upgrade() {
                    plane.listen_for_contacts();
                }
            }
            if name == "Moved" {
                // A queued write: a refusal comes back with the frame's flush.
                let _ = me.controller.set(ControllerProp::ReportMoved(n > 0));
            }
        });
        signals.push((name, s.clone()));
        s
    }

    /// Handlers connected to any of its signals.
    pub fn listeners(&self) -> usize {
        self.signals
            .borrow()
            .iter()
            .map(|(_, s)| s.listeners())
            .sum()
    }

    /// Fires `name` with `args` when someone listens.
    pub fn fire(&self, lua: &Lua, name: &str, args: MultiValue) -> mlua::Result<()> {
        let signal = self
            .signals
            .borrow()
            .iter()
            .find(|(n, _)| *n == name)
            .map(|(_, s)| s.clone());
        match signal {
            Some(s) if s.listeners() > 0 => s.fire(lua, args),
            _ => Ok(()),
        }
    }

    pub(crate) fn disconnect_all(&self) {
        for (_, s) in self.signals.borrow().iter() {
            s.disconnect_all();
        }
    }
}

impl LuaController {
    /// The SDK controller while it lives; else an error naming `what`.
    pub fn live(&self, what: &str) -> mlua::Result<&Controller> {
        match self.0.body.ended() {
            None => Ok(&self.0.controller),
            Some(why) => Err(mlua::Error::runtime(format!(
                "Controller.{what}: the controller {}",
                why.says()
            ))),
        }
    }

    /// Its published state (newest tick, with this process's writes on top).
    pub fn state(&self, what: &str) -> mlua::Result<BodyState> {
        self.live(what)?
            .object()
            .state()
            .map_err(|e| sdk_error(&format!("Controller.{what}"), e))
    }

    /// Its facing (yaw, radians) from the published rotation.
    pub fn yaw(&self, what: &str) -> mlua::Result<f32> {
        let [x, y, z, w] = self.state(what)?.rotation;
        // The body turns only about Y: forward (+Z) rotated by the quaternion.
        let fx = 2.0 * (x * z + w * y);
        let fz = 1.0 - 2.0 * (x * x + y * y);
        Ok(fx.atan2(fz))
    }

    pub(crate) fn set_intent(
        &self,
        what: &str,
        x: Option<f32>,
        z: Option<f32>,
    ) -> mlua::Result<()> {
        let [mut mx, mut mz] = self.0.move_vector.get();
        if let Some(x) = x {
            mx = x;
        }
        if let Some(z) = z {
            mz = z;
        }
        self.live(what)?
            .set_move_vector(mx, mz)
            .map_err(|e| sdk_error(&format!("Controller:{what}"), e))?;
        self.0.move_vector.set([mx, mz]);
        Ok(())
    }
}

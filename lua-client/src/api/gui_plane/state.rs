//! The state of a GUI plane as the host holds it: the plane, its objects' handles
//! ([`PhysicsGuiObject`]) and its controllers, and the script's GUI planes. The methods of
//! these live with their types (`gui_plane/`, `gui_object/`, `gui_controller.rs`).

use std::cell::{Cell, RefCell};
use std::collections::HashMap;
use std::rc::{Rc, Weak};

use client_sdk::{GuiController, GuiObject, GuiPlane, Handle};
use mlua::Lua;

use crate::api::gui_basic::PrimState;
use crate::host::scheduler::scheduler;
use crate::host::signal::Signal;

/// A GUI plane as the host holds it.
pub struct GuiPlaneState {
    /// The SDK's plane.
    pub plane: GuiPlane,
    pub(super) alive: Cell<bool>,
    pub(super) prims: RefCell<Vec<Rc<PrimState>>>,
    pub(super) controllers: RefCell<HashMap<Handle, Rc<ControllerState>>>,
}

impl GuiPlaneState {
    /// False after `:Destroy()`.
    pub fn alive(&self) -> bool {
        self.alive.get()
    }

    /// Errors with "the plane was destroyed" for `what` once destroyed.
    pub fn check_alive(&self, what: &str) -> mlua::Result<()> {
        match self.alive() {
            true => Ok(()),
            false => Err(mlua::Error::runtime(format!(
                "GuiPhysicsPlane.{what}: the plane was destroyed"
            ))),
        }
    }

    /// Forgets a primitive whose body ended.
    pub fn forget(&self, prim: &Rc<PrimState>, handle: Handle) {
        self.prims.borrow_mut().retain(|p| !Rc::ptr_eq(p, prim));
        self.controllers.borrow_mut().remove(&handle);
    }
}

/// The GUI planes of a Lua state, kept until `:Destroy()`.
#[derive(Default)]
pub(crate) struct GuiPlanes(pub(crate) RefCell<Vec<Rc<GuiPlaneState>>>);

/// The Lua handle of a GUI plane.
#[derive(Clone)]
pub struct GuiPhysicsPlane(pub Rc<GuiPlaneState>);

/// The Lua handle of a GUI body.
#[derive(Clone)]
pub struct PhysicsGuiObject {
    /// The SDK's object.
    pub object: GuiObject,
    /// The primitive it simulates.
    pub prim: Rc<PrimState>,
    /// Its plane.
    pub plane: Weak<GuiPlaneState>,
}

impl PhysicsGuiObject {
    /// Whether the body still exists (its plane alive, not destroyed).
    pub fn alive(&self) -> bool {
        self.plane.upgrade().is_some_and(|p| p.alive()) && self.object.is_alive().unwrap_or(false)
    }

    /// Errors naming `what` once the body ended.
    pub fn check_alive(&self, what: &str) -> mlua::Result<()> {
        match self.alive() {
            true => Ok(()),
            false => Err(mlua::Error::runtime(format!(
                "{what}: the PhysicsGuiObject was destroyed (or its plane was)"
            ))),
        }
    }
}

/// A controller as the host holds it.
pub struct ControllerState {
    pub(crate) ctrl: GuiController,
    pub(crate) object: PhysicsGuiObject,
    pub(crate) move_direction: Cell<[f32; 2]>,
    pub(crate) waypoints: RefCell<Vec<[f32; 2]>>,
    pub(crate) waypoint_reached: Signal,
    pub(crate) path_finished: Signal,
    pub(crate) moved: Signal,
    pub(crate) ground_changed: Signal,
}

/// The script's handle on a new GUI plane of this client (`NewGUI`, `FromSnapshot`).
pub(crate) fn wrap_gui_plane(lua: &Lua, plane: GuiPlane) -> GuiPhysicsPlane {
    let state = Rc::new(GuiPlaneState {
        plane,
        alive: Cell::new(true),
        prims: RefCell::default(),
        controllers: RefCell::default(),
    });
    scheduler(lua).watch(state.clone());
    // GUI planes stay alive until `:Destroy()`, whether or not the script keeps a reference.
    if lua.app_data_ref::<GuiPlanes>().is_none() {
        lua.set_app_data(GuiPlanes::default());
    }
    if let Some(planes) = lua.app_data_ref::<GuiPlanes>() {
        planes.0.borrow_mut().push(state.clone());
    }
    GuiPhysicsPlane(state)
}

/// The script's handle on GUI plane `id` when it holds one (`Open` of a plane it has).
pub(crate) fn held_gui_plane(lua: &Lua, id: client_sdk::PlaneId) -> Option<GuiPhysicsPlane> {
    let planes = lua.app_data_ref::<GuiPlanes>()?;
    let found = planes
        .0
        .borrow()
        .iter()
        .find(|s| s.alive() && s.plane.plane().id() == id)
        .cloned();
    found.map(GuiPhysicsPlane)
}

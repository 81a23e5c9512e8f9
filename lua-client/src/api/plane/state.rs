//! The state of a `PhysicsPlane` as the host holds it: its parts, its contact delivery
//! ([`ContactPump`]), and the maps and character controllers it keeps. The methods of
//! these live with their types (`contacts.rs`, `map.rs`, `controller/`); what is here is
//! what the plane itself does with them.

use std::cell::{Cell, RefCell};
use std::collections::HashMap;
use std::rc::{Rc, Weak};

use client_sdk::{Controller, Handle, Plane, PlaneInfo};
use mlua::AnyUserData;

use crate::api::part::state::{handlers_changed, Ended, HandlersAnswer, PartObject, PartState};
use crate::host::signal::Signal;
use crate::values::sdk_error;

/// A plane as the host holds it. Its options live in the daemon alone: the property rows
/// read them back from there.
pub struct PlaneState {
    /// The SDK's plane.
    pub plane: Plane,
    alive: Cell<bool>,
    pub(crate) parts: RefCell<Vec<Rc<PartState>>>,
    /// The same parts by their body's handle (contacts and query hits name handles).
    by_handle: RefCell<HashMap<Handle, Rc<PartState>>>,
    /// Contact delivery of this plane (`contacts.rs`).
    pub(crate) contacts: ContactPump,
    /// Its character controllers by body handle (`controller/`).
    controllers: RefCell<HashMap<Handle, Rc<ControllerState>>>,
    /// Its maps by body handle (`map.rs`): hits and contacts on a map hand back its Map.
    pub(crate) maps: RefCell<HashMap<Handle, Rc<MapState>>>,
    /// Whether a part has CFrame handlers (so a step with none connected does not copy and
    /// ask every part).
    pub(crate) cframe_listen: HandlersAnswer,
}

impl PlaneState {
    /// A live plane of `plane` with nothing in it yet.
    pub fn new(plane: Plane) -> PlaneState {
        PlaneState {
            plane,
            alive: Cell::new(true),
            parts: RefCell::default(),
            by_handle: RefCell::default(),
            contacts: ContactPump::default(),
            controllers: RefCell::default(),
            maps: RefCell::default(),
            cframe_listen: Default::default(),
        }
    }

    /// False once `:Destroy()` was called.
    pub fn alive(&self) -> bool {
        self.alive.get()
    }

    /// The plane's options: a local lookup in the SDK's mirror for a plane this script
    /// created (not shared), otherwise one round trip that sends the queued writes first;
    /// `what` names the property read, for errors.
    pub fn info(&self, what: &str) -> mlua::Result<PlaneInfo> {
        if !self.alive() {
            return Err(mlua::Error::runtime(format!(
                "PhysicsPlane.{what}: the plane was destroyed"
            )));
        }
        self.plane
            .properties()
            .map_err(|e| sdk_error(&format!("PhysicsPlane.{what}"), e))
    }

    /// Live objects of the plane; 0 once destroyed.
    pub fn object_count(&self) -> Result<u32, client_sdk::Error> {
        if !self.alive() {
            return Ok(0);
        }
        self.plane.object_count()
    }

    /// Forgets `part`, whose body `handle` left the plane.
    pub fn forget(&self, part: &Rc<PartState>, handle: Handle) {
        self.parts.borrow_mut().retain(|p| !Rc::ptr_eq(p, part));
        self.by_handle.borrow_mut().remove(&handle);
        self.contacts.forget_joints_of(handle);
        handlers_changed();
    }

    /// Makes `body` the simulated body of `part` in this plane.
    pub fn adopt(&self, part: &Rc<PartState>, body: Rc<PartObject>, reporting: bool) {
        let handle = body.object.handle();
        part.link(body, reporting);
        self.parts.borrow_mut().push(part.clone());
        self.by_handle.borrow_mut().insert(handle, part.clone());
        handlers_changed();
    }

    /// Keeps a controller so its events reach it.
    pub fn keep_controller(&self, c: Rc<ControllerState>) {
        self.controllers
            .borrow_mut()
            .insert(c.controller.handle(), c);
    }

    /// Forgets the controller of body `handle` (destroyed).
    pub fn forget_controller(&self, handle: Handle) {
        self.controllers.borrow_mut().remove(&handle);
    }

    /// The controller of body `handle`, if this host made it.
    pub fn controller_of(&self, handle: Handle) -> Option<Rc<ControllerState>> {
        self.controllers.borrow().get(&handle).cloned()
    }

    /// Whether any controller of the plane has signal handlers.
    pub fn controller_listeners(&self) -> bool {
        self.controllers
            .borrow()
            .values()
            .any(|c| c.listeners() > 0)
    }

    /// Whether any part of the plane passes `f`.
    pub fn any_part(&self, f: impl Fn(&PartState) -> bool) -> bool {
        self.parts.borrow().iter().any(|p| f(p))
    }

    /// The parts this host simulates in the plane, with their bodies' handles.
    pub fn parts_by_handle(&self) -> Vec<(Handle, Rc<PartState>)> {
        self.by_handle
            .borrow()
            .iter()
            .map(|(h, p)| (*h, p.clone()))
            .collect()
    }

    /// The part whose body is `handle`, if this host added it.
    pub fn part_of(&self, handle: Handle) -> Option<Rc<PartState>> {
        self.by_handle.borrow().get(&handle).cloned()
    }

    /// Removes every body (their parts stay at their last pose) and the plane itself.
    pub(crate) fn destroy(&self) -> Result<(), client_sdk::Error> {
        if !self.alive.replace(false) {
            return Ok(());
        }
        for part in self.parts.take() {
            part.unlink(Ended::PlaneDestroyed);
        }
        self.contacts.forget_all_joints();
        handlers_changed();
        self.by_handle.borrow_mut().clear();
        self.controllers.borrow_mut().clear();
        self.maps.borrow_mut().clear();
        self.plane.destroy()
    }

    /// Something of the plane got handlers: subscribe to the plane's events now, so the
    /// first event after this point is delivered, and drop what queued while nobody
    /// listened.
    pub fn listen_for_contacts(&self) {
        if !self.alive() || self.contacts.reading.get() {
            return;
        }
        if let Err(e) = self.plane.subscribe_events() {
            eprintln!(
                "PhysicsPlane {}: cannot read contact events: {e}",
                self.plane.id()
            );
            return;
        }
        // Reading starts here: what was queued before is not news, and what the next step
        // publishes is (a joint that breaks on the first step after `Broke:Connect`).
        if !self.contacts.reading.get() && self.plane.events().is_ok() {
            self.contacts.reading.set(true);
        }
    }
}

/// Per plane: whether events are being read, and the `EventsLost` signal.
pub struct ContactPump {
    /// True while some part of the plane has touch handlers (events are drained each frame).
    pub(crate) reading: Cell<bool>,
    /// Whether a part had touch handlers, as of a `HANDLERS_EPOCH` (so a frame with nothing
    /// changed does not ask every part again).
    pub(crate) parts_listen: HandlersAnswer,
    /// `plane.EventsLost`, created on first access.
    pub(crate) lost: RefCell<Option<Signal>>,
    /// `joint.Broke` of the joints whose signal was read, by joint handle.
    pub(crate) broke: RefCell<HashMap<Handle, Broke>>,
}

/// A joint's `Broke` signal and what it needs to fire again.
pub(crate) struct Broke {
    pub(crate) signal: Signal,
    /// The objects the joint joins (the world is none): the joint goes with either.
    pub(crate) ends: Vec<Handle>,
    /// It fired: a joint breaks once.
    pub(crate) fired: Cell<bool>,
}

impl Default for ContactPump {
    fn default() -> Self {
        ContactPump {
            reading: Cell::new(false),
            parts_listen: HandlersAnswer::default(),
            lost: RefCell::new(None),
            broke: RefCell::default(),
        }
    }
}

impl ContactPump {
    /// A destroyed joint's Broke signal goes (its handlers with it).
    pub fn forget_joint(&self, joint: Handle) {
        let broke = self.broke.borrow_mut().remove(&joint);
        if let Some(b) = broke {
            b.signal.disconnect_all();
        }
    }

    /// The object `object` left the plane: its joints went with it, and so do their Broke
    /// signals and handlers (as on Roblox, where destroying an instance disconnects them).
    pub fn forget_joints_of(&self, object: Handle) {
        self.forget_broke(|b| b.ends.contains(&object));
    }

    /// The plane went: every Broke signal and its handlers go with it.
    pub fn forget_all_joints(&self) {
        self.forget_broke(|_| true);
    }

    /// Removes the Broke signals `which` picks and disconnects their handlers (after the map is
    /// released: a handler's finaliser may reach the plane).
    fn forget_broke(&self, which: impl Fn(&Broke) -> bool) {
        let gone: Vec<Broke> = self
            .broke
            .borrow_mut()
            .extract_if(|_, b| which(b))
            .map(|(_, b)| b)
            .collect();
        for b in gone {
            b.signal.disconnect_all();
        }
    }
}

/// A map as the host holds it: the SDK's map, its plane, and whether the script destroyed it.
pub struct MapState {
    /// The SDK's map (its anchored object and the daemon's report).
    pub map: client_sdk::Map,
    pub(crate) plane: Weak<PlaneState>,
    /// The file name it was loaded from (what `Name` and `tostring` show).
    pub(crate) name: String,
    pub(crate) destroyed: Cell<bool>,
}

impl MapState {
    /// The map `map`, loaded from a file called `name` into `plane`.
    pub fn new(map: client_sdk::Map, plane: &Rc<PlaneState>, name: String) -> MapState {
        MapState {
            map,
            plane: Rc::downgrade(plane),
            name,
            destroyed: Cell::new(false),
        }
    }
}

/// A controller as the host holds it.
pub struct ControllerState {
    /// The SDK's controller.
    pub controller: Controller,
    /// The part it drives.
    pub part: Rc<PartState>,
    /// The part's own userdata (`controller:BasePart() == part`).
    pub part_ud: AnyUserData,
    /// Its body, shared with the part while the controller lives.
    pub body: Rc<PartObject>,
    /// The plane.
    pub plane: Weak<PlaneState>,
    /// The script's motion intent (MoveForward etc. change one axis of it).
    pub(crate) move_vector: Cell<[f32; 2]>,
    pub(crate) signals: RefCell<Vec<(&'static str, Signal)>>,
}

/// The Lua handle of a plane.
#[derive(Clone)]
pub struct PhysicsPlane(pub Rc<PlaneState>);

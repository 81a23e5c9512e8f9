//! `PhysicsService.New` and the `PhysicsPlane` it returns: the plane's state
//! ([`state`]), the script's planes ([`mod@context`]), its property rows ([`props`]), and here
//! what a plane does per step, `plane:Add` and `New` itself.

pub(crate) mod context;
pub(crate) mod props;
pub(crate) mod state;

use std::rc::Rc;

use client_sdk::{ObjectProp, PlaneOptions};
use mlua::{Lua, Value};

use super::lifecycle::LuaPlane;
use super::object::state::PhysicsObject;
use super::part::state::{BasePart, PartObject, PartState};
use crate::values::{describe, expected, sdk_error};
use context::{context, wrap_plane};
use props::PLANE;
use state::{PhysicsPlane, PlaneState};

impl PlaneState {
    /// The post-tick pass of a step: every part of the plane whose CFrame signal has
    /// listeners announces its new pose (handlers run before `Step` returns).
    pub(crate) fn after_tick(&self, lua: &Lua) -> mlua::Result<()> {
        self.deliver_contacts(lua)?;
        if !self
            .cframe_listen
            .get(|| self.any_part(|p| p.cframe_listeners() > 0))
        {
            return Ok(());
        }
        // A copy: handlers may add, unlink or destroy parts.
        let parts: Vec<Rc<PartState>> = self.parts.borrow().clone();
        for part in parts {
            if part.cframe_listeners() > 0 {
                part.fire_cframe_if_moved(lua)?;
            }
        }
        Ok(())
    }
}

impl LuaPlane for PhysicsPlane {
    const TYPE: &'static str = "PhysicsPlane";
    fn alive(&self) -> bool {
        self.0.alive()
    }
    fn sdk_plane(&self) -> &client_sdk::Plane {
        &self.0.plane
    }
    fn after_tick(&self, lua: &Lua) -> mlua::Result<()> {
        self.0.after_tick(lua)
    }
    fn destroy(&self, lua: &Lua) -> mlua::Result<()> {
        context(lua)
            .planes
            .borrow_mut()
            .retain(|q| !Rc::ptr_eq(q, &self.0));
        self.0
            .destroy()
            .map_err(|e| sdk_error("PhysicsPlane:Destroy", e))
    }
}

pub(crate) fn add(plane: &Rc<PlaneState>, part: Value) -> mlua::Result<PhysicsObject> {
    let Value::UserData(ud) = &part else {
        return Err(expected("PhysicsPlane:Add", "a BasePart", &part));
    };
    let state = match ud.borrow::<BasePart>() {
        Ok(p) => p.0.clone(),
        Err(_) => return Err(expected("PhysicsPlane:Add", "a BasePart", &part)),
    };
    let what = || format!("PhysicsPlane:Add({})", describe(&part));
    if !plane.alive() {
        return Err(mlua::Error::runtime(format!(
            "{}: the plane was destroyed",
            what()
        )));
    }
    if state.is_destroyed() {
        return Err(mlua::Error::runtime(format!(
            "{}: the part was destroyed",
            what()
        )));
    }
    if state.object().is_some() {
        return Err(mlua::Error::runtime(format!(
            "{}: the part is already in a physics plane (Unlink it first)",
            what()
        )));
    }
    let collider = state.collider();
    // A part whose Touched already has handlers reports contacts from its first tick.
    let reporting = state.touch_listeners() > 0;
    let mut props = Vec::new();
    if reporting {
        props.push(ObjectProp::ReportContacts(true));
    }
    if state.anchor_on_add() {
        props.push(ObjectProp::Anchored(true));
    }
    let group = state.collision_group();
    if group != "Default" {
        let id = plane
            .plane
            .client()
            .collision_group_id(&group)
            .map_err(|e| sdk_error(&what(), e))?;
        props.push(ObjectProp::CollisionGroup(id));
    }
    let object = plane
        .plane
        .add(collider, state.cframe().pose(), &props)
        .map_err(|e| sdk_error(&what(), e))?;
    let body = PartObject::new(object, Rc::downgrade(plane));
    plane.adopt(&state, body.clone(), reporting);
    if reporting {
        plane.listen_for_contacts();
    }
    Ok(PhysicsObject {
        body,
        part: state,
        part_ud: ud.clone(),
    })
}

/// `PhysicsService.New(opts?)`.
pub(crate) fn new_plane(lua: &Lua, opts: Value) -> mlua::Result<mlua::AnyUserData> {
    const WHAT: &str = "PhysicsService.New";
    let opts = match opts {
        Value::Nil => None,
        Value::Table(t) => Some(t),
        other => return Err(expected(WHAT, "a table of options or nil", &other)),
    };
    // Every option is part of the creation request: the plane never ticks before all of
    // them apply (a manual plane never ticks on its own at all).
    let mut options = PlaneOptions::default();
    let mut placement: Option<String> = None;
    let mut record = false;
    for pair in opts.iter().flat_map(|t| t.pairs::<Value, Value>()) {
        let (key, value) = pair?;
        // Whether the daemon records the plane from its first tick: not a plane setting.
        if super::recording::is_record_option(&key) {
            record = super::recording::record_option(WHAT, &value)?;
            continue;
        }
        // Where the plane lives: not a plane setting, a choice of daemon.
        if matches!(&key, Value::String(k) if k.as_bytes() == b"Placement") {
            placement = match value {
                Value::String(p) => Some(p.to_str()?.to_string()),
                other => {
                    return Err(expected(
                        "PhysicsService.New: Placement",
                        "\"local\", \"auto\" or a daemon's name",
                        &other,
                    ))
                }
            };
            continue;
        }
        // No row of PhysicsPlane makes a GUI option (NewGUI has its own rows).
        options.set(PLANE.option(WHAT, &key, &value)?);
    }
    let ctx = context(lua);
    let plane = ctx
        .client_for(lua, placement.as_deref())?
        .create_plane(&options)
        .map_err(|e| sdk_error(WHAT, e))?;
    // Placed on a daemon by name: `--rebalance` leaves it there.
    if placement
        .as_deref()
        .is_some_and(|p| p != "local" && p != "auto")
    {
        plane.pin().map_err(|e| sdk_error(WHAT, e))?;
    }
    if record {
        super::recording::record_new_plane(WHAT, &plane)?;
    }
    wrap_plane(lua, plane)
}

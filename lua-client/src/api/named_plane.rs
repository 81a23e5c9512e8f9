//! Named and persistent planes in Luau: `PhysicsService.ListPlanes()` (the named planes of
//! the domain), `PhysicsService.Open(name)` (a `PhysicsPlane` handle on one, live or restored
//! from the daemon's state directory), `plane:Save()` (write a persistent plane's file now)
//! and `plane.Recovered(lostTicks)`, fired once for a plane that came back from its file.
//!
//! `Recovered` is fired at the first frame after `Open` at which it has handlers, so a script
//! that connects right after `Open` (before its next `wait`) hears it.

use std::cell::{Cell, RefCell};
use std::collections::HashMap;
use std::rc::Rc;

use client_sdk::{GuiPlane, PlaneId, PlaneKind};
use mlua::{Lua, MultiValue, Table, UserDataMethods, Value};

use super::gui_plane::state::{held_gui_plane, wrap_gui_plane, GuiPhysicsPlane, GuiPlaneState};
use super::plane::context::{context, plane_ud, wrap_plane};
use super::plane::state::{PhysicsPlane, PlaneState};
use crate::host::scheduler::scheduler;
use crate::host::signal::Signal;
use crate::host::Watched;
use crate::values::{expected, sdk_error};

/// A plane's `Recovered` signal and the lost ticks it has yet to announce.
struct Recovery {
    signal: Signal,
    lost: Cell<Option<u64>>,
    /// The plane, once the script read its signal: a plane that came back on another
    /// member after its daemon died announces it through the SDK (`Plane::take_recovered`).
    plane: RefCell<Option<client_sdk::Plane>>,
}

impl Watched for Recovery {
    fn listeners(&self) -> usize {
        if self.lost.get().is_none() {
            if let Some(lost) = self
                .plane
                .borrow()
                .as_ref()
                .and_then(|p| p.take_recovered())
            {
                self.lost.set(Some(lost));
            }
        }
        match self.lost.get() {
            Some(_) => self.signal.listeners(),
            None => 0,
        }
    }

    fn fire_if_changed(&self, lua: &Lua) -> mlua::Result<()> {
        match self.lost.take() {
            Some(lost) => self
                .signal
                .fire(lua, MultiValue::from_iter([Value::Number(lost as f64)])),
            None => Ok(()),
        }
    }
}

/// The `Recovered` signals of the planes the script read or opened, by plane id.
#[derive(Default)]
struct Recoveries(RefCell<HashMap<PlaneId, Rc<Recovery>>>);

fn recovery(lua: &Lua, id: PlaneId) -> Rc<Recovery> {
    if lua.app_data_ref::<Rc<Recoveries>>().is_none() {
        lua.set_app_data(Rc::new(Recoveries::default()));
    }
    let all = lua
        .app_data_ref::<Rc<Recoveries>>()
        .expect("set above")
        .clone();
    let mut map = all.0.borrow_mut();
    map.entry(id)
        .or_insert_with(|| {
            let r = Rc::new(Recovery {
                signal: Signal::new(format!("PhysicsPlane {id}.Recovered")),
                lost: Cell::new(None),
                plane: RefCell::new(None),
            });
            scheduler(lua).watch(r.clone());
            r
        })
        .clone()
}

/// `plane.Recovered`: the signal (the same value on every read).
pub fn recovered_signal(lua: &Lua, p: &PlaneState) -> mlua::Result<Value> {
    let r = recovery(lua, p.plane.id());
    r.plane.borrow_mut().get_or_insert_with(|| p.plane.clone());
    Ok(Value::UserData(r.signal.userdata(lua)?))
}

/// `plane.Recovered` of a GUI plane: the signal (the same value on every read).
pub fn gui_recovered_signal(lua: &Lua, p: &GuiPlaneState) -> mlua::Result<Value> {
    Ok(Value::UserData(
        recovery(lua, p.plane.plane().id()).signal.userdata(lua)?,
    ))
}

fn kind_name(kind: PlaneKind) -> &'static str {
    match kind {
        PlaneKind::Rapier3d => "3D",
        PlaneKind::Gui2d => "GUI",
    }
}

fn name_arg(what: &str, v: &Value) -> mlua::Result<String> {
    match v {
        Value::String(s) => Ok(s.to_str()?.to_string()),
        _ => Err(expected(what, "a plane name (a string)", v)),
    }
}

/// `PhysicsService.ListPlanes()`: `{ {Name, Id, Kind, Persistent, Tick, Orphaned} }`, by name.
fn list_planes(lua: &Lua, (): ()) -> mlua::Result<Table> {
    const WHAT: &str = "PhysicsService.ListPlanes";
    let list = context(lua)
        .client
        .list_planes()
        .map_err(|e| sdk_error(WHAT, e))?;
    let out = lua.create_table()?;
    for p in list {
        let t = lua.create_table()?;
        t.set("Name", p.name)?;
        t.set("Id", p.id)?;
        t.set("Kind", kind_name(p.kind))?;
        t.set("Persistent", p.persistent)?;
        t.set("Tick", p.tick as f64)?;
        t.set("Orphaned", p.orphaned)?;
        out.push(t)?;
    }
    Ok(out)
}

/// `PhysicsService.Open(name)`: the named plane as a `PhysicsPlane`, or a `GuiPhysicsPlane`
/// for a GUI plane (the script's own value when it already holds the plane).
fn open(lua: &Lua, name: Value) -> mlua::Result<mlua::AnyUserData> {
    const WHAT: &str = "PhysicsService.Open";
    let text = name_arg(WHAT, &name)?;
    let ctx = context(lua);
    let opened = ctx
        .client
        .open_named(&text)
        .map_err(|e| sdk_error(&format!("{WHAT}({text:?})"), e))?;
    let id = opened.plane.id();
    if let Some(lost) = opened.recovered {
        recovery(lua, id).lost.set(Some(lost));
    }
    let kind = opened
        .plane
        .info()
        .map_err(|e| sdk_error(&format!("{WHAT}({text:?})"), e))?
        .kind;
    if kind == PlaneKind::Gui2d {
        let plane = match held_gui_plane(lua, id) {
            Some(held) => held,
            None => wrap_gui_plane(lua, GuiPlane::from_plane(opened.plane)),
        };
        return lua.create_userdata(plane);
    }
    match ctx.plane_state(id) {
        Some(state) => plane_ud(lua, &state),
        None => wrap_plane(lua, opened.plane),
    }
}

/// `Save` on `PhysicsPlane`: the persistent plane's file written now; returns its tick.
pub fn add_methods<M: UserDataMethods<PhysicsPlane>>(methods: &mut M) {
    methods.add_method("Save", |_, p, ()| {
        const WHAT: &str = "PhysicsPlane:Save";
        if !p.0.alive() {
            return Err(mlua::Error::runtime(format!(
                "{WHAT}: the plane was destroyed"
            )));
        }
        p.0.plane
            .save()
            .map(|tick| tick as f64)
            .map_err(|e| sdk_error(WHAT, e))
    });
}

/// `Save` and `Rewind` on `GuiPhysicsPlane`: the persistent plane's file written now
/// (returns its tick); back `ticks` ticks (at most its RollbackTicks).
pub fn add_gui_methods<M: UserDataMethods<GuiPhysicsPlane>>(methods: &mut M) {
    methods.add_method("Save", |_, p, ()| {
        const WHAT: &str = "GuiPhysicsPlane:Save";
        p.0.check_alive(WHAT)?;
        p.0.plane
            .plane()
            .save()
            .map(|tick| tick as f64)
            .map_err(|e| sdk_error(WHAT, e))
    });
    methods.add_method("Rewind", |_, p, ticks: Value| {
        const WHAT: &str = "GuiPhysicsPlane:Rewind";
        p.0.check_alive(WHAT)?;
        let n = match ticks {
            Value::Integer(n) if (0..=u32::MAX as i64).contains(&n) => n as u32,
            Value::Number(n) if n.fract() == 0.0 && (0.0..=u32::MAX as f64).contains(&n) => {
                n as u32
            }
            other => return Err(expected(WHAT, "a whole number of ticks >= 0", &other)),
        };
        p.0.plane
            .plane()
            .rewind(n)
            .map(|_| ())
            .map_err(|e| sdk_error(WHAT, e))
    });
}

/// Adds `ListPlanes` and `Open` to the `PhysicsService` module.
pub fn install(lua: &Lua, module: &Table) -> mlua::Result<()> {
    module.set("ListPlanes", lua.create_function(list_planes)?)?;
    module.set("Open", lua.create_function(open)?)?;
    Ok(())
}

//! `GUIController` (`plane:NewController` / `plane:NewUncontrolled`): `Object`,
//! `MoveDirection`, `MoveSpeed`, `Acceleration`, `JumpStrength`, `WaypointRadius`,
//! `OnGround`, the signals `WaypointReached(i)`, `PathFinished()`, `Moved(dx, dy)`,
//! `GroundChanged(onGround)`, and `Move`, `Jump`, `SetWaypoints`, `GetWaypoints`, `MoveTo`,
//! `ClearWaypoints`, `Destroy`. The daemon drives the body and produces the signals as
//! events; the plane delivers them here in the order they happened (never dropped while
//! the script keeps up within the event queue's 64 ticks; a loss is reported on stderr).

use std::cell::{Cell, RefCell};

use client_sdk::{GuiController, GuiControllerProp, GuiEvent, Handle};
use mlua::{Lua, MetaMethod, MultiValue, Table, UserData, UserDataMethods, Value};

use super::gui_plane::state::{ControllerState, PhysicsGuiObject};
use crate::host::signal::Signal;
use crate::values::{describe, expected, number, sdk_error};
use crate::values::{dim_arg, new_dim};

impl ControllerState {
    /// A controller of `object`.
    pub fn new(ctrl: GuiController, object: PhysicsGuiObject) -> ControllerState {
        let n = |s: &str| Signal::new(format!("GUIController.{s}"));
        ControllerState {
            ctrl,
            object,
            move_direction: Cell::new([0.0; 2]),
            waypoints: RefCell::default(),
            waypoint_reached: n("WaypointReached"),
            path_finished: n("PathFinished"),
            moved: n("Moved"),
            ground_changed: n("GroundChanged"),
        }
    }

    /// Its body's handle.
    pub fn handle(&self) -> Handle {
        self.object.object.handle()
    }

    /// Handlers connected to its signals.
    pub fn listeners(&self) -> usize {
        self.waypoint_reached.listeners()
            + self.path_finished.listeners()
            + self.moved.listeners()
            + self.ground_changed.listeners()
    }

    /// Fires the signal of one event.
    pub fn deliver(&self, lua: &Lua, e: GuiEvent) -> mlua::Result<()> {
        match e {
            GuiEvent::WaypointReached { index, .. } => fire(
                lua,
                &self.waypoint_reached,
                MultiValue::from_iter([Value::Integer(index as i64)]),
            ),
            GuiEvent::PathFinished { .. } => fire(lua, &self.path_finished, MultiValue::new()),
            GuiEvent::Moved { dx, dy, .. } => fire(
                lua,
                &self.moved,
                MultiValue::from_iter([
                    crate::values::lua_number(dx),
                    crate::values::lua_number(dy),
                ]),
            ),
            GuiEvent::GroundChanged { on_ground, .. } => fire(
                lua,
                &self.ground_changed,
                MultiValue::from_iter([Value::Boolean(on_ground)]),
            ),
        }
    }
}

/// `opts` of NewController / NewUncontrolled as controller properties.
pub fn options(what: &str, opts: &Value) -> mlua::Result<Vec<GuiControllerProp>> {
    let t = match opts {
        Value::Nil => return Ok(Vec::new()),
        Value::Table(t) => t,
        other => return Err(expected(what, "a table of options or nil", other)),
    };
    let mut props = Vec::new();
    for pair in t.pairs::<Value, Value>() {
        let (k, v) = pair?;
        props.push(prop(&format!("{what} option"), &k, &v)?);
    }
    Ok(props)
}

fn prop(what: &str, key: &Value, value: &Value) -> mlua::Result<GuiControllerProp> {
    let name = match key {
        Value::String(s) => s.to_string_lossy(),
        other => describe(other),
    };
    // "GUIController." + "MoveSpeed", "NewController option" + " MoveSpeed".
    let full = if what.ends_with('.') {
        format!("{what}{name}")
    } else {
        format!("{what} {name}")
    };
    let make: fn(f32) -> GuiControllerProp = match name.as_str() {
        "MoveSpeed" => GuiControllerProp::MoveSpeed,
        "Acceleration" => GuiControllerProp::Acceleration,
        "JumpStrength" => GuiControllerProp::JumpStrength,
        "WaypointRadius" => GuiControllerProp::WaypointRadius,
        _ => {
            return Err(mlua::Error::runtime(format!(
                "{what}: unknown option {name} (given {}; known: MoveSpeed, Acceleration, \
                 JumpStrength, WaypointRadius)",
                describe(value)
            )))
        }
    };
    match number(value) {
        Some(n) if n.is_finite() && n >= 0.0 => {
            let p = make(n as f32);
            p.checked()
                .map_err(|e| mlua::Error::runtime(format!("{full}: {}", e.message)))
        }
        _ => Err(expected(&full, "a finite number >= 0", value)),
    }
}

/// The Lua handle of a controller.
#[derive(Clone)]
pub struct GuiControllerUd(pub std::rc::Rc<ControllerState>);

fn points(what: &str, v: &Value) -> mlua::Result<Vec<[f32; 2]>> {
    let Value::Table(t) = v else {
        return Err(expected(what, "an array of Dims", v));
    };
    let mut out = Vec::new();
    for (i, p) in t.sequence_values::<Value>().enumerate() {
        out.push(dim_arg(&format!("{what} point {}", i + 1), &p?)?);
    }
    Ok(out)
}

fn dims(lua: &Lua, ps: &[[f32; 2]]) -> mlua::Result<Table> {
    let t = lua.create_table()?;
    for p in ps {
        t.push(new_dim(*p))?;
    }
    Ok(t)
}

impl UserData for GuiControllerUd {
    fn add_methods<M: UserDataMethods<Self>>(methods: &mut M) {
        methods.add_meta_method(MetaMethod::ToString, |_, _, ()| Ok("GUIController"));
        let sdk = |what: &'static str| move |e| sdk_error(what, e);
        methods.add_method("Move", move |_, c, d: Value| {
            const WHAT: &str = "GUIController:Move";
            c.0.object.check_alive(WHAT)?;
            let d = dim_arg(WHAT, &d)?;
            c.0.move_direction.set(d);
            c.0.ctrl.move_direction(d).map_err(sdk(WHAT))
        });
        methods.add_method("Jump", move |_, c, ()| {
            const WHAT: &str = "GUIController:Jump";
            c.0.object.check_alive(WHAT)?;
            c.0.ctrl.jump().map_err(sdk(WHAT))
        });
        methods.add_method("SetWaypoints", move |_, c, ps: Value| {
            const WHAT: &str = "GUIController:SetWaypoints";
            c.0.object.check_alive(WHAT)?;
            let ps = points(WHAT, &ps)?;
            c.0.ctrl.set_waypoints(&ps).map_err(sdk(WHAT))?;
            *c.0.waypoints.borrow_mut() = ps;
            Ok(())
        });
        methods.add_method("MoveTo", move |_, c, p: Value| {
            const WHAT: &str = "GUIController:MoveTo";
            c.0.object.check_alive(WHAT)?;
            let p = dim_arg(WHAT, &p)?;
            c.0.ctrl.set_waypoints(&[p]).map_err(sdk(WHAT))?;
            *c.0.waypoints.borrow_mut() = vec![p];
            Ok(())
        });
        methods.add_method("GetWaypoints", |lua, c, ()| {
            dims(lua, &c.0.waypoints.borrow())
        });
        methods.add_method("ClearWaypoints", move |_, c, ()| {
            const WHAT: &str = "GUIController:ClearWaypoints";
            c.0.object.check_alive(WHAT)?;
            c.0.ctrl.clear_waypoints().map_err(sdk(WHAT))?;
            c.0.waypoints.borrow_mut().clear();
            Ok(())
        });
        methods.add_method("Destroy", move |_, c, ()| {
            if !c.0.object.alive() {
                return Ok(());
            }
            c.0.ctrl.destroy().map_err(sdk("GUIController:Destroy"))?;
            c.0.object.prim.unlink();
            if let Some(p) = c.0.object.plane.upgrade() {
                p.forget(&c.0.object.prim, c.0.handle());
            }
            Ok(())
        });
        methods.add_meta_method(MetaMethod::Index, |lua, c, key: Value| {
            let name = match &key {
                Value::String(s) => s.to_string_lossy(),
                other => describe(other),
            };
            let signal = |s: &Signal| Ok(Value::UserData(s.userdata(lua)?));
            match name.as_str() {
                "Object" => Ok(Value::UserData(super::gui_object::gui_object_ud(
                    lua,
                    c.0.object.clone(),
                )?)),
                "MoveDirection" => Ok(Value::UserData(
                    lua.create_userdata(new_dim(c.0.move_direction.get()))?,
                )),
                "WaypointReached" => signal(&c.0.waypoint_reached),
                "PathFinished" => signal(&c.0.path_finished),
                "Moved" => signal(&c.0.moved),
                "GroundChanged" => signal(&c.0.ground_changed),
                _ => {
                    let what = format!("GUIController.{name}");
                    let known = [
                        "MoveSpeed",
                        "Acceleration",
                        "JumpStrength",
                        "WaypointRadius",
                        "OnGround",
                    ];
                    if !known.contains(&name.as_str()) {
                        return Err(mlua::Error::runtime(format!(
                            "GUIController has no property \"{name}\""
                        )));
                    }
                    c.0.object.check_alive(&what)?;
                    let info = c.0.ctrl.info().map_err(|e| sdk_error(&what, e))?;
                    Ok(match name.as_str() {
                        "MoveSpeed" => crate::values::lua_number(info.move_speed),
                        "Acceleration" => crate::values::lua_number(info.acceleration),
                        "JumpStrength" => crate::values::lua_number(info.jump_strength),
                        "WaypointRadius" => crate::values::lua_number(info.waypoint_radius),
                        _ => Value::Boolean(info.on_ground),
                    })
                }
            }
        });
        methods.add_meta_method(
            MetaMethod::NewIndex,
            |_, c, (key, value): (Value, Value)| {
                let name = match &key {
                    Value::String(s) => s.to_string_lossy(),
                    other => describe(other),
                };
                match name.as_str() {
                    "Object" | "MoveDirection" | "OnGround" => Err(mlua::Error::runtime(format!(
                        "GUIController.{name} is read-only (assigned {})",
                        describe(&value)
                    ))),
                    _ => {
                        let p = prop("GUIController.", &key, &value).map_err(|e| {
                            mlua::Error::runtime(e.to_string().replace("option ", ""))
                        })?;
                        let what = format!("GUIController.{name}");
                        c.0.object.check_alive(&what)?;
                        c.0.ctrl.set(p).map_err(|e| sdk_error(&what, e))
                    }
                }
            },
        );
    }
}

/// Fires `signal` with `args` (used by controllers).
pub fn fire(lua: &Lua, signal: &crate::host::signal::Signal, args: MultiValue) -> mlua::Result<()> {
    if signal.listeners() > 0 {
        signal.fire(lua, args)
    } else {
        Ok(())
    }
}

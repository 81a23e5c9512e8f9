//! `Controller`: what `plane:NewController(part, opts?)` and
//! `plane:NewControlledController(part, opts?)` return. The daemon moves it every tick; its
//! part's CFrame follows zero-copy like any simulated part. Signals (Jumped, Landed, Moved,
//! WaypointReached, PathFinished) come from the plane's per-tick event stream.

pub(crate) mod props;
pub(crate) mod state;

use std::cell::{Cell, RefCell};
use std::rc::Rc;

use client_sdk::{Pose, Vec3};
use mlua::{MetaMethod, UserData, UserDataMethods, Value};

use super::part::state::{BasePart, Ended, PartObject};
use super::plane::state::{ControllerState, PlaneState};
use crate::values::{describe, expected, finite_number, sdk_error, vector, CFrame};
use props::CONTROLLER;
use state::LuaController;

/// A point: a Vector, or a CFrame's position.
fn point(what: &str, v: &Value) -> mlua::Result<Vec3> {
    if let Some(p) = vector(v) {
        if p.iter().all(|c| c.is_finite()) {
            return Ok(p);
        }
    }
    if let Some(cf) = CFrame::from_value(v) {
        return Ok(cf.pose().position);
    }
    Err(expected(what, "a Vector or a CFrame", v))
}

fn intensity(what: &str, v: &Value) -> mlua::Result<f32> {
    let n = match v {
        Value::Nil => 1.0,
        other => finite_number(what, other)?,
    };
    if !(-1.0..=1.0).contains(&n) {
        return Err(expected(what, "a number in [-1, 1]", v));
    }
    Ok(n as f32)
}

impl UserData for LuaController {
    fn add_methods<M: UserDataMethods<Self>>(methods: &mut M) {
        methods.add_method("BasePart", |_, c, ()| Ok(c.0.part_ud.clone()));
        methods.add_method("WalkTo", |_, c, target: Value| {
            const W: &str = "Controller:WalkTo";
            let p = point(W, &target)?;
            c.live("WalkTo")?.walk_to(p).map_err(|e| sdk_error(W, e))
        });
        methods.add_method("ComputePath", |_, c, list: Value| {
            const W: &str = "Controller:ComputePath";
            let Value::Table(t) = &list else {
                return Err(expected(W, "an array of Vectors or CFrames", &list));
            };
            let points = t
                .sequence_values::<Value>()
                .enumerate()
                .map(|(i, v)| point(&format!("{W} waypoints[{}]", i + 1), &v?))
                .collect::<mlua::Result<Vec<_>>>()?;
            c.live("ComputePath")?
                .compute_path(&points)
                .map_err(|e| sdk_error(W, e))
        });
        methods.add_method("AppendWaypoint", |_, c, target: Value| {
            const W: &str = "Controller:AppendWaypoint";
            let p = point(W, &target)?;
            c.live("AppendWaypoint")?
                .append_waypoint(p)
                .map_err(|e| sdk_error(W, e))
        });
        methods.add_method("StopWalking", |_, c, ()| {
            c.0.move_vector.set([0.0; 2]);
            c.live("StopWalking")?
                .stop_walking()
                .map_err(|e| sdk_error("Controller:StopWalking", e))
        });
        methods.add_method("Jump", |_, c, ()| {
            c.live("Jump")?
                .jump()
                .map_err(|e| sdk_error("Controller:Jump", e))
        });
        methods.add_method("Teleport", |_, c, target: Value| {
            const W: &str = "Controller:Teleport";
            let pose = match CFrame::from_value(&target) {
                Some(cf) => cf.pose(),
                None => Pose::at(point(W, &target)?),
            };
            c.live("Teleport")?
                .teleport(pose)
                .map_err(|e| sdk_error(W, e))
        });
        methods.add_method("SetMoveVector", |_, c, (x, z): (Value, Value)| {
            let x = intensity("Controller:SetMoveVector x", &x)?;
            let z = intensity("Controller:SetMoveVector z", &z)?;
            c.set_intent("SetMoveVector", Some(x), Some(z))
        });
        methods.add_method("MoveForward", |_, c, i: Value| {
            let i = intensity("Controller:MoveForward", &i)?;
            c.set_intent("MoveForward", None, Some(i))
        });
        methods.add_method("MoveBackward", |_, c, i: Value| {
            let i = intensity("Controller:MoveBackward", &i)?;
            c.set_intent("MoveBackward", None, Some(-i))
        });
        methods.add_method("MoveRight", |_, c, i: Value| {
            let i = intensity("Controller:MoveRight", &i)?;
            c.set_intent("MoveRight", Some(i), None)
        });
        methods.add_method("MoveLeft", |_, c, i: Value| {
            let i = intensity("Controller:MoveLeft", &i)?;
            c.set_intent("MoveLeft", Some(-i), None)
        });
        methods.add_method("ClearMoveIntent", |_, c, ()| {
            c.set_intent("ClearMoveIntent", Some(0.0), Some(0.0))
        });
        methods.add_method("Destroy", |_, c, ()| {
            // The part stays at its last CFrame; destroying twice does nothing.
            if c.0.body.ended().is_none() {
                c.0.part.detach(Ended::Destroyed);
                if let Some(plane) = c.0.plane.upgrade() {
                    plane.forget_controller(c.0.controller.handle());
                }
                c.0.disconnect_all();
            }
            Ok(())
        });
        methods.add_meta_method(MetaMethod::Index, |lua, c, key: Value| {
            CONTROLLER.get(lua, c, &key)
        });
        methods.add_meta_method(
            MetaMethod::NewIndex,
            |lua, c, (key, value): (Value, Value)| CONTROLLER.set(lua, c, &key, &value),
        );
        methods.add_meta_method(MetaMethod::ToString, |_, c, ()| {
            let gone = if c.0.body.ended().is_some() {
                " (destroyed)"
            } else {
                ""
            };
            Ok(format!("Controller \"{}\"{gone}", c.0.part.name()))
        });
        methods.add_meta_method(MetaMethod::Eq, |_, c, other: Value| {
            Ok(match other {
                Value::UserData(ud) => ud
                    .borrow::<LuaController>()
                    .is_ok_and(|o| Rc::ptr_eq(&o.0, &c.0)),
                _ => false,
            })
        });
    }
}

/// `plane:NewController(part, opts?)` (`controlled` false) and
/// `plane:NewControlledController(part, opts?)`.
pub fn new_controller(
    plane: &Rc<PlaneState>,
    part: Value,
    opts: Value,
    controlled: bool,
) -> mlua::Result<LuaController> {
    let what = if controlled {
        "PhysicsPlane:NewControlledController"
    } else {
        "PhysicsPlane:NewController"
    };
    let Value::UserData(ud) = &part else {
        return Err(expected(what, "a BasePart", &part));
    };
    let state = match ud.borrow::<BasePart>() {
        Ok(p) => p.0.clone(),
        Err(_) => return Err(expected(what, "a BasePart", &part)),
    };
    let fail = |why: &str| mlua::Error::runtime(format!("{what}({}): {why}", describe(&part)));
    if !plane.alive() {
        return Err(fail("the plane was destroyed"));
    }
    if state.is_destroyed() {
        return Err(fail("the part was destroyed"));
    }
    if state.object().is_some() {
        return Err(fail(
            "the part is already in a physics plane (Unlink it first)",
        ));
    }
    let mut props = Vec::new();
    match &opts {
        Value::Nil => {}
        Value::Table(t) => {
            for pair in t.pairs::<Value, Value>() {
                let (key, value) = pair?;
                props.push(CONTROLLER.option(what, &key, &value)?);
            }
        }
        other => return Err(expected(what, "a table of options or nil", other)),
    }
    let controller = plane
        .plane
        .new_controller(state.cframe().pose(), state.size(), controlled, &props)
        .map_err(|e| sdk_error(what, e))?;
    let group = state.collision_group();
    if group != "Default" {
        controller
            .object()
            .set_collision_group(&group)
            .map_err(|e| sdk_error(what, e))?;
    }
    let body = PartObject::new(controller.object().clone(), Rc::downgrade(plane));
    plane.adopt(&state, body.clone(), false);
    let c = Rc::new(ControllerState {
        controller,
        part: state,
        part_ud: ud.clone(),
        body,
        plane: Rc::downgrade(plane),
        move_vector: Cell::new([0.0; 2]),
        signals: RefCell::default(),
    });
    plane.keep_controller(c.clone());
    Ok(LuaController(c))
}

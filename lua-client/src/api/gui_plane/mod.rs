//! `PhysicsService.NewGUI(opts?)` and the `GuiPhysicsPlane` it returns: options (`Gravity`,
//! `Enabled`, `TickRate`, `LinearDamping`, `AngularDamping`, `Drag`, `ConstantForce`,
//! `RestThreshold`, `SolverIterations`, `NeverSleep`, creation-only `BoundsMin` /
//! `BoundsMax`), `ObjectCount`, `Alive`, and `:Add`, `:NewController`, `:NewUncontrolled`,
//! `:Raycast`, `:Step`, `:SetEnabled`, `:Destroy`. Each frame (and after `:Step`) the plane
//! announces its primitives' new Position / Rotation to listeners and delivers controller
//! signals in the order the daemon produced them.

pub(crate) mod props;
pub(crate) mod state;

use std::rc::Rc;

use client_sdk::{GuiPlaneOptions, GuiPlaneProp, PlaneProp};
use mlua::{Lua, MetaMethod, UserData, UserDataMethods, Value};

use super::gui_basic::{GuiPrimitive, PrimState};
use super::gui_controller::GuiControllerUd;
use super::plane::context::context;
use crate::host::Watched;
use crate::values::{describe, expected, finite_number, sdk_error};
use crate::values::{dim_arg, new_dim};
use state::{
    wrap_gui_plane, ControllerState, GuiPhysicsPlane, GuiPlaneState, GuiPlanes, PhysicsGuiObject,
};

impl GuiPlaneState {
    pub(crate) fn after_tick(&self, lua: &Lua) -> mlua::Result<()> {
        self.deliver_signals(lua)?;
        let prims: Vec<Rc<PrimState>> = self.prims.borrow().clone();
        for p in prims {
            p.fire_if_moved(lua)?;
        }
        Ok(())
    }

    fn deliver_signals(&self, lua: &Lua) -> mlua::Result<()> {
        if !self.alive() || self.controllers.borrow().is_empty() {
            return Ok(());
        }
        let (events, lost) = self
            .plane
            .events()
            .map_err(|e| sdk_error("GuiPhysicsPlane controller signals", e))?;
        if lost > 0 {
            eprintln!(
                "GuiPhysicsPlane {}: {lost} controller signals lost (the script fell more than \
                 {} ticks with events behind)",
                self.plane.plane().id(),
                client_sdk::EVENT_BUFFER_TICKS
            );
        }
        for e in events {
            let c = self.controllers.borrow().get(&e.handle()).cloned();
            if let Some(c) = c {
                c.deliver(lua, e)?;
            }
        }
        Ok(())
    }

    pub(crate) fn destroy(&self) -> mlua::Result<()> {
        if !self.alive.replace(false) {
            return Ok(());
        }
        for p in self.prims.take() {
            p.unlink();
        }
        self.controllers.borrow_mut().clear();
        self.plane
            .destroy()
            .map_err(|e| sdk_error("GuiPhysicsPlane:Destroy", e))
    }

    fn add(self: &Rc<Self>, what: &str, prim: &Value) -> mlua::Result<PhysicsGuiObject> {
        self.check_alive(what)?;
        let p = match prim {
            Value::UserData(ud) => ud.borrow::<GuiPrimitive>().map(|p| p.0.clone()).ok(),
            _ => None,
        }
        .ok_or_else(|| {
            expected(
                what,
                "a GUI primitive (GUI.Basic.Square, Circle, Triangle, Image or Text)",
                prim,
            )
        })?;
        if p.body().is_some() {
            return Err(mlua::Error::runtime(format!(
                "{what}({}): the primitive is already in a GUI plane",
                describe(prim)
            )));
        }
        let object = self
            .plane
            .add(
                p.shape,
                p.size(),
                p.position(),
                &[
                    client_sdk::GuiObjectProp::Rotation(p.rotation()),
                    client_sdk::GuiObjectProp::ZIndex(p.z_index()),
                ],
            )
            .map_err(|e| sdk_error(what, e))?;
        p.link(object.clone());
        self.prims.borrow_mut().push(p.clone());
        Ok(PhysicsGuiObject {
            object,
            prim: p,
            plane: Rc::downgrade(self),
        })
    }

    fn new_controller(
        self: &Rc<Self>,
        what: &str,
        prim: &Value,
        opts: Value,
        uncontrolled: bool,
    ) -> mlua::Result<GuiControllerUd> {
        let props = super::gui_controller::options(what, &opts)?;
        let object = self.add(what, prim)?;
        // Subscribe before the controller exists: none of its signals is missed.
        self.plane
            .plane()
            .subscribe_events()
            .map_err(|e| sdk_error(what, e))?;
        let ctrl = self
            .plane
            .new_controller(&object.object, uncontrolled, &props)
            .map_err(|e| sdk_error(what, e))?;
        let state = Rc::new(ControllerState::new(ctrl, object));
        self.controllers
            .borrow_mut()
            .insert(state.handle(), state.clone());
        Ok(GuiControllerUd(state))
    }
}

impl super::lifecycle::LuaPlane for GuiPhysicsPlane {
    const TYPE: &'static str = "GuiPhysicsPlane";
    fn alive(&self) -> bool {
        self.0.alive()
    }
    fn sdk_plane(&self) -> &client_sdk::Plane {
        self.0.plane.plane()
    }
    fn after_tick(&self, lua: &Lua) -> mlua::Result<()> {
        self.0.after_tick(lua)
    }
    fn destroy(&self, lua: &Lua) -> mlua::Result<()> {
        if let Some(planes) = lua.app_data_ref::<GuiPlanes>() {
            planes.0.borrow_mut().retain(|q| !Rc::ptr_eq(q, &self.0));
        }
        self.0.destroy()
    }
}

impl UserData for GuiPhysicsPlane {
    fn add_methods<M: UserDataMethods<Self>>(methods: &mut M) {
        methods.add_method("Add", |lua, p, prim: Value| {
            super::gui_object::gui_object_ud(lua, p.0.add("GuiPhysicsPlane:Add", &prim)?)
        });
        super::snapshot::add_gui_plane_methods(methods);
        super::recording::add_methods(methods);
        super::named_plane::add_gui_methods(methods);
        methods.add_method("NewController", |_, p, (prim, opts): (Value, Value)| {
            p.0.new_controller("GuiPhysicsPlane:NewController", &prim, opts, false)
        });
        methods.add_method("NewUncontrolled", |_, p, (prim, opts): (Value, Value)| {
            p.0.new_controller("GuiPhysicsPlane:NewUncontrolled", &prim, opts, true)
        });
        methods.add_method(
            "Raycast",
            |lua, p, (from, dir, max): (Value, Value, Value)| {
                const WHAT: &str = "GuiPhysicsPlane:Raycast";
                p.0.check_alive("Raycast")?;
                let from = dim_arg(&format!("{WHAT} from"), &from)?;
                let dir = dim_arg(&format!("{WHAT} dir"), &dir)?;
                let max = match &max {
                    Value::Nil => None,
                    v => match finite_number(&format!("{WHAT} maxDistance"), v)? {
                        d if d >= 0.0 => Some(d as f32),
                        _ => return Err(expected(WHAT, "a maxDistance >= 0", v)),
                    },
                };
                let hit =
                    p.0.plane
                        .raycast(from, dir, max)
                        .map_err(|e| sdk_error(WHAT, e))?;
                let Some(hit) = hit else {
                    return Ok(Value::Nil);
                };
                let t = lua.create_table()?;
                t.set("Distance", hit.distance)?;
                t.set("Position", new_dim(hit.position))?;
                t.set("Normal", new_dim(hit.normal))?;
                let prim =
                    p.0.prims
                        .borrow()
                        .iter()
                        .find(|q| q.body().is_some_and(|b| b.handle() == hit.handle))
                        .cloned();
                if let Some(prim) = prim {
                    let object = PhysicsGuiObject {
                        object: prim.body().expect("linked"),
                        prim,
                        plane: Rc::downgrade(&p.0),
                    };
                    t.set("Object", super::gui_object::gui_object_ud(lua, object)?)?;
                }
                Ok(Value::Table(t))
            },
        );
        super::lifecycle::add_methods(methods);
        methods.add_method("SetEnabled", |_, p, on: Value| {
            p.0.check_alive("SetEnabled")?;
            let Value::Boolean(on) = on else {
                return Err(expected("GuiPhysicsPlane:SetEnabled", "a boolean", &on));
            };
            p.0.plane
                .set_common(PlaneProp::Enabled(on))
                .map_err(|e| sdk_error("GuiPhysicsPlane:SetEnabled", e))
        });
        methods.add_meta_method(MetaMethod::Index, |lua, p, key: Value| {
            props::GUI_PLANE.get(lua, &p.0, &key)
        });
        methods.add_meta_method(
            MetaMethod::NewIndex,
            |lua, p, (key, value): (Value, Value)| props::GUI_PLANE.set(lua, &p.0, &key, &value),
        );
        // Two handles on one plane are equal (`Open` of a plane the script holds).
        methods.add_meta_function(
            MetaMethod::Eq,
            |_, (a, b): (mlua::AnyUserData, mlua::AnyUserData)| {
                let (Ok(a), Ok(b)) = (a.borrow::<Self>(), b.borrow::<Self>()) else {
                    return Ok(false);
                };
                Ok(Rc::ptr_eq(&a.0, &b.0))
            },
        );
    }
}

impl Watched for GuiPlaneState {
    fn listeners(&self) -> usize {
        if !self.alive() {
            return 0;
        }
        let prims = self.prims.borrow().iter().any(|p| p.motion_listeners());
        let ctrls = self
            .controllers
            .borrow()
            .values()
            .any(|c| c.listeners() > 0);
        usize::from(prims || ctrls)
    }

    fn fire_if_changed(&self, lua: &Lua) -> mlua::Result<()> {
        self.after_tick(lua)
    }
}

/// `PhysicsService.NewGUI(opts?)`.
pub fn new_gui(lua: &Lua, opts: Value) -> mlua::Result<GuiPhysicsPlane> {
    const WHAT: &str = "PhysicsService.NewGUI";
    let opts = match opts {
        Value::Nil => None,
        Value::Table(t) => Some(t),
        other => return Err(expected(WHAT, "a table of options or nil", &other)),
    };
    let mut o = GuiPlaneOptions::default();
    let (mut bmin, mut bmax) = (None, None);
    let mut record = false;
    for pair in opts.iter().flat_map(|t| t.pairs::<Value, Value>()) {
        let (key, value) = pair?;
        match &key {
            k if super::recording::is_record_option(k) => {
                record = super::recording::record_option(WHAT, &value)?
            }
            Value::String(s) if &*s.as_bytes() == b"BoundsMin" => {
                bmin = Some(dim_arg(&format!("{WHAT} option BoundsMin"), &value)?)
            }
            Value::String(s) if &*s.as_bytes() == b"BoundsMax" => {
                bmax = Some(dim_arg(&format!("{WHAT} option BoundsMax"), &value)?)
            }
            _ => match props::GUI_PLANE.option(WHAT, &key, &value)? {
                PlaneProp::TickRate(v) => o.tick_rate = Some(v),
                PlaneProp::Enabled(v) => o.enabled = Some(v),
                PlaneProp::Name(v) => o.name = Some(v),
                PlaneProp::Persistent(v) => o.persistent = Some(v),
                PlaneProp::RollbackTicks(v) => o.rollback_ticks = Some(v),
                PlaneProp::Gui(g) => match g {
                    GuiPlaneProp::Gravity(v) => o.gravity = Some(v),
                    GuiPlaneProp::LinearDamping(v) => o.linear_damping = Some(v),
                    GuiPlaneProp::AngularDamping(v) => o.angular_damping = Some(v),
                    GuiPlaneProp::Drag(v) => o.drag = Some(v),
                    GuiPlaneProp::ConstantForce(v) => o.constant_force = Some(v),
                    GuiPlaneProp::RestThreshold(v) => o.rest_threshold = Some(v),
                    GuiPlaneProp::SolverIterations(v) => o.solver_iterations = Some(v),
                    GuiPlaneProp::NeverSleep(v) => o.never_sleep = Some(v),
                    GuiPlaneProp::Bounds { min, max } => o.bounds = Some((min, max)),
                },
                _ => {}
            },
        }
    }
    match (bmin, bmax) {
        (Some(min), Some(max)) => o.bounds = Some((min, max)),
        (None, None) => {}
        _ => {
            return Err(mlua::Error::runtime(format!(
                "{WHAT}: BoundsMin and BoundsMax go together (only one was given)"
            )))
        }
    }
    let ctx = context(lua);
    let plane = ctx
        .client
        .create_gui_plane(&o)
        .map_err(|e| sdk_error(WHAT, e))?;
    if record {
        super::recording::record_new_plane(WHAT, plane.plane())?;
    }
    Ok(wrap_gui_plane(lua, plane))
}

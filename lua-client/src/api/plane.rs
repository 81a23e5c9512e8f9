//! `PhysicsService.New` and the `PhysicsPlane` it returns.

use std::cell::{Cell, RefCell};
use std::rc::Rc;

use client_sdk::{Client, Plane, PlaneOptions, PlaneProp};
use mlua::{Lua, MetaMethod, Table, UserData, UserDataMethods, Value};

use client_sdk::validate::MAX_DT;

use super::object::PhysicsObject;
use super::part::{BasePart, Link, PartState};
use crate::props::plane::{AT_CREATION, NOT_YET_METHODS, PLANE};
use crate::props::{not_yet_methods, Set};
use crate::values::{describe, expected, finite_number, sdk_error};

pub struct PlaneState {
    pub plane: Plane,
    alive: Cell<bool>,
    // Option values as last written by this script (the daemon applies them in order).
    pub gravity: Cell<[f32; 3]>,
    pub enabled: Cell<bool>,
    pub tick_rate: Cell<f32>,
    pub threads: u32,
    parts: RefCell<Vec<Rc<PartState>>>,
}

impl PlaneState {
    pub fn alive(&self) -> bool {
        self.alive.get()
    }

    /// Queues an option change for the frame's batch.
    pub fn set(&self, prop: PlaneProp) -> mlua::Result<()> {
        if !self.alive() {
            return Err(mlua::Error::runtime(format!(
                "PhysicsPlane: cannot set {prop:?} on a destroyed plane"
            )));
        }
        self.plane
            .set(prop)
            .map_err(|e| sdk_error("PhysicsPlane", e))
    }

    pub fn object_count(&self) -> Result<u32, client_sdk::Error> {
        if !self.alive() {
            return Ok(0);
        }
        Ok(self.plane.info()?.object_count)
    }

    pub fn forget(&self, part: &Rc<PartState>) {
        self.parts.borrow_mut().retain(|p| !Rc::ptr_eq(p, part));
    }

    /// Removes every body (their parts stay at their last pose) and the plane itself.
    fn destroy(&self) -> Result<(), client_sdk::Error> {
        if !self.alive.replace(false) {
            return Ok(());
        }
        for part in self.parts.take() {
            part.unlink();
        }
        self.plane.destroy()
    }
}

/// Planes stay alive until `:Destroy()`, whether or not the script keeps a reference.
pub struct Context {
    pub client: Client,
    planes: RefCell<Vec<Rc<PlaneState>>>,
}

impl Context {
    pub fn new(client: Client) -> Context {
        Context {
            client,
            planes: RefCell::default(),
        }
    }
}

fn context(lua: &Lua) -> Rc<Context> {
    lua.app_data_ref::<Rc<Context>>()
        .expect("lua_client::install registers the context")
        .clone()
}

#[derive(Clone)]
pub struct PhysicsPlane(pub Rc<PlaneState>);

impl UserData for PhysicsPlane {
    fn add_methods<M: UserDataMethods<Self>>(methods: &mut M) {
        methods.add_method("Add", |_, p, part: Value| add(&p.0, part));
        methods.add_method("SetEnabled", |lua, p, on: Value| {
            PLANE.set(
                lua,
                &p.0,
                &Value::String(lua.create_string("Enabled")?),
                &on,
            )
        });
        methods.add_method("Step", |_, p, dt: Value| {
            let dt = match finite_number("PhysicsPlane:Step", &dt) {
                Ok(dt) if dt > 0.0 && dt <= MAX_DT as f64 => dt,
                _ => {
                    return Err(expected(
                        "PhysicsPlane:Step",
                        "a number of seconds in (0, 1]",
                        &dt,
                    ))
                }
            };
            // Documented as a no-op on a destroyed plane (the daemon skips disabled ones).
            if !p.0.alive() {
                return Ok(());
            }
            p.0.plane
                .step(dt as f32)
                .map(|_| ())
                .map_err(|e| sdk_error("PhysicsPlane:Step", e))
        });
        methods.add_method("Destroy", |lua, p, ()| {
            context(lua)
                .planes
                .borrow_mut()
                .retain(|q| !Rc::ptr_eq(q, &p.0));
            p.0.destroy()
                .map_err(|e| sdk_error("PhysicsPlane:Destroy", e))
        });
        not_yet_methods(methods, "PhysicsPlane", NOT_YET_METHODS);
        methods.add_meta_method(MetaMethod::Index, |lua, p, key: Value| {
            PLANE.get(lua, &p.0, &key)
        });
        methods.add_meta_method(
            MetaMethod::NewIndex,
            |lua, p, (key, value): (Value, Value)| PLANE.set(lua, &p.0, &key, &value),
        );
        methods.add_meta_method(MetaMethod::ToString, |_, p, ()| {
            Ok(format!("PhysicsPlane {}", p.0.plane.id()))
        });
    }
}

fn add(plane: &Rc<PlaneState>, part: Value) -> mlua::Result<PhysicsObject> {
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
    let collider = state.shape.collider(state.size());
    let object = plane
        .plane
        .add(collider, state.cframe().pose(), &[])
        .map_err(|e| sdk_error(&what(), e))?;
    state.link(Link {
        object: object.clone(),
        plane: Rc::downgrade(plane),
    });
    plane.parts.borrow_mut().push(state.clone());
    Ok(PhysicsObject {
        object,
        part: state,
        part_ud: ud.clone(),
    })
}

/// `PhysicsService.New(opts?)`.
fn new_plane(lua: &Lua, opts: Value) -> mlua::Result<PhysicsPlane> {
    const WHAT: &str = "PhysicsService.New";
    let opts = match opts {
        Value::Nil => None,
        Value::Table(t) => Some(t),
        other => return Err(expected(WHAT, "a table of options or nil", &other)),
    };
    let mut options = PlaneOptions::default();
    let mut later = Vec::new();
    for pair in opts.iter().flat_map(|t| t.pairs::<Value, Value>()) {
        let (key, value) = pair?;
        let row = PLANE.row(&key).ok_or_else(|| {
            mlua::Error::runtime(format!(
                "{WHAT}: unknown option {} (given {})",
                describe(&key),
                describe(&value)
            ))
        })?;
        let creation = AT_CREATION.iter().find(|(n, _)| *n == row.name);
        match (&row.set, creation) {
            (Set::NotYet, _) => return Err(PLANE.not_supported(row.name)),
            (Set::ReadOnly, None) => {
                return Err(mlua::Error::runtime(format!(
                    "{WHAT}: {} is read-only, not an option (given {})",
                    row.name,
                    describe(&value)
                )))
            }
            _ => {}
        }
        let arg = row
            .kind
            .convert(&format!("{WHAT} option {}", row.name), &value)?;
        match creation {
            Some((_, apply)) => apply(&mut options, &arg)?,
            None => later.push((row, arg)),
        }
    }
    let ctx = context(lua);
    let plane = ctx
        .client
        .create_plane(&options)
        .map_err(|e| sdk_error(WHAT, e))?;
    let info = plane.info().map_err(|e| sdk_error(WHAT, e))?;
    let state = Rc::new(PlaneState {
        plane,
        alive: Cell::new(true),
        gravity: Cell::new(info.gravity),
        enabled: Cell::new(info.enabled),
        tick_rate: Cell::new(info.tick_rate),
        threads: info.threads,
        parts: RefCell::default(),
    });
    for (row, arg) in later {
        if let Set::Fn(set) = row.set {
            set(lua, &state, arg)?;
        }
    }
    ctx.planes.borrow_mut().push(state.clone());
    Ok(PhysicsPlane(state))
}

/// The `PhysicsService` module.
pub fn module(lua: &Lua) -> mlua::Result<Table> {
    let m = lua.create_table()?;
    m.set("New", lua.create_function(new_plane)?)?;
    m.set(
        "NewGUI",
        lua.create_function(|_, _: Value| -> mlua::Result<()> {
            Err(mlua::Error::runtime(
                "PhysicsService.NewGUI is not supported yet",
            ))
        })?,
    )?;
    Ok(m)
}

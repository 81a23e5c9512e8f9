//! The Luau API types, one file each: `PhysicsService` and its planes ([`plane`]), the
//! `PhysicsObject` a plane's `:Add` returns ([`object`]), and `Renderable.BasePart`
//! ([`part`]). Their properties are the rows in `props`; values come from `values`.
//!
//! Layers, importing downward only: the state the types share (`part/state.rs`, then
//! `plane/state.rs` and `plane/context.rs`, `gui_plane/state.rs`), each type's handle
//! state, rows and methods above it, and here at the top the registration: the modules,
//! `PhysicsPlane`'s methods (gathered from the files of its concerns) and what a body asks
//! of its plane.

pub mod animated_ragdoll;
pub mod axis_motor;
pub mod collision_groups;
pub mod contact_points;
pub mod contacts;
pub mod controller;
pub mod dyn_mesh;
pub mod gui_basic;
pub mod gui_controller;
pub mod gui_object;
pub mod gui_plane;
pub mod joint;
pub(crate) mod lifecycle;
pub mod map;
pub(crate) mod method_tables;
pub mod move_to;
pub mod named_plane;
pub mod object;
pub mod part;
pub mod plane;
pub mod plane_objects;
pub mod probe;
pub mod query;
pub mod ragdoll;
pub mod recording;
pub mod snapshot;
pub mod start_plane;
pub mod static_shapes;

use std::rc::Rc;

use client_sdk::{Client, Handle};
use mlua::{Lua, MetaMethod, Table, UserData, UserDataMethods, Value};

use method_tables::MethodTables;
use part::state::{PartPlane, PartState};
use plane::context::{context, Context};
use plane::props::PLANE;
use plane::state::{PhysicsPlane, PlaneState};

/// The modules `import` knows, in the order error messages list them.
pub const MODULES: [&str; 5] = [
    "PhysicsService",
    "Renderable",
    "Primitives",
    "GUI",
    "DynMesh",
];

/// Registers the API's state in `lua` (talking to the daemon through `client`) and returns
/// the modules by name.
pub fn modules(lua: &Lua, client: Client) -> mlua::Result<Table> {
    lua.set_app_data(Rc::new(Context::new(client)));
    lua.set_app_data(Rc::new(MethodTables {
        part: part::methods(lua)?,
        object: object::methods(lua)?,
    }));
    part::pose_index::install(lua)?;
    let modules = lua.create_table()?;
    modules.set("PhysicsService", physics_service(lua)?)?;
    let renderable = part::module(lua)?;
    static_shapes::add_constructors(lua, &renderable)?;
    modules.set("Renderable", renderable)?;
    modules.set("Primitives", crate::values::module(lua)?)?;
    modules.set("GUI", gui_basic::module(lua)?)?;
    modules.set("DynMesh", dyn_mesh::module(lua)?)?;
    freeze(&modules)?;
    Ok(modules)
}

/// Makes `table` and every table reachable from it read-only, so a script cannot change a
/// module for the scripts it shares a state with (`import("Primitives").Vector = nil`).
fn freeze(table: &Table) -> mlua::Result<()> {
    let mut seen = std::collections::HashSet::new();
    let mut stack = vec![table.clone()];
    while let Some(t) = stack.pop() {
        if !seen.insert(t.to_pointer()) {
            continue;
        }
        for pair in t.pairs::<Value, Value>() {
            if let (_, Value::Table(inner)) = pair? {
                stack.push(inner);
            }
        }
        if let Some(meta) = t.metatable() {
            stack.push(meta);
        }
        t.set_readonly(true);
    }
    Ok(())
}

impl UserData for PhysicsPlane {
    fn add_methods<M: UserDataMethods<Self>>(methods: &mut M) {
        methods.add_method("Add", |lua, p, part: Value| {
            object::object_ud(lua, plane::add(&p.0, part)?)
        });
        methods.add_method("SetEnabled", |lua, p, on: Value| {
            PLANE.set(
                lua,
                &p.0,
                &Value::String(lua.create_string("Enabled")?),
                &on,
            )
        });
        lifecycle::add_methods(methods);
        query::add_methods(methods);
        snapshot::add_plane_methods(methods);
        recording::add_methods(methods);
        methods.add_method("NewController", |_, p, (part, opts): (Value, Value)| {
            controller::new_controller(&p.0, part, opts, false)
        });
        methods.add_method(
            "NewControlledController",
            |_, p, (part, opts): (Value, Value)| controller::new_controller(&p.0, part, opts, true),
        );
        joint::add_methods(methods);
        ragdoll::add_methods(methods);
        probe::add_methods(methods);
        named_plane::add_methods(methods);
        plane_objects::add_methods(methods);
        move_to::add_methods(methods);
        methods.add_meta_method(MetaMethod::Index, |lua, p, key: Value| {
            PLANE.get(lua, &p.0, &key)
        });
        methods.add_meta_method(
            MetaMethod::NewIndex,
            |lua, p, (key, value): (Value, Value)| PLANE.set(lua, &p.0, &key, &value),
        );
    }
}

/// The `PhysicsService` module.
fn physics_service(lua: &Lua) -> mlua::Result<Table> {
    let m = lua.create_table()?;
    m.set("New", lua.create_function(plane::new_plane)?)?;
    let ctx = context(lua);
    m.set("Stalled", ctx.stalled.clone())?;
    m.set("Resumed", ctx.resumed.clone())?;
    m.set("HumanoidRagdoll", lua.create_function(ragdoll::humanoid)?)?;
    collision_groups::install(lua, &m)?;
    m.set("NewGUI", lua.create_function(gui_plane::new_gui)?)?;
    snapshot::install(lua, &m)?;
    named_plane::install(lua, &m)?;
    start_plane::install(lua, &m)?;
    Ok(m)
}

/// What a body asks of its plane: `part/state.rs` cannot name the plane's state (which
/// holds the parts), so the plane answers through [`PartPlane`].
impl PartPlane for PlaneState {
    fn forget(&self, part: &Rc<PartState>, handle: Handle) {
        PlaneState::forget(self, part, handle);
    }

    fn listen_for_contacts(&self) {
        PlaneState::listen_for_contacts(self);
    }

    fn body_value(&self, lua: &Lua, handle: Handle) -> mlua::Result<Value> {
        contact_points::body_value(lua, self, handle)
    }
}

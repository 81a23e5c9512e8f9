//! The Luau API types, one file each: `PhysicsService` and its planes ([`plane`]), the
//! `PhysicsObject` a plane's `:Add` returns ([`object`]), and `Renderable.BasePart`
//! ([`part`]). Their properties are the rows in `props`; values come from `values`.

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
pub mod move_to;
pub mod named_plane;
pub mod object;
pub mod part;
pub mod plane;
pub mod plane_objects;
pub mod probe;
pub mod query;
pub mod ragdoll;
pub mod snapshot;
pub mod start_plane;
pub mod static_shapes;

use std::rc::Rc;

use client_sdk::Client;
use mlua::{Function, Lua, Table, Value};

use crate::props::{Props, Target};

/// The modules `import` knows, in the order error messages list them.
pub const MODULES: [&str; 5] = [
    "PhysicsService",
    "Renderable",
    "Primitives",
    "GUI",
    "DynMesh",
];

/// Methods of the types whose `__index` is ours alone (see [`index`]).
pub struct MethodTables {
    /// BasePart's methods.
    pub part: Table,
    /// PhysicsObject's methods.
    pub object: Table,
}

/// The method tables [`modules`] registered in `lua`.
pub fn method_tables(lua: &Lua) -> Rc<MethodTables> {
    lua.app_data_ref::<Rc<MethodTables>>()
        .expect("lua_client::install registers the method tables")
        .clone()
}

/// Registers the API's state in `lua` (talking to the daemon through `client`) and returns
/// the modules by name.
pub fn modules(lua: &Lua, client: Client) -> mlua::Result<Table> {
    lua.set_app_data(Rc::new(plane::Context::new(client)));
    lua.set_app_data(Rc::new(MethodTables {
        part: part::methods(lua)?,
        object: object::methods(lua)?,
    }));
    part::pose_index::install(lua)?;
    let modules = lua.create_table()?;
    modules.set("PhysicsService", plane::module(lua)?)?;
    modules.set("Renderable", part::module(lua)?)?;
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

/// `__index` of a type whose methods live in a table consulted after its properties: with
/// no mlua-registered methods, mlua installs this `__index` as is, sparing every property
/// read a Lua-side method lookup.
pub fn index<T: Target>(
    lua: &Lua,
    props: &Props<T>,
    methods: fn(&MethodTables) -> &Table,
    target: &T,
    key: Value,
) -> mlua::Result<Value> {
    match props.row(&key) {
        Some(row) => props.read(lua, target, row),
        None => methods(&method_tables(lua))
            .raw_get::<Option<Function>>(key.clone())?
            .map(Value::Function)
            .ok_or_else(|| props.unknown(&key)),
    }
}

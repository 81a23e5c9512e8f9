//! The method tables of the types whose `__index` is ours alone (BasePart, PhysicsObject):
//! properties first, then methods, without mlua's own method lookup.

use std::rc::Rc;

use mlua::{Function, Lua, Table, Value};

use crate::props::{Props, Target};

/// Methods of the types whose `__index` is ours alone (see [`index`]).
pub struct MethodTables {
    /// BasePart's methods.
    pub part: Table,
    /// PhysicsObject's methods.
    pub object: Table,
}

/// The method tables [`super::modules`] registered in `lua`.
pub fn method_tables(lua: &Lua) -> Rc<MethodTables> {
    lua.app_data_ref::<Rc<MethodTables>>()
        .expect("lua_client::install registers the method tables")
        .clone()
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

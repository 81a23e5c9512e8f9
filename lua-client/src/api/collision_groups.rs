//! Collision groups, with Roblox's `PhysicsService` names: `RegisterCollisionGroup`,
//! `UnregisterCollisionGroup`, `RenameCollisionGroup`, `IsCollisionGroupRegistered`,
//! `CollisionGroupSetCollidable`, `CollisionGroupsAreCollidable`,
//! `GetRegisteredCollisionGroups`, `GetMaxCollisionGroups`. Callable with `:` or `.`.
//! The table belongs to the script's connection and applies to every plane it creates.

use mlua::{Lua, MultiValue, Table, Value};

use super::plane::context::context;
use crate::values::{expected, sdk_error};

/// The arguments without the module itself (`PhysicsService:F(...)` passes it first; a
/// group name is never a table).
fn args(all: MultiValue) -> Vec<Value> {
    let mut v: Vec<Value> = all.into_iter().collect();
    if matches!(v.first(), Some(Value::Table(_))) {
        v.remove(0);
    }
    v
}

fn string_arg(what: &str, v: &[Value], i: usize, name: &str) -> mlua::Result<String> {
    match v.get(i) {
        Some(Value::String(s)) => Ok(s.to_str()?.to_string()),
        other => Err(expected(
            &format!("{what} {name}"),
            "a string",
            other.unwrap_or(&Value::Nil),
        )),
    }
}

fn bool_arg(what: &str, v: &[Value], i: usize, name: &str) -> mlua::Result<bool> {
    match v.get(i) {
        Some(Value::Boolean(b)) => Ok(*b),
        other => Err(expected(
            &format!("{what} {name}"),
            "a boolean",
            other.unwrap_or(&Value::Nil),
        )),
    }
}

/// Adds the collision-group functions to the `PhysicsService` module.
pub fn install(lua: &Lua, m: &Table) -> mlua::Result<()> {
    m.set(
        "RegisterCollisionGroup",
        lua.create_function(|lua, all: MultiValue| {
            const W: &str = "PhysicsService:RegisterCollisionGroup";
            let v = args(all);
            let name = string_arg(W, &v, 0, "name")?;
            context(lua)
                .client
                .register_collision_group(&name)
                .map_err(|e| sdk_error(W, e))
        })?,
    )?;
    m.set(
        "UnregisterCollisionGroup",
        lua.create_function(|lua, all: MultiValue| {
            const W: &str = "PhysicsService:UnregisterCollisionGroup";
            let v = args(all);
            let name = string_arg(W, &v, 0, "name")?;
            let ctx = context(lua);
            ctx.client
                .unregister_collision_group(&name)
                .map_err(|e| sdk_error(W, e))?;
            ctx.group_renamed(&name, client_sdk::DEFAULT_GROUP);
            Ok(())
        })?,
    )?;
    m.set(
        "RenameCollisionGroup",
        lua.create_function(|lua, all: MultiValue| {
            const W: &str = "PhysicsService:RenameCollisionGroup";
            let v = args(all);
            let from = string_arg(W, &v, 0, "from")?;
            let to = string_arg(W, &v, 1, "to")?;
            let ctx = context(lua);
            ctx.client
                .rename_collision_group(&from, &to)
                .map_err(|e| sdk_error(W, e))?;
            ctx.group_renamed(&from, &to);
            Ok(())
        })?,
    )?;
    m.set(
        "IsCollisionGroupRegistered",
        lua.create_function(|lua, all: MultiValue| {
            const W: &str = "PhysicsService:IsCollisionGroupRegistered";
            let v = args(all);
            let name = string_arg(W, &v, 0, "name")?;
            Ok(context(lua).client.is_collision_group_registered(&name))
        })?,
    )?;
    m.set(
        "CollisionGroupSetCollidable",
        lua.create_function(|lua, all: MultiValue| {
            const W: &str = "PhysicsService:CollisionGroupSetCollidable";
            let v = args(all);
            let a = string_arg(W, &v, 0, "group1")?;
            let b = string_arg(W, &v, 1, "group2")?;
            let on = bool_arg(W, &v, 2, "collidable")?;
            context(lua)
                .client
                .collision_group_set_collidable(&a, &b, on)
                .map_err(|e| sdk_error(W, e))
        })?,
    )?;
    m.set(
        "CollisionGroupsAreCollidable",
        lua.create_function(|lua, all: MultiValue| {
            const W: &str = "PhysicsService:CollisionGroupsAreCollidable";
            let v = args(all);
            let a = string_arg(W, &v, 0, "group1")?;
            let b = string_arg(W, &v, 1, "group2")?;
            context(lua)
                .client
                .collision_groups_are_collidable(&a, &b)
                .map_err(|e| sdk_error(W, e))
        })?,
    )?;
    m.set(
        "GetRegisteredCollisionGroups",
        lua.create_function(|lua, _: MultiValue| {
            let list = lua.create_table()?;
            for (i, g) in context(lua)
                .client
                .registered_collision_groups()
                .into_iter()
                .enumerate()
            {
                let t = lua.create_table()?;
                t.set("name", g.name)?;
                t.set("id", g.id)?;
                t.set("mask", g.mask)?;
                list.raw_set(i + 1, t)?;
            }
            Ok(list)
        })?,
    )?;
    m.set(
        "GetMaxCollisionGroups",
        lua.create_function(|lua, _: MultiValue| Ok(context(lua).client.max_collision_groups()))?,
    )?;
    Ok(())
}

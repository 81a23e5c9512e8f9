//! Contact manifolds in Luau: `contact.Points` (up to four, each `{Position, Normal, Depth,
//! Impulse}`) in the contact table `Touched` hands its handlers, and
//! `PhysicsObject:GetContacts()`, every part the object touches now with the same table.
//! Normals point from the other part's surface toward the part they are reported to, as
//! `Touched`'s `contact.Normal` does.

use client_sdk::{ContactPoint, Vec3};
use mlua::{Lua, Table, Value};

use client_sdk::Handle;

use super::map::map_value;
use super::object::state::PhysicsObject;
use super::part::part_ud;
use super::plane::state::PlaneState;
use crate::values::{expected, lua_number, new_vector, sdk_error};

fn neg(v: Vec3) -> Vec3 {
    v.map(|c| -c)
}

/// `contact.Points`: the points as an array of `{Position, Normal, Depth, Impulse}`;
/// `flip` turns the normals around (the wire's point from the first object toward the
/// second).
pub fn points_table(lua: &Lua, points: &[ContactPoint], flip: bool) -> mlua::Result<Table> {
    let list = lua.create_table_with_capacity(points.len(), 0)?;
    for p in points {
        let t = lua.create_table_with_capacity(0, 4)?;
        t.set("Position", new_vector(p.position))?;
        t.set(
            "Normal",
            new_vector(if flip { neg(p.normal) } else { p.normal }),
        )?;
        t.set("Depth", lua_number(p.depth))?;
        t.set("Impulse", lua_number(p.impulse))?;
        list.push(t)?;
    }
    Ok(list)
}

/// `PhysicsObject:GetContacts()`: an array with one table per object it touches now,
/// `{Part, Position, Normal, Impulse, Points}` (`Part` nil for a body that is no part of
/// this script; a Map for a map it loaded).
pub fn get_contacts(lua: &Lua, this: Value) -> mlua::Result<Table> {
    let what = "PhysicsObject:GetContacts";
    let o = match &this {
        Value::UserData(ud) => ud.borrow::<PhysicsObject>().ok(),
        _ => None,
    }
    .ok_or_else(|| expected(what, "a PhysicsObject as self (call it with ':')", &this))?;
    let list = o.live(what)?.contacts().map_err(|e| sdk_error(what, e))?;
    let plane = o.body.plane.upgrade();
    let out = lua.create_table_with_capacity(list.len(), 0)?;
    for c in &list {
        let t = lua.create_table_with_capacity(0, 5)?;
        // The part the script holds (one value per part), or the Map it touches.
        let part = match &plane {
            Some(plane) => plane.body_value(lua, c.other)?,
            None => Value::Nil,
        };
        t.set("Part", part)?;
        t.set("Position", new_vector(c.position))?;
        // The wire's normal points from this object toward the other.
        t.set("Normal", new_vector(neg(c.normal)))?;
        t.set("Impulse", lua_number(c.impulse))?;
        t.set("Points", points_table(lua, &c.points, true)?)?;
        out.push(t)?;
    }
    Ok(out)
}

/// The script's value of body `handle` of `plane`: the BasePart it holds for it (one value
/// per part), the Map it loaded, or nil.
pub(crate) fn body_value(lua: &Lua, plane: &PlaneState, handle: Handle) -> mlua::Result<Value> {
    Ok(match plane.part_of(handle) {
        Some(p) => Value::UserData(part_ud(lua, &p)?),
        None => map_value(lua, plane, handle)?.unwrap_or(Value::Nil),
    })
}

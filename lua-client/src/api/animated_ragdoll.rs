//! Skeleton-driven hitboxes: a ragdoll whose bones follow an animation instead of falling.
//! `ragdoll.Animated = true` anchors every bone (a bone then stays where its CFrame is put,
//! pushed by nothing, its joints idle); `ragdoll:SetBoneCFrame(name, cframe)` poses one bone,
//! each frame as the animation plays. Rays and sweeps see a posed bone at once, and a hit
//! on a bone names it (`hit.Bone`). `ragdoll.Animated = false` hands the bones back to the
//! simulation from the pose they are in (a character dies and falls as a ragdoll).

use std::cell::Cell;
use std::rc::Rc;

use mlua::{AnyUserData, Lua, ObjectLike, Table, Value};

use crate::values::{describe, expected, CFrame};

/// The bone called `name` of the ragdoll's `Bones` table, or an error for `what` listing
/// the bones.
fn bone(what: &str, bones: &Table, name: &Value) -> mlua::Result<AnyUserData> {
    if let Value::String(_) = name {
        if let Value::UserData(ud) = bones.raw_get::<Value>(name.clone())? {
            return Ok(ud);
        }
    }
    let mut names: Vec<String> = bones
        .pairs::<String, Value>()
        .filter_map(|p| p.ok().map(|(k, _)| k))
        .collect();
    names.sort();
    Err(mlua::Error::runtime(format!(
        "{what}: no bone called {} (the bones: {})",
        describe(name),
        names.join(", ")
    )))
}

/// Gives the ragdoll table `doll` (with its `Bones`) its `Animated` property and
/// `SetBoneCFrame` method.
pub fn install(lua: &Lua, doll: &Table) -> mlua::Result<()> {
    let animated = Rc::new(Cell::new(false));
    let meta = lua.create_table()?;
    let on = animated.clone();
    meta.set(
        "__index",
        lua.create_function(move |_, (_, key): (Table, Value)| {
            Ok(match &key {
                Value::String(s) if &*s.as_bytes() == b"Animated" => Value::Boolean(on.get()),
                _ => Value::Nil,
            })
        })?,
    )?;
    let on = animated.clone();
    meta.set(
        "__newindex",
        lua.create_function(move |_, (this, key, value): (Table, Value, Value)| {
            match &key {
                Value::String(s) if &*s.as_bytes() == b"Animated" => {}
                _ => {
                    return Err(mlua::Error::runtime(format!(
                        "Ragdoll: {} is not a settable member (Animated is)",
                        describe(&key)
                    )))
                }
            }
            let Value::Boolean(want) = value else {
                return Err(expected("Ragdoll.Animated", "a boolean", &value));
            };
            let bones: Table = this.raw_get("Bones")?;
            for pair in bones.pairs::<Value, AnyUserData>() {
                let (_, o) = pair?;
                o.set("Anchored", want)?;
            }
            on.set(want);
            Ok(())
        })?,
    )?;
    doll.set(
        "SetBoneCFrame",
        lua.create_function(|_, (this, name, cframe): (Value, Value, Value)| {
            let what = "Ragdoll:SetBoneCFrame";
            let Value::Table(this) = &this else {
                return Err(expected(
                    what,
                    "a ragdoll as self (call it with ':')",
                    &this,
                ));
            };
            let bones: Table = this.raw_get("Bones")?;
            let o = bone(what, &bones, &name)?;
            let ok = CFrame::from_value(&cframe).is_some();
            if !ok {
                return Err(expected(&format!("{what} cframe"), "a CFrame", &cframe));
            }
            o.set("CFrame", cframe)
        })?,
    )?;
    doll.set_metatable(Some(meta))?;
    Ok(())
}

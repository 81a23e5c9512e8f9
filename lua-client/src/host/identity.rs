//! One Lua value per thing: every API that hands a script a part, an object, a controller,
//! a joint or a GUI object gives the userdata the script already holds for it (so `==`,
//! table keys and `rawequal` agree), not a fresh wrapper. The values live in a weak-valued
//! registry table keyed by the address of the host state they wrap (a light userdata, with a
//! small per-type tag added: the states are at least 8-aligned), so a value the script
//! dropped is collected as before and the next lookup makes a new one.

use mlua::{AnyUserData, LightUserData, Lua, Table, UserData};

const REGISTRY_KEY: &str = "lua_client.identity";

/// Per-type tags: two types may wrap states at the same address only if one wraps the other
/// (a part and its own state), never at the same tag.
pub(crate) mod tag {
    /// `BasePart` (its `PartState`).
    pub const PART: usize = 0;
    /// `PhysicsObject` (its body).
    pub const OBJECT: usize = 1;
    /// `PhysicsGuiObject` (its primitive, checked against the body's handle: a primitive
    /// added again is another object).
    pub const GUI_OBJECT: usize = 2;
    /// `Map` (its `MapState`).
    pub const MAP: usize = 3;
    /// `PhysicsPlane` (its `PlaneState`).
    pub const PLANE: usize = 4;
    /// `Signal` (its shared connections).
    pub const SIGNAL: usize = 5;
}

fn table(lua: &Lua) -> mlua::Result<Table> {
    if let Ok(t) = lua.named_registry_value::<Table>(REGISTRY_KEY) {
        return Ok(t);
    }
    let t = lua.create_table()?;
    let meta = lua.create_table()?;
    meta.set("__mode", "v")?;
    t.set_metatable(Some(meta))?;
    lua.set_named_registry_value(REGISTRY_KEY, &t)?;
    Ok(t)
}

/// The userdata for the state at `address` (type tag `tag`): the one already handed out if
/// the script still holds it, otherwise `make()`'s, remembered.
pub(crate) fn userdata<T: UserData + 'static>(
    lua: &Lua,
    address: *const (),
    tag: usize,
    make: impl FnOnce() -> T,
) -> mlua::Result<AnyUserData> {
    userdata_if(lua, address, tag, |_: &T| true, make)
}

/// [`userdata`], reusing a remembered value only if `same` says it still is the one.
pub(crate) fn userdata_if<T: UserData + 'static>(
    lua: &Lua,
    address: *const (),
    tag: usize,
    same: impl FnOnce(&T) -> bool,
    make: impl FnOnce() -> T,
) -> mlua::Result<AnyUserData> {
    let key = LightUserData((address as usize).wrapping_add(tag) as *mut std::ffi::c_void);
    let t = table(lua)?;
    if let Ok(Some(ud)) = t.raw_get::<Option<AnyUserData>>(key) {
        if ud.borrow::<T>().is_ok_and(|v| same(&v)) {
            return Ok(ud);
        }
    }
    let ud = lua.create_userdata(make())?;
    t.raw_set(key, &ud)?;
    Ok(ud)
}

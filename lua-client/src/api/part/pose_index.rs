//! `part.CFrame` at close to table speed: BasePart's `__index` is a Luau C function that
//! answers `CFrame` itself and hands every other key to the mlua `__index` behind it.
//!
//! A read through mlua costs its callback (~85 ns: argument references, the error and panic
//! guards) plus an mlua userdata for the value (~80 ns); a C `__index` costs ~20 ns and a
//! CFrame value ([`crate::values::cframe_ud`]) ~10 ns. The part behind a BasePart value is
//! found in a weak-keyed table (part value → its `PartState`, registered by `part_ud`), and
//! the value last handed out in a second one, reused while the pose is bit for bit the same
//! (so a second read in a tick, or a resting part, allocates nothing and reads `rawequal`).
//! The pose itself is the same Rust read as before (newest sample, this process's pending
//! writes on top); a panic there falls back to the mlua path, which reports it.

use std::ffi::c_void;
use std::os::raw::c_int;
use std::panic::AssertUnwindSafe;
use std::rc::Rc;

use mlua::{ffi, AnyUserData, Function, LightUserData, Lua, Table};

use super::{BasePart, PartShape, PartState};
use crate::values::cframe_ud;

/// What `register` adds to: part value → light userdata of its `PartState` (weak keys; the
/// C `__index`'s upvalue 2; upvalue 3 maps a part value to the CFrame value its last read
/// handed out).
pub(crate) struct PoseIndex {
    parts: Table,
}

fn weak_keyed(lua: &Lua) -> mlua::Result<Table> {
    let t = lua.create_table()?;
    let meta = lua.create_table()?;
    meta.raw_set("__mode", "k")?;
    t.set_metatable(Some(meta))?;
    Ok(t)
}

/// Puts the C `__index` in front of BasePart's mlua `__index` (once per Lua state).
pub(crate) fn install(lua: &Lua) -> mlua::Result<()> {
    if lua.app_data_ref::<Rc<PoseIndex>>().is_some() {
        return Ok(());
    }
    let parts = weak_keyed(lua)?;
    let values = weak_keyed(lua)?;
    let probe = lua.create_userdata(BasePart(Rc::new(PartState::new(PartShape::Cube))))?;
    // SAFETY: replaces the probe on top of mlua's stack by its metatable (every BasePart
    // value has it: mlua keeps one metatable per type).
    let meta: Table = unsafe {
        lua.exec_raw(probe, |state| {
            ffi::lua_getmetatable(state, -1);
            ffi::lua_remove(state, -2);
        })?
    };
    let fallback: Function = meta.raw_get("__index")?;
    // SAFETY: `index` reads upvalues 1 to 3 as pushed here.
    let fast = unsafe {
        cframe_ud::c_closure(
            lua,
            index,
            c"BasePart.__index",
            (fallback, parts.clone(), values),
        )?
    };
    meta.raw_set("__index", fast)?;
    lua.set_app_data(Rc::new(PoseIndex { parts }));
    Ok(())
}

/// Lets the C `__index` find `part` behind `ud` (its one BasePart value).
pub(crate) fn register(lua: &Lua, ud: &AnyUserData, part: &Rc<PartState>) -> mlua::Result<()> {
    let Some(ix) = lua.app_data_ref::<Rc<PoseIndex>>().map(|ix| ix.clone()) else {
        return Ok(());
    };
    ix.parts
        .raw_set(ud, LightUserData(Rc::as_ptr(part) as *mut c_void))
}

/// The C `__index` of BasePart: `part.CFrame` here, anything else (and a part value it does
/// not know) through the mlua `__index` in upvalue 1.
unsafe extern "C-unwind" fn index(state: *mut ffi::lua_State) -> c_int {
    if is_cframe_key(state) {
        ffi::lua_pushvalue(state, 1);
        ffi::lua_rawget(state, ffi::lua_upvalueindex(2));
        let part = ffi::lua_tolightuserdata(state, -1) as *const PartState;
        ffi::lua_pop(state, 1);
        if !part.is_null() {
            // SAFETY: the part value at index 1 holds an `Rc` of this `PartState`, and only
            // Rust code runs until the read returns.
            let read = std::panic::catch_unwind(AssertUnwindSafe(|| {
                let part = &*part;
                let cf = part.cframe();
                (cf, part.handed_out_same(&cf))
            }));
            if let Ok((cf, same)) = read {
                if same {
                    ffi::lua_pushvalue(state, 1);
                    if ffi::lua_rawget(state, ffi::lua_upvalueindex(3)) == ffi::LUA_TUSERDATA {
                        return 1;
                    }
                    ffi::lua_pop(state, 1);
                }
                // May raise a memory error: nothing of ours needs dropping from here on.
                cframe_ud::push(state, cf);
                ffi::lua_pushvalue(state, 1);
                ffi::lua_pushvalue(state, -2);
                ffi::lua_rawset(state, ffi::lua_upvalueindex(3));
                (*part).handed_out(cf);
                return 1;
            }
        }
    }
    ffi::lua_pushvalue(state, ffi::lua_upvalueindex(1));
    ffi::lua_insert(state, 1);
    ffi::lua_call(state, ffi::lua_gettop(state) - 1, 1);
    1
}

/// Whether the key at index 2 is the string `"CFrame"` (a number is not converted).
unsafe fn is_cframe_key(state: *mut ffi::lua_State) -> bool {
    if ffi::lua_type(state, 2) != ffi::LUA_TSTRING {
        return false;
    }
    let mut len = 0usize;
    let s = ffi::lua_tolstring(state, 2, &mut len) as *const u8;
    len == 6 && std::slice::from_raw_parts(s, len) == b"CFrame"
}

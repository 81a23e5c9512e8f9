//! `part.CFrame` at close to table speed: BasePart's `__index` is a Luau C function that
//! answers `CFrame` itself and hands every other key to the mlua `__index` behind it.
//!
//! A read through mlua costs its callback (~85 ns: argument references, the error and panic
//! guards) plus an mlua userdata for the value (~80 ns); a C `__index` costs ~20 ns and a
//! CFrame value ([`crate::values::cframe_ud`]) ~10 ns. The part behind a BasePart value is
//! found by the value's address in a Rust map ([`PoseIndex`]: every BasePart value is
//! registered there when `part_ud` makes it), and the value last handed out is kept in an
//! array table at the part's slot, reused while the pose is bit for bit the same (so a
//! second read in a tick, or a resting part, allocates nothing and reads `rawequal`).
//! Weak-keyed Luau tables did both before: two userdata-keyed lookups a read (~25 ns each,
//! more once the tables outgrow the cache) and two tables for the collector to clear every
//! cycle. The pose itself is the same Rust read as before (newest sample, this process's
//! pending writes on top); a panic there falls back to the mlua path, which reports it.

use std::cell::{Cell, RefCell};
use std::ffi::c_void;
use std::os::raw::c_int;
use std::panic::AssertUnwindSafe;
use std::rc::{Rc, Weak};

use mlua::{ffi, AnyUserData, Function, LightUserData, Lua, Table};

use super::state::{BasePart, PartShape, PartState};
use crate::values::cframe_ud;

/// One registered BasePart value: its part and the slot of the array table (the C
/// `__index`'s upvalue 2) holding the CFrame value its last read handed out.
struct Entry {
    part: Weak<PartState>,
    slot: c_int,
}

/// BasePart value address → its part (see the module doc). One per Lua state, in its app
/// data; the C `__index` reaches it through upvalue 3.
pub(crate) struct PoseIndex {
    parts: RefCell<hashbrown::HashMap<usize, Entry>>,
    /// The array table of handed-out values (by slot).
    values: Table,
    /// Slots given back by entries removed (their value cleared), and the next new one.
    free: RefCell<Vec<c_int>>,
    next: Cell<c_int>,
    /// The map's size that makes the next `register` drop the entries of dropped parts.
    sweep_at: Cell<usize>,
}

/// Fewest entries before dropped parts' entries are swept (then twice the entries kept).
const SWEEP_FROM: usize = 64;

/// Puts the C `__index` in front of BasePart's mlua `__index` (once per Lua state).
pub(crate) fn install(lua: &Lua) -> mlua::Result<()> {
    if lua.app_data_ref::<Rc<PoseIndex>>().is_some() {
        return Ok(());
    }
    let values = lua.create_table()?;
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
    let ix = Rc::new(PoseIndex {
        parts: RefCell::new(hashbrown::HashMap::new()),
        values: values.clone(),
        free: RefCell::new(Vec::new()),
        next: Cell::new(1),
        sweep_at: Cell::new(SWEEP_FROM),
    });
    // The app data keeps `ix` (and so this address) for the Lua state's life.
    let at = LightUserData(Rc::as_ptr(&ix) as *mut c_void);
    // SAFETY: `index` reads upvalues 1 to 4 as pushed here.
    let fast = unsafe {
        cframe_ud::c_closure(
            lua,
            index,
            c"BasePart.__index",
            (fallback, values, at, meta.clone()),
        )?
    };
    meta.raw_set("__index", fast)?;
    lua.set_app_data(ix);
    Ok(())
}

/// Lets the C `__index` find `part` behind `ud` (its one BasePart value, just made).
pub(crate) fn register(lua: &Lua, ud: &AnyUserData, part: &Rc<PartState>) -> mlua::Result<()> {
    let Some(ix) = lua.app_data_ref::<Rc<PoseIndex>>().map(|ix| ix.clone()) else {
        return Ok(());
    };
    let key = ud.to_pointer() as usize;
    let ours = |e: &Entry| std::ptr::eq(e.part.as_ptr(), Rc::as_ptr(part));
    let mut parts = ix.parts.borrow_mut();
    let mut freed = Vec::new();
    // The part's earlier value (collected, or it would not be made again) gives its slot
    // over, with the value last handed out; an entry another value left at this address
    // (collected too) gives its slot back.
    let earlier = part.pose_key.replace(key);
    let mut slot = None;
    if earlier != 0 && earlier != key && parts.get(&earlier).is_some_and(ours) {
        slot = parts.remove(&earlier).map(|e| e.slot);
    }
    if let Some(e) = parts.remove(&key) {
        if slot.is_none() && ours(&e) {
            slot = Some(e.slot);
        } else {
            freed.push(e.slot);
        }
    }
    let slot = match slot.or_else(|| ix.free.borrow_mut().pop()) {
        Some(slot) => slot,
        None => {
            let slot = ix.next.get();
            ix.next.set(slot.checked_add(1).ok_or_else(|| {
                mlua::Error::runtime("more BasePart values than the pose index can hold")
            })?);
            slot
        }
    };
    parts.insert(
        key,
        Entry {
            part: Rc::downgrade(part),
            slot,
        },
    );
    // Parts dropped since the last sweep give their slots back.
    if parts.len() >= ix.sweep_at.get() {
        parts.retain(|_, e| {
            let alive = e.part.strong_count() > 0;
            if !alive {
                freed.push(e.slot);
            }
            alive
        });
        ix.sweep_at.set((parts.len() * 2).max(SWEEP_FROM));
    }
    drop(parts);
    for &slot in &freed {
        ix.values.raw_set(slot, mlua::Value::Nil)?;
    }
    ix.free.borrow_mut().extend(freed);
    Ok(())
}

/// The C `__index` of BasePart: `part.CFrame` here, anything else (and a value it does not
/// know) through the mlua `__index` in upvalue 1.
unsafe extern "C-unwind" fn index(state: *mut ffi::lua_State) -> c_int {
    if is_cframe_key(state) {
        if let Some((part, slot)) = registered(state) {
            // SAFETY: the BasePart value at index 1 holds an `Rc` of this `PartState`, and
            // only Rust code runs until the read returns.
            let read = std::panic::catch_unwind(AssertUnwindSafe(|| {
                let part = &*part;
                let cf = part.cframe();
                (cf, part.handed_out_same(&cf))
            }));
            if let Ok((cf, same)) = read {
                if same {
                    if ffi::lua_rawgeti(state, ffi::lua_upvalueindex(2), slot.into())
                        == ffi::LUA_TUSERDATA
                    {
                        return 1;
                    }
                    ffi::lua_pop(state, 1);
                }
                // May raise a memory error: nothing of ours needs dropping from here on.
                cframe_ud::push(state, cf);
                ffi::lua_pushvalue(state, -1);
                ffi::lua_rawseti(state, ffi::lua_upvalueindex(2), slot.into());
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

/// The part and slot of the BasePart value at index 1, if it is one the map knows.
unsafe fn registered(state: *mut ffi::lua_State) -> Option<(*const PartState, c_int)> {
    // Only a BasePart value (BasePart's metatable, upvalue 4) is looked up: a script may
    // call this `__index` with any value, and an address alone may be a collected part's.
    if ffi::lua_getmetatable(state, 1) == 0 {
        return None;
    }
    let is_part = ffi::lua_rawequal(state, -1, ffi::lua_upvalueindex(4)) != 0;
    ffi::lua_pop(state, 1);
    if !is_part {
        return None;
    }
    let key = ffi::lua_touserdata(state, 1) as usize;
    let ix = ffi::lua_tolightuserdata(state, ffi::lua_upvalueindex(3)) as *const PoseIndex;
    // SAFETY: upvalue 3 is the state's `PoseIndex`, kept by its app data.
    let parts = (*ix).parts.try_borrow().ok()?;
    let e = parts.get(&key)?;
    // A live BasePart value at a registered address is that entry's (each is registered
    // when made), so its part is alive; the count is checked all the same.
    (e.part.strong_count() > 0).then_some((e.part.as_ptr(), e.slot))
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

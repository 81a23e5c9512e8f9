//! How a `CFrame` lives in Luau: a tagged userdata of its own, not an mlua `UserData`.
//!
//! A CFrame is 28 bytes (position, rotation quaternion) with nothing to drop, and reading a
//! part's pose makes one per moved part per tick, so its cost decides what `part.CFrame`
//! costs. An mlua userdata is made in ~80 ns (a boxed cell, a destructor the collector must
//! call, a reference slot for the handle); this one is `lua_newuserdatataggedwithmetatable`:
//! the bytes, tag [`TAG`] and the metatable Luau keeps for that tag, in ~10 ns, with no
//! destructor. Its `__index` is a C function too (components and `Position` without crossing
//! mlua), falling back to an mlua function for the rest of the members and the methods.
//!
//! A value that arrives as an mlua [`AnyUserData`] (an argument of any API function) is
//! recognised by the tag in Luau's userdata header (see [`cframe_of_userdata`]); scripts cannot
//! make a userdata of this tag (`newproxy` makes tag 0), so the tag is proof of the type.

use std::cell::RefCell;
use std::mem::size_of;
use std::os::raw::c_int;

use mlua::{ffi, AnyUserData, Function, Lua, Value};

use super::cframe::CFrame;

/// The Luau userdata tag of CFrame values (mlua uses 1 for destructed values and its own
/// destructor tag; 0 is `newproxy`'s).
pub const TAG: c_int = 64;

/// Bytes of a CFrame userdata.
const SIZE: usize = size_of::<CFrame>();

/// Luau's `Udata` header precedes the data: `tt, marked, memcat, tag` (one byte each), `len`
/// (int), `metatable` (pointer), then the data (VM/src/lobject.h). Offsets back from the data.
const TAG_OFFSET: usize = 13;
const LEN_OFFSET: usize = 12;

/// Pushes `cf` on `state`'s stack as a new CFrame value.
///
/// # Safety
/// `state` is a live Luau state with a free stack slot whose CFrame metatable is installed
/// ([`install`]); may raise a Lua memory error (call it where a Lua error may be raised).
pub unsafe fn push(state: *mut ffi::lua_State, cf: CFrame) {
    let p = ffi::lua_newuserdatataggedwithmetatable(state, SIZE, TAG) as *mut CFrame;
    p.write_unaligned(cf);
}

/// The CFrame at stack index `idx`, if the value there is one.
///
/// # Safety
/// `state` is a live Luau state and `idx` a valid index.
pub unsafe fn at(state: *mut ffi::lua_State, idx: c_int) -> Option<CFrame> {
    let p = ffi::lua_touserdatatagged(state, idx, TAG) as *const CFrame;
    (!p.is_null()).then(|| p.read_unaligned())
}

/// The tag and length Luau's header records for the userdata whose data starts at `data`.
///
/// # Safety
/// `data` is the data pointer of a live Luau userdata (`lua_topointer` of one).
unsafe fn header(data: *const u8) -> (u8, i32) {
    let tag = data.sub(TAG_OFFSET).read();
    let len = (data.sub(LEN_OFFSET) as *const i32).read_unaligned();
    (tag, len)
}

/// The CFrame `ud` holds, if it is a CFrame value.
pub fn cframe_of_userdata(ud: &AnyUserData) -> Option<CFrame> {
    let data = ud.to_pointer() as *const u8;
    if data.is_null() {
        return None;
    }
    // SAFETY: `ud` keeps the userdata alive; its header precedes the data in the same
    // allocation (checked against Luau's own accessors by `install`).
    unsafe {
        match header(data) {
            (tag, len) if c_int::from(tag) == TAG && len as usize == SIZE => {
                Some((data as *const CFrame).read_unaligned())
            }
            _ => None,
        }
    }
}

/// `__index` of CFrame values: `X`, `Y`, `Z` and `Position` here; anything else goes to the
/// mlua function in upvalue 1 (the other members, the methods, the error for a wrong key).
unsafe extern "C-unwind" fn index(state: *mut ffi::lua_State) -> c_int {
    if let Some(cf) = at(state, 1) {
        if ffi::lua_type(state, 2) == ffi::LUA_TSTRING {
            let mut len = 0usize;
            let s = ffi::lua_tolstring(state, 2, &mut len) as *const u8;
            match std::slice::from_raw_parts(s, len) {
                b"Position" => {
                    let [x, y, z] = cf.position;
                    ffi::lua_pushvector(state, x, y, z);
                    return 1;
                }
                b"X" => {
                    ffi::lua_pushnumber(state, f64::from(cf.position[0]));
                    return 1;
                }
                b"Y" => {
                    ffi::lua_pushnumber(state, f64::from(cf.position[1]));
                    return 1;
                }
                b"Z" => {
                    ffi::lua_pushnumber(state, f64::from(cf.position[2]));
                    return 1;
                }
                _ => {}
            }
        }
    }
    ffi::lua_pushvalue(state, ffi::lua_upvalueindex(1));
    ffi::lua_insert(state, 1);
    ffi::lua_call(state, ffi::lua_gettop(state) - 1, 1);
    1
}

/// A C closure of `f` with the values pushed by `upvalues` as its upvalues.
///
/// # Safety
/// `f` is a valid Luau C function reading at most that many upvalues.
pub unsafe fn c_closure(
    lua: &Lua,
    f: ffi::lua_CFunction,
    name: &'static std::ffi::CStr,
    upvalues: impl mlua::IntoLuaMulti,
) -> mlua::Result<Function> {
    let upvalues = upvalues.into_lua_multi(lua)?;
    let n = upvalues.len() as c_int;
    lua.exec_raw::<Function>(upvalues, |state| {
        ffi::lua_pushcclosurek(state, f, name.as_ptr(), n, None);
    })
}

/// Makes `metatable` (fields and metamethods already set, `__index` the mlua fallback) the one
/// Luau gives every CFrame value, with the C `__index` in front of that fallback, and checks
/// that [`cframe_of_userdata`] reads Luau's header as Luau does. Once per Lua state; a second
/// call does nothing.
pub fn install(lua: &Lua, metatable: &mlua::Table) -> mlua::Result<()> {
    // SAFETY: plain Luau API calls on mlua's state inside `exec_raw` (protected).
    let installed: bool = unsafe {
        lua.exec_raw((), |state| {
            ffi::lua_getuserdatametatable(state, TAG);
            let set = ffi::lua_type(state, -1) != ffi::LUA_TNIL;
            ffi::lua_pop(state, 1);
            ffi::lua_pushboolean(state, set as c_int);
        })?
    };
    if installed {
        return Ok(());
    }
    let fallback: Function = metatable.raw_get("__index")?;
    // SAFETY: `index` reads upvalue 1 only.
    let fast = unsafe { c_closure(lua, index, c"CFrame.__index", fallback)? };
    metatable.raw_set("__index", fast)?;
    metatable.set_readonly(true);
    // SAFETY: the metatable is on top of the stack when `lua_setuserdatametatable` pops it.
    unsafe {
        lua.exec_raw::<()>(metatable.clone(), |state| {
            ffi::lua_setuserdatametatable(state, TAG);
        })?;
    }
    check_header(lua)
}

/// Checks that the header Luau writes is where [`header`] reads it: for a CFrame, an mlua
/// userdata and a `newproxy` value the tag read back is Luau's `lua_userdatatag`. A Luau
/// update that moved the header would fail here, at startup, instead of misreading values.
fn check_header(lua: &Lua) -> mlua::Result<()> {
    let probes = [
        CFrame::IDENTITY.into_value(lua)?,
        Value::UserData(lua.create_any_userdata(())?),
        lua.load("newproxy(false)").eval::<Value>()?,
    ];
    for probe in probes {
        let Value::UserData(ud) = &probe else {
            continue;
        };
        // SAFETY: reads the probe's tag and length on mlua's stack, then pops it.
        let (tag, len): (c_int, c_int) = unsafe {
            lua.exec_raw(probe.clone(), |state| {
                let tag = ffi::lua_userdatatag(state, -1);
                let len = ffi::lua_objlen(state, -1) as c_int;
                ffi::lua_pop(state, 1);
                ffi::lua_pushinteger(state, tag as _);
                ffi::lua_pushinteger(state, len as _);
            })?
        };
        // SAFETY: `ud` is a live userdata.
        let (read_tag, read_len) = unsafe { header(ud.to_pointer() as *const u8) };
        if c_int::from(read_tag) != tag || read_len != len {
            return Err(mlua::Error::runtime(format!(
                "Luau's userdata header is not where this build reads it (tag {tag} read as \
                 {read_tag}, length {len} read as {read_len}): CFrame values cannot be told apart"
            )));
        }
    }
    Ok(())
}

impl CFrame {
    /// `self` as a Lua value (a new CFrame userdata).
    pub fn into_value(self, lua: &Lua) -> mlua::Result<Value> {
        // SAFETY: `push` needs one stack slot and the metatable, which `install` set up
        // before any CFrame is made (`Primitives`); `exec_raw` catches a memory error.
        unsafe { lua.exec_raw::<Value>((), |state| push(state, self)) }
    }
}

impl mlua::IntoLua for CFrame {
    fn into_lua(self, lua: &Lua) -> mlua::Result<Value> {
        self.into_value(lua)
    }
}

/// The Lua value of a CFrame that something (a part, an object) hands out again and again:
/// its last value, returned as long as the pose is bit for bit the same, so reading the pose
/// of a body that did not move since the last read (a second read in the same tick, a body
/// at rest) allocates nothing. CFrame values are immutable, so a script cannot tell a
/// returned value from a fresh equal one (except by `rawequal`).
#[derive(Default)]
pub struct CFrameCache(RefCell<Option<(CFrame, AnyUserData)>>);

impl CFrameCache {
    /// `cf` as a Lua value: the cached one when it is the same pose, else a new one (which
    /// the cache keeps).
    pub fn value(&self, lua: &Lua, cf: CFrame) -> mlua::Result<Value> {
        if let Some(ud) = self.cached(&cf) {
            return Ok(Value::UserData(ud));
        }
        let Value::UserData(ud) = cf.into_value(lua)? else {
            unreachable!("a CFrame is a userdata")
        };
        *self.0.borrow_mut() = Some((cf, ud.clone()));
        Ok(Value::UserData(ud))
    }

    /// The value handed out last, if it holds `cf` bit for bit.
    pub fn cached(&self, cf: &CFrame) -> Option<AnyUserData> {
        match &*self.0.borrow() {
            Some((cached, ud)) if cached.same_bits(cf) => Some(ud.clone()),
            _ => None,
        }
    }
}

impl CFrame {
    /// The CFrame `value` holds, if it is one.
    pub fn from_value(value: &Value) -> Option<CFrame> {
        match value {
            Value::UserData(ud) => cframe_of_userdata(ud),
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lua() -> Lua {
        let lua = Lua::new();
        lua.globals()
            .set("Primitives", crate::values::module(&lua).unwrap())
            .unwrap();
        lua
    }

    #[test]
    fn a_cframe_value_reads_back_and_nothing_else_reads_as_one() {
        let lua = lua();
        let cf: Value = lua
            .load("Primitives.CFrame.new(1, 2, 3, 0, 0.5, 0)")
            .eval()
            .unwrap();
        let Value::UserData(ud) = &cf else {
            panic!("a CFrame is a userdata: {cf:?}")
        };
        let read = cframe_of_userdata(ud).expect("reads as a CFrame");
        assert_eq!(read.position, [1.0, 2.0, 3.0]);
        assert!((read.rotation[1] - 0.25f32.sin()).abs() < 1e-6, "{read:?}");
        // A userdata of another kind, of the same size, or forged with the type's name.
        let others: [Value; 3] = [
            Value::UserData(lua.create_any_userdata([0f32; 7]).unwrap()),
            lua.load("newproxy(false)").eval().unwrap(),
            lua.load("local p = newproxy(true); getmetatable(p).__type = 'CFrame'; return p")
                .eval()
                .unwrap(),
        ];
        for other in others {
            let Value::UserData(ud) = &other else {
                panic!("{other:?}")
            };
            assert_eq!(cframe_of_userdata(ud), None, "{other:?}");
            assert!(CFrame::from_value(&other).is_none());
        }
    }

    #[test]
    fn the_header_check_passes_and_installing_twice_is_harmless() {
        let lua = lua();
        check_header(&lua).unwrap();
        crate::values::module(&lua).unwrap();
        let x: f64 = lua
            .load("return Primitives.CFrame.new(4, 5, 6).X")
            .eval()
            .unwrap();
        assert_eq!(x, 4.0);
    }

    #[test]
    fn the_c_index_answers_components_and_falls_back_for_the_rest() {
        let lua = lua();
        let (p, x, look, err): (Value, f64, Value, String) = lua
            .load(
                r#"
                local cf = Primitives.CFrame.new(7, 8, 9)
                local ok, e = pcall(function() return cf.Nope end)
                return cf.Position, cf.Z, cf.LookVector, tostring(e)
                "#,
            )
            .eval()
            .unwrap();
        assert_eq!(crate::values::vector(&p), Some([7.0, 8.0, 9.0]));
        assert_eq!(x, 9.0);
        assert_eq!(crate::values::vector(&look), Some([0.0, 0.0, -1.0]));
        assert!(
            err.contains("CFrame has no member string \"Nope\""),
            "{err}"
        );
    }
}

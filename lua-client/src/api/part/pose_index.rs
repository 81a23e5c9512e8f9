//! `part.CFrame` at close to table speed: BasePart's `__index` is a Luau C function that
//! answers `CFrame` itself and hands every other key to the mlua `__index` behind it.
//!
//! A read through mlua costs its callback (~85 ns: argument references, the error and panic
//! guards) plus an mlua userdata for the value (~80 ns); a C `__index` costs ~20 ns and a
//! CFrame value ([`crate::values::cframe_ud`]) ~10 ns. The BasePart value is found by its
//! address in a Rust map ([`PoseIndex`]: every BasePart value is registered there when
//! `part_ud` makes it) giving its slot; the slot's entry in the [`PoseTable`] holds the SDK
//! object the pose is read from (so a read does not visit the part: see `pose_table`), and
//! the value last handed out is kept in an array table at the same slot, reused while the
//! pose is bit for bit the same (so a second read in a tick, or a resting part, allocates
//! nothing and reads `rawequal`). The pose itself is the same SDK read as before (newest
//! sample, this process's pending writes on top); a part without a body is read from the
//! part; a panic there falls back to the mlua path, which reports it.

use std::cell::{Cell, RefCell};
use std::ffi::c_void;
use std::hash::{BuildHasher, Hasher};
use std::os::raw::c_int;
use std::panic::AssertUnwindSafe;
use std::rc::{Rc, Weak};

use mlua::{ffi, AnyUserData, Function, LightUserData, Lua, Table};

use super::pose_table::PoseTable;
use super::state::{BasePart, PartShape, PartState};
use crate::values::{cframe_ud, CFrame};

/// One registered BasePart value: its part and its slot (of the array table, the C
/// `__index`'s upvalue 2, holding the CFrame value its last read handed out, and of the
/// [`PoseTable`]).
struct Entry {
    part: Weak<PartState>,
    slot: c_int,
}

/// BasePart value address → its part (see the module doc). One per Lua state, in its app
/// data; the C `__index` reaches it through upvalue 3.
pub(crate) struct PoseIndex {
    parts: RefCell<hashbrown::HashMap<usize, Entry, AddressHash>>,
    /// The array table of handed-out values (by slot).
    values: Table,
    /// What reads need of each slot's part.
    table: Rc<PoseTable>,
    /// Slots given back by entries removed (their value cleared), and the next new one.
    free: RefCell<Vec<c_int>>,
    next: Cell<c_int>,
    /// The map's size that makes the next `register` drop the entries of dropped parts.
    sweep_at: Cell<usize>,
}

/// Hashes a BasePart value's address so that values made one after another (Luau gives a
/// size of objects consecutive addresses of the same pages) land in neighbouring buckets: a
/// loop over parts reads the map in memory order, which the processor prefetches, where a
/// scrambling hash made each read wait for one random cache line (the most of a first read's
/// time in `perf annotate`). The bucket is the address / 16; the top 7 bits, the map's tag
/// byte, come from a multiplicative (Fibonacci) mix of the address / 8 so that the values
/// sharing a probe group have different tags.
#[derive(Clone, Copy, Default)]
pub(crate) struct AddressHash;

/// The hasher of [`AddressHash`].
pub(crate) struct AddressHasher(u64);

impl BuildHasher for AddressHash {
    type Hasher = AddressHasher;

    fn build_hasher(&self) -> AddressHasher {
        AddressHasher(0)
    }
}

impl Hasher for AddressHasher {
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 = self.0.rotate_left(8) ^ u64::from(b);
        }
    }

    fn write_usize(&mut self, n: usize) {
        self.0 = n as u64;
    }

    fn finish(&self) -> u64 {
        let a = self.0;
        (a >> 4) ^ ((a >> 3).wrapping_mul(0x9E37_79B9_7F4A_7C15) & !(u64::MAX >> 7))
    }
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
        parts: RefCell::new(hashbrown::HashMap::with_hasher(AddressHash)),
        values: values.clone(),
        table: Rc::new(PoseTable::default()),
        free: RefCell::new(Vec::new()),
        next: Cell::new(1),
        sweep_at: Cell::new(SWEEP_FROM),
    });
    // The app data keeps `ix` (and so this address) for the Lua state's life.
    let at = LightUserData(Rc::as_ptr(&ix) as *mut c_void);
    let key = lua.create_string("CFrame")?;
    // SAFETY: `index` reads upvalues 1 to 5 as pushed here.
    let fast = unsafe {
        cframe_ud::c_closure(
            lua,
            index,
            c"BasePart.__index",
            (fallback, values, at, meta.clone(), key),
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
            // A part still alive (held elsewhere) no longer has this slot.
            if let Some(other) = e.part.upgrade() {
                if other.pose_slot() == Some(e.slot as usize) {
                    other.set_pose_slot(None);
                }
            }
        }
    }
    // A slot taken over keeps its entry (the value handed out is still at that slot).
    let fresh = slot.is_none();
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
        ix.table.clear(slot as usize);
    }
    ix.free.borrow_mut().extend(freed);
    if fresh {
        ix.table.clear(slot as usize);
    }
    part.set_pose_slot(Some((ix.table.clone(), slot as usize)));
    Ok(())
}

/// The C `__index` of BasePart: `part.CFrame` here, anything else (and a value it does not
/// know) through the mlua `__index` in upvalue 1.
unsafe extern "C-unwind" fn index(state: *mut ffi::lua_State) -> c_int {
    // Upvalue 5 is the interned string "CFrame": one pointer comparison.
    if ffi::lua_rawequal(state, 2, ffi::lua_upvalueindex(5)) != 0 {
        if let Some((key, slot)) = registered(state) {
            let ix = index_of(state);
            // Only Rust code runs until the read returns.
            let read = std::panic::catch_unwind(AssertUnwindSafe(|| read(ix, key, slot)));
            if let Ok(Some((cf, same))) = read {
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
                ix.table.get(slot as usize, |s| s.last = Some(cf));
                return 1;
            }
        }
    }
    ffi::lua_pushvalue(state, ffi::lua_upvalueindex(1));
    ffi::lua_insert(state, 1);
    ffi::lua_call(state, ffi::lua_gettop(state) - 1, 1);
    1
}

/// The state's `PoseIndex` (upvalue 3 of the C `__index`).
///
/// # Safety
/// Called from that `__index`; the app data keeps the index for the Lua state's life.
unsafe fn index_of<'a>(state: *mut ffi::lua_State) -> &'a PoseIndex {
    &*(ffi::lua_tolightuserdata(state, ffi::lua_upvalueindex(3)) as *const PoseIndex)
}

/// The pose of the part at `slot` and whether the value last handed out there holds it bit
/// for bit: from the slot's SDK object while the part has a body (the part is not visited),
/// else from the part. `None` when the slot or its part is not there (the mlua path answers).
fn read(ix: &PoseIndex, key: usize, slot: c_int) -> Option<(CFrame, bool)> {
    let from_source = ix.table.get(slot as usize, |s| {
        let cf = CFrame::from_pose(s.source.as_ref()?.pose().ok()?);
        Some((cf, s.last.is_some_and(|l| l.same_bits(&cf))))
    })?;
    if from_source.is_some() {
        return from_source;
    }
    // No body (or its read failed): the part's own answer, as the mlua path gives it.
    let part = ix.part_at(key)?;
    let cf = part.cframe();
    let last = ix.table.get(slot as usize, |s| s.last)?;
    Some((cf, last.is_some_and(|l| l.same_bits(&cf))))
}

impl PoseIndex {
    /// The live part of the BasePart value at address `key`.
    fn part_at(&self, key: usize) -> Option<Rc<PartState>> {
        let parts = self.parts.try_borrow().ok()?;
        parts.get(&key).and_then(|e| e.part.upgrade())
    }
}

/// The address and slot of the BasePart value at index 1, if it is one the map knows.
unsafe fn registered(state: *mut ffi::lua_State) -> Option<(usize, c_int)> {
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
    // A live BasePart value at a registered address is that entry's (each is registered
    // when made), so the slot is its part's.
    let parts = index_of(state).parts.try_borrow().ok()?;
    parts.get(&key).map(|e| (key, e.slot))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn hash(address: usize) -> u64 {
        AddressHash.hash_one(address)
    }

    #[test]
    fn neighbouring_addresses_land_in_neighbouring_buckets_with_distinct_tags() {
        // Values 48 bytes apart (a Luau size class): buckets 3 apart, in address order.
        let base = 0x7f12_3456_7000usize;
        let mask = (1u64 << 11) - 1; // a map of 2048 buckets
        let hashes: Vec<u64> = (0..64).map(|i| hash(base + 48 * i)).collect();
        for (i, w) in hashes.windows(2).enumerate() {
            assert_eq!(
                (w[1] & mask).wrapping_sub(w[0] & mask) & mask,
                3,
                "value {i}"
            );
        }
        // Any 6 neighbours (as many as share a 16-bucket probe group at the widest spacing
        // that packs them) have 6 different tags, for every 8-aligned spacing up to 256.
        for stride in (8..=256).step_by(8) {
            let tags: Vec<u64> = (0..64).map(|i| hash(base + stride * i) >> 57).collect();
            for (i, w) in tags.windows(6).enumerate() {
                let distinct: std::collections::BTreeSet<_> = w.iter().collect();
                assert_eq!(distinct.len(), 6, "spacing {stride}, values {i}..: {w:?}");
            }
        }
    }

    #[test]
    fn the_map_finds_every_address_it_holds() {
        let mut map = hashbrown::HashMap::with_hasher(AddressHash);
        let base = 0x5555_0000_1000usize;
        for i in 0..5000 {
            map.insert(base + 64 * i, i);
        }
        for i in 0..5000 {
            assert_eq!(map.get(&(base + 64 * i)), Some(&i));
            assert_eq!(map.get(&(base + 64 * i + 8)), None);
        }
    }
}

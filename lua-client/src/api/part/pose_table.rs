//! What `part.CFrame` reads, kept where the read finds it without visiting the part: one
//! entry per registered BasePart value (by its pose index slot), in one dense array.
//!
//! A first read after a tick touches memory nothing else in the frame did; each pointer it
//! follows is a cache miss (~60 ns on a busy machine). Following the value to its part, the
//! part to its [`super::state::PartObject`] and that to the SDK object cost three of them a
//! read. The entry holds a clone of the SDK object (the part's link pushes it here when it
//! changes: [`PoseTable::set_source`]) and the pose last handed out, so a read visits the
//! entry, the sample's slot in shared memory and, for a new pose, the new value only.

use std::cell::RefCell;

use client_sdk::Object;

use crate::values::CFrame;

/// One registered BasePart value's read state.
#[derive(Default)]
pub(crate) struct PoseSlot {
    /// The SDK object of the part's body while a plane simulates it (`None`: read the part).
    pub(crate) source: Option<Object>,
    /// The pose of the value the last read handed out (kept in the index's value table at
    /// the same slot).
    pub(crate) last: Option<CFrame>,
}

/// The entries of one Lua state's BasePart values, by pose index slot (1-based, as the
/// value table's; entry 0 unused).
#[derive(Default)]
pub(crate) struct PoseTable {
    slots: RefCell<Vec<PoseSlot>>,
}

impl PoseTable {
    /// Runs `f` on the entry of `slot`, made if needed; `None` while the table is borrowed
    /// (a read in progress: the caller then leaves the entry as it is).
    pub(crate) fn with<R>(&self, slot: usize, f: impl FnOnce(&mut PoseSlot) -> R) -> Option<R> {
        let mut slots = self.slots.try_borrow_mut().ok()?;
        if slots.len() <= slot {
            slots.resize_with(slot + 1, PoseSlot::default);
        }
        Some(f(&mut slots[slot]))
    }

    /// The part of `slot` is now read through `source` (its body's object, or `None`).
    pub(crate) fn set_source(&self, slot: usize, source: Option<Object>) {
        self.with(slot, |s| s.source = source);
    }

    /// `slot` no longer belongs to a part: nothing of it is kept.
    pub(crate) fn clear(&self, slot: usize) {
        self.with(slot, |s| *s = PoseSlot::default());
    }

    /// The entry of `slot` for the duration of `f` if it exists and the table is free.
    pub(crate) fn get<R>(&self, slot: usize, f: impl FnOnce(&mut PoseSlot) -> R) -> Option<R> {
        let mut slots = self.slots.try_borrow_mut().ok()?;
        slots.get_mut(slot).map(f)
    }
}

//! Stable, stale-proof handles: a table of slots, each with a generation that grows every
//! time the slot is reused. A handle `(slot, generation)` finds its value only while the
//! slot still holds that generation, so a handle to a removed value is an error, never
//! another value. Bodies, and later controllers, joints and GUI bodies, use it alike.
//!
//! A table made with [`SlotTable::tracked`] (a plane's bodies) also records which slots
//! changed ([`Dirty`]): [`SlotTable::insert`], [`SlotTable::get_mut`] and
//! [`SlotTable::remove`] mark their slot themselves, so an op that changes an object through
//! its handle cannot forget to; the publisher drains the marks. The engine's own passes
//! ([`SlotTable::at_mut`], [`SlotTable::iter_mut`]) do not mark. The marks no step has seen
//! yet are state (the next step's force pass lists their bodies): a snapshot of the table
//! carries them, and a table that replaces a plane's (restored, or a copy kept for Rewind)
//! brings them to the marks it takes over ([`SlotTable::take_marks_of`]).

use shm_layout::{CommandError, ErrorKind, Handle};

use super::dirty::Dirty;

#[derive(Clone, serde::Serialize, serde::Deserialize)]
struct Entry<T> {
    generation: u32,
    value: Option<T>,
}

/// Values addressed by generation-checked handles. Freed slots are reused (the published
/// arrays stay dense); `what` names the values in error messages ("object").
#[derive(Clone, serde::Serialize, serde::Deserialize)]
pub struct SlotTable<T> {
    /// Not part of a snapshot: a restored table takes it from the table it replaces.
    #[serde(skip)]
    what: &'static str,
    entries: Vec<Entry<T>>,
    free: Vec<u32>,
    live: u32,
    #[serde(skip)]
    max_slots: usize,
    /// Slots changed since the last publish, in a tracked table. Only the marks no step
    /// has seen yet are state (written as [`Dirty::unseen`]; an untracked table writes
    /// none): a copy or a decoded table takes the marks of the live table it replaces,
    /// its unseen ones with them ([`SlotTable::take_marks_of`]).
    #[serde(with = "unseen_marks")]
    marks: Option<Dirty>,
}

/// A table's marks on the wire: the unseen ones ([`Dirty::unseen`]); decoded, marks that
/// hold only those (`None` when there are none: a table that replaces a live one takes
/// the live one's marks).
mod unseen_marks {
    use serde::{Deserialize, Deserializer, Serialize, Serializer};

    use crate::backend::dirty::{Dirty, Unseen};

    pub fn serialize<S: Serializer>(marks: &Option<Dirty>, s: S) -> Result<S::Ok, S::Error> {
        match marks {
            Some(marks) => marks.unseen().serialize(s),
            None => Dirty::default().unseen().serialize(s),
        }
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Option<Dirty>, D::Error> {
        let unseen = Unseen::deserialize(d)?;
        Ok((unseen != Unseen::default()).then(|| Dirty::carrying(unseen)))
    }
}

impl<T> SlotTable<T> {
    /// An empty table of at most `max_slots` slots.
    pub fn new(what: &'static str, max_slots: usize) -> Self {
        SlotTable {
            what,
            entries: Vec::new(),
            free: Vec::new(),
            live: 0,
            max_slots,
            marks: None,
        }
    }

    /// An empty table of at most `max_slots` slots that marks the slots ops change.
    pub fn tracked(what: &'static str, max_slots: usize) -> Self {
        SlotTable {
            marks: Some(Dirty::default()),
            ..SlotTable::new(what, max_slots)
        }
    }

    fn mark(&mut self, slot: u32) {
        if let Some(marks) = &mut self.marks {
            marks.mark(slot);
        }
    }

    /// Marks made so far in a tracked table ([`Dirty::marks`]; 0 in an untracked one): a
    /// copy of the table's values taken when it read `n` is current while it reads `n`.
    pub fn marks_made(&self) -> u64 {
        self.marks.as_ref().map_or(0, Dirty::marks)
    }

    /// Marks every slot as changed (a plane-wide change).
    pub fn mark_all(&mut self) {
        if let Some(marks) = &mut self.marks {
            marks.mark_all();
        }
    }

    /// Slots marked since the last step (possibly repeated; see [`Dirty::since_step`]).
    pub fn since_step(&self) -> &[u32] {
        self.marks.as_ref().map_or(&[], |m| m.since_step())
    }

    /// A step has seen every slot marked so far (see [`Dirty::stepped`]).
    pub fn stepped(&mut self) {
        let n = self.entries.len();
        if let Some(marks) = &mut self.marks {
            marks.stepped(n);
        }
    }

    /// Hands the marked slots to `into` (appended) and forgets them. Returns true when the
    /// whole table changed.
    pub fn drain_marks(&mut self, into: &mut Vec<u32>) -> bool {
        self.marks.as_mut().is_some_and(|m| m.drain(into))
    }

    /// Takes over the marks of `live`, the table this one replaces (a restore or a rewind:
    /// what changed since the last publish is still to be published). `live`'s marks count
    /// as seen by a step; the next step sees this table's unseen marks instead, those of
    /// the plane it was taken from (see [`Dirty::resume`]).
    pub fn take_marks_of(&mut self, live: &mut SlotTable<T>) {
        let carried = self.marks.take().unwrap_or_default();
        self.marks = live.marks.take();
        if let Some(marks) = &mut self.marks {
            marks.resume(carried);
        }
    }

    /// Takes the name and slot limit of `like` (a table decoded from a snapshot has
    /// neither) after checking that the decoded bookkeeping holds together: within the
    /// limit, every free slot empty and listed once, the live count right.
    pub fn adopt_limits(&mut self, like: &SlotTable<T>) -> Result<(), CommandError> {
        let bad = |why: String| {
            Err(CommandError::new(
                ErrorKind::InvalidValue,
                format!("snapshot refused: its {} table {why}", like.what),
            ))
        };
        if self.entries.len() > like.max_slots {
            return bad(format!(
                "has {} slots (at most {})",
                self.entries.len(),
                like.max_slots
            ));
        }
        let live = self.entries.iter().filter(|e| e.value.is_some()).count();
        if live != self.live as usize {
            return bad(format!("counts {} live of {live}", self.live));
        }
        let mut seen = vec![false; self.entries.len()];
        for &f in &self.free {
            match self.entries.get(f as usize) {
                Some(e) if e.value.is_none() && !seen[f as usize] => seen[f as usize] = true,
                _ => return bad(format!("lists slot {f} as free")),
            }
        }
        if self.free.len() + live != self.entries.len() {
            return bad("loses track of a slot".into());
        }
        if let Some(marks) = &self.marks {
            if like.marks.is_none() {
                return bad("marks slots (a table that keeps no marks)".into());
            }
            if let Err(why) = marks.check_unseen(self.entries.len()) {
                return bad(why);
            }
        }
        self.what = like.what;
        self.max_slots = like.max_slots;
        Ok(())
    }

    /// The slot the next [`SlotTable::insert`] will use, or `None` when the table is full.
    pub fn next_slot(&self) -> Option<u32> {
        match self.free.last() {
            Some(s) => Some(*s),
            None if self.entries.len() < self.max_slots => Some(self.entries.len() as u32),
            None => None,
        }
    }

    /// Stores `value` in a free slot with a new generation.
    pub fn insert(&mut self, value: T) -> Result<Handle, CommandError> {
        let slot = match self.free.pop() {
            Some(s) => s,
            None if self.entries.len() < self.max_slots => {
                self.entries.push(Entry {
                    generation: 0,
                    value: None,
                });
                (self.entries.len() - 1) as u32
            }
            None => {
                return Err(CommandError::new(
                    ErrorKind::Internal,
                    format!("full ({} {}s)", self.max_slots, self.what),
                ))
            }
        };
        let entry = &mut self.entries[slot as usize];
        entry.generation = entry.generation.wrapping_add(1).max(1);
        entry.value = Some(value);
        self.live += 1;
        let generation = entry.generation;
        self.mark(slot);
        Ok(Handle { slot, generation })
    }

    /// The value of `handle`, or a clear error for unknown and stale handles.
    pub fn get(&self, handle: Handle) -> Result<&T, CommandError> {
        let entry = self.entry(handle)?;
        Ok(entry.value.as_ref().expect("checked by entry"))
    }

    /// The value of `handle`, mutably; its slot is marked changed.
    pub fn get_mut(&mut self, handle: Handle) -> Result<&mut T, CommandError> {
        self.entry(handle)?;
        self.mark(handle.slot);
        let entry = &mut self.entries[handle.slot as usize];
        Ok(entry.value.as_mut().expect("checked by entry"))
    }

    /// Removes the value of `handle`; its slot is reused with a new generation (and marked
    /// changed).
    pub fn remove(&mut self, handle: Handle) -> Result<T, CommandError> {
        self.entry(handle)?;
        self.mark(handle.slot);
        let value = self.entries[handle.slot as usize]
            .value
            .take()
            .expect("checked by entry");
        self.free.push(handle.slot);
        self.live -= 1;
        Ok(value)
    }

    fn entry(&self, handle: Handle) -> Result<&Entry<T>, CommandError> {
        let what = self.what;
        let entry = self.entries.get(handle.slot as usize).ok_or_else(|| {
            CommandError::new(
                ErrorKind::StaleHandle,
                format!("{what} {handle} does not exist"),
            )
        })?;
        match entry.value {
            Some(_) if entry.generation == handle.generation => Ok(entry),
            _ => Err(CommandError::new(
                ErrorKind::StaleHandle,
                format!(
                    "{what} {handle} is stale: slot {} now holds generation {} ({})",
                    handle.slot,
                    entry.generation,
                    if entry.value.is_some() {
                        "alive"
                    } else {
                        "empty"
                    }
                ),
            )),
        }
    }

    /// The value in slot `slot` whatever its generation, if the slot is occupied.
    pub fn at(&self, slot: usize) -> Option<&T> {
        self.entries.get(slot)?.value.as_ref()
    }

    /// The value in slot `slot` mutably, if occupied (for the engine's own passes: the slot
    /// is not marked).
    pub fn at_mut(&mut self, slot: usize) -> Option<&mut T> {
        self.entries.get_mut(slot)?.value.as_mut()
    }

    /// The handle of the value in slot `slot`, if occupied.
    pub fn handle_at(&self, slot: usize) -> Option<Handle> {
        let entry = self.entries.get(slot)?;
        entry.value.as_ref().map(|_| Handle {
            slot: slot as u32,
            generation: entry.generation,
        })
    }

    /// The generation of slot `slot` (of its value, or of the last value it held).
    pub fn generation(&self, slot: usize) -> u32 {
        self.entries.get(slot).map_or(0, |e| e.generation)
    }

    /// Slots ever used (occupied or free): the length of a published array.
    pub fn slot_count(&self) -> usize {
        self.entries.len()
    }

    /// Occupied slots.
    pub fn live(&self) -> u32 {
        self.live
    }

    /// Every occupied slot with its handle and value.
    pub fn iter(&self) -> impl Iterator<Item = (Handle, &T)> + '_ {
        self.entries.iter().enumerate().filter_map(|(i, e)| {
            e.value.as_ref().map(|v| {
                (
                    Handle {
                        slot: i as u32,
                        generation: e.generation,
                    },
                    v,
                )
            })
        })
    }

    /// Every occupied slot with its handle and value, mutably (not marked).
    pub fn iter_mut(&mut self) -> impl Iterator<Item = (Handle, &mut T)> + '_ {
        self.entries.iter_mut().enumerate().filter_map(|(i, e)| {
            let generation = e.generation;
            e.value.as_mut().map(|v| {
                (
                    Handle {
                        slot: i as u32,
                        generation,
                    },
                    v,
                )
            })
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reused_slots_get_new_generations_and_stale_handles_fail() {
        let mut t = SlotTable::new("thing", 2);
        let a = t.insert("a").unwrap();
        let b = t.insert("b").unwrap();
        assert!(t.insert("c").is_err(), "full at 2");
        assert_eq!(t.remove(a).unwrap(), "a");
        let c = t.insert("c").unwrap();
        assert_eq!(c.slot, a.slot);
        assert_eq!(c.generation, a.generation + 1);
        let e = t.get(a).unwrap_err();
        assert_eq!(e.kind, ErrorKind::StaleHandle);
        assert!(e.message.contains("stale"), "{e}");
        assert_eq!(*t.get(c).unwrap(), "c");
        assert_eq!(*t.get(b).unwrap(), "b");
        assert_eq!(t.live(), 2);
        assert_eq!(t.slot_count(), 2);
        let e = t
            .get(Handle {
                slot: 9,
                generation: 1,
            })
            .unwrap_err();
        assert!(e.message.contains("does not exist"), "{e}");
        assert_eq!(t.iter().count(), 2);
    }

    fn drained(t: &mut SlotTable<&str>) -> (Vec<u32>, bool) {
        let mut slots = Vec::new();
        let all = t.drain_marks(&mut slots);
        slots.sort_unstable();
        slots.dedup();
        (slots, all)
    }

    #[test]
    fn a_tracked_table_marks_what_handles_change_and_only_that() {
        let mut t = SlotTable::tracked("thing", 8);
        let a = t.insert("a").unwrap();
        let b = t.insert("b").unwrap();
        let c = t.insert("c").unwrap();
        assert_eq!(t.since_step(), &[0, 1, 2]);
        t.stepped();
        assert_eq!(drained(&mut t), (vec![0, 1, 2], false), "inserts mark");
        t.get(a).unwrap();
        t.at(1).unwrap();
        t.at_mut(2).unwrap();
        t.iter_mut().for_each(|_| {});
        assert_eq!(
            drained(&mut t),
            (vec![], false),
            "reads and engine passes do not"
        );
        *t.get_mut(b).unwrap() = "B";
        t.remove(c).unwrap();
        assert!(t.get_mut(c).is_err());
        assert_eq!(t.since_step(), &[1, 2], "seen by the next step");
        t.stepped();
        assert!(t.since_step().is_empty());
        assert_eq!(
            drained(&mut t),
            (vec![1, 2], false),
            "get_mut and remove mark"
        );
        t.mark_all();
        assert_eq!(drained(&mut t), (vec![], true));
        // A copy (Rewind) or a decoded table takes the live table's marks when it replaces
        // it; the next step sees the copy's unseen marks, not the live table's.
        t.get_mut(a).unwrap();
        t.stepped();
        let mut copy = t.clone();
        copy.get_mut(b).unwrap();
        t.insert("d").unwrap();
        assert_eq!(t.since_step(), &[2]);
        copy.take_marks_of(&mut t);
        assert_eq!(copy.since_step(), &[1], "the copy's");
        assert_eq!(drained(&mut copy), (vec![0, 1, 2], false));
        assert_eq!(
            copy.since_step(),
            &[1],
            "still the next step's after a publish"
        );
        copy.stepped();
        assert!(copy.since_step().is_empty());
        // Through a snapshot's bytes: the unseen marks only.
        copy.get_mut(b).unwrap();
        copy.get_mut(a).unwrap();
        let bytes = postcard::to_allocvec(&copy).unwrap();
        let mut decoded: SlotTable<&str> = postcard::from_bytes(&bytes).unwrap();
        decoded.adopt_limits(&copy).unwrap();
        decoded.take_marks_of(&mut copy);
        assert_eq!(decoded.since_step(), &[1, 0]);
        assert_eq!(drained(&mut decoded), (vec![0, 1], false));
        // An untracked table (joints) keeps no marks.
        let mut u = SlotTable::new("thing", 2);
        let x = u.insert("x").unwrap();
        u.get_mut(x).unwrap();
        assert_eq!(drained(&mut u), (vec![], false));
    }
}

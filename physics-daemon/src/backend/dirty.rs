//! What changed in a plane since its states were last published: slots touched by ops
//! (set, add, destroy, impulse, wake), or the whole plane. The plane marks, the publisher
//! drains; the plane's force pass reads the slots marked since its last step. Those are
//! state: a snapshot carries them ([`Unseen`]) and a restored plane's next step reads them
//! as the original's would have, a publish in between (a restore publishes at once)
//! leaving them for the step.

/// Slots changed since the last publish.
#[derive(Debug, Default, Clone)]
pub struct Dirty {
    slots: Vec<u32>,
    all: bool,
    /// `slots[..stepped]` were already seen by a step.
    stepped: usize,
    /// Unseen marks at which `mark` next folds repeats (at least `FOLD_MIN`).
    fold_at: usize,
    /// Marks ever made (never reset): a copy of the plane's state taken when it read `n`
    /// is current while it still reads `n`.
    marks: u64,
}

impl Dirty {
    /// Marks one slot as changed. The slots marked since the last step fold their repeats
    /// once they have doubled since the last fold: a plane that is written but neither
    /// stepped nor published (manual, disabled) keeps at most twice its distinct marks
    /// plus [`super::marks::FOLD_MIN`], not one entry a write.
    pub fn mark(&mut self, slot: u32) {
        self.marks += 1;
        self.slots.push(slot);
        let seen = self.stepped.min(self.slots.len());
        let unseen = self.slots.len() - seen;
        if unseen >= self.fold_at.max(super::marks::FOLD_MIN) {
            let mut tail = self.slots.split_off(seen);
            tail.sort_unstable();
            tail.dedup();
            self.fold_at = 2 * tail.len();
            self.slots.append(&mut tail);
        }
    }

    /// Marks every slot as changed (a plane-wide change).
    pub fn mark_all(&mut self) {
        self.marks += 1;
        self.all = true;
    }

    /// Marks made so far, [`Dirty::mark`] and [`Dirty::mark_all`] alike.
    pub fn marks(&self) -> u64 {
        self.marks
    }

    /// Slots marked since the last step (possibly repeated).
    pub fn since_step(&self) -> &[u32] {
        &self.slots[self.stepped.min(self.slots.len())..]
    }

    /// A step has seen every slot marked so far. Planes stepped without being published
    /// (in-process use) keep the list bounded: repeats are folded once it outgrows the
    /// plane.
    pub fn stepped(&mut self, slot_count: usize) {
        if self.slots.len() > 2 * slot_count + 64 {
            self.slots.sort_unstable();
            self.slots.dedup();
        }
        self.stepped = self.slots.len();
        self.fold_at = 0;
    }

    /// Hands the marked slots to `into` (appended) and forgets them, but for those no step
    /// has seen yet: they stay for the next step (handed out again by the next drain).
    /// Returns true when the whole plane changed.
    pub fn drain(&mut self, into: &mut Vec<u32>) -> bool {
        let seen = self.stepped.min(self.slots.len());
        if seen == self.slots.len() {
            into.append(&mut self.slots);
        } else {
            into.extend_from_slice(&self.slots);
            self.slots.drain(..seen);
        }
        self.stepped = 0;
        std::mem::take(&mut self.all)
    }

    /// The marks no step has seen yet, in order, with the count at which the next mark
    /// folds them: what a snapshot carries.
    pub fn unseen(&self) -> UnseenRef<'_> {
        UnseenRef {
            slots: self.since_step(),
            fold_at: self.fold_at as u64,
        }
    }

    /// Marks that hold only `unseen` (a decoded table's), none seen by a step yet.
    pub fn carrying(unseen: Unseen) -> Dirty {
        Dirty {
            slots: unseen.slots,
            fold_at: unseen.fold_at as usize,
            ..Dirty::default()
        }
    }

    /// Why these marks cannot be a plane's of `slot_count` slots (decoded from a
    /// snapshot): a slot past the table, or more unseen marks, or a fold count, than the
    /// marks ever hold unfolded.
    pub fn check_unseen(&self, slot_count: usize) -> Result<(), String> {
        let unseen = self.since_step();
        if let Some(s) = unseen.iter().find(|s| **s as usize >= slot_count) {
            return Err(format!("marks slot {s} of {slot_count}"));
        }
        let n = unseen.len();
        if n >= self.fold_at.max(super::marks::FOLD_MIN) || self.fold_at > 2 * n {
            return Err(format!(
                "holds {n} unseen marks to fold at {}: marks never stay so",
                self.fold_at
            ));
        }
        Ok(())
    }

    /// This plane's marks so far count as seen by a step, and `carried`'s unseen ones (a
    /// restored state's) are the marks the next step sees: later marks add to them and
    /// fold with them as they would have in the plane the state was taken from.
    pub fn resume(&mut self, carried: Dirty) {
        self.stepped = self.slots.len();
        self.slots.extend_from_slice(carried.since_step());
        self.fold_at = carried.fold_at;
    }
}

/// [`Dirty::unseen`], as a snapshot writes it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub struct UnseenRef<'a> {
    slots: &'a [u32],
    fold_at: u64,
}

/// [`UnseenRef`], decoded: the marks of a plane no step has seen yet
/// ([`Dirty::since_step`], in order) and the count at which the next mark folds them.
#[derive(Debug, Default, Clone, PartialEq, Eq, serde::Deserialize)]
pub struct Unseen {
    slots: Vec<u32>,
    fold_at: u64,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::backend::marks::FOLD_MIN;

    /// Marks `n` slots of `of` from a xorshift stream (`seed`), repeats included.
    fn mark_some(d: &mut Dirty, seed: &mut u64, n: usize, of: u64) {
        for _ in 0..n {
            *seed ^= *seed << 13;
            *seed ^= *seed >> 7;
            *seed ^= *seed << 17;
            d.mark((*seed % of) as u32);
        }
    }

    /// `d`'s unseen marks through a snapshot's bytes.
    fn carried(d: &Dirty) -> Dirty {
        let bytes = postcard::to_allocvec(&d.unseen()).unwrap();
        Dirty::carrying(postcard::from_bytes(&bytes).unwrap())
    }

    /// A plane's unseen marks carried into another (`resume`, with a drain between, as a
    /// restore's publish does) give the next step the same list as the plane they were
    /// taken from, when further marks follow: folds included.
    #[test]
    fn unseen_marks_carried_over_give_the_same_list_as_the_original() {
        let mut folded = 0;
        for (before, after, of) in [
            (0, 0, 10),
            (0, 5, 10),
            (3, 4, 10),
            (FOLD_MIN - 1, 1, 2_000),
            (FOLD_MIN + 10, 600, 300),
            (3 * FOLD_MIN, 2 * FOLD_MIN + 7, 700),
            (5 * FOLD_MIN, 0, 5_000),
        ] {
            let mut seed = 0x2545_f491_4f6c_dd1d_u64 ^ before as u64;
            let mut original = Dirty::default();
            // A step saw some marks first.
            mark_some(&mut original, &mut seed, 40, of);
            original.stepped(of as usize);
            mark_some(&mut original, &mut seed, before, of);
            let carried = carried(&original);
            carried.check_unseen(of as usize).unwrap();
            // The restoring plane had marks of its own, seen and unseen.
            let mut restored = Dirty::default();
            mark_some(&mut restored, &mut 7, 30, of);
            restored.stepped(of as usize);
            mark_some(&mut restored, &mut 9, 20, of);
            restored.resume(carried);
            let mut published = Vec::new();
            restored.drain(&mut published);
            assert!(published.len() >= original.since_step().len());
            assert_eq!(restored.since_step(), original.since_step(), "drained");
            let mut again = seed;
            mark_some(&mut original, &mut seed, after, of);
            mark_some(&mut restored, &mut again, after, of);
            assert_eq!(
                restored.since_step(),
                original.since_step(),
                "{before} marks carried, {after} after"
            );
            assert_eq!(restored.unseen(), original.unseen());
            folded += usize::from(original.fold_at > 0);
        }
        assert!(folded >= 3, "folds carried over: {folded}");
    }

    /// A drain keeps the marks no step has seen, and hands out every mark.
    #[test]
    fn a_drain_keeps_what_the_next_step_has_not_seen() {
        let mut d = Dirty::default();
        d.mark(3);
        d.mark(1);
        d.stepped(8);
        d.mark(5);
        d.mark(3);
        let mut out = Vec::new();
        assert!(!d.drain(&mut out));
        assert_eq!(out, [3, 1, 5, 3]);
        assert_eq!(d.since_step(), &[5, 3]);
        d.stepped(8);
        out.clear();
        d.drain(&mut out);
        assert_eq!(out, [5, 3], "handed out again after the step");
        assert!(d.since_step().is_empty());
        out.clear();
        d.drain(&mut out);
        assert!(out.is_empty());
    }

    #[test]
    fn unseen_marks_no_plane_holds_are_refused() {
        let check = |slots: Vec<u32>, fold_at: u64| {
            Dirty::carrying(Unseen { slots, fold_at }).check_unseen(10)
        };
        assert!(check(vec![], 0).is_ok());
        assert!(check(vec![9, 0, 9], 0).is_ok());
        assert!(check(vec![1, 2], 4).is_ok());
        assert!(check(vec![10], 0).unwrap_err().contains("slot 10"));
        assert!(
            check(vec![1], 3).is_err(),
            "folds at most at twice the marks"
        );
        assert!(check(vec![0; FOLD_MIN], 0).is_err(), "would have folded");
        assert!(check(vec![0; FOLD_MIN], 2 * FOLD_MIN as u64).is_ok());
    }
}

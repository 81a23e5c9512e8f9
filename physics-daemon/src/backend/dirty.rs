//! What changed in a plane since its states were last published: slots touched by ops
//! (set, add, destroy, impulse, wake), or the whole plane. The plane marks, the publisher
//! drains; the plane's force pass reads the slots marked since its last step.

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

    /// Hands the marked slots to `into` (appended) and forgets them. Returns true when the
    /// whole plane changed.
    pub fn drain(&mut self, into: &mut Vec<u32>) -> bool {
        into.append(&mut self.slots);
        self.stepped = 0;
        self.fold_at = 0;
        std::mem::take(&mut self.all)
    }
}

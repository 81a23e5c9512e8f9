//! A list of things marked until the next step (bodies whose colliders a query must bring
//! up to date first), with repeats folded away once it outgrows what it held at the last
//! fold. Every property write marks its body, and a plane that is not stepped (manual,
//! disabled) nor queried never empties the list: as a plain `Vec` it grew by one entry a
//! write, 1,000 writes a frame at 60 Hz making 1.7 GB an hour. Folded, it holds at most
//! twice the distinct marks plus [`FOLD_MIN`], whatever the number of writes.

use std::collections::HashSet;
use std::hash::Hash;

/// Entries below which the list is never folded (folding costs a pass and a set).
pub const FOLD_MIN: usize = 1024;

/// Marked items in marking order (repeats possible until the next fold).
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct Marks<T> {
    items: Vec<T>,
    /// Length at which the next push folds repeats.
    fold_at: usize,
}

impl<T> Default for Marks<T> {
    fn default() -> Self {
        Marks {
            items: Vec::new(),
            fold_at: FOLD_MIN,
        }
    }
}

impl<T: Eq + Hash + Copy> Marks<T> {
    /// Marks `item`; folds repeats (keeping each item's first mark, in order) when the list
    /// has doubled since the last fold, so each push costs amortised O(1).
    pub fn push(&mut self, item: T) {
        self.items.push(item);
        if self.items.len() >= self.fold_at {
            let mut seen = HashSet::with_capacity(self.items.len());
            self.items.retain(|x| seen.insert(*x));
            self.fold_at = (2 * self.items.len()).max(FOLD_MIN);
        }
    }
}

impl<T> Marks<T> {
    /// Whether nothing is marked.
    pub fn is_empty(&self) -> bool {
        self.items.is_empty()
    }

    /// Entries held (repeats not yet folded included).
    pub fn len(&self) -> usize {
        self.items.len()
    }

    /// Forgets every mark.
    pub fn clear(&mut self) {
        self.items.clear();
        self.fold_at = FOLD_MIN;
    }
}

impl<T> IntoIterator for Marks<T> {
    type Item = T;
    type IntoIter = std::vec::IntoIter<T>;

    fn into_iter(self) -> Self::IntoIter {
        self.items.into_iter()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_million_marks_of_ten_things_stay_bounded_and_keep_every_thing() {
        let mut m = Marks::default();
        let mut longest = 0;
        for i in 0..1_000_000u32 {
            m.push(i % 10);
            longest = longest.max(m.len());
        }
        // Folded at FOLD_MIN to 10 distinct, never past FOLD_MIN again.
        assert!(longest <= FOLD_MIN, "held {longest} entries for 10 things");
        let mut all: Vec<u32> = m.into_iter().collect();
        all.sort_unstable();
        all.dedup();
        assert_eq!(all, (0..10).collect::<Vec<_>>());
    }

    #[test]
    fn many_distinct_marks_are_all_kept() {
        let mut m = Marks::default();
        for i in 0..5_000u32 {
            m.push(i);
            m.push(i);
        }
        assert!(m.len() <= 2 * 5_000 + FOLD_MIN);
        let mut all: Vec<u32> = m.clone().into_iter().collect();
        all.sort_unstable();
        all.dedup();
        assert_eq!(all.len(), 5_000, "every distinct mark survives the folds");
        m.clear();
        assert!(m.is_empty());
    }
}

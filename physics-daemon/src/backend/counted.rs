//! Per-plane state that grows on a client's word (controller paths, today) and must count
//! against that client's quota. A [`CountedVec`] keeps the bytes its buffer holds in the
//! plane's [`Counter`], which the plane reports in [`super::Usage::state_bytes`]: 9,000
//! controllers with 65,536-point paths held 6.8 GB that no quota saw.

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;

/// Bytes held by a plane's counted vectors.
#[derive(Debug, Clone, Default)]
pub struct Counter(Arc<AtomicU64>);

impl Counter {
    /// The bytes held now.
    pub fn get(&self) -> u64 {
        self.0.load(Ordering::Relaxed)
    }

    fn change(&self, old: u64, new: u64) {
        self.0.fetch_add(new, Ordering::Relaxed);
        self.0.fetch_sub(old, Ordering::Relaxed);
    }
}

/// A vector whose buffer (its capacity, not only its length) is counted in a [`Counter`].
/// Clearing frees the buffer.
#[derive(Debug)]
pub struct CountedVec<T> {
    items: Vec<T>,
    counted: u64,
    counter: Counter,
}

impl<T> CountedVec<T> {
    /// An empty vector counted in `counter`.
    pub fn new(counter: &Counter) -> Self {
        CountedVec {
            items: Vec::new(),
            counted: 0,
            counter: counter.clone(),
        }
    }

    fn recount(&mut self) {
        let now = (self.items.capacity() * std::mem::size_of::<T>()) as u64;
        self.counter.change(self.counted, now);
        self.counted = now;
    }

    /// Replaces the contents with `items`.
    pub fn replace(&mut self, items: Vec<T>) {
        self.items = items;
        self.items.shrink_to_fit();
        self.recount();
    }

    /// Appends one item.
    pub fn push(&mut self, item: T) {
        self.items.push(item);
        self.recount();
    }

    /// Empties the vector and frees its buffer.
    pub fn clear(&mut self) {
        self.items = Vec::new();
        self.recount();
    }

    /// The items as a vector (a copy, counted nowhere).
    pub fn to_vec(&self) -> Vec<T>
    where
        T: Clone,
    {
        self.items.clone()
    }
}

/// `n` bytes held elsewhere (a kept copy of a plane's state) counted in a [`Counter`] for as
/// long as this lives.
#[derive(Debug)]
pub struct CountedBytes {
    n: u64,
    counter: Counter,
}

impl CountedBytes {
    /// Counts `n` bytes in `counter` until dropped.
    pub fn new(counter: &Counter, n: u64) -> CountedBytes {
        counter.change(0, n);
        CountedBytes {
            n,
            counter: counter.clone(),
        }
    }
}

impl Drop for CountedBytes {
    fn drop(&mut self) {
        self.counter.change(self.n, 0);
    }
}

impl<T> CountedVec<T> {
    /// Moves the count of this vector's buffer to `counter` (a vector restored from a
    /// snapshot counts in its new plane's counter).
    pub fn count_in(&mut self, counter: &Counter) {
        self.counter.change(self.counted, 0);
        self.counter = counter.clone();
        self.counted = 0;
        self.recount();
    }
}

/// A snapshot holds the items; the counter is the restoring plane's (see
/// [`CountedVec::count_in`]).
impl<T: serde::Serialize> serde::Serialize for CountedVec<T> {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        self.items.serialize(s)
    }
}

impl<'de, T: serde::Deserialize<'de>> serde::Deserialize<'de> for CountedVec<T> {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let mut v = CountedVec::new(&Counter::default());
        v.replace(Vec::deserialize(d)?);
        Ok(v)
    }
}

impl<T> std::ops::Deref for CountedVec<T> {
    type Target = [T];
    fn deref(&self) -> &[T] {
        &self.items
    }
}

impl<T: Clone> Clone for CountedVec<T> {
    fn clone(&self) -> Self {
        let mut copy = CountedVec::new(&self.counter);
        copy.replace(self.items.clone());
        copy
    }
}

impl<T> Drop for CountedVec<T> {
    fn drop(&mut self) {
        self.counter.change(self.counted, 0);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_counter_follows_buffers_and_drops() {
        let counter = Counter::default();
        let mut a = CountedVec::<[f32; 3]>::new(&counter);
        a.replace(vec![[0.0; 3]; 100]);
        assert_eq!(counter.get(), 1_200);
        let b = a.clone();
        assert_eq!(counter.get(), 2_400);
        a.clear();
        assert_eq!(counter.get(), 1_200);
        drop(b);
        a.push([1.0; 3]);
        assert!(counter.get() >= 12);
        drop(a);
        assert_eq!(counter.get(), 0);
    }
}

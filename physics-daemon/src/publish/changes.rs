//! Which slots of a plane changed since each recycled sample was last written: the slots
//! the plane marked dirty (ops), the slots awake now or at the last publish (motion).

use crate::backend::{Backend, SlotFilter};

/// Samples a plane's publisher may recycle that are remembered; more means the publisher
/// allocates something unexpected, and remembering is dropped (full writes stay correct).
const MAX_TRACKED_SAMPLES: usize = 1024;

/// What changed since each recycled sample was last written.
#[derive(Default)]
pub struct Changes {
    /// Publishes so far.
    seq: u64,
    /// Slot count the bookkeeping is for; a new count starts over with full writes.
    slot_count: usize,
    /// Per slot: the publish from which on its state may differ from earlier publishes.
    changed_at: Vec<u64>,
    /// The last publish at which every slot counted as changed (most bodies awake): one
    /// number instead of rewriting `changed_at` whole at every such publish.
    all_changed_at: u64,
    /// Slots awake at the last publish: they may have moved, or fallen asleep, since.
    awake_before: Vec<usize>,
    /// Most bodies were awake at the last publish: every slot counted as changed.
    mostly_awake_before: bool,
    /// Slots the plane marked as changed since the last publish (drained from it).
    dirty: Vec<u32>,
    /// Slots awake now, gathered from the plane.
    awake_now: Vec<usize>,
    /// Payload address of a recycled sample → the publish that last wrote all of it.
    samples: Vec<(usize, u64)>,
}

impl Changes {
    /// Advances to a new publish of `plane` (draining the slots it marked); returns the
    /// publish's sequence number.
    pub fn begin(&mut self, plane: &mut dyn Backend) -> u64 {
        self.seq += 1;
        let seq = self.seq;
        let n = plane.slot_count();
        let all = plane.drain_dirty(&mut self.dirty);
        if n != self.slot_count || all {
            // The publisher may have grown its samples: forget every recycled one.
            self.slot_count = n;
            self.samples.clear();
            self.changed_at.clear();
            self.changed_at.resize(n, seq);
        }
        let changed_at = &mut self.changed_at;
        let dirty = self.dirty.drain(..).map(|s| s as usize);
        for slot in dirty.chain(self.awake_before.drain(..)) {
            if let Some(c) = changed_at.get_mut(slot) {
                *c = seq;
            }
        }
        // When most bodies are awake, looking up each one costs more than rewriting all.
        let mostly_awake = plane.awake_count() * 2 >= n;
        if mostly_awake || self.mostly_awake_before {
            self.all_changed_at = seq;
            self.awake_before.clear();
        }
        if !mostly_awake {
            let awake = &mut self.awake_now;
            awake.clear();
            plane.for_each_awake(&mut |slot| awake.push(slot));
            for &slot in awake.iter() {
                if let Some(c) = changed_at.get_mut(slot) {
                    *c = seq;
                    self.awake_before.push(slot);
                }
            }
        }
        self.mostly_awake_before = mostly_awake;
        seq
    }

    /// Which slots of the sample at `addr` need writing for the current publish.
    pub fn filter(&self, addr: usize) -> SlotFilter<'_> {
        match self.written_at(addr) {
            Some(written) if !self.mostly_awake_before && self.all_changed_at <= written => {
                SlotFilter::ChangedAfter {
                    changed_at: &self.changed_at,
                    written,
                }
            }
            _ => SlotFilter::All,
        }
    }

    /// The publish that last wrote the whole sample at `addr`, if it is one we wrote.
    fn written_at(&self, addr: usize) -> Option<u64> {
        self.samples
            .iter()
            .find(|(a, _)| *a == addr)
            .map(|(_, s)| *s)
    }

    pub fn remember(&mut self, addr: usize, seq: u64) {
        let tracked = self.samples.len();
        match self.samples.iter_mut().find(|(a, _)| *a == addr) {
            Some(entry) => entry.1 = seq,
            None if tracked < MAX_TRACKED_SAMPLES => self.samples.push((addr, seq)),
            None => self.samples.clear(),
        }
    }
}

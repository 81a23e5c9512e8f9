//! A plane's object count without a round trip: the newest tick header's `body_count`, plus
//! this process's adds and removals that header does not show yet.
//!
//! Adds and removals of plain objects and controllers are followed exactly: an add is
//! counted from its reply (the tick after which the daemon applied it), a removal from the
//! moment it is queued. A change the ledger cannot follow (a map build) makes the count ask
//! the daemon once, then trust headers again from the first tick after that answer.

use shm_layout::Handle;

#[derive(Debug, Clone, Copy)]
struct Change {
    /// The removed object (`None` for an add).
    removed: Option<Handle>,
    /// The tick after which the daemon applied it: headers of later ticks count it. `None`
    /// while it is queued or in flight.
    applied_at: Option<u64>,
}

#[derive(Debug, Default)]
pub(crate) struct Members {
    pending: Vec<Change>,
    /// A change the ledger cannot follow happened: `Some(None)` until the daemon is asked,
    /// then `Some(Some(tick))` until a header newer than the answer's tick is visible.
    unknown: Option<Option<u64>>,
}

impl Members {
    /// The daemon added an object after `tick`.
    pub(crate) fn added(&mut self, tick: u64) {
        self.pending.push(Change {
            removed: None,
            applied_at: Some(tick),
        });
    }

    /// This process queued the removal of `handle`.
    pub(crate) fn removal_queued(&mut self, handle: Handle) {
        if !self.pending.iter().any(|c| c.removed == Some(handle)) {
            self.pending.push(Change {
                removed: Some(handle),
                applied_at: None,
            });
        }
    }

    /// The daemon removed `handle` after `tick`.
    pub(crate) fn removal_applied(&mut self, handle: Handle, tick: u64) {
        for c in &mut self.pending {
            if c.removed == Some(handle) && c.applied_at.is_none() {
                c.applied_at = Some(tick);
            }
        }
    }

    /// The daemon refused to remove `handle` (unknown or stale): nothing changed.
    pub(crate) fn removal_refused(&mut self, handle: Handle) {
        self.pending
            .retain(|c| !(c.removed == Some(handle) && c.applied_at.is_none()));
    }

    /// Something changed the plane's objects in a way the ledger does not follow.
    pub(crate) fn unknown_change(&mut self) {
        self.unknown = Some(None);
    }

    /// The daemon answered an info read taken after `tick`: its count is exact, and headers
    /// of later ticks include everything it counted.
    pub(crate) fn asked(&mut self, tick: u64) {
        if self.unknown.is_some() {
            self.unknown = Some(Some(tick));
        }
    }

    /// The object count given the newest header (`tick`, `body_count`); `None` when only
    /// the daemon can say.
    pub(crate) fn count(&mut self, tick: u64, body_count: u32) -> Option<u32> {
        match self.unknown {
            Some(None) => return None,
            Some(Some(t)) if tick <= t => return None,
            Some(Some(_)) => self.unknown = None,
            None => {}
        }
        // Changes a header of this tick already counts are done with.
        self.pending
            .retain(|c| c.applied_at.is_none_or(|applied| tick <= applied));
        let mut n = i64::from(body_count);
        for c in &self.pending {
            n += if c.removed.is_some() { -1 } else { 1 };
        }
        Some(n.clamp(0, i64::from(u32::MAX)) as u32)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const H: Handle = Handle {
        slot: 3,
        generation: 1,
    };

    #[test]
    fn adds_count_until_a_later_header_shows_them() {
        let mut m = Members::default();
        m.added(10);
        assert_eq!(m.count(10, 5), Some(6), "tick 10's header predates the add");
        assert_eq!(m.count(11, 6), Some(6), "tick 11 counts it itself");
        assert_eq!(m.count(12, 6), Some(6));
    }

    #[test]
    fn removals_count_from_the_queue_and_refusals_undo_them() {
        let mut m = Members::default();
        m.removal_queued(H);
        m.removal_queued(H);
        assert_eq!(m.count(4, 5), Some(4), "queued, counted once");
        m.removal_refused(H);
        assert_eq!(m.count(4, 5), Some(5));
        m.removal_queued(H);
        m.removal_applied(H, 4);
        assert_eq!(m.count(4, 5), Some(4));
        assert_eq!(m.count(5, 4), Some(4));
    }

    #[test]
    fn an_unknown_change_asks_once_then_trusts_later_headers() {
        let mut m = Members::default();
        m.unknown_change();
        assert_eq!(m.count(7, 2), None);
        m.asked(7);
        assert_eq!(m.count(7, 2), None, "the header of tick 7 may predate it");
        assert_eq!(m.count(8, 3), Some(3));
    }
}

//! Rollback (`RollbackTicks = K`, `PlaneOp::Rewind(n)`) for the planes whose whole state is
//! a value (both rapier planes): a [`Ring`] of the states after each of the last K ticks,
//! each an in-memory copy counted in the owner's state bytes, and the rewind that finds the
//! tick `n` back and hands out a copy of its state for the plane to become. The plane makes
//! the copies (it knows its fields) and decides when; the ring keeps them, drops the oldest
//! and answers what goes wrong in the same words for every plane.

use std::collections::VecDeque;

use shm_layout::CommandError;

use super::counted::CountedBytes;

/// A kept state that can be copied again (a second rewind to the same tick).
pub trait Duplicate {
    /// Another copy of this state.
    fn duplicate(&self) -> Self;
}

/// The kept states, oldest first, each with its tick and what it counts in the owner's
/// state bytes.
pub struct Ring<S> {
    kept: VecDeque<(u64, Box<S>, CountedBytes)>,
    /// A step's tick is yet to be kept (for a plane that puts the copy off its tick's path).
    pending: bool,
    /// States let go are dropped on the disposal thread (see [`Ring::dropping_off_thread`]).
    off_thread: bool,
}

impl<S> Default for Ring<S> {
    /// A ring that drops the states it lets go where it lets them go.
    fn default() -> Self {
        Ring {
            kept: VecDeque::new(),
            pending: false,
            off_thread: false,
        }
    }
}

impl<S> std::fmt::Debug for Ring<S> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Ring({} ticks)", self.kept.len())
    }
}

impl<S: Duplicate + Send + 'static> Ring<S> {
    /// A ring that drops the states it lets go on a thread of its own (freeing an awake
    /// pile's contact manifolds costs about as much as copying them).
    pub fn dropping_off_thread() -> Self {
        Ring {
            off_thread: true,
            ..Ring::default()
        }
    }

    /// Whether no state is kept.
    pub fn is_empty(&self) -> bool {
        self.kept.is_empty()
    }

    /// Forgets every kept state (and a tick yet to be kept).
    pub fn clear(&mut self) {
        self.pending = false;
        let off_thread = self.off_thread;
        for (_, state, _) in self.kept.drain(..) {
            let_go(off_thread, state);
        }
    }

    /// The tick just stepped is to be kept (the plane keeps it later: see
    /// [`Ring::take_pending`]).
    pub fn note_step(&mut self) {
        self.pending = true;
    }

    /// Whether a stepped tick is yet to be kept.
    pub fn pending(&self) -> bool {
        self.pending
    }

    /// Whether a stepped tick was yet to be kept; it no longer is.
    pub fn take_pending(&mut self) -> bool {
        std::mem::take(&mut self.pending)
    }

    /// Keeps `state`, the state after `tick`, counted as `counted`, and drops the oldest
    /// beyond the `k + 1` newest (the state of the tick `k` back included).
    pub fn keep(&mut self, tick: u64, state: Box<S>, counted: CountedBytes, k: usize) {
        self.kept.push_back((tick, state, counted));
        while self.kept.len() > k + 1 {
            if let Some((_, state, _)) = self.kept.pop_front() {
                let_go(self.off_thread, state);
            }
        }
    }

    /// Goes back `n` ticks from tick `now` with `k` = RollbackTicks (1 ≤ n ≤ k and ticks
    /// kept so far): a copy of the state to become, `None` for `n = 0` (nothing to do). The
    /// state of the tick gone back to stays kept (a second rewind to it works); later ones
    /// are dropped. `plane` names the plane in errors ("the plane", "the GUI plane").
    pub fn rewind(
        &mut self,
        k: u32,
        n: u32,
        now: u64,
        plane: &str,
    ) -> Result<Option<S>, CommandError> {
        if k == 0 {
            return Err(CommandError::invalid_field(
                "Rewind",
                format!(
                    "Rewind needs RollbackTicks > 0 (set it when creating {plane} or before the \
                     ticks to go back over)"
                ),
            ));
        }
        if n == 0 {
            return Ok(None);
        }
        let at = now
            .checked_sub(n as u64)
            .and_then(|t| self.kept.iter().position(|(tick, _, _)| *tick == t));
        let (Some(at), true) = (at, n <= k) else {
            let oldest = self.kept.front().map_or(now, |(t, _, _)| *t);
            return Err(CommandError::invalid_field(
                "Rewind",
                format!(
                    "Rewind({n}) goes further back than the plane keeps: RollbackTicks = {k}, \
                     ticks {oldest} to {now} kept"
                ),
            ));
        };
        let off_thread = self.off_thread;
        for (_, state, _) in self.kept.drain(at + 1..) {
            let_go(off_thread, state);
        }
        // A copy: the kept state stays for another rewind to the same tick.
        Ok(Some(self.kept[at].1.duplicate()))
    }
}

/// Drops `state` here, or on the disposal thread when `off_thread`.
fn let_go<S: Send + 'static>(off_thread: bool, state: Box<S>) {
    if off_thread {
        dispose(state);
    } else {
        drop(state);
    }
}

/// Drops `state` on the disposal thread (made on first use; it sleeps while there is
/// nothing to drop), or here if that thread cannot be had.
fn dispose(state: Box<dyn Send>) {
    use std::sync::mpsc::{channel, Sender};
    use std::sync::{Mutex, OnceLock};
    type Disposal = Option<Mutex<Sender<Box<dyn Send>>>>;
    static DISPOSAL: OnceLock<Disposal> = OnceLock::new();
    let sender = DISPOSAL.get_or_init(|| {
        let (tx, rx) = channel::<Box<dyn Send>>();
        std::thread::Builder::new()
            .name("rollback-drop".into())
            .spawn(move || while rx.recv().is_ok() {})
            .ok()
            .map(|_| Mutex::new(tx))
    });
    let state = match sender {
        Some(tx) => match tx.lock().unwrap_or_else(|p| p.into_inner()).send(state) {
            Ok(()) => return,
            Err(e) => e.0,
        },
        None => state,
    };
    drop(state);
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::backend::counted::Counter;

    #[derive(Debug, PartialEq)]
    struct Tick(u64);

    impl Duplicate for Tick {
        fn duplicate(&self) -> Tick {
            Tick(self.0)
        }
    }

    fn ring(
        off_thread: bool,
        counter: &Counter,
        ticks: std::ops::RangeInclusive<u64>,
    ) -> Ring<Tick> {
        let mut ring = match off_thread {
            true => Ring::dropping_off_thread(),
            false => Ring::default(),
        };
        for t in ticks {
            ring.keep(t, Box::new(Tick(t)), CountedBytes::new(counter, 10), 3);
        }
        ring
    }

    #[test]
    fn a_ring_keeps_k_plus_one_ticks_and_rewinds_to_any_of_them() {
        for off_thread in [false, true] {
            let counter = Counter::default();
            let mut r = ring(off_thread, &counter, 1..=10);
            // Ticks 7 to 10 kept (k = 3: the tick 3 back and the three after it).
            assert_eq!(counter.get(), 40);
            assert_eq!(r.rewind(3, 0, 10, "the plane").unwrap(), None);
            let e = r.rewind(3, 4, 10, "the plane").unwrap_err();
            assert!(e.message.contains("ticks 7 to 10 kept"), "{}", e.message);
            let e = r.rewind(0, 1, 10, "the GUI plane").unwrap_err();
            assert!(
                e.message.contains("creating the GUI plane"),
                "{}",
                e.message
            );
            assert_eq!(r.rewind(3, 2, 10, "the plane").unwrap(), Some(Tick(8)));
            // 9 and 10 dropped; 8 stays for another rewind to it.
            assert_eq!(counter.get(), 20);
            assert_eq!(r.rewind(3, 0, 8, "the plane").unwrap(), None);
            assert_eq!(r.rewind(3, 1, 8, "the plane").unwrap(), Some(Tick(7)));
            r.note_step();
            assert!(r.pending());
            r.clear();
            assert!(!r.pending() && r.is_empty());
            assert_eq!(counter.get(), 0);
        }
    }
}

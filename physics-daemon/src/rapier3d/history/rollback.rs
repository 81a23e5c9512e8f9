//! Rollback (`RollbackTicks = K`, `PlaneOp::Rewind(n)`): a plane with K > 0 keeps its state
//! after each of its last K ticks (an in-memory copy each: the engine's sets cloned, shapes
//! shared; counted in the owner's state bytes by an estimate) and can go back n ≤ K ticks; the script then re-applies corrected inputs and
//! steps again (rollback netcode). With K = 0 (the default) nothing is kept and a step
//! pays nothing.
//!
//! The copy is not made on the tick's path: a step only notes that its tick is to be kept,
//! and the plane's worker makes the copy right after the tick is published and answered
//! (`Backend::idle_work`), when no one waits for the plane; any op or step that comes first
//! makes it before it runs, so what is kept is always the state right after its tick. The
//! oldest copy is dropped on a thread of its own (freeing an awake pile's contact manifolds
//! costs about as much as copying them).

use std::collections::VecDeque;

use crate::backend::counted::CountedBytes;

/// The kept states (`S`: the plane's state), oldest first, each with its tick.
pub(crate) struct Ring<S: Send + 'static> {
    kept: VecDeque<(u64, Box<S>, CountedBytes)>,
    /// A step's tick is yet to be kept (see the module doc).
    pending: bool,
}

impl<S: Send + 'static> Default for Ring<S> {
    fn default() -> Self {
        Ring {
            kept: VecDeque::new(),
            pending: false,
        }
    }
}

impl<S: Send + 'static> std::fmt::Debug for Ring<S> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Ring({} ticks)", self.kept.len())
    }
}

impl<S: Send + 'static> Ring<S> {
    /// Forgets every kept state (and a tick yet to be kept).
    pub fn clear(&mut self) {
        self.pending = false;
        for (_, state, _) in self.kept.drain(..) {
            dispose(state);
        }
    }

    /// The tick just stepped is to be kept (by the plane's `finish_keep`).
    pub fn note_step(&mut self) {
        self.pending = true;
    }

    /// Whether a stepped tick is to be kept, clearing the note.
    pub fn take_pending(&mut self) -> bool {
        std::mem::take(&mut self.pending)
    }

    /// Whether a stepped tick is to be kept.
    pub fn pending(&self) -> bool {
        self.pending
    }

    /// Whether no state is kept.
    pub fn is_empty(&self) -> bool {
        self.kept.is_empty()
    }

    /// Keeps `state` of `tick` (counted as `counted`), then drops the oldest beyond `k + 1`.
    pub fn keep(&mut self, tick: u64, state: Box<S>, counted: CountedBytes, k: usize) {
        self.kept.push_back((tick, state, counted));
        while self.kept.len() > k + 1 {
            if let Some((_, state, _)) = self.kept.pop_front() {
                dispose(state);
            }
        }
    }

    /// The index of the state kept for `tick`.
    pub fn position(&self, tick: u64) -> Option<usize> {
        self.kept.iter().position(|(t, _, _)| *t == tick)
    }

    /// The tick of the oldest state kept.
    pub fn oldest_tick(&self) -> Option<u64> {
        self.kept.front().map(|(t, _, _)| *t)
    }

    /// Drops the states kept after index `at` and returns the one at `at`.
    pub fn back_to(&mut self, at: usize) -> &S {
        for (_, state, _) in self.kept.drain(at + 1..) {
            dispose(state);
        }
        &self.kept[at].1
    }
}

/// What one kept tick is counted as per object slot (a snapshot body takes about 1.5 KB a
/// body with its contacts; the copy is of the same order).
pub(crate) const BYTES_PER_SLOT: u64 = 1536;

/// Drops `state` on the disposal thread (made on first use; it sleeps while there is
/// nothing to drop), or here if that thread cannot be had.
fn dispose<S: Send + 'static>(state: Box<S>) {
    use std::sync::mpsc::{channel, Sender};
    use std::sync::{Mutex, OnceLock};
    type Dropped = Box<dyn Send>;
    static DISPOSAL: OnceLock<Option<Mutex<Sender<Dropped>>>> = OnceLock::new();
    let sender = DISPOSAL.get_or_init(|| {
        let (tx, rx) = channel::<Dropped>();
        std::thread::Builder::new()
            .name("rollback-drop".into())
            .spawn(move || while rx.recv().is_ok() {})
            .ok()
            .map(|_| Mutex::new(tx))
    });
    let state: Dropped = state;
    let state = match sender {
        Some(tx) => match tx.lock().unwrap_or_else(|p| p.into_inner()).send(state) {
            Ok(()) => return,
            Err(e) => e.0,
        },
        None => state,
    };
    drop(state);
}

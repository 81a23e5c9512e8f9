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

use shm_layout::{CommandError, Reply};

use super::snapshot::State;
use super::Plane;
use crate::backend::counted::CountedBytes;

/// What one kept tick is counted as per object slot (a snapshot body takes about 1.5 KB a
/// body with its contacts; the copy is of the same order).
const BYTES_PER_SLOT: u64 = 1536;

/// The kept states, oldest first.
#[derive(Default)]
pub(super) struct Ring {
    kept: VecDeque<(u64, Box<State>, CountedBytes)>,
    /// A step's tick is yet to be kept (see the module doc).
    pending: bool,
}

impl std::fmt::Debug for Ring {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Ring({} ticks)", self.kept.len())
    }
}

impl Ring {
    /// Forgets every kept state (and a tick yet to be kept).
    pub fn clear(&mut self) {
        self.pending = false;
        for (_, state, _) in self.kept.drain(..) {
            dispose(state);
        }
    }

    /// The tick just stepped is to be kept (by [`Plane::finish_keep`]).
    pub fn note_step(&mut self) {
        self.pending = true;
    }
}

/// Drops `state` on the disposal thread (made on first use; it sleeps while there is
/// nothing to drop), or here if that thread cannot be had.
fn dispose(state: Box<State>) {
    use std::sync::mpsc::{channel, Sender};
    use std::sync::{Mutex, OnceLock};
    static DISPOSAL: OnceLock<Option<Mutex<Sender<Box<State>>>>> = OnceLock::new();
    let sender = DISPOSAL.get_or_init(|| {
        let (tx, rx) = channel::<Box<State>>();
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

impl Plane {
    /// Keeps the last step's tick if that is still to be done: before anything changes the
    /// plane, and when the worker is idle.
    pub(super) fn finish_keep(&mut self) -> Result<(), CommandError> {
        if std::mem::take(&mut self.rollback.pending) {
            self.keep_for_rollback()?;
        }
        Ok(())
    }

    /// Whether a stepped tick is yet to be kept.
    pub(super) fn keep_pending(&self) -> bool {
        self.rollback.pending
            && (self.settings.rollback_ticks > 0 || !self.rollback.kept.is_empty())
    }

    /// After a step: keeps the state of the new tick when RollbackTicks > 0.
    fn keep_for_rollback(&mut self) -> Result<(), CommandError> {
        let k = self.settings.rollback_ticks as usize;
        if k == 0 {
            if !self.rollback.kept.is_empty() {
                self.rollback.clear();
            }
            return Ok(());
        }
        let copy = Box::new(self.clone_state());
        let counted = CountedBytes::new(
            &self.state_bytes,
            BYTES_PER_SLOT * self.bodies.slot_count() as u64,
        );
        self.rollback
            .kept
            .push_back((self.clock.tick, copy, counted));
        while self.rollback.kept.len() > k + 1 {
            if let Some((_, state, _)) = self.rollback.kept.pop_front() {
                dispose(state);
            }
        }
        Ok(())
    }

    /// Goes back `n` ticks (1 ≤ n ≤ RollbackTicks and ticks kept so far). The state of the
    /// tick gone back to stays kept (a second rewind to it works); later ones are dropped.
    pub(super) fn rewind(&mut self, n: u32) -> Result<Reply, CommandError> {
        let k = self.settings.rollback_ticks;
        if k == 0 {
            return Err(CommandError::invalid_field(
                "Rewind",
                "Rewind needs RollbackTicks > 0 (set it when creating the plane or before the \
                 ticks to go back over)",
            ));
        }
        if n == 0 {
            return Ok(Reply::Applied {
                tick: self.clock.tick,
            });
        }
        let at = self.clock.tick.checked_sub(n as u64).and_then(|t| {
            self.rollback
                .kept
                .iter()
                .position(|(tick, _, _)| *tick == t)
        });
        let (Some(at), true) = (at, n <= k) else {
            let oldest = self
                .rollback
                .kept
                .front()
                .map_or(self.clock.tick, |(t, _, _)| *t);
            return Err(CommandError::invalid_field(
                "Rewind",
                format!(
                    "Rewind({n}) goes further back than the plane keeps: RollbackTicks = {k}, \
                     ticks {oldest} to {} kept",
                    self.clock.tick
                ),
            ));
        };
        for (_, state, _) in self.rollback.kept.drain(at + 1..) {
            dispose(state);
        }
        // A copy: the kept state stays for another rewind to the same tick.
        let copy = self.rollback.kept[at].1.duplicate();
        self.adopt_copy(copy)?;
        Ok(Reply::Applied {
            tick: self.clock.tick,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::backend::Backend;
    use shm_layout::{PlaneOp, PlaneProp, Pose, Shape};

    fn falling(k: u32) -> Plane {
        let mut plane = Plane::new(1, &[PlaneProp::RollbackTicks(k)]).unwrap();
        for i in 0..4 {
            plane
                .apply(PlaneOp::AddObject {
                    shape: Shape::Cube { size: [1.0; 3] },
                    pose: Pose::at([0.0, 1.0 + 1.1 * i as f32, 0.0]),
                    props: vec![],
                })
                .unwrap();
        }
        plane
    }

    /// The copy a step puts off is made by whatever comes first (the worker's idle work, the
    /// next step, an op): the kept ticks are the same either way, and a rewind finds them.
    #[test]
    fn a_deferred_keep_keeps_the_same_ticks_whoever_makes_it() {
        let dt = 1.0 / 60.0;
        let mut idle = falling(3);
        let mut busy = falling(3);
        let mut hashes = Vec::new();
        for _ in 0..5 {
            idle.step(dt).unwrap();
            assert!(idle.has_idle_work());
            idle.idle_work().unwrap();
            assert!(!idle.has_idle_work());
            busy.step(dt).unwrap();
            assert_eq!(idle.state_hash, busy.state_hash);
            hashes.push(idle.state_hash);
        }
        // `busy` kept its ticks at each next step; its last is kept by the rewind itself.
        assert!(busy.has_idle_work());
        for plane in [&mut idle, &mut busy] {
            assert_eq!(
                plane.apply(PlaneOp::Rewind(2)).unwrap(),
                Reply::Applied { tick: 3 }
            );
            assert_eq!(plane.state_hash, hashes[2]);
            plane.step(dt).unwrap();
            assert_eq!(plane.state_hash, hashes[3], "the same tick again");
        }
        // Nothing is kept, nor pending, with RollbackTicks = 0.
        let mut none = falling(0);
        none.step(dt).unwrap();
        assert!(!none.has_idle_work());
    }
}

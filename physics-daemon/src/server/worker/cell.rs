//! The plane, shared by its worker and the request loop ([`PlaneCell`]): the loop applies a
//! short run of ops inline, with no hand-over, when the worker is idle and nothing is queued
//! for the plane ([`PlaneCell::try_apply`]); otherwise it hands the run over.

use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Mutex, MutexGuard, TryLockError};
use std::time::{Duration, Instant};

use shm_layout::{CommandResult, PlaneId, PlaneOp};

use crate::backend::Backend;

use super::messages::{Budget, SharedUsage};
use super::ops::run_ops;
use crate::server::persistence::persist;

/// The plane, shared by its worker and the request loop.
#[derive(Default)]
pub(crate) struct PlaneCell {
    /// `None` until the worker created the plane, and after the plane failed.
    pub(crate) plane: Mutex<Option<Box<dyn Backend>>>,
    /// Runs handed to the worker that it has not finished applying. While any is, the loop
    /// never applies a run inline (it would overtake them).
    pub(crate) queued: AtomicUsize,
    /// Its tick, whether it changed since its last write, held or destroyed (`persist`).
    pub marks: persist::Marks,
}

/// What [`PlaneCell::try_apply`] did.
pub(crate) enum Inline {
    /// The run was applied; `failed`: the plane panicked and is gone. `reschedule`: the
    /// run changed the tick rate or Enabled (the worker must restart its schedule).
    Applied {
        results: Vec<CommandResult>,
        failed: bool,
        reschedule: bool,
    },
    /// The worker is busy, runs are queued, or the run must go to the worker: hand it over.
    HandOver(Vec<PlaneOp>),
}

impl PlaneCell {
    /// Whether the loop may apply `op` itself: a short op that neither steps nor touches the
    /// plane's shared-memory output (which lives on the worker's thread), and that is cheap
    /// enough not to hold up the other clients (no meshes, no maps, no scene queries: a
    /// query's time grows with its rays and filter, so it runs on the plane's worker; nor a
    /// joint list, whose page may describe thousands of joints).
    pub fn inline_op(op: &PlaneOp) -> bool {
        !matches!(
            op,
            PlaneOp::Step { .. }
                | PlaneOp::Info
                | PlaneOp::Map(_)
                | PlaneOp::Query(_)
                | PlaneOp::Joint(shm_layout::joint_op::JointOp::List { .. })
                | PlaneOp::Snapshot
                | PlaneOp::Restore { .. }
                | PlaneOp::Rewind(_)
                | PlaneOp::Save
                | PlaneOp::Record(_)
        ) && op.cost().mesh_vertices == 0
    }

    /// Notes a run handed to the worker (before sending it).
    pub fn handed_over(&self) {
        self.queued.fetch_add(1, Ordering::SeqCst);
    }

    /// Applies the run `ops` on the calling thread (the request loop) when the worker is
    /// idle and no run is queued for the plane: the run then applies exactly where a
    /// hand-over would have (after every earlier run, between two ticks). Otherwise the run
    /// comes back to be handed over.
    pub fn try_apply(
        &self,
        id: PlaneId,
        ops: Vec<PlaneOp>,
        budget: &Budget,
        usage: &SharedUsage,
    ) -> Inline {
        if !ops.iter().all(PlaneCell::inline_op) || self.queued.load(Ordering::SeqCst) != 0 {
            return Inline::HandOver(ops);
        }
        let mut guard = match self.plane.try_lock() {
            Ok(guard) => guard,
            Err(TryLockError::WouldBlock) => return Inline::HandOver(ops),
            Err(TryLockError::Poisoned(p)) => p.into_inner(),
        };
        // Checked again under the lock: the worker finishes a run before it lets go.
        if self.queued.load(Ordering::SeqCst) != 0 {
            return Inline::HandOver(ops);
        }
        let Some(plane) = guard.as_mut() else {
            return Inline::HandOver(ops);
        };
        // Work the worker put off its tick (a copy for Rewind) is the worker's to do.
        if plane.has_idle_work() {
            return Inline::HandOver(ops);
        }
        let before = schedule_of(plane.as_ref());
        self.note_changes(&ops);
        let (results, failed) = run_ops(id, plane.as_mut(), ops, budget, usage, None, None);
        if failed {
            *guard = None;
            usage.release();
            return Inline::Applied {
                results,
                failed,
                reschedule: false,
            };
        }
        usage.update(plane.as_ref());
        let reschedule = schedule_of(plane.as_ref()) != before;
        Inline::Applied {
            results,
            failed,
            reschedule,
        }
    }

    /// Notes that a run with ops that are not reads changes the plane (it is written again
    /// at the next period, when persistent).
    pub(crate) fn note_changes(&self, ops: &[PlaneOp]) {
        if ops.iter().any(|op| !op.is_read_only()) {
            self.marks.changed.store(true, Ordering::SeqCst);
        }
    }

    pub(crate) fn lock(&self) -> MutexGuard<'_, Option<Box<dyn Backend>>> {
        self.plane.lock().unwrap_or_else(|p| p.into_inner())
    }

    /// Locks the plane between two ticks once every run handed to its worker is applied
    /// (migration: `moves`), waiting up to `wait`; `None` when runs are still queued then.
    /// While the guard lives the worker neither steps nor applies anything.
    pub fn lock_idle(&self, wait: Duration) -> Option<MutexGuard<'_, Option<Box<dyn Backend>>>> {
        let deadline = Instant::now() + wait;
        loop {
            if self.queued.load(Ordering::SeqCst) == 0 {
                let guard = self.lock();
                // Checked again under the lock: the worker finishes a run before it lets go.
                if self.queued.load(Ordering::SeqCst) == 0 {
                    return Some(guard);
                }
            }
            if Instant::now() >= deadline {
                return None;
            }
            std::thread::sleep(Duration::from_micros(200));
        }
    }
}

/// What the tick schedule depends on.
fn schedule_of(plane: &dyn Backend) -> (u32, bool) {
    (plane.tick_rate().to_bits(), plane.enabled())
}

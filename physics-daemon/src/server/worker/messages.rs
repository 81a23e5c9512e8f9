//! What the request loop and a plane's worker tell each other: the jobs the loop hands over
//! ([`Job`], with the [`Budget`] a run is checked against), the worker's answers
//! ([`Event`]), and the [`Waker`] that wakes the loop when one is ready.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};

use iceoryx2_bb_posix::socket_pair::StreamingSocket;
use shm_layout::{CommandResult, PlaneId, PlaneOp};

use crate::server::persistence::transfers;
use crate::server::quotas::limits::Limits;
use crate::server::quotas::quota;

/// What the request loop asks of a worker.
pub(crate) enum Job {
    /// Apply `ops` in order (a run of consecutive commands of one request for this plane)
    /// and answer with `ticket`.
    Run {
        ticket: u64,
        ops: Vec<PlaneOp>,
        budget: Budget,
    },
    /// The loop changed the plane's tick rate or Enabled inline: restart the schedule.
    Reschedule,
    /// Finish the queued jobs, then drop the plane and end.
    Stop,
    /// Write the (persistent) plane's file now; answer with `ticket` once it is on disk.
    Save { ticket: u64 },
}

/// What a worker tells the request loop.
pub(crate) enum Event {
    /// The answer to a job (or to the creation, ticket of the `CreatePlane`).
    Done {
        ticket: u64,
        plane: PlaneId,
        results: Vec<CommandResult>,
        /// The plane panicked and is gone: the loop forgets it.
        failed: bool,
    },
    /// An automatic tick panicked: the plane is gone.
    Failed { plane: PlaneId },
}

/// The quotas a run is checked against: the limits, how many reply bytes the request it
/// belongs to may still fill, and who pays for what it adds.
#[derive(Debug, Clone)]
pub(crate) struct Budget {
    pub limits: Limits,
    pub reply_left: usize,
    /// The requesting process's total when it is not the plane owner's (a `Shared` plane):
    /// the objects it adds count against it.
    pub guest: Option<Arc<quota::OwnerUsage>>,
    /// The requesting connection's snapshot transfers: a snapshot too large for the reply
    /// waits there as a download.
    pub transfers: Option<Arc<transfers::ClientTransfers>>,
}

/// A plane's usage, counted in its owner's total.
pub(crate) type SharedUsage = quota::PlaneUsage;

/// Wakes the request loop (its WaitSet watches the other end of the socket pair). One byte
/// stands for any number of events: the loop drains them all.
pub(crate) struct Waker {
    socket: Mutex<StreamingSocket>,
    armed: AtomicBool,
}

impl Waker {
    pub fn new(socket: StreamingSocket) -> Waker {
        Waker {
            socket: Mutex::new(socket),
            armed: AtomicBool::new(false),
        }
    }

    /// Called by the loop before it drains the events.
    pub fn disarm(&self) {
        self.armed.store(false, Ordering::SeqCst);
    }

    pub(crate) fn wake(&self) {
        if !self.armed.swap(true, Ordering::SeqCst) {
            if let Ok(socket) = self.socket.lock() {
                let _ = socket.try_send(&[1]);
            }
        }
    }
}

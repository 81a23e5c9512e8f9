//! One plane's worker: a thread that owns the plane and its shared-memory output, applies the
//! command runs the request loop hands it (in the order they arrive), steps and publishes
//! the plane (on `Step`, or on its own schedule when it ticks automatically), and reports
//! back to the request loop. Planes therefore step side by side, and a heavy tick of one
//! plane never holds up a request for another.
//!
//! The worker has an iceoryx2 node of its own (ports stay on the thread that made them).

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::mpsc::{Receiver, RecvTimeoutError, Sender};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use iceoryx2::config::Config;
use iceoryx2::prelude::*;
use iceoryx2_bb_posix::socket_pair::StreamingSocket;
use shm_layout::{
    CommandError, CommandResult, ErrorKind, PlaneId, PlaneKind, PlaneOp, PlaneProp, Reply,
};

use super::dispatch::unknown_plane;
use super::limits::{exceeded, Limits};
use crate::backend::{self, Backend, Usage};
use crate::publish::PlaneOutput;
use crate::DaemonError;

/// What the request loop asks of a worker.
pub(super) enum Job {
    /// Apply `ops` in order (a run of consecutive commands of one request for this plane)
    /// and answer with `ticket`.
    Run {
        ticket: u64,
        ops: Vec<PlaneOp>,
        budget: Budget,
    },
    /// Finish the queued jobs, then drop the plane and end.
    Stop,
}

/// What a worker tells the request loop.
pub(super) enum Event {
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

/// The quotas a run is checked against: the limits, and what the other planes of the
/// plane owner's process held when the run was handed out.
#[derive(Debug, Clone, Copy)]
pub(super) struct Budget {
    pub limits: Limits,
    pub other: Usage,
}

/// A plane's [`Usage`] as the worker last saw it, for the quotas of the owner's other planes.
#[derive(Debug, Default)]
pub(super) struct SharedUsage {
    objects: AtomicU64,
    mesh_vertices: AtomicU64,
}

impl SharedUsage {
    pub fn get(&self) -> Usage {
        Usage {
            objects: self.objects.load(Ordering::Relaxed),
            mesh_vertices: self.mesh_vertices.load(Ordering::Relaxed),
        }
    }

    fn set(&self, usage: Usage) {
        self.objects.store(usage.objects, Ordering::Relaxed);
        self.mesh_vertices
            .store(usage.mesh_vertices, Ordering::Relaxed);
    }
}

/// Wakes the request loop (its WaitSet watches the other end of the socket pair). One byte
/// stands for any number of events: the loop drains them all.
pub(super) struct Waker {
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

    fn wake(&self) {
        if !self.armed.swap(true, Ordering::SeqCst) {
            if let Ok(socket) = self.socket.lock() {
                let _ = socket.try_send(&[1]);
            }
        }
    }
}

/// Everything a worker starts with.
pub(super) struct Setup {
    pub id: PlaneId,
    pub kind: PlaneKind,
    pub props: Vec<PlaneProp>,
    /// The ticket of the creating command: the creation's `Done` carries it.
    pub ticket: u64,
    pub config: Config,
    pub usage: Arc<SharedUsage>,
    pub events: Sender<Event>,
    pub waker: Arc<Waker>,
    pub panic_on_step_dt: Option<f32>,
}

/// The worker thread's body.
pub(super) fn run(setup: Setup, jobs: Receiver<Job>) {
    let Setup {
        id,
        ticket,
        ref events,
        ref waker,
        ..
    } = setup;
    let report = |event: Event| {
        let _ = events.send(event);
        waker.wake();
    };
    let created = catch_unwind(AssertUnwindSafe(|| create(&setup)));
    let mut worker = match created {
        Ok(Ok((worker, info))) => {
            report(Event::Done {
                ticket,
                plane: id,
                results: vec![Ok(info)],
                failed: false,
            });
            worker
        }
        Ok(Err(e)) => {
            report(Event::Done {
                ticket,
                plane: id,
                results: vec![Err(e)],
                failed: true,
            });
            return drain(id, jobs, &report);
        }
        Err(panic) => {
            let e = CommandError::new(
                ErrorKind::Internal,
                format!(
                    "creating plane {id} failed: {}",
                    super::dispatch::panic_message(panic.as_ref())
                ),
            );
            report(Event::Done {
                ticket,
                plane: id,
                results: vec![Err(e)],
                failed: true,
            });
            return drain(id, jobs, &report);
        }
    };
    worker.usage.set(worker.plane.usage());
    worker.reschedule(Instant::now());
    loop {
        let job = match worker.next_tick {
            Some(due) => match jobs.recv_timeout(due.saturating_duration_since(Instant::now())) {
                Ok(job) => Some(job),
                Err(RecvTimeoutError::Timeout) => None,
                Err(RecvTimeoutError::Disconnected) => return,
            },
            None => match jobs.recv() {
                Ok(job) => Some(job),
                Err(_) => return,
            },
        };
        match job {
            Some(Job::Stop) => return,
            Some(Job::Run {
                ticket,
                ops,
                budget,
            }) => {
                let (results, failed) = worker.run_ops(ops, budget);
                worker.usage.set(worker.plane.usage());
                report(Event::Done {
                    ticket,
                    plane: id,
                    results,
                    failed,
                });
                if failed {
                    return drain(id, jobs, &report);
                }
            }
            None => {}
        }
        if !worker.tick_if_due(Instant::now()) {
            report(Event::Failed { plane: id });
            return drain(id, jobs, &report);
        }
    }
}

/// After the plane failed: answers what is still queued (the loop forgets the plane once it
/// reads the failure) until told to stop.
fn drain(id: PlaneId, jobs: Receiver<Job>, report: &dyn Fn(Event)) {
    while let Ok(Job::Run { ticket, ops, .. }) = jobs.recv() {
        report(Event::Done {
            ticket,
            plane: id,
            results: ops.iter().map(|_| Err(unknown_plane(id))).collect(),
            failed: true,
        });
    }
}

struct Worker {
    id: PlaneId,
    plane: Box<dyn Backend>,
    out: PlaneOutput,
    usage: Arc<SharedUsage>,
    panic_on_step_dt: Option<f32>,
    /// The tick period the schedule was made for; `None` for manual or disabled planes.
    period: Option<Duration>,
    /// When the next automatic tick is due; `None` for manual or disabled planes.
    next_tick: Option<Instant>,
    // The node goes last: the ports above are dropped before it.
    _node: Node<ipc::Service>,
}

fn create(setup: &Setup) -> Result<(Worker, Reply), CommandError> {
    let id = setup.id;
    let internal = |e: DaemonError| CommandError::new(ErrorKind::Internal, e.to_string());
    let mut plane = backend::create(setup.kind, id, &setup.props)?;
    let node = NodeBuilder::new()
        .config(&setup.config)
        .signal_handling_mode(SignalHandlingMode::Disabled)
        .create::<ipc::Service>()
        .map_err(|e| {
            internal(DaemonError::Ipc(format!(
                "plane {id}: cannot create node: {e:?}"
            )))
        })?;
    let out = PlaneOutput::new(&node, id).map_err(internal)?;
    // Publish tick 0 so readers see the plane (and late joiners get history) at once.
    out.publish(plane.as_mut()).map_err(internal)?;
    let info = plane.apply(PlaneOp::Info)?;
    tracing::info!(plane = id, kind = ?setup.kind, ?info, "plane created");
    Ok((
        Worker {
            id,
            plane,
            out,
            usage: setup.usage.clone(),
            panic_on_step_dt: setup.panic_on_step_dt,
            period: None,
            next_tick: None,
            _node: node,
        },
        info,
    ))
}

impl Worker {
    /// The period the plane asks for now: `None` when manual, disabled, or not
    /// representable (validation keeps rates within bounds; this never panics).
    fn wanted_period(&self) -> Option<Duration> {
        let rate = self.plane.tick_rate();
        if !(rate > 0.0 && self.plane.enabled()) {
            return None;
        }
        Duration::try_from_secs_f64(1.0 / rate as f64)
            .ok()
            .filter(|p| !p.is_zero())
    }

    /// Restarts the schedule when the plane's rate or Enabled changed.
    fn reschedule(&mut self, now: Instant) {
        let period = self.wanted_period();
        if period != self.period {
            self.period = period;
            self.next_tick = period.and_then(|p| now.checked_add(p));
        }
    }

    /// Runs the automatic tick when it is due. False when the plane panicked.
    fn tick_if_due(&mut self, now: Instant) -> bool {
        let (Some(due), Some(period)) = (self.next_tick.filter(|t| *t <= now), self.period) else {
            return true;
        };
        let (plane, out) = (&mut self.plane, &self.out);
        let stepped = catch_unwind(AssertUnwindSafe(|| {
            plane.step(period.as_secs_f32()).and_then(|stepped| {
                if stepped {
                    out.publish(plane.as_mut())
                        .map_err(super::dispatch::internal)?;
                }
                Ok(())
            })
        }));
        match stepped {
            Ok(Ok(())) => {}
            Ok(Err(e)) => tracing::warn!(plane = self.id, "tick failed: {e}"),
            Err(panic) => {
                let message = super::dispatch::panic_message(panic.as_ref());
                tracing::error!(plane = self.id, "plane failed and was removed: {message}");
                return false;
            }
        }
        self.usage.set(self.plane.usage());
        // Keep the cadence; after a stall, restart from now instead of catching up.
        let now = Instant::now();
        let next = due + period;
        self.next_tick = Some(if next + period * 4 < now {
            now + period
        } else {
            next
        });
        true
    }

    /// Applies a run of ops in order. A panic fails the plane: that op gets an error naming
    /// it, the rest of the run find the plane gone.
    fn run_ops(&mut self, ops: Vec<PlaneOp>, budget: Budget) -> (Vec<CommandResult>, bool) {
        let mut results = Vec::with_capacity(ops.len());
        let id = self.id;
        let mut ops = ops.into_iter();
        for op in ops.by_ref() {
            let outcome = catch_unwind(AssertUnwindSafe(|| self.op(op, &budget)));
            match outcome {
                Ok(result) => results.push(result),
                Err(panic) => {
                    let message = super::dispatch::panic_message(panic.as_ref());
                    tracing::error!(plane = id, "plane failed and was removed: {message}");
                    results.push(Err(CommandError::new(
                        ErrorKind::Internal,
                        format!("plane {id} failed and was removed: {message}"),
                    )));
                    results.extend(ops.map(|_| Err(unknown_plane(id))));
                    return (results, true);
                }
            }
        }
        self.reschedule(Instant::now());
        (results, false)
    }

    fn op(&mut self, op: PlaneOp, budget: &Budget) -> CommandResult {
        check_quota(self.plane.as_ref(), &op, budget)?;
        match op {
            PlaneOp::Step { dt } => {
                if self.panic_on_step_dt == Some(dt) {
                    panic!("injected fault: Step({dt})");
                }
                if self.plane.step(dt)? {
                    self.out
                        .publish(self.plane.as_mut())
                        .map_err(super::dispatch::internal)?;
                }
                Ok(Reply::Stepped {
                    tick: self.plane.tick(),
                })
            }
            op => {
                if op == PlaneOp::Info {
                    // A reader that just subscribed gets the newest tick at once.
                    self.out.connect_readers();
                }
                let result = self.plane.apply(op);
                // A rate or Enabled change takes effect from now.
                self.reschedule(Instant::now());
                result
            }
        }
    }
}

/// What `op` adds must fit the quotas of the plane's owner.
fn check_quota(plane: &dyn Backend, op: &PlaneOp, budget: &Budget) -> Result<(), CommandError> {
    let cost = op.cost();
    if cost == Default::default() {
        return Ok(());
    }
    let limits = &budget.limits;
    if cost.mesh_vertices > limits.mesh_vertices_per_object {
        return Err(exceeded(
            "mesh vertices per object",
            limits.mesh_vertices_per_object,
            "max-mesh-vertices",
            cost.mesh_vertices,
        ));
    }
    let own = plane.usage();
    let objects = budget.other.objects + own.objects + cost.objects as u64;
    let vertices = budget.other.mesh_vertices + own.mesh_vertices + cost.mesh_vertices;
    if objects > limits.objects_per_client {
        return Err(exceeded(
            "objects per client",
            limits.objects_per_client,
            "max-objects-per-client",
            objects,
        ));
    }
    if vertices > limits.mesh_vertices_per_client {
        return Err(exceeded(
            "mesh vertices per client",
            limits.mesh_vertices_per_client,
            "max-mesh-vertices-per-client",
            vertices,
        ));
    }
    Ok(())
}

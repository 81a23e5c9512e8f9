//! One plane's worker: a thread that owns the plane and its shared-memory output, applies the
//! command runs the request loop hands it (in the order they arrive), steps and publishes
//! the plane (on `Step`, or on its own schedule when it ticks automatically), and reports
//! back to the request loop. Planes therefore step side by side, and a heavy tick of one
//! plane never holds up a request for another.
//!
//! The plane itself sits behind a mutex ([`PlaneCell`]) so that the request loop can apply a
//! short run of ops inline, with no hand-over, when the worker is idle and nothing is queued
//! for the plane ([`PlaneCell::try_apply`]): one round trip then costs no thread wake-ups.
//! Steps and anything that touches the plane's shared-memory output stay on the worker.
//!
//! The worker thread is the only thread of a rayon pool of its own, so the parallel parts of
//! a plane's step (rapier's, for planes without a pool of their own) run on the plane's own
//! thread instead of queueing on the process-wide pool behind every other plane's step.
//!
//! The worker has an iceoryx2 node of its own (ports stay on the thread that made them).

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::mpsc::{Receiver, RecvTimeoutError, Sender};
use std::sync::{Arc, Mutex, MutexGuard, TryLockError};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use iceoryx2::config::Config;
use iceoryx2::prelude::*;
use iceoryx2_bb_posix::socket_pair::StreamingSocket;
use shm_layout::{
    CommandError, CommandResult, ErrorKind, PlaneId, PlaneKind, PlaneOp, PlaneProp, Reply,
};

use super::dispatch::unknown_plane;
use super::limits::{exceeded, Limits};
use crate::backend::{Backend, Usage};
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
    /// The loop changed the plane's tick rate or Enabled inline: restart the schedule.
    Reschedule,
    /// Finish the queued jobs, then drop the plane and end.
    Stop,
    /// Write the (persistent) plane's file now; answer with `ticket` once it is on disk.
    Save { ticket: u64 },
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

/// The quotas a run is checked against: the limits, how many reply bytes the request it
/// belongs to may still fill, and who pays for what it adds.
#[derive(Debug, Clone)]
pub(super) struct Budget {
    pub limits: Limits,
    pub reply_left: usize,
    /// The requesting process's total when it is not the plane owner's (a `Shared` plane):
    /// the objects it adds count against it.
    pub guest: Option<Arc<super::quota::OwnerUsage>>,
    /// The requesting connection's snapshot transfers: a snapshot too large for the reply
    /// waits there as a download.
    pub transfers: Option<Arc<super::transfers::ClientTransfers>>,
}

/// A plane's usage, counted in its owner's total.
pub(super) type SharedUsage = super::quota::PlaneUsage;

/// The plane, shared by its worker and the request loop.
#[derive(Default)]
pub(super) struct PlaneCell {
    /// `None` until the worker created the plane, and after the plane failed.
    plane: Mutex<Option<Box<dyn Backend>>>,
    /// Runs handed to the worker that it has not finished applying. While any is, the loop
    /// never applies a run inline (it would overtake them).
    queued: AtomicUsize,
    /// Its tick, whether it changed since its last write, held or destroyed (`persist`).
    pub marks: super::persist::Marks,
}

/// What [`PlaneCell::try_apply`] did.
pub(super) enum Inline {
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
    /// query's time grows with its rays and filter, so it runs on the plane's worker).
    pub fn inline_op(op: &PlaneOp) -> bool {
        !matches!(
            op,
            PlaneOp::Step { .. }
                | PlaneOp::Info
                | PlaneOp::Map(_)
                | PlaneOp::Query(_)
                | PlaneOp::Snapshot
                | PlaneOp::Restore { .. }
                | PlaneOp::Rewind(_)
                | PlaneOp::Save
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
    fn note_changes(&self, ops: &[PlaneOp]) {
        if ops.iter().any(|op| !op.is_read_only()) {
            self.marks.changed.store(true, Ordering::SeqCst);
        }
    }

    fn lock(&self) -> MutexGuard<'_, Option<Box<dyn Backend>>> {
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

    pub(super) fn wake(&self) {
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
    pub cell: Arc<PlaneCell>,
    pub usage: Arc<SharedUsage>,
    pub events: Sender<Event>,
    pub waker: Arc<Waker>,
    pub panic_on_step_dt: Option<f32>,
    /// The plane's file, when it is persistent.
    pub file: Option<super::persist::PlaneFile>,
    /// A snapshot the plane starts from (a persistent plane restored at start).
    pub restore: Option<Vec<u8>>,
}

/// Starts the worker of a plane: a thread that is the only thread of a rayon pool of its
/// own (so the plane's parallel work runs on it), running [`run`]. Returns the thread.
pub(super) fn spawn(mut setup: Setup, jobs: Receiver<Job>) -> std::io::Result<JoinHandle<()>> {
    let id = setup.id;
    let mut thread = None;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .thread_name(move |_| format!("plane-{id}"))
        // `run` catches the plane's panics; anything else is logged, not an abort.
        .panic_handler(move |panic| {
            let message = super::dispatch::panic_message(panic.as_ref());
            tracing::error!(plane = id, "plane worker failed: {message}");
        })
        .spawn_handler(|builder| {
            let mut named = std::thread::Builder::new();
            if let Some(name) = builder.name() {
                named = named.name(name.to_string());
            }
            thread = Some(named.spawn(move || builder.run())?);
            Ok(())
        })
        .build()
        .map_err(std::io::Error::other)?;
    let file = setup.file.take();
    // The job keeps the pool alive until it returns; the pool's thread ends after it.
    pool.spawn(move || run(setup, file, jobs));
    drop(pool);
    thread.ok_or_else(|| std::io::Error::other("the pool started no thread"))
}

/// The worker thread's body.
fn run(setup: Setup, file: Option<super::persist::PlaneFile>, jobs: Receiver<Job>) {
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
    let created = catch_unwind(AssertUnwindSafe(|| create(&setup))).unwrap_or_else(|panic| {
        Err(CommandError::new(
            ErrorKind::Internal,
            format!(
                "creating plane {id} failed: {}",
                super::dispatch::panic_message(panic.as_ref())
            ),
        ))
    });
    let mut worker = match created {
        Ok((worker, info)) => {
            report(Event::Done {
                ticket,
                plane: id,
                results: vec![Ok(info)],
                failed: false,
            });
            worker
        }
        Err(e) => {
            report(Event::Done {
                ticket,
                plane: id,
                results: vec![Err(e)],
                failed: true,
            });
            return drain(id, jobs, &report);
        }
    };
    worker.file = file;
    worker.reschedule(Instant::now());
    loop {
        let wake = match (worker.next_tick, worker.file.as_ref().map(|f| f.due())) {
            (Some(a), Some(b)) => Some(a.min(b)),
            (a, b) => a.or(b),
        };
        let job = match wake {
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
            Some(Job::Stop) => {
                worker.finish_file();
                return;
            }
            Some(Job::Reschedule) => worker.reschedule(Instant::now()),
            Some(Job::Save { ticket }) => {
                let result = worker.save_now();
                report(Event::Done {
                    ticket,
                    plane: id,
                    results: vec![result],
                    failed: false,
                });
            }
            Some(Job::Run {
                ticket,
                ops,
                budget,
            }) => {
                let (results, failed) = worker.run_job(ops, budget);
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
        if !worker.tick_if_due(Instant::now()) || !worker.idle_work() {
            report(Event::Failed { plane: id });
            return drain(id, jobs, &report);
        }
        worker.save_if_due(Instant::now());
    }
}

/// After the plane failed: answers what is still queued (the loop forgets the plane once it
/// reads the failure) until told to stop.
fn drain(id: PlaneId, jobs: Receiver<Job>, report: &dyn Fn(Event)) {
    loop {
        match jobs.recv() {
            Ok(Job::Run { ticket, ops, .. }) => report(Event::Done {
                ticket,
                plane: id,
                results: ops.iter().map(|_| Err(unknown_plane(id))).collect(),
                failed: true,
            }),
            Ok(Job::Reschedule) => {}
            Ok(Job::Save { ticket }) => report(Event::Done {
                ticket,
                plane: id,
                results: vec![Err(unknown_plane(id))],
                failed: true,
            }),
            Ok(Job::Stop) | Err(_) => return,
        }
    }
}

struct Worker {
    id: PlaneId,
    cell: Arc<PlaneCell>,
    out: PlaneOutput,
    usage: Arc<SharedUsage>,
    panic_on_step_dt: Option<f32>,
    /// The tick period the schedule was made for; `None` for manual or disabled planes.
    period: Option<Duration>,
    /// When the next automatic tick is due; `None` for manual or disabled planes.
    next_tick: Option<Instant>,
    /// The plane's file, when it is persistent.
    file: Option<super::persist::PlaneFile>,
    // The node goes last: the ports above are dropped before it.
    _node: Node<ipc::Service>,
}

impl Drop for Worker {
    fn drop(&mut self) {
        // The plane goes with its worker (before the worker's ports and node).
        self.cell.lock().take();
        self.usage.release();
    }
}

fn create(setup: &Setup) -> Result<(Worker, Reply), CommandError> {
    let id = setup.id;
    let internal = |e: DaemonError| CommandError::new(ErrorKind::Internal, e.to_string());
    let mut plane = crate::kinds::create(setup.kind, id, &setup.props)?;
    if let Some(bytes) = &setup.restore {
        plane.apply(PlaneOp::Restore {
            bytes: bytes.clone(),
            overrides: Vec::new(),
        })?;
    }
    setup.cell.marks.tick.store(plane.tick(), Ordering::SeqCst);
    // A new plane is written at once; a restored one only once it changes (its file holds
    // it already, and a daemon killed again before anyone opens it keeps that file as is).
    setup
        .cell
        .marks
        .changed
        .store(setup.restore.is_none(), Ordering::SeqCst);
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
    for prop in &setup.props {
        if let PlaneProp::SharedObjectLimit(limit) = prop {
            setup.usage.set_guest_limit(*limit);
        }
    }
    setup.usage.update(plane.as_ref());
    *setup.cell.lock() = Some(plane);
    Ok((
        Worker {
            id,
            cell: setup.cell.clone(),
            out,
            usage: setup.usage.clone(),
            panic_on_step_dt: setup.panic_on_step_dt,
            period: None,
            next_tick: None,
            file: None,
            _node: node,
        },
        info,
    ))
}

impl Worker {
    /// Restarts the schedule when the plane's rate or Enabled changed.
    fn reschedule(&mut self, now: Instant) {
        let period = match self.cell.marks.held.load(Ordering::SeqCst) {
            // A restored plane waits for its first Open.
            true => None,
            false => self.cell.lock().as_deref().and_then(wanted_period),
        };
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
        // The owner's process is past its CPU share (see `fair`): this plane waits too.
        if let Some(ready) = self.usage.owner().cpu.ready_at(now) {
            self.next_tick = Some(ready);
            return true;
        }
        let started = Instant::now();
        let mut guard = self.cell.lock();
        let Some(plane) = guard.as_mut() else {
            return false;
        };
        let out = &self.out;
        // A plane slower than 1 Hz steps its period in equal pieces of at most MAX_DT (the
        // longest step the engines take) and publishes once.
        let (pieces, dt) = pieces_of(period);
        let stepped = catch_unwind(AssertUnwindSafe(|| {
            let mut stepped = false;
            for _ in 0..pieces {
                stepped |= plane.step(dt)?;
            }
            if stepped {
                out.publish(plane.as_mut())
                    .map_err(super::dispatch::internal)?;
            }
            Ok::<(), CommandError>(())
        }));
        match stepped {
            Ok(Ok(())) => {}
            Ok(Err(e)) => tracing::warn!(plane = self.id, "tick failed: {e}"),
            Err(panic) => {
                let message = super::dispatch::panic_message(panic.as_ref());
                tracing::error!(plane = self.id, "plane failed and was removed: {message}");
                *guard = None;
                self.usage.release();
                return false;
            }
        }
        self.usage.update(plane.as_ref());
        self.cell.marks.tick.store(plane.tick(), Ordering::SeqCst);
        self.cell.marks.changed.store(true, Ordering::SeqCst);
        drop(guard);
        // Keep the cadence; after a stall, restart from now instead of catching up.
        let now = Instant::now();
        let next = due + period;
        let next = if next + period * 4 < now {
            now + period
        } else {
            next
        };
        // A process past its CPU share slows its own planes.
        let ready = self.usage.owner().cpu.charge(now - started, now);
        self.next_tick = Some(ready.map_or(next, |r| r.max(next)));
        true
    }

    /// What the plane put off its tick's path (`Backend::idle_work`), now that the tick is
    /// answered. False when the plane panicked.
    fn idle_work(&mut self) -> bool {
        let mut guard = self.cell.lock();
        let Some(plane) = guard.as_mut() else {
            return true;
        };
        match catch_unwind(AssertUnwindSafe(|| plane.idle_work())) {
            Ok(Ok(())) => {
                self.usage.update(plane.as_ref());
                true
            }
            Ok(Err(e)) => {
                tracing::warn!(plane = self.id, "keeping the tick failed: {e}");
                true
            }
            Err(panic) => {
                let message = super::dispatch::panic_message(panic.as_ref());
                tracing::error!(plane = self.id, "plane failed and was removed: {message}");
                *guard = None;
                self.usage.release();
                false
            }
        }
    }

    /// Applies a run handed over by the loop, under the plane's lock.
    fn run_job(&mut self, ops: Vec<PlaneOp>, budget: Budget) -> (Vec<CommandResult>, bool) {
        let mut guard = self.cell.lock();
        self.cell.note_changes(&ops);
        let outcome = match guard.as_mut() {
            Some(plane) => {
                let (results, failed) = run_ops(
                    self.id,
                    plane.as_mut(),
                    ops,
                    &budget,
                    &self.usage,
                    Some(&self.out),
                    self.panic_on_step_dt,
                );
                if failed {
                    *guard = None;
                    self.usage.release();
                } else {
                    self.usage.update(plane.as_ref());
                    self.cell.marks.tick.store(plane.tick(), Ordering::SeqCst);
                }
                (results, failed)
            }
            None => (
                ops.iter().map(|_| Err(unknown_plane(self.id))).collect(),
                true,
            ),
        };
        // Finished before the lock goes: the loop may apply the next run inline.
        self.cell.queued.fetch_sub(1, Ordering::SeqCst);
        drop(guard);
        if !outcome.1 {
            self.reschedule(Instant::now());
        }
        outcome
    }
}

impl Worker {
    /// The periodic write of a persistent plane (see `persist`).
    fn save_if_due(&mut self, now: Instant) {
        let Some(file) = self.file.as_mut() else {
            return;
        };
        if !file.is_due(now, self.cell.marks.tick.load(Ordering::SeqCst)) {
            return;
        }
        let mut guard = self.cell.lock();
        if let Some(plane) = guard.as_mut() {
            file.save_if_due(plane.as_mut(), &self.cell.marks, now);
        }
    }

    /// `Save`: the plane's file written now (after the runs handed over before it).
    fn save_now(&mut self) -> CommandResult {
        let mut guard = self.cell.lock();
        let result = match (self.file.as_mut(), guard.as_mut()) {
            (Some(file), Some(plane)) => file.save_now(plane.as_mut(), &self.cell.marks),
            (None, _) => Err(CommandError::invalid_field(
                "Persistent",
                format!(
                    "plane {} is not persistent: only planes created with a Name and \
                     Persistent = true are written to the state directory (use Snapshot to \
                     keep any plane's state)",
                    self.id
                ),
            )),
            (_, None) => Err(unknown_plane(self.id)),
        };
        // Finished before the lock goes: the loop may apply the next run inline.
        self.cell.queued.fetch_sub(1, Ordering::SeqCst);
        drop(guard);
        result
    }

    /// The worker ends: a persistent plane is written one last time (or its files removed
    /// when its owner destroyed it).
    fn finish_file(&mut self) {
        if let Some(mut file) = self.file.take() {
            let mut guard = self.cell.lock();
            file.finish(
                guard.as_mut().map(|p| p.as_mut() as &mut dyn Backend),
                &self.cell.marks,
            );
        }
    }
}

/// How an automatic tick of `period` steps: the number of steps and the dt of each (equal
/// pieces of at most [`shm_layout::validate::MAX_DT`]).
fn pieces_of(period: Duration) -> (u32, f32) {
    let max = shm_layout::validate::MAX_DT as f64;
    let secs = period.as_secs_f64();
    let pieces = (secs / max).ceil().max(1.0) as u32;
    (pieces, (secs / pieces as f64) as f32)
}

/// The period `plane` asks for now: `None` when manual, disabled, or not representable
/// (validation keeps rates within bounds; this never panics).
fn wanted_period(plane: &dyn Backend) -> Option<Duration> {
    let rate = plane.tick_rate();
    if !(rate > 0.0 && plane.enabled()) {
        return None;
    }
    Duration::try_from_secs_f64(1.0 / rate as f64)
        .ok()
        .filter(|p| !p.is_zero())
}

/// Applies a run of ops in order. A panic fails the plane: that op gets an error naming it,
/// the rest of the run find the plane gone. `out` is the plane's output (on its worker;
/// `None` inline, where runs hold no op that needs it).
fn run_ops(
    id: PlaneId,
    plane: &mut dyn Backend,
    ops: Vec<PlaneOp>,
    budget: &Budget,
    usage: &SharedUsage,
    out: Option<&PlaneOutput>,
    panic_on_step_dt: Option<f32>,
) -> (Vec<CommandResult>, bool) {
    let mut results = Vec::with_capacity(ops.len());
    let mut reply_left = budget.reply_left;
    let mut ops = ops.into_iter();
    for op in ops.by_ref() {
        let outcome = catch_unwind(AssertUnwindSafe(|| {
            apply_op(id, plane, out, panic_on_step_dt, op, budget, usage)
        }));
        match outcome {
            Ok(result) => {
                let result = stage_large(result, reply_left, budget);
                let result = count_reply(result, &mut reply_left, &budget.limits);
                results.push(result)
            }
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
    (results, false)
}

fn apply_op(
    id: PlaneId,
    plane: &mut dyn Backend,
    out: Option<&PlaneOutput>,
    panic_on_step_dt: Option<f32>,
    op: PlaneOp,
    budget: &Budget,
    usage: &SharedUsage,
) -> CommandResult {
    let cost = op.cost();
    if let PlaneOp::Set(PlaneProp::SharedObjectLimit(limit)) = op {
        let result = apply_inner(plane, out, panic_on_step_dt, op);
        if result.is_ok() {
            usage.set_guest_limit(limit);
        }
        return result;
    }
    if let PlaneOp::Step { .. } = op {
        // Explicit steps are charged to the owner's CPU account (never postponed).
        let started = Instant::now();
        let result = apply_inner(plane, out, panic_on_step_dt, op);
        let now = Instant::now();
        usage.owner().cpu.charge(now - started, now);
        return result;
    }
    if cost == Default::default() {
        return apply_inner(plane, out, panic_on_step_dt, op);
    }
    // An object another process adds to this (shared) plane counts against that process,
    // within the owner's SharedObjectLimit, for as long as the object lives.
    if let (Some(guest), PlaneOp::AddObject { .. }) = (&budget.guest, &op) {
        usage.check_guest_room(id, cost.objects as u64)?;
        let reserved = guest.reserve(&budget.limits, cost)?;
        let result = apply_inner(plane, out, panic_on_step_dt, op);
        if let Ok(Reply::Object { handle, .. }) = &result {
            reserved.keep();
            let paid = Usage {
                objects: cost.objects as u64,
                mesh_vertices: cost.mesh_vertices,
                state_bytes: cost.state_bytes,
            };
            usage.add_guest(*handle, guest.clone(), paid);
        }
        usage.update(&*plane);
        return result;
    }
    // Reserved before the op runs, released after the plane's count holds what it added:
    // runs of the same process on other planes cannot overtake it.
    let _reserved = usage.owner().reserve(&budget.limits, cost)?;
    let result = apply_inner(plane, out, panic_on_step_dt, op);
    usage.update(&*plane);
    result
}

fn apply_inner(
    plane: &mut dyn Backend,
    out: Option<&PlaneOutput>,
    panic_on_step_dt: Option<f32>,
    op: PlaneOp,
) -> CommandResult {
    let needs_output = matches!(
        op,
        PlaneOp::Step { .. } | PlaneOp::Info | PlaneOp::Restore { .. } | PlaneOp::Rewind(_)
    );
    let out = match out {
        Some(out) => Some(out),
        None if needs_output => {
            return Err(CommandError::new(
                ErrorKind::Internal,
                format!("{} must run on the plane's worker", op_name(&op)),
            ))
        }
        None => None,
    };
    match op {
        PlaneOp::Step { dt } => {
            if panic_on_step_dt == Some(dt) {
                panic!("injected fault: Step({dt})");
            }
            if plane.step(dt)? {
                if let Some(out) = out {
                    out.publish(plane).map_err(super::dispatch::internal)?;
                }
            }
            Ok(Reply::Stepped { tick: plane.tick() })
        }
        // Readers see the restored state at once, as after a step.
        op @ (PlaneOp::Restore { .. } | PlaneOp::Rewind(_)) => {
            let reply = plane.apply(op)?;
            if let Some(out) = out {
                out.publish(plane).map_err(super::dispatch::internal)?;
            }
            Ok(reply)
        }
        op => {
            if op == PlaneOp::Info {
                // A reader that just subscribed gets the newest tick at once.
                if let Some(out) = out {
                    out.connect_readers();
                }
            }
            plane.apply(op)
        }
    }
}

/// The op's variant for messages (never its payload: a restore carries megabytes).
fn op_name(op: &PlaneOp) -> &'static str {
    match op {
        PlaneOp::Step { .. } => "Step",
        PlaneOp::Info => "Info",
        PlaneOp::Restore { .. } => "Restore",
        PlaneOp::Rewind(_) => "Rewind",
        _ => "this op",
    }
}

/// A snapshot larger than [`shm_layout::snapshot_transfer::STAGE_ABOVE`] (or than what the
/// reply may still hold) is kept as a download of the requester's and answered with its
/// number; everything else passes unchanged.
fn stage_large(result: CommandResult, reply_left: usize, budget: &Budget) -> CommandResult {
    match (result, &budget.transfers) {
        (Ok(Reply::Snapshot(bytes)), Some(transfers))
            if bytes.len() > shm_layout::snapshot_transfer::STAGE_ABOVE.min(reply_left) =>
        {
            transfers.stage(bytes)
        }
        (result, _) => result,
    }
}

/// Results up to this size always go out (an acknowledgement, a step's tick): they are
/// about as big as the commands that asked for them, so they amplify nothing.
const SMALL_RESULT: usize = 64;

/// `result`, or a `Quota` error when it would pass what the request's reply may still
/// hold; takes its size from `left`.
fn count_reply(result: CommandResult, left: &mut usize, limits: &Limits) -> CommandResult {
    let size = shm_layout::codec::result_size(&result);
    if size > *left && size > SMALL_RESULT {
        let used = limits.reply_bytes.saturating_sub(*left);
        return Err(exceeded(
            "reply bytes per request",
            limits.reply_bytes,
            "max-reply-bytes",
            used.saturating_add(size),
        ));
    }
    *left = left.saturating_sub(size);
    result
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slow_ticks_step_in_pieces_of_at_most_max_dt() {
        let max = shm_layout::validate::MAX_DT;
        assert_eq!(pieces_of(Duration::from_secs_f64(1.0 / 60.0)).0, 1);
        for rate in [0.9f64, 0.5, 0.01] {
            let (n, dt) = pieces_of(Duration::from_secs_f64(1.0 / rate));
            assert!(dt <= max && dt > 0.0, "rate {rate}: dt {dt}");
            assert!(
                (n as f64 * dt as f64 - 1.0 / rate).abs() < 1e-4,
                "rate {rate}"
            );
        }
    }
}

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

mod cell;
mod messages;
mod ops;

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::atomic::Ordering;
use std::sync::mpsc::{Receiver, RecvTimeoutError, Sender};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use iceoryx2::config::Config;
use iceoryx2::prelude::*;
use shm_layout::{
    CommandError, CommandResult, ErrorKind, PlaneId, PlaneKind, PlaneOp, PlaneProp, Reply,
};

use crate::backend::Backend;
use crate::publish::PlaneOutput;
use crate::server::requests::refusals::{self, unknown_plane};
use crate::DaemonError;

use crate::server::persistence::persist;
pub(crate) use cell::{Inline, PlaneCell};
pub(crate) use messages::{Budget, Event, Job, SharedUsage, Waker};
use ops::run_ops;

/// Everything a worker starts with.
pub(crate) struct Setup {
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
    pub file: Option<persist::PlaneFile>,
    /// A snapshot the plane starts from (a persistent plane restored at start).
    pub restore: Option<Vec<u8>>,
    /// How the plane records (`--record`, `record`).
    pub record: crate::record::RecordSettings,
    /// It arrived from another daemon where it was recording: it records on here.
    pub arrived_recording: bool,
}

/// Starts the worker of a plane: a thread that is the only thread of a rayon pool of its
/// own (so the plane's parallel work runs on it), running [`run`]. Returns the thread.
pub(crate) fn spawn(mut setup: Setup, jobs: Receiver<Job>) -> std::io::Result<JoinHandle<()>> {
    let id = setup.id;
    let mut thread = None;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .thread_name(move |_| format!("plane-{id}"))
        // `run` catches the plane's panics; anything else is logged, not an abort.
        .panic_handler(move |panic| {
            let message = refusals::panic_message(panic.as_ref());
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
fn run(setup: Setup, file: Option<persist::PlaneFile>, jobs: Receiver<Job>) {
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
                refusals::panic_message(panic.as_ref())
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
    file: Option<persist::PlaneFile>,
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
    let kind = crate::kinds::create(setup.kind, id, &setup.props)?;
    let mut recorded = crate::record::Recorded::new(kind, id, setup.record.clone());
    if let Some(bytes) = &setup.restore {
        recorded.apply(PlaneOp::Restore {
            bytes: bytes.clone(),
            overrides: Vec::new(),
        })?;
    }
    // `--record DIR`: from its first state here (a restored or arrived plane's included).
    recorded.record_if_asked(setup.arrived_recording);
    let mut plane: Box<dyn Backend> = Box::new(recorded);
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
                out.publish(plane.as_mut()).map_err(refusals::internal)?;
            }
            Ok::<(), CommandError>(())
        }));
        match stepped {
            Ok(Ok(())) => {}
            Ok(Err(e)) => tracing::warn!(plane = self.id, "tick failed: {e}"),
            Err(panic) => {
                let message = refusals::panic_message(panic.as_ref());
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
                let message = refusals::panic_message(panic.as_ref());
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

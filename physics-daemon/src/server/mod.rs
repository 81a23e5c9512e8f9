//! The daemon's request loop. It sleeps in an iceoryx2 WaitSet until a client announces a
//! request, a plane worker reports, or (while clients are connected) housekeeping is due, so
//! an idle daemon costs no CPU.
//!
//! Every plane lives on a worker thread of its own (`worker`): it applies the command runs
//! the loop hands it, in order, steps and publishes. The loop itself never steps: a request
//! whose commands wait on a plane is parked (its client's later requests queue behind it)
//! while the loop serves everyone else, and its reply goes out when the last of its commands
//! is answered. So planes step in parallel, a heavy tick of one plane never delays a request
//! for another, and `Step` replies once its tick is published.
//!
//! A short run that neither steps nor touches shared memory (a write, a query) is applied
//! by the loop itself when the plane's worker is idle and no run is queued for it: it then
//! lands exactly where a hand-over would have put it, and its round trip costs no thread
//! wake-ups. A busy worker (stepping, publishing, or with runs queued) gets the run handed
//! over as before, so the loop never waits for a plane.
//!
//! - `clients`: who is connected, and noticing clients that died.
//! - `dispatch`: decoding requests and routing each command to its plane by id.
//!
//! The server knows planes only through [`crate::backend::Backend`]: it never names an
//! engine type, an object property or a per-feature op.

pub mod alarm;
pub mod clients;
mod dispatch;
pub mod fair;
pub mod files;
pub mod folder_watch;
pub mod gauge;
pub mod heartbeat;
pub mod limits;
pub mod liveness;
pub mod moves;
mod named;
mod origin;
pub mod persist;
pub mod pidwatch;
pub mod quota;
mod request_bytes;
pub mod resources;
mod serve;
mod transfers;
pub mod trim;
mod worker;

use std::collections::{BTreeMap, HashMap, VecDeque};
use std::sync::atomic::AtomicBool;
use std::sync::mpsc::{Receiver, Sender};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use iceoryx2::active_request::ActiveRequest;
use iceoryx2::config::Config;
use iceoryx2::port::server::Server;
use iceoryx2::prelude::*;
use shm_layout::{names, Command, CommandResult, PlaneId};

use crate::publish::MAX_NODES;
use crate::DaemonError;
use clients::Clients;
pub use limits::Limits;
use worker::{Event, Inline, Job, PlaneCell, SharedUsage, Waker};

/// How the daemon runs beyond its domain.
#[derive(Debug, Clone, Default)]
pub struct Options {
    /// Per-client quotas.
    pub limits: Limits,
    /// The process that started this daemon on demand: once it is gone and no client is
    /// left, the daemon exits.
    pub starter_pid: Option<u32>,
    /// Fault injection for tests: a `Step` with exactly this dt panics inside the plane.
    #[doc(hidden)]
    pub panic_on_step_dt: Option<f32>,
    /// Where persistent planes are written (`--state-dir`, `--snapshot-every`); `None`:
    /// `Persistent = true` is refused.
    pub persistence: Option<persist::Persistence>,
    /// Fed the planes' usage for the cluster's load report (`--cluster`); `None` outside a
    /// cluster.
    pub load: Option<Arc<gauge::Gauge>>,
    /// Planes a cluster peer hands over at run time (failover, `--cluster` with
    /// `--state-dir`); `None` outside a cluster.
    pub adopt: Option<Arc<persist::Adoptions>>,
    /// How planes move to and arrive from other daemons (`--cluster`; `MoveTo`); `None`
    /// outside a cluster.
    pub migrate: Option<Arc<moves::Migration>>,
}

/// How often dead clients are looked for while clients are connected (and, for a daemon
/// started on demand, whether its starter is gone). Otherwise the daemon has nothing to look
/// for and sleeps until a request (or a shutdown wake-up).
const HOUSEKEEPING: Duration = Duration::from_millis(500);
/// Planes one daemon hosts at once.
pub const MAX_PLANES: usize = 1024;

/// The user header (u128) is what older clients sent as their id; it is ignored (identity
/// comes from the transport) but kept so the service layout never changes across versions.
type ControlServer = Server<ipc::Service, [u8], u128, [u8], ()>;
type Request = ActiveRequest<ipc::Service, [u8], u128, [u8], ()>;

/// The loop's view of a plane: who may do what, and the way to its worker.
struct PlaneEntry {
    /// Client that created the plane; the plane is released when that client goes away.
    owner: u128,
    /// Other clients may change the plane (only the owner destroys it).
    shared: bool,
    jobs: Sender<Job>,
    /// The plane, shared with its worker (short runs apply inline while the worker idles).
    cell: Arc<PlaneCell>,
    /// What the plane holds, as its worker last saw it (for the owner's other quotas).
    usage: Arc<SharedUsage>,
    /// Its kind.
    kind: shm_layout::PlaneKind,
    /// Its `Name`, unique in the domain (`named`).
    name: Option<shm_layout::PlaneName>,
    /// Written to the state directory and kept when its owner leaves (`persist`).
    persistent: bool,
    /// Restored from a file and not opened yet: the ticks it lost (`Recovered`).
    recovered: Option<u64>,
}

/// A request being served: its commands run in order; the loop parks it while one of its
/// runs is with a plane worker.
struct Pending {
    request: Request,
    origin: Origin,
    commands: VecDeque<Command>,
    results: Vec<CommandResult>,
    /// The job whose answer it waits for.
    waiting: Option<u64>,
    /// A reply decided without running commands (malformed, over a limit).
    early: Option<Vec<u8>>,
    /// Encoded bytes of `results` (counted against `--max-reply-bytes`).
    reply_bytes: usize,
}

/// Everything the daemon owns except the WaitSet, the request listener and the workers'
/// wake-up socket, which stay on the stack of [`run`] (the WaitSet borrows them).
pub struct Daemon {
    domain: String,
    config: Config,
    node: Node<ipc::Service>,
    server: ControlServer,
    clients: Clients,
    planes: BTreeMap<PlaneId, PlaneEntry>,
    next_plane_id: PlaneId,
    options: Options,
    /// Per client, its requests in arrival order; the first one is being served.
    queues: HashMap<u128, VecDeque<Pending>>,
    /// Jobs with a worker, and the client whose request waits for each.
    tickets: HashMap<u64, u128>,
    next_ticket: u64,
    events: Receiver<Event>,
    events_tx: Sender<Event>,
    waker: Arc<Waker>,
    workers: Vec<JoinHandle<()>>,
    /// Per client process, what its planes hold (quotas reserve against it atomically).
    owners: quota::Owners,
    /// Reply bytes the request being routed may still fill.
    reply_left: usize,
    /// The control service (its port list tells which node sent a request).
    control: origin::ControlService,
    /// Client port → node and process, for identifying senders.
    origins: origin::Origins,
    /// Who pays for what the command being routed adds, when not the plane's owner.
    guest: Option<Arc<quota::OwnerUsage>>,
    /// What the resource guard thread needs to know (who said Hello, which planes exist).
    watch: Arc<resources::Watch>,
    /// The writer of persistent planes (`--state-dir`).
    writer: Option<persist::Writer>,
    /// Each connection's open snapshot transfers (snapshots in pieces).
    transfers: HashMap<u128, Arc<transfers::ClientTransfers>>,
    /// Where a large snapshot of the command being routed is staged (its sender's transfers).
    stage_to: Option<Arc<transfers::ClientTransfers>>,
    /// When to list nodes to find gone clients (`liveness`).
    liveness: liveness::Schedule,
    /// Planes that moved to other daemons (`moves`).
    moved: moves::Tombstones,
}

/// Wakes the loop of the daemon of `domain` (e.g. from a signal handler thread after setting
/// the shutdown flag). Uses a node of its own: iceoryx2 ports stay on their thread.
pub fn wake(domain: &str) -> Result<(), DaemonError> {
    let config = names::config(domain)?;
    let node = NodeBuilder::new()
        .config(&config)
        .signal_handling_mode(SignalHandlingMode::Disabled)
        .create::<ipc::Service>()
        .map_err(|e| DaemonError::Ipc(format!("cannot create node: {e:?}")))?;
    let notifier = node
        .service_builder(&names::control_wake())
        .event()
        .open()
        .map_err(|e| DaemonError::Ipc(format!("cannot open the request event: {e:?}")))?
        .notifier_builder()
        .create()
        .map_err(|e| DaemonError::Ipc(format!("cannot create a notifier: {e:?}")))?;
    notifier
        .notify()
        .map_err(|e| DaemonError::Ipc(format!("cannot notify: {e:?}")))?;
    Ok(())
}

/// Runs the daemon of `domain` until `shutdown` becomes true; then releases every resource.
pub fn run(domain: &str, shutdown: &AtomicBool) -> Result<(), DaemonError> {
    run_with(domain, shutdown, Options::default())
}

/// [`run`] with explicit options (quotas, the on-demand starter).
pub fn run_with(domain: &str, shutdown: &AtomicBool, options: Options) -> Result<(), DaemonError> {
    let config = names::config(domain)?;
    files::check_ownership(domain)?;
    remove_dead_nodes(&config);
    let watch = Arc::new(resources::Watch::default());
    let trims = trim::Trims::default();
    let limits = options.limits;
    std::thread::scope(|s| {
        s.spawn(|| resources::run(&config, &limits, &watch));
        s.spawn(|| trim::run(&trims));
        let served = serve::serve(domain, &config, shutdown, options, watch.clone(), &trims);
        watch.stop();
        trims.stop();
        served
    })?;
    release_domain(&config);
    Ok(())
}

/// Removes what dead processes of `domain` left behind, and the domain's last segment when
/// no process of it is left (for tools and tests that kill daemons).
pub fn cleanup_domain(domain: &str) -> Result<(), DaemonError> {
    let config = names::config(domain)?;
    remove_dead_nodes(&config);
    release_domain(&config);
    Ok(())
}

/// The domain keeps one persistent segment (iceoryx2's node counter); the last process of the
/// domain removes it so a stopped deployment leaves nothing in /dev/shm.
fn release_domain(config: &Config) {
    // A node may be on its way out (the signal handler's waker): give it a moment.
    let deadline = Instant::now() + Duration::from_millis(300);
    loop {
        let mut nodes = 0;
        let _ = Node::<ipc::Service>::list(config, |_| {
            nodes += 1;
            CallbackProgression::Continue
        });
        if nodes == 0 {
            // SAFETY: no node of this domain exists any more, so nobody uses the segment.
            let _ =
                unsafe { iceoryx2::testing::remove_global_mgmt_segment::<ipc::Service>(config) };
            // The domain's own node directory, once empty (another process of the domain
            // starting now recreates it).
            let _ = std::fs::remove_dir(config.global.node_dir().to_string());
            return;
        }
        if Instant::now() > deadline {
            return;
        }
        std::thread::sleep(Duration::from_millis(5));
    }
}

/// Nodes that may open the control services: every client's, one spare each for nodes
/// that have not said Hello yet, and never fewer than a plane's services allow.
fn control_nodes(limits: &Limits) -> usize {
    (limits.max_clients * 2).max(MAX_NODES)
}

/// Removes what crashed processes of this domain left behind (a crashed daemon's server
/// port would otherwise block the new daemon).
fn remove_dead_nodes(config: &Config) {
    let mut dead = Vec::new();
    let _ = Node::<ipc::Service>::list(config, |state| {
        if let NodeState::Dead(view) = state {
            dead.push(view);
        }
        CallbackProgression::Continue
    });
    for view in dead {
        let _ = view.try_remove_stale_resources();
    }
}

/// The sender of a request, as the transport reports it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Origin {
    /// The sender's iceoryx2 node id.
    pub id: u128,
    /// The sender's process id.
    pub pid: u32,
}

impl Daemon {
    /// Takes every request that arrived: each joins its client's queue and runs at once
    /// unless an earlier request of the same client is still being served.
    fn serve_requests(&mut self) {
        loop {
            let request = match self.server.receive() {
                Ok(Some(request)) => request,
                Ok(None) => break,
                Err(e) => {
                    tracing::warn!("receive failed: {e:?}");
                    break;
                }
            };
            // Who sent it comes from the connection it arrived on (see `origin`), never from
            // the request header or the payload, which the sender writes: a client cannot
            // speak for another.
            let port = request.origin_client_id();
            let Some(origin) = self.origins.of(&self.control, port) else {
                tracing::warn!(
                    port = format!("{port:032x}"),
                    "request from a client port the service no longer lists: dropped"
                );
                continue;
            };
            let client = origin.id;
            let pending = match self.take_bytes(&request).and_then(|b| self.decode(&b)) {
                Ok(commands) => Pending {
                    request,
                    origin,
                    results: Vec::with_capacity(commands.len()),
                    commands: commands.into(),
                    waiting: None,
                    early: None,
                    reply_bytes: 0,
                },
                Err(reply) => Pending {
                    request,
                    origin,
                    commands: VecDeque::new(),
                    results: Vec::new(),
                    waiting: None,
                    early: Some(reply),
                    reply_bytes: 0,
                },
            };
            let queue = self.queues.entry(client).or_default();
            queue.push_back(pending);
            if queue.len() == 1 {
                self.advance(client);
            }
        }
    }

    /// Serves the requests of `client` in order until one waits for a worker or none is
    /// left.
    fn advance(&mut self, client: u128) {
        loop {
            let Some(mut pending) = self.queues.get_mut(&client).and_then(|q| q.pop_front()) else {
                self.queues.remove(&client);
                return;
            };
            if pending.waiting.is_some() {
                self.queues.entry(client).or_default().push_front(pending);
                return;
            }
            while let Some(command) = pending.commands.pop_front() {
                self.reply_left = self
                    .options
                    .limits
                    .reply_bytes
                    .saturating_sub(pending.reply_bytes);
                match self.route(pending.origin, command, &mut pending.commands) {
                    Routed::Now(results) => pending.count(results),
                    Routed::Wait(ticket) => {
                        pending.waiting = Some(ticket);
                        self.tickets.insert(ticket, client);
                        break;
                    }
                }
            }
            if pending.waiting.is_some() {
                self.queues.entry(client).or_default().push_front(pending);
                return;
            }
            self.reply(pending);
        }
    }

    /// Sends the reply of a finished request and wakes its client.
    fn reply(&self, pending: Pending) {
        let client = pending.origin.id;
        let bytes = pending.early.unwrap_or_else(|| {
            shm_layout::codec::encode_response(&shm_layout::Response::Results(pending.results))
        });
        let sent = pending
            .request
            .loan_slice_uninit(bytes.len())
            .map_err(|e| format!("{e:?}"))
            .and_then(|r| {
                r.write_from_slice(&bytes)
                    .send()
                    .map_err(|e| format!("{e:?}"))
            });
        if let Err(e) = sent {
            tracing::warn!(client = format!("{client:032x}"), "reply failed: {e}");
        }
        self.clients.wake(&self.node, client);
    }

    /// What the plane workers reported: answers of parked requests, failed planes.
    fn handle_events(&mut self) {
        while let Ok(event) = self.events.try_recv() {
            match event {
                Event::Done {
                    ticket,
                    plane,
                    results,
                    failed,
                } => {
                    if failed {
                        self.remove_plane(plane);
                    }
                    let Some(client) = self.tickets.remove(&ticket) else {
                        continue;
                    };
                    let Some(pending) = self
                        .queues
                        .get_mut(&client)
                        .and_then(|q| q.front_mut())
                        .filter(|p| p.waiting == Some(ticket))
                    else {
                        continue;
                    };
                    pending.count(results);
                    pending.waiting = None;
                    self.advance(client);
                }
                Event::Failed { plane } => self.remove_plane(plane),
            }
        }
    }

    /// Applies a run of ops for plane `id` at once when its worker is idle and nothing is
    /// queued for it (see [`PlaneCell::try_apply`]); otherwise hands it to the worker, and
    /// the ticket names its answer.
    fn send_job(&mut self, id: PlaneId, ops: Vec<shm_layout::PlaneOp>) -> Routed {
        let budget = self.budget();
        let n = ops.len();
        let Some(entry) = self.planes.get(&id) else {
            return Routed::Now((0..n).map(|_| Err(dispatch::unknown_plane(id))).collect());
        };
        let ops = match entry.cell.try_apply(id, ops, &budget, &entry.usage) {
            Inline::Applied {
                results,
                failed,
                reschedule,
            } => {
                if failed {
                    self.remove_plane(id);
                } else if reschedule {
                    let _ = entry.jobs.send(Job::Reschedule);
                }
                return Routed::Now(results);
            }
            Inline::HandOver(ops) => ops,
        };
        let ticket = self.next_ticket;
        self.next_ticket += 1;
        entry.cell.handed_over();
        match entry.jobs.send(Job::Run {
            ticket,
            ops,
            budget,
        }) {
            Ok(()) => Routed::Wait(ticket),
            Err(_) => Routed::Now((0..n).map(|_| Err(dispatch::unknown_plane(id))).collect()),
        }
    }

    /// Drops a plane (its worker finishes what is queued, then ends) and forgets it in its
    /// owner's list.
    fn remove_plane(&mut self, id: PlaneId) {
        if let Some(entry) = self.planes.remove(&id) {
            let _ = entry.jobs.send(Job::Stop);
            if let Some(c) = self.clients.get_mut(entry.owner) {
                c.planes.retain(|p| *p != id);
            }
        }
    }

    /// Ends every worker and waits for them (their planes' shared memory is gone after).
    fn stop_workers(&mut self) {
        let ids: Vec<PlaneId> = self.planes.keys().copied().collect();
        for id in ids {
            self.remove_plane(id);
        }
        for worker in self.workers.drain(..) {
            let _ = worker.join();
        }
    }

    fn release_client(&mut self, client: u128) {
        let owned: Vec<PlaneId> = self
            .planes
            .iter()
            .filter(|(_, p)| p.owner == client)
            .map(|(id, _)| *id)
            .collect();
        let owned = self.orphan_persistent(owned);
        for id in &owned {
            self.remove_plane(*id);
        }
        self.clients.disconnect(client);
        // The resource guard's Hello clock for its node starts again now (a Goodbye and a
        // Hello again on the same node are not a node that never said Hello).
        self.update_watch();
        // Its snapshot transfers (a half-sent restore, an unread download) go with it.
        self.transfers.remove(&client);
        tracing::info!(
            client = format!("{client:032x}"),
            planes_released = owned.len(),
            "client released"
        );
    }

    /// Whether this daemon was started on demand by a process that no longer runs (a
    /// zombie counts as gone).
    fn starter_gone(&self) -> bool {
        let Some(pid) = self.options.starter_pid else {
            return false;
        };
        match std::fs::read_to_string(format!("/proc/{pid}/stat")) {
            // The state follows the parenthesised command name.
            Ok(stat) => stat
                .rsplit_once(") ")
                .is_some_and(|(_, rest)| rest.starts_with('Z') || rest.starts_with('X')),
            Err(_) => true,
        }
    }

    /// Tells the resource guard who is connected and which planes exist.
    fn update_watch(&self) {
        self.watch
            .update(self.clients.ids(), self.planes.keys().copied());
    }

    fn release_gone_clients(&mut self) {
        // Listing nodes reads every node of the domain: only when a client's process exited,
        // a node came or went, or rarely (`liveness::Schedule`).
        let clients = &self.clients;
        let all_alive = || {
            clients.ids().all(|id| {
                clients
                    .get(id)
                    .is_some_and(|c| liveness::process_alive(c.pid))
            })
        };
        let pids = clients
            .ids()
            .filter_map(|id| clients.get(id).map(|c| c.pid));
        let folder = self.config.global.node_dir().to_string();
        if !self.liveness.list_now(pids, &folder, all_alive) {
            return;
        }
        for client in self.clients.reap(&self.config) {
            tracing::warn!(client = format!("{client:032x}"), "client process is gone");
            // Its requests go unanswered: nobody waits for them.
            self.queues.remove(&client);
            self.release_client(client);
        }
    }
}

impl Pending {
    /// Adds `results`, counting their encoded bytes.
    fn count(&mut self, results: Vec<CommandResult>) {
        self.reply_bytes = results
            .iter()
            .map(shm_layout::codec::result_size)
            .fold(self.reply_bytes, usize::saturating_add);
        self.results.extend(results);
    }
}

/// How a command was served.
enum Routed {
    /// Answered at once (one result per command taken).
    Now(Vec<CommandResult>),
    /// Handed to a plane worker; the answer comes with this ticket.
    Wait(u64),
}

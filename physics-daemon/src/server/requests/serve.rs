//! The daemon's request loop in named stages: open the transport ports, build the daemon,
//! then per wake-up wait, consume the wake-ups, serve one round (worker events, adopted
//! planes, requests, load, heartbeat) and look after the house when it is due; at the end,
//! stop the workers and flush the state writer. Each stage is a function below; the loop
//! itself only strings them together.

use std::collections::{BTreeMap, HashMap};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{mpsc, Arc};
use std::time::{Duration, Instant};

use iceoryx2::config::Config;
use iceoryx2::port::listener::Listener;
use iceoryx2::prelude::*;
use iceoryx2_bb_posix::socket_pair::StreamingSocket;
use shm_layout::names;

use crate::publish::MAX_NODES;
use crate::server::daemon::{ControlServer, Daemon, Options};
use crate::server::files;
use crate::server::liveness::{alarm, pidwatch, schedule};
use crate::server::moves::migration::Tombstones;
use crate::server::persistence::persist;
use crate::server::quotas::limits::Limits;
use crate::server::quotas::{quota, resources};
use crate::server::requests::clients::Clients;
use crate::server::requests::origin;
use crate::server::trim;
use crate::server::worker::Waker;
use crate::DaemonError;

/// How often dead clients are looked for while clients are connected (and, for a daemon
/// started on demand, whether its starter is gone). Otherwise the daemon has nothing to look
/// for and sleeps until a request (or a shutdown wake-up).
const HOUSEKEEPING: Duration = Duration::from_millis(500);

/// Nodes that may open the control services: every client's, one spare each for nodes
/// that have not said Hello yet, and never fewer than a plane's services allow.
fn control_nodes(limits: &Limits) -> usize {
    (limits.max_clients * 2).max(MAX_NODES)
}

/// The transport ports the daemon keeps: the node, the control service and its (single)
/// server. The request wake-up listener stays with the loop, which waits on it.
struct Ports {
    node: Node<ipc::Service>,
    control: origin::ControlService,
    server: ControlServer,
}

/// Runs the daemon of `domain` until `shutdown` (or, for an on-demand daemon, until its
/// starter is gone and no client is left).
pub(crate) fn serve(
    domain: &str,
    config: &Config,
    shutdown: &AtomicBool,
    options: Options,
    watch: Arc<resources::Watch>,
    trims: &trim::Trims,
) -> Result<(), DaemonError> {
    let (ports, listener) = open_ports(domain, config, &options)?;
    let waitset = WaitSetBuilder::new()
        .signal_handling_mode(SignalHandlingMode::Disabled)
        .create::<ipc::Service>()
        .map_err(|e| DaemonError::Ipc(format!("cannot create the waitset: {e:?}")))?;
    let _request_guard = waitset
        .attach_notification(&listener)
        .map_err(|e| DaemonError::Ipc(format!("cannot attach the request listener: {e:?}")))?;
    // Plane workers wake the loop through a socket pair the WaitSet watches.
    let (worker_wake, wake_end) = StreamingSocket::create_pair()
        .map_err(|e| DaemonError::Ipc(format!("cannot create the worker wake-up: {e:?}")))?;
    let _worker_guard = waitset
        .attach_notification(&worker_wake)
        .map_err(|e| DaemonError::Ipc(format!("cannot attach the worker wake-up: {e:?}")))?;
    let mut daemon = start(domain, config, ports, options, watch, wake_end)?;
    // A daemon started on demand hears of its starter's exit through a pidfd the WaitSet
    // watches, so without clients it sleeps until a request or that exit instead of
    // looking twice a second.
    let starter = daemon
        .options
        .starter_pid
        .and_then(pidwatch::ProcessExit::watch);
    let mut starter_guard = starter
        .as_ref()
        .and_then(|s| waitset.attach_notification(s).ok());
    // Clients' exits ring an alarm the WaitSet watches, so with idle clients the loop
    // sleeps instead of looking at its period.
    let alarm = alarm::Alarm::new().map(|(alarm, registry)| {
        daemon.liveness.ring(registry);
        alarm
    });
    // Watched only while clients are connected (without, the loop looks for nothing).
    let mut attached = None;
    let mut had_clients = false;
    let mut house = House {
        last: Instant::now(),
        next: Instant::now() + HOUSEKEEPING,
        trims: trim::Schedule::default(),
        busy: true,
    };
    while !shutdown.load(Ordering::Relaxed) {
        daemon.wait(&waitset, house.next, starter_guard.is_some());
        let now = Instant::now();
        if now < house.next {
            // Something woke the loop: look after the house within the period again.
            house.busy = true;
            house.next = house.next.min(now + HOUSEKEEPING);
        }
        if starter_guard.is_some() && starter.as_ref().is_some_and(|s| s.exited()) {
            // Its pidfd stays readable: stop watching it, and look after now (the daemon
            // ends here without clients, else at a later look once the last one is gone).
            starter_guard = None;
            house.next = now;
        }
        if alarm.as_ref().is_some_and(alarm::Alarm::drain) {
            // A client's process exited: look now, or a period after the last look (the
            // looks, which list nodes, stay at most two a second however many exit).
            house.next = house.next.min((house.last + HOUSEKEEPING).max(now));
        }
        consume_wake_ups(&listener, &worker_wake, &daemon.waker);
        daemon.serve_round();
        // Attached when the first client comes (once: a WaitSet that refuses it leaves the
        // loop looking at its period), detached when the last one goes.
        let with_clients = !daemon.clients.is_empty();
        if with_clients != had_clients {
            had_clients = with_clients;
            attached = match (&alarm, with_clients) {
                (Some(alarm), true) => waitset.attach_notification(alarm).ok(),
                _ => None,
            };
        }
        if Instant::now() >= house.next && !daemon.look_after(&mut house, trims, attached.is_some())
        {
            break;
        }
    }
    daemon.shut_down();
    Ok(())
}

/// Opens the node, the request wake-up listener and the control ports of `domain`; a second
/// daemon of the domain fails here with [`DaemonError::AlreadyRunning`].
fn open_ports(
    domain: &str,
    config: &Config,
    options: &Options,
) -> Result<(Ports, Listener<ipc::Service>), DaemonError> {
    let limits = &options.limits;
    let node = NodeBuilder::new()
        .name(&NodeName::new(names::DAEMON_NODE_NAME).expect("valid node name"))
        .config(config)
        .signal_handling_mode(SignalHandlingMode::Disabled)
        .create::<ipc::Service>()
        .map_err(|e| DaemonError::Ipc(format!("cannot create node: {e:?}")))?;
    let listener = open_listener(&node, options)?;
    let control = node
        .service_builder(&names::control())
        .request_response::<[u8], [u8]>()
        .request_user_header::<u128>()
        .max_servers(1)
        // Room beyond --max-clients: ports that never say Hello (or a process at its
        // per-process limit) leave ports for other processes.
        .max_clients(limits.max_clients * 2)
        .max_nodes(control_nodes(limits))
        .max_active_requests_per_client(4)
        // One reply per request, copied out by the client at once: one place each. The
        // server preallocates a reference count per possible reply for each of its 255
        // growth segments (clients × 8 × these three), so the defaults (2 each) cost twice
        // the memory for places no reply uses: 50 MB instead of 25 at 256 clients.
        .max_response_buffer_size(1)
        .max_borrowed_responses_per_pending_response(1)
        .open_or_create()
        .map_err(|e| DaemonError::Ipc(format!("cannot create the control service: {e:?}")))?;
    let server = control
        .server_builder()
        .max_loaned_responses_per_request(1)
        .initial_max_slice_len(4096)
        .allocation_strategy(AllocationStrategy::PowerOfTwo)
        .create()
        .map_err(|_| DaemonError::AlreadyRunning {
            domain: domain.to_string(),
        })?;
    Ok((
        Ports {
            node,
            control,
            server,
        },
        listener,
    ))
}

/// The listener clients notify after sending a request (the loop waits on it).
fn open_listener(
    node: &Node<ipc::Service>,
    options: &Options,
) -> Result<Listener<ipc::Service>, DaemonError> {
    let limits = &options.limits;
    node.service_builder(&names::control_wake())
        .event()
        .max_listeners(2)
        .max_notifiers(limits.max_clients * 2)
        .max_nodes(control_nodes(limits))
        .open_or_create()
        .map_err(|e| DaemonError::Ipc(format!("cannot create the request event: {e:?}")))?
        .listener_builder()
        .create()
        .map_err(|e| DaemonError::Ipc(format!("cannot create the request listener: {e:?}")))
}

/// The daemon over `ports`, with its state writer, its persistent planes of the last run
/// restored and its files narrowed to this user: ready for the first request.
fn start(
    domain: &str,
    config: &Config,
    ports: Ports,
    options: Options,
    watch: Arc<resources::Watch>,
    wake_end: StreamingSocket,
) -> Result<Daemon, DaemonError> {
    let writer = match &options.persistence {
        Some(p) => Some(persist::Writer::start(p, domain).map_err(|e| {
            DaemonError::Ipc(format!(
                "cannot use the state directory {}: {e}",
                persist::domain_dir(&p.dir, domain).display()
            ))
        })?),
        None => None,
    };
    let (events_tx, events) = mpsc::channel();
    let mut daemon = Daemon {
        domain: domain.to_string(),
        config: config.clone(),
        node: ports.node,
        server: ports.server,
        clients: Clients::new(options.limits.max_clients),
        planes: BTreeMap::new(),
        next_plane_id: 1,
        owners: quota::Owners::new(options.limits.memory_bytes()),
        options,
        queues: HashMap::new(),
        tickets: HashMap::new(),
        next_ticket: 1,
        events,
        events_tx,
        waker: Arc::new(Waker::new(wake_end)),
        workers: Vec::new(),
        reply_left: 0,
        control: ports.control,
        origins: origin::Origins::default(),
        guest: None,
        watch,
        writer,
        transfers: HashMap::new(),
        stage_to: None,
        liveness: schedule::Schedule::default(),
        moved: Tombstones::default(),
    };
    // Persistent planes of the last daemon come back before the first request.
    daemon.restore_saved();
    // iceoryx2 creates its node-counter segment world-writable: narrow it to this user.
    files::restrict(domain);
    tracing::info!(domain, pid = std::process::id(), "physics daemon ready");
    Ok(daemon)
}

/// The longest the loop goes without a look while its clients sit idle and the alarm
/// watches every one of them (what it then looks for is rare: ended workers, pruned quota
/// counters, memory given back).
const QUIET_LOOK: std::time::Duration = std::time::Duration::from_secs(5);

/// When the house is next looked after, and when freed memory is next given back.
struct House {
    /// When the house was last looked after.
    last: Instant,
    next: Instant,
    trims: trim::Schedule,
    /// Something woke the loop since the last look (a request, a worker, an alarm).
    busy: bool,
}

/// Consumes the wake-ups that ended the wait (requests announced, workers reporting), so
/// the next wait sleeps until something new arrives.
fn consume_wake_ups(
    listener: &Listener<ipc::Service>,
    worker_wake: &StreamingSocket,
    waker: &Waker,
) {
    if let Err(e) = listener.try_wait(|_| {}) {
        tracing::warn!("request listener: {e:?}");
    }
    let mut buf = [0u8; 256];
    while matches!(worker_wake.try_receive(&mut buf), Ok(n) if n > 0) {}
    waker.disarm();
}

impl Daemon {
    /// Sleeps in `waitset` until a request, a worker, a shutdown wake-up or (when
    /// `starter_watched`) the starter's exit arrives, and while clients are connected (or a
    /// starter is looked for at the period) no later than `housekeeping`.
    fn wait(&self, waitset: &WaitSet<ipc::Service>, housekeeping: Instant, starter_watched: bool) {
        let watching =
            !self.clients.is_empty() || (self.options.starter_pid.is_some() && !starter_watched);
        let waited = if watching {
            let timeout = housekeeping.saturating_duration_since(Instant::now());
            waitset.wait_and_process_once_with_timeout(|_| CallbackProgression::Continue, timeout)
        } else {
            // Nothing to look after: sleep until a request, a worker or a shutdown wake-up.
            waitset.wait_and_process_once(|_| CallbackProgression::Continue)
        };
        if let Err(e) = waited {
            tracing::warn!("waitset: {e:?}");
        }
    }

    /// One round of work after a wake-up: what workers reported, planes handed over,
    /// every queued request, the load report and the heartbeat.
    fn serve_round(&mut self) {
        self.handle_events();
        self.adopt_planes();
        self.take_arrivals();
        self.take_rebalance();
        self.serve_requests();
        if let Some(gauge) = &self.options.load {
            gauge.track(self.planes.len(), self.next_plane_id, || {
                self.planes.values().map(|p| p.usage.clone()).collect()
            });
        }
        self.watch.beat(!self.clients.is_empty());
    }

    /// Housekeeping, once `house.next` has come: with clients, gone clients released, ended
    /// workers reaped, quotas pruned and memory given back; without, the watch updated and
    /// ended workers' memory given back. Returns false when the daemon should stop (an
    /// on-demand daemon whose starter is gone and no client is left).
    fn look_after(&mut self, house: &mut House, trims: &trim::Trims, alarmed: bool) -> bool {
        let idle = self.clients.is_empty();
        if !idle {
            self.release_gone_clients();
        }
        self.update_watch();
        // What gone planes held goes back to the system too, once their workers have ended.
        let workers = self.workers.len();
        self.workers.retain(|w| !w.is_finished());
        let ended = self.workers.len() < workers;
        if idle {
            if ended {
                trims.request();
            }
            if self.starter_gone() {
                tracing::info!(
                    starter = self.options.starter_pid,
                    "the process that started this daemon is gone and no client is left"
                );
                return false;
            }
        } else {
            self.owners.prune();
            // A plane gone (megabytes: its world and its ports' bookkeeping) is given back
            // now, not up to a period later.
            if house.trims.due(ended) {
                trims.request();
            }
        }
        // Nothing happened since the last look and the alarm rings for every client's exit:
        // the next look can wait (it is a safety net then); else the period.
        let quiet = !std::mem::take(&mut house.busy) && alarmed && self.liveness.alarmed();
        house.last = Instant::now();
        house.next = house.last + if quiet { QUIET_LOOK } else { HOUSEKEEPING };
        true
    }

    /// The end of the loop: workers stopped, the state writer flushed.
    fn shut_down(&mut self) {
        tracing::info!(domain = self.domain, "shutting down");
        self.stop_workers();
        if let Some(writer) = &mut self.writer {
            writer.finish();
        }
    }
}

//! Caps on the iceoryx2 resources a client process holds in the daemon's services. Every
//! service has a fixed number of node and port slots (`max_nodes`, `max_clients`,
//! `max_subscribers`, `max_listeners`), and iceoryx2 lets any process of the user take them:
//! one process could hold 63 of a plane's 64 reader slots, or 127 nodes that never say Hello
//! could fill the control service (`ExceedsMaxNumberOfNodes` for everyone after).
//!
//! A thread of its own (with its own node, so the request loop never waits for it) looks at
//! who holds what every [`PERIOD`] while any other process has a node in the domain (with
//! none there is nothing to cap, and it sleeps until the domain's node folder changes:
//! [`crate::server::liveness::folder_watch`]) and evicts the excess: it removes
//! the offending node from the service, exactly as it removes a dead process's node (its
//! ports there, their connections and data segments; iceoryx2's slots are owner-tagged, so
//! the evicted process cannot later release a slot someone else got). The evicted process
//! keeps running; its ports in that service are cut off. Evicted are
//!
//! - a node that has not said Hello within `--hello-timeout-ms` of the daemon first seeing it
//!   (from every daemon service it joined),
//! - the nodes of a process beyond `--max-nodes-per-process` (those without Hello first,
//!   then the newest),
//! - in each service, the nodes of a process holding more than `--max-ports-per-process`
//!   ports there (the node with the most ports first).
//!
//! The same thread beats the daemon's heartbeat at each look while clients are connected
//! ([`crate::server::liveness::heartbeat`]).
//!
//! Identities here come from iceoryx2's node and port lists (see `docs/security.md` for
//! what a process of the same user can still forge).

use std::collections::{BTreeSet, HashMap, HashSet};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Condvar, Mutex};
use std::time::{Duration, Instant};

use iceoryx2::config::Config;
use iceoryx2::identifiers::UniqueNodeId;
use iceoryx2::node::NodeView;
use iceoryx2::prelude::*;
use iceoryx2::service::internal::ServiceInternal;
use iceoryx2::service::service_hash::ServiceHash;
use shm_layout::{names, BodyState, EventRecord, PlaneId, TickHeader};

use crate::server::liveness::folder_watch;
use crate::server::liveness::folder_watch::{FolderWatch, Wake};
use crate::server::liveness::heartbeat;
use crate::server::liveness::pidwatch;
use crate::server::liveness::schedule;
use crate::server::quotas::limits::Limits;
use crate::server::requests::origin::ControlService;
use crate::DaemonError;

/// Most departures a watch keeps for the guard's next look (see `WatchState::left`).
const MAX_LEFT: usize = 4096;

/// Time between two looks: the heartbeat's period (the guard beats at each look).
pub const PERIOD: Duration = heartbeat::PERIOD;

/// How long an evicted node is left alone before it is looked at again (it may have joined
/// services again).
const RECHECK_EVICTED: Duration = Duration::from_secs(10);

type BodyService = iceoryx2::service::port_factory::publish_subscribe::PortFactory<
    ipc::Service,
    [BodyState],
    TickHeader,
>;
type EventService = iceoryx2::service::port_factory::publish_subscribe::PortFactory<
    ipc::Service,
    [EventRecord],
    TickHeader,
>;
type TickService = iceoryx2::service::port_factory::event::PortFactory<ipc::Service>;

/// One plane's services, opened by the daemon's loop to read their port lists.
struct PlaneServices {
    bodies: BodyService,
    events: EventService,
    tick: TickService,
}

/// What was evicted, and why (logged by the loop; tests read the log).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Eviction {
    /// The evicted node's id.
    pub node: u128,
    /// Its process.
    pub pid: u32,
    /// The service it was removed from.
    pub service: String,
    /// Why.
    pub reason: String,
}

/// What the request loop tells the guard thread: who said Hello, which planes exist, and
/// when to stop.
#[derive(Debug)]
pub struct Watch {
    state: Mutex<WatchState>,
    changed: Condvar,
    /// Ends the guard's wait at once on stop or when beats start (`None`: the system gave no
    /// eventfd; the guard then waits on `changed` a period at a time).
    wake: Option<Wake>,
    /// Whether clients are connected: the guard then beats the heartbeat every look.
    beating: AtomicBool,
}

impl Default for Watch {
    fn default() -> Self {
        Watch {
            state: Mutex::default(),
            changed: Condvar::new(),
            wake: Wake::new(),
            beating: AtomicBool::new(false),
        }
    }
}

#[derive(Debug, Default)]
struct WatchState {
    connected: HashSet<u128>,
    /// Nodes that stopped being connected (a Goodbye, a released client) since the guard's
    /// last look, and when: their Hello clock starts again then, so a client that says
    /// Goodbye and Hello again on the same node is not taken for one that never said Hello.
    left: Vec<(u128, Instant)>,
    planes: Vec<PlaneId>,
    stop: bool,
}

impl Watch {
    /// Records the connected clients (node ids) and the planes.
    pub fn update(
        &self,
        connected: impl Iterator<Item = u128>,
        planes: impl Iterator<Item = PlaneId>,
    ) {
        if let Ok(mut state) = self.state.lock() {
            let connected: HashSet<u128> = connected.collect();
            let now = Instant::now();
            let WatchState {
                connected: before,
                left,
                ..
            } = &mut *state;
            left.extend(before.difference(&connected).map(|id| (*id, now)));
            // Unread only while the guard does not run (it could not start): keep the newest.
            let excess = left.len().saturating_sub(MAX_LEFT);
            left.drain(..excess);
            state.connected = connected;
            state.planes = planes.collect();
        }
    }

    /// Beats the heartbeat at every look while `on` (clients are connected); a quiet guard
    /// is woken to start at once.
    pub fn beat(&self, on: bool) {
        if self.beating.swap(on, Ordering::Relaxed) != on && on {
            if let Some(wake) = &self.wake {
                wake.wake();
            }
        }
    }

    fn beating(&self) -> bool {
        self.beating.load(Ordering::Relaxed)
    }

    /// Ends the guard thread.
    pub fn stop(&self) {
        if let Ok(mut state) = self.state.lock() {
            state.stop = true;
            self.changed.notify_all();
        }
        if let Some(wake) = &self.wake {
            wake.wake();
        }
    }

    fn stopped(&self) -> bool {
        self.state.lock().map_or(true, |s| s.stop)
    }

    /// Waits one period, or while `quiet` until `folder` changes (at most [`QUIET_LOOK`]).
    /// Returns `None` once stopped, else whether the folder changed.
    fn wait(&self, quiet: bool, folder: Option<&FolderWatch>) -> Option<bool> {
        if self.stopped() {
            return None;
        }
        let changed = match (&self.wake, folder) {
            (Some(wake), Some(folder)) if quiet => {
                folder_watch::wait(wake, Some(folder), QUIET_LOOK)
            }
            (Some(wake), folder) => {
                folder_watch::wait(wake, None, PERIOD);
                folder.is_some_and(FolderWatch::drain)
            }
            (None, folder) => {
                let state = self.state.lock().ok()?;
                let (state, _) = self
                    .changed
                    .wait_timeout_while(state, PERIOD, |s| !s.stop)
                    .ok()?;
                if state.stop {
                    return None;
                }
                drop(state);
                folder.is_some_and(FolderWatch::drain)
            }
        };
        (!self.stopped()).then_some(changed)
    }
}

/// The longest a quiet guard sleeps without a change in the node folder: a safety net, as
/// the loop's own listing ([`crate::server::liveness::schedule::SAFETY_NET`]).
const QUIET_LOOK: Duration = schedule::SAFETY_NET;

/// Runs the guard until `watch` says stop. Errors are logged: without the guard the daemon
/// still serves (only without the caps).
pub fn run(config: &Config, limits: &Limits, watch: &Watch) {
    if let Err(e) = guard(config, limits, watch) {
        tracing::warn!("resource guard stopped: {e}");
    }
}

fn guard(config: &Config, limits: &Limits, watch: &Watch) -> Result<(), DaemonError> {
    let ipc = |what: &str, e: &dyn core::fmt::Debug| {
        DaemonError::Ipc(format!("resource guard: cannot open the {what}: {e:?}"))
    };
    let node = NodeBuilder::new()
        .config(config)
        .signal_handling_mode(SignalHandlingMode::Disabled)
        .create::<ipc::Service>()
        .map_err(|e| ipc("node", &e))?;
    let mut control: Option<ControlService> = None;
    let mut guard = Guard::default();
    let mut heart = match heartbeat::Heart::open(&node, limits.max_clients) {
        Ok(heart) => Some(heart),
        Err(e) => {
            tracing::warn!("no heartbeat: {e}");
            None
        }
    };
    let beat = |heart: &mut Option<heartbeat::Heart>| {
        if let Some(heart) = heart.as_mut().filter(|_| watch.beating()) {
            heart.beat();
        }
    };
    // Watched from before the first listing, so no node created after it goes unnoticed.
    let folder_path = config.global.node_dir().to_string();
    let mut folder = FolderWatch::new(&folder_path);
    let mut quiet = false;
    while let Some(changed) = watch.wait(quiet, folder.as_ref()) {
        // The beat first: a long look must not delay it.
        beat(&mut heart);
        guard.folder_changed |= changed;
        if !folder.as_ref().is_some_and(FolderWatch::is_live) {
            // Removed and made again (or never watched): watch it anew, and look once. Where
            // inotify cannot watch it, the guard looks every period as before.
            folder = FolderWatch::new(&folder_path);
            guard.folder_changed |= folder.is_some();
        }
        // The loop creates the control service after this thread starts.
        if control.is_none() {
            control = node
                .service_builder(&names::control())
                .request_response::<[u8], [u8]>()
                .request_user_header::<u128>()
                .open()
                .ok();
        }
        let Some(control) = &control else { continue };
        let (connected, planes) = match watch.state.lock() {
            Ok(mut s) => {
                // A node that left is seen anew from then (its Hello clock), and the nodes
                // are listed at this look, so its verdict comes on time.
                for (id, at) in std::mem::take(&mut s.left) {
                    guard.seen.insert(id, at);
                    guard.folder_changed = true;
                }
                (s.connected.clone(), s.planes.clone())
            }
            Err(_) => return Ok(()),
        };
        guard.planes.retain(|id, _| planes.contains(id));
        let started = Instant::now();
        let evictions = guard.enforce(
            &node,
            config,
            control,
            planes.into_iter(),
            &|id| connected.contains(&id),
            limits,
        );
        for e in &evictions {
            tracing::warn!(
                node = format!("{:032x}", e.node),
                pid = e.pid,
                service = e.service,
                "evicted: {}",
                e.reason
            );
        }
        // A long look (many evictions) beats again at its end, so the silence a client sees
        // is never a look plus a whole period.
        if started.elapsed() >= PERIOD / 2 {
            beat(&mut heart);
        }
        if !evictions.is_empty() {
            tracing::info!(
                evictions = evictions.len(),
                took_ms = started.elapsed().as_secs_f64() * 1e3,
                "resource caps enforced"
            );
        }
        // Nothing to cap while no other process has a node in the domain (every port
        // belongs to a node; a client gone since the loop last said who is connected has
        // no node either): sleep until the node folder changes.
        quiet = folder.as_ref().is_some_and(FolderWatch::is_live)
            && !watch.beating()
            && guard.seen.is_empty()
            && guard.pending_hello == 0
            && guard.listed.is_some();
    }
    Ok(())
}

/// The guard's view of who holds what.
#[derive(Default)]
struct Guard {
    /// Live nodes of other processes, and when the daemon first saw each (or saw it stop
    /// being connected, `WatchState::left`): their Hello clocks.
    seen: HashMap<u128, Instant>,
    /// Nodes evicted, and when.
    evicted: HashMap<u128, Instant>,
    planes: HashMap<PlaneId, PlaneServices>,
    /// When the nodes were last listed, and the domain's node folder's modification time
    /// then (`list_nodes_now`).
    listed: Option<(Instant, Option<std::time::SystemTime>)>,
    /// Nodes of other processes that have not said Hello yet and are not evicted: their
    /// verdict is due at a later look.
    pending_hello: usize,
    /// The processes of the live nodes last listed (a killed one leaves its node behind).
    pids: pidwatch::PidWatch,
    /// The node folder changed since the last listing (its watch woke the guard).
    folder_changed: bool,
}

/// A node as the node list shows it.
#[derive(Clone, Copy)]
struct Seen {
    id: UniqueNodeId,
    pid: u32,
    first_seen: Instant,
    connected: bool,
}

impl Guard {
    /// Looks at every node and port of the daemon's services and evicts what is over the
    /// caps in `limits`. `connected` tells whether a node has said Hello.
    fn enforce(
        &mut self,
        node: &Node<ipc::Service>,
        config: &Config,
        control: &ControlService,
        planes: impl Iterator<Item = PlaneId>,
        connected: &dyn Fn(u128) -> bool,
        limits: &Limits,
    ) -> Vec<Eviction> {
        let now = Instant::now();
        let own = std::process::id();
        let mut done = Vec::new();
        if self.list_nodes_now(config, now) {
            self.enforce_nodes(config, connected, limits, now, own, &mut done);
        }
        self.enforce_ports(node, control, planes, limits, config, own, &mut done);
        done
    }

    /// Whether the nodes must be listed this period. Listing reads every node's files (the
    /// most of an idle daemon's CPU when done every period), and what it finds changes only
    /// when a node comes or goes, which changes the domain's node folder. So the nodes are
    /// listed when that folder changed, while a node's Hello verdict is pending, when the
    /// process of a listed node exited (a killed process leaves its node behind without
    /// touching the folder: its resources are removed then; seen through pidfds,
    /// `crate::server::liveness::pidwatch`), and at least every [`crate::server::liveness::schedule::SAFETY_NET`]
    /// ([`crate::server::liveness::schedule::FULL_CHECK`] where pidfds cannot watch every such process).
    fn list_nodes_now(&mut self, config: &Config, now: Instant) -> bool {
        let folder = config.global.node_dir().to_string();
        let stamp = pidwatch::folder_stamp(&folder);
        let exited = self.pids.any_exited();
        let period = match exited {
            Some(_) => schedule::SAFETY_NET,
            None => schedule::FULL_CHECK,
        };
        let due = match self.listed {
            None => true,
            Some((at, seen)) => {
                std::mem::take(&mut self.folder_changed)
                    || self.pending_hello > 0
                    || stamp.is_none()
                    || seen != stamp
                    || exited == Some(true)
                    || now.duration_since(at) >= period
            }
        };
        if due {
            self.listed = Some((now, stamp));
        }
        due
    }

    /// The node caps: Hello within the timeout, nodes per process; and dead nodes' cleanup.
    fn enforce_nodes(
        &mut self,
        config: &Config,
        connected: &dyn Fn(u128) -> bool,
        limits: &Limits,
        now: Instant,
        own: u32,
        done: &mut Vec<Eviction>,
    ) {
        let mut alive = Vec::new();
        let mut dead = Vec::new();
        let _ = Node::<ipc::Service>::list(config, |state| {
            match state {
                NodeState::Alive(view) => {
                    let id = *view.id();
                    let pid = id.pid::<ipc::Service>().map_or(0, |p| p.value() as u32);
                    if pid != own {
                        alive.push((id, pid));
                    }
                }
                NodeState::Dead(view) => dead.push(view),
                _ => {}
            }
            CallbackProgression::Continue
        });
        // What killed processes left (also without any client connected, when the loop does
        // no housekeeping): their node records, ports, connections and data segments.
        for view in dead {
            let id = view.id().value();
            if let Err(e) = view.try_remove_stale_resources() {
                tracing::debug!(node = format!("{id:032x}"), "cleanup of a dead node: {e:?}");
            }
        }
        self.pids.watch(alive.iter().map(|&(_, pid)| pid));
        self.seen
            .retain(|id, _| alive.iter().any(|(n, _)| n.value() == *id));
        self.evicted.retain(|id, at| {
            now.duration_since(*at) < RECHECK_EVICTED && self.seen.contains_key(id)
        });
        let nodes: Vec<Seen> = alive
            .iter()
            .map(|(id, pid)| Seen {
                id: *id,
                pid: *pid,
                first_seen: *self.seen.entry(id.value()).or_insert(now),
                connected: connected(id.value()),
            })
            .filter(|n| !self.evicted.contains_key(&n.id.value()))
            .collect();

        // Nodes to remove from every service they joined.
        let mut everywhere: Vec<(Seen, String)> = Vec::new();
        let timeout = Duration::from_millis(limits.hello_timeout_ms);
        for n in &nodes {
            if !n.connected && now.duration_since(n.first_seen) >= timeout {
                everywhere.push((*n, format!("no Hello within {timeout:?}")));
            }
        }
        let mut by_pid: HashMap<u32, Vec<Seen>> = HashMap::new();
        for n in &nodes {
            by_pid.entry(n.pid).or_default().push(*n);
        }
        for (pid, mut list) in by_pid {
            // A process may always hold as many nodes as it may hold clients.
            let node_cap = limits.nodes_per_process.max(limits.clients_per_process);
            if list.len() <= node_cap {
                continue;
            }
            // Keep connected ones first, then the oldest.
            list.sort_by_key(|n| (!n.connected, std::cmp::Reverse(now - n.first_seen)));
            let held = list.len();
            for n in list.into_iter().skip(node_cap) {
                if !everywhere.iter().any(|(e, _)| e.id == n.id) {
                    everywhere.push((
                        n,
                        format!(
                            "process {pid} holds {held} nodes (--max-nodes-per-process {node_cap})"
                        ),
                    ));
                }
            }
        }

        if !everywhere.is_empty() {
            let targets: BTreeSet<u128> = everywhere.iter().map(|(n, _)| n.id.value()).collect();
            let mut joined: Vec<(UniqueNodeId, ServiceHash, String)> = Vec::new();
            let _ = ipc::Service::list(config, |details| {
                if let Some(dynamic) = &details.dynamic_details {
                    for state in &dynamic.nodes {
                        let id = *state.node_id();
                        if targets.contains(&id.value()) {
                            joined.push((
                                id,
                                *details.static_details.service_hash(),
                                details.static_details.name().to_string(),
                            ));
                        }
                    }
                }
                CallbackProgression::Continue
            });
            for (id, hash, service) in joined {
                let Some((n, reason)) = everywhere.iter().find(|(n, _)| n.id == id) else {
                    continue;
                };
                if evict(&id, &hash, config) {
                    done.push(Eviction {
                        node: id.value(),
                        pid: n.pid,
                        service,
                        reason: reason.clone(),
                    });
                }
            }
            for (n, _) in &everywhere {
                self.evicted.insert(n.id.value(), now);
            }
        }
        self.pending_hello = nodes
            .iter()
            .filter(|n| !n.connected && !self.evicted.contains_key(&n.id.value()))
            .count();
    }

    /// Ports per process in each service: read from the services' port lists in shared
    /// memory every period (cheap; a process can open ports without a new node).
    #[allow(clippy::too_many_arguments)]
    fn enforce_ports(
        &mut self,
        node: &Node<ipc::Service>,
        control: &ControlService,
        planes: impl Iterator<Item = PlaneId>,
        limits: &Limits,
        config: &Config,
        own: u32,
        done: &mut Vec<Eviction>,
    ) {
        // Ports per process in each service.
        // Each client of a process has one port per service.
        let cap = limits.ports_per_process.max(limits.clients_per_process);
        let mut lists: Vec<(String, ServiceHash, Vec<UniqueNodeId>)> = Vec::new();
        let mut holders = Vec::new();
        control.dynamic_config().list_clients(|d| {
            holders.push(d.node_id);
            CallbackProgression::Continue
        });
        lists.push((
            names::control().to_string(),
            *control.service_hash(),
            holders,
        ));
        for id in planes {
            let Some(services) = self.plane_services(node, id) else {
                continue;
            };
            let mut holders = Vec::new();
            services.bodies.dynamic_config().list_subscribers(|d| {
                holders.push(d.node_id);
                CallbackProgression::Continue
            });
            lists.push((
                names::plane_bodies(id).to_string(),
                *services.bodies.service_hash(),
                holders,
            ));
            let mut holders = Vec::new();
            services.events.dynamic_config().list_subscribers(|d| {
                holders.push(d.node_id);
                CallbackProgression::Continue
            });
            lists.push((
                names::plane_events(id).to_string(),
                *services.events.service_hash(),
                holders,
            ));
            let mut holders = Vec::new();
            services.tick.dynamic_config().list_listeners(|d| {
                holders.push(d.node_id);
                CallbackProgression::Continue
            });
            lists.push((
                names::plane_tick(id).to_string(),
                *services.tick.service_hash(),
                holders,
            ));
        }
        for (service, hash, holders) in lists {
            for (pid, node_id, reason) in over_port_cap(&holders, cap, own) {
                if evict(&node_id, &hash, config) {
                    done.push(Eviction {
                        node: node_id.value(),
                        pid,
                        service: service.clone(),
                        reason,
                    });
                }
            }
        }
    }

    fn plane_services(&mut self, node: &Node<ipc::Service>, id: PlaneId) -> Option<&PlaneServices> {
        match self.planes.entry(id) {
            std::collections::hash_map::Entry::Occupied(e) => Some(e.into_mut()),
            std::collections::hash_map::Entry::Vacant(e) => {
                // The plane's worker creates these; until it has, there is nothing to look at.
                let bodies = node
                    .service_builder(&names::plane_bodies(id))
                    .publish_subscribe::<[BodyState]>()
                    .user_header::<TickHeader>()
                    .open()
                    .ok()?;
                let events = node
                    .service_builder(&names::plane_events(id))
                    .publish_subscribe::<[EventRecord]>()
                    .user_header::<TickHeader>()
                    .open()
                    .ok()?;
                let tick = node
                    .service_builder(&names::plane_tick(id))
                    .event()
                    .open()
                    .ok()?;
                Some(e.insert(PlaneServices {
                    bodies,
                    events,
                    tick,
                }))
            }
        }
    }
}

/// The nodes to evict from one service whose ports `holders` (one entry per port, naming
/// its node) hold: per process over `cap`, the node with the most ports first.
fn over_port_cap(
    holders: &[UniqueNodeId],
    cap: usize,
    own: u32,
) -> Vec<(u32, UniqueNodeId, String)> {
    let mut per_node: HashMap<u128, (UniqueNodeId, u32, usize)> = HashMap::new();
    for id in holders {
        let pid = id.pid::<ipc::Service>().map_or(0, |p| p.value() as u32);
        per_node.entry(id.value()).or_insert((*id, pid, 0)).2 += 1;
    }
    let mut per_pid: HashMap<u32, Vec<(UniqueNodeId, usize)>> = HashMap::new();
    for (_, (id, pid, n)) in per_node {
        if pid != own {
            per_pid.entry(pid).or_default().push((id, n));
        }
    }
    let mut out = Vec::new();
    for (pid, mut nodes) in per_pid {
        let mut total: usize = nodes.iter().map(|(_, n)| n).sum();
        if total <= cap {
            continue;
        }
        let held = total;
        nodes.sort_by_key(|(_, n)| std::cmp::Reverse(*n));
        for (id, n) in nodes {
            if total <= cap {
                break;
            }
            total -= n;
            out.push((
                pid,
                id,
                format!("process {pid} holds {held} ports (--max-ports-per-process {cap})"),
            ));
        }
    }
    out
}

/// Removes node `id` from the service `hash` as if it had died. Returns whether it worked.
fn evict(id: &UniqueNodeId, hash: &ServiceHash, config: &Config) -> bool {
    // iceoryx2's own dead-node cleanup of one service (public, though hidden from its docs).
    match <ipc::Service as ServiceInternal<ipc::Service>>::__internal_remove_node_from_service(
        id, hash, config,
    ) {
        Ok(()) => true,
        Err(e) => {
            tracing::warn!(
                node = format!("{:032x}", id.value()),
                "eviction failed: {e:?}"
            );
            false
        }
    }
}

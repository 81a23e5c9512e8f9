//! The connection to the daemon: handshake, one request per flush, daemon liveness.

use std::cell::RefCell;
use std::collections::HashMap;
use std::rc::Rc;
use std::time::{Duration, Instant};

use shm_layout::codec;
use shm_layout::{
    CollisionGroups, Command, CommandError, CommandResult, ErrorKind, GuiControllerOp, GuiObjectOp,
    GuiOp, Handle, ObjectOp, PlaneId, PlaneOp, Reply, Request, Response, CRATE_VERSION,
    LAYOUT_VERSION,
};

use crate::plane_shared::PlaneShared;
use crate::remote::{RemoteOptions, RemoteTransport};
use crate::transport::{Transport, LIVENESS_PERIOD};
use crate::Error;

/// A daemon whose heartbeat (two beats a second, from a thread that never waits for its
/// request loop) has been
/// silent this long while a request waits, and whose process is stopped (SIGSTOP), is
/// stalled, not slow.
pub const STALL_AFTER: Duration = Duration::from_secs(1);
/// A silent heartbeat this long means a hung daemon even when its process is not stopped
/// (longer than [`STALL_AFTER`], so a heavily loaded machine that starves the heartbeat
/// thread for a moment does not fail requests).
pub const HUNG_AFTER: Duration = Duration::from_secs(3);

/// A silent heartbeat this long, with the daemon's process stopped, is a stall for
/// [`Client::watch_daemon`] (a beat missed: a reader learns of a SIGSTOP within a second;
/// a silence this long with the process running only costs a look at `/proc`).
pub const WATCH_STALL_AFTER: Duration = Duration::from_millis(600);

/// What [`Client::watch_daemon`] finds.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum DaemonHealth {
    /// Beating (or answering).
    Live,
    /// Stopped (SIGSTOP) or hung: no heartbeat for `silent`.
    Stalled {
        /// How long the heartbeat has been silent.
        silent: Duration,
    },
    /// The daemon process is gone.
    Gone,
}

/// How to connect.
#[derive(Debug, Clone)]
pub struct ConnectOptions {
    /// The deployment domain.
    pub domain: String,
    /// Longest wait for one reply (a Step of a huge plane may legitimately take a while).
    pub request_timeout: Duration,
    /// Test support: claim another crate version in the handshake.
    #[doc(hidden)]
    pub crate_version: String,
    /// Test support: claim another layout version in every request.
    #[doc(hidden)]
    pub layout_version: u32,
    /// Objects this client adds start held (`ObjectProp::Held`) and are released by its
    /// next flush: the writes it queues right after an add apply before the object's first
    /// step, even on a plane that ticks by itself. For clients that flush every frame (the
    /// Lua host does); a client that never flushes leaves new objects held for
    /// `MAX_HELD_TICKS` ticks. Default off.
    pub hold_adds_until_flush: bool,
    /// Writes the daemon refuses after the call that queued them returned (a refusal that
    /// depends on the plane's state, such as an object write the GPU path cannot do) are
    /// kept by plane and reported by the next call into that plane
    /// ([`Error::Refused`]), instead of by the next [`Client::flush`]: a host whose frame
    /// loop flushes (the Lua host) then never ends a frame on another call's refusal, and a
    /// script can catch it where it works with the plane. [`Client::take_refused`] collects
    /// what no call reported. Default off (`flush` reports every refusal).
    pub refusals_at_next_call: bool,
}

impl ConnectOptions {
    /// Defaults for `domain` (30 s request timeout).
    pub fn new(domain: &str) -> Self {
        ConnectOptions {
            domain: domain.to_string(),
            request_timeout: Duration::from_secs(30),
            crate_version: CRATE_VERSION.to_string(),
            layout_version: LAYOUT_VERSION,
            hold_adds_until_flush: false,
            refusals_at_next_call: false,
        }
    }
}

/// A queued command and the overlay entry its reply confirms.
struct Queued {
    command: Command,
    confirms: Option<(PlaneId, Handle)>,
    /// The host's line that made the write ([`Client::set_origin`]; 0: unknown).
    origin: u32,
    /// An impulse's overlay ticket (`overlay::Entry::impulse`).
    impulse: Option<u32>,
}

/// What applying the results of a request's queued writes needs, in queue order.
struct Sent {
    n_queued: usize,
    confirms: Vec<Option<(PlaneId, Handle)>>,
    /// The plane, object and whether it is a removal, of each queued command.
    targets: Vec<Option<(PlaneId, Option<Handle>, bool)>>,
    releases: Vec<bool>,
    origins: Vec<(u32, Option<u32>)>,
}

/// A pipelined flush's request whose reply is not applied yet.
struct InFlight {
    pending: crate::transport::PendingReply,
    sent: Sent,
    commands: Vec<Command>,
    since: Instant,
}

/// The host's answer to "which line of the script is running?" (0: none).
type Origin = Box<dyn Fn() -> u32>;

/// A queued write the daemon refused, kept for the next call into its plane.
struct Refusal {
    plane: Option<PlaneId>,
    error: CommandError,
}

#[derive(Default)]
struct State {
    queue: Vec<Queued>,
    /// Failures of queued commands sent along with another call, reported by `flush` (or
    /// by the next call into their plane: [`ConnectOptions::refusals_at_next_call`]).
    deferred: Vec<Refusal>,
    planes: HashMap<PlaneId, Rc<PlaneShared>>,
    /// Planes this client created (they take its collision-group table).
    owned: Vec<PlaneId>,
    /// The collision-group table of this client (`collision_groups.rs`).
    groups: CollisionGroups,
    gone: bool,
}

struct Inner {
    options: ConnectOptions,
    transport: Transport,
    daemon_node: u128,
    daemon_pid: u32,
    state: RefCell<State>,
    /// The frame number of [`Client::begin_frame`] (0: no frames, every read looks for the
    /// newest sample).
    frame: std::cell::Cell<u64>,
    /// Where the host's script queues a write ([`Client::set_origin`]).
    origin: RefCell<Option<Origin>>,
    /// When the daemon last showed life (a heartbeat or a reply).
    last_beat: std::cell::Cell<Instant>,
    /// When [`Client::watch_daemon`] last read the node list.
    last_node_check: std::cell::Cell<Instant>,
    /// How long the next request polls for its reply before sleeping ([`crate::spin`]).
    reply_spin: std::cell::Cell<std::time::Duration>,
    /// Connections to the daemons this client's planes moved to, by daemon (`moving`).
    peers: RefCell<HashMap<String, Client>>,
    /// How this client reached its cluster, when it did ([`Client::connect_cluster`]).
    remote: Option<RemoteOptions>,
    /// Pipelined flushes' requests, oldest first ([`Client::flush`]).
    in_flight: RefCell<std::collections::VecDeque<InFlight>>,
    /// What applying that request's reply failed with, for the next call.
    in_flight_error: RefCell<Option<Error>>,
}

/// A connection to the physics daemon of one domain. Cheap to clone; not `Send` (shared
/// memory ports belong to the thread that opened them).
#[derive(Clone)]
pub struct Client {
    inner: Rc<Inner>,
}

/// Pipelined flushes whose replies may be outstanding at once ([`Client::flush`]; the
/// daemon takes four requests of a client at a time).
pub const MAX_IN_FLIGHT: usize = 2;

/// How long the handshake waits for an answer before it asks again.
const HELLO_RETRY: Duration = Duration::from_secs(1);

impl Client {
    /// Connects to the daemon of `domain` and performs the version handshake.
    pub fn connect(domain: &str) -> Result<Client, Error> {
        Self::connect_with(ConnectOptions::new(domain))
    }

    /// Connects with explicit options.
    pub fn connect_with(options: ConnectOptions) -> Result<Client, Error> {
        let transport = Transport::open(&options.domain)?;
        Self::handshake(options, transport)
    }

    /// Connects to a daemon of a physics cluster, on this host or another (docs/cluster.md):
    /// the same API as [`Client::connect`], carried by Zenoh to the daemon's relay. With
    /// `remote.daemon` unset, the live daemon with the smallest share of its tick budget
    /// used is chosen. [`Client::domain`] reads `cluster/daemon`.
    pub fn connect_cluster(remote: &RemoteOptions) -> Result<Client, Error> {
        Self::connect_cluster_with(remote, ConnectOptions::new(""))
    }

    /// [`Client::connect_cluster`] with explicit options (`options.domain` is replaced).
    pub fn connect_cluster_with(
        remote: &RemoteOptions,
        mut options: ConnectOptions,
    ) -> Result<Client, Error> {
        let transport = RemoteTransport::open(remote)?;
        options.domain = format!("{}/{}", transport.cluster(), transport.daemon());
        let client = Self::handshake(options, Transport::Remote(transport))?;
        Ok(client.with_remote(remote.clone()))
    }

    /// The cluster daemon this client uses (`None`: this host's daemon, not through a
    /// cluster).
    pub fn cluster_daemon(&self) -> Option<&str> {
        match &self.inner.transport {
            Transport::Remote(t) => Some(t.daemon()),
            Transport::Local(_) => None,
        }
    }

    fn handshake(options: ConnectOptions, transport: Transport) -> Result<Client, Error> {
        let mut inner = Inner {
            options,
            transport,
            daemon_node: 0,
            daemon_pid: 0,
            state: RefCell::default(),
            frame: std::cell::Cell::new(0),
            origin: RefCell::new(None),
            last_beat: std::cell::Cell::new(Instant::now()),
            reply_spin: std::cell::Cell::new(std::time::Duration::ZERO),
            last_node_check: std::cell::Cell::new(Instant::now()),
            peers: RefCell::default(),
            remote: None,
            in_flight: RefCell::default(),
            in_flight_error: RefCell::default(),
        };
        let hello = Command::Hello {
            crate_version: inner.options.crate_version.clone(),
            pid: std::process::id(),
        };
        // A Hello can be lost while the daemon evicts another process's ports from the
        // control service (see the daemon's `server/resources.rs`): ask again with fresh
        // ports every HELLO_RETRY, within the request timeout. A remote Hello is a Zenoh query
        // that is not lost that way (the relay opens its session's local connection before it
        // answers, which can take seconds on a loaded host): it gets the whole timeout.
        let timeout = inner.options.request_timeout;
        let deadline = Instant::now() + timeout;
        if inner.transport.is_local() {
            inner.options.request_timeout = timeout.min(HELLO_RETRY);
        }
        let welcome = loop {
            match inner.round_trip(vec![hello.clone()]) {
                Err(Error::Timeout(_))
                    if Instant::now() < deadline && inner.transport.is_local() =>
                {
                    tracing::debug!("no answer to Hello: asking again with new ports");
                    inner.transport = Transport::open(&inner.options.domain)?;
                }
                other => break other,
            }
        };
        inner.options.request_timeout = timeout;
        match welcome?.pop() {
            Some(Ok(Reply::Welcome {
                daemon_pid,
                daemon_node_id,
                ..
            })) => {
                inner.daemon_pid = daemon_pid;
                inner.daemon_node = daemon_node_id;
            }
            Some(Err(e)) if e.kind == ErrorKind::VersionMismatch => {
                return Err(Error::VersionMismatch(e.message))
            }
            Some(Err(e)) => return Err(e.into()),
            other => {
                return Err(Error::Protocol(format!(
                    "unexpected handshake reply {other:?}"
                )))
            }
        }
        Ok(Client {
            inner: Rc::new(inner),
        })
    }

    /// Whether adds start held until the next flush ([`ConnectOptions::hold_adds_until_flush`]).
    pub(crate) fn holds_adds(&self) -> bool {
        self.inner.options.hold_adds_until_flush
    }

    /// The domain this client talks to.
    pub fn domain(&self) -> &str {
        &self.inner.options.domain
    }

    /// Process id of the daemon this client talks to.
    pub fn daemon_pid(&self) -> u32 {
        self.inner.daemon_pid
    }

    /// The per-plane state this client already keeps for `id`, if attached.
    pub(crate) fn attached(&self, id: PlaneId) -> Option<Rc<PlaneShared>> {
        self.inner.state.borrow().planes.get(&id).cloned()
    }

    /// Keeps `shared` as this client's state for plane `id`.
    pub(crate) fn remember_plane(&self, id: PlaneId, shared: Rc<PlaneShared>) {
        self.inner.state.borrow_mut().planes.insert(id, shared);
    }

    /// Records that this client created plane `id`.
    pub(crate) fn note_owned(&self, id: PlaneId) {
        self.inner.state.borrow_mut().owned.push(id);
    }

    /// Sends every queued write as one request. Errors of individual commands (including
    /// ones sent along with earlier calls) come back together; the others were applied.
    ///
    /// With [`ConnectOptions::refusals_at_next_call`] the refusals stay with their planes
    /// for the next call into each (or [`Client::take_refused`]), and `flush` does not wait
    /// for the daemon: it sends the writes and returns (pipelined; on this host's
    /// transport). The daemon applies them in order before any later request of this
    /// client; their reply is collected by the next request, the next
    /// [`Client::begin_frame`] or the next read that takes a new sample, and until then
    /// reads show the writes (read-your-writes). A frame that ends with a flush therefore
    /// never waits for a step the daemon is in the middle of. `flush` then reports a
    /// failure to send, or a failure of the previous flush's request (the daemon gone).
    pub fn flush(&self) -> Result<(), Error> {
        if self.inner.options.refusals_at_next_call {
            return self.send_queues(true);
        }
        self.send_queue()?;
        let mut deferred = self.take_refused(None);
        // Refusals of writes to planes that moved to other daemons.
        for peer in self.inner.peers.borrow().values() {
            deferred.extend(peer.take_refused(None));
        }
        if deferred.is_empty() {
            Ok(())
        } else {
            Err(Error::Batch(deferred))
        }
    }

    /// Takes the refused writes not reported yet: of plane `plane`, or of every plane
    /// (`None`, which also takes refusals of commands that name no plane).
    pub fn take_refused(&self, plane: Option<PlaneId>) -> Vec<CommandError> {
        // A pipelined flush's refusals count too. A failure to collect them stays for the
        // next call to report.
        if let Err(e) = self.collect_in_flight(true) {
            *self.inner.in_flight_error.borrow_mut() = Some(e);
        }
        let mut state = self.inner.state.borrow_mut();
        if state.deferred.is_empty() {
            return Vec::new();
        }
        let (taken, kept) = std::mem::take(&mut state.deferred)
            .into_iter()
            .partition(|r| plane.is_none() || r.plane == plane);
        state.deferred = kept;
        taken.into_iter().map(|r| r.error).collect()
    }

    /// Gives the client a way to ask the host which line of its script queues a write
    /// (0: none), so that a write refused later names it ("written at line 12"). Asked
    /// once per queued write.
    pub fn set_origin(&self, origin: impl Fn() -> u32 + 'static) {
        *self.inner.origin.borrow_mut() = Some(Box::new(origin));
    }

    /// Starts a frame of a host's frame loop: from now until the next call, object reads
    /// (`pose`, `state`, ...) take each plane's newest sample once, at their first read in
    /// the frame, instead of looking for a newer one at every read (`Plane::step`,
    /// `wait_tick` and `snapshot` still take the newest at once). Without it every read
    /// looks.
    pub fn begin_frame(&self) {
        self.inner.frame.set(self.inner.frame.get() + 1);
        // The last frame's pipelined flush, if its reply is here (usually: a frame later).
        let _ = self.collect_in_flight(false);
    }

    /// The frame of [`Client::begin_frame`] (0 before the first).
    /// Lets the next request poll for its reply for up to `spin` before sleeping (a `Step`,
    /// whose reply is due after about the plane's last step time: see [`crate::spin`]).
    pub(crate) fn spin_next_reply(&self, spin: std::time::Duration) {
        self.inner.reply_spin.set(spin);
    }

    pub(crate) fn frame(&self) -> u64 {
        self.inner.frame.get()
    }

    /// Number of writes waiting for the next flush.
    pub fn queued(&self) -> usize {
        self.inner.state.borrow().queue.len()
    }

    /// Sends the queue plus `command` and returns the reply to `command`.
    ///
    /// With [`ConnectOptions::refusals_at_next_call`], a call into a plane first reports the
    /// plane's refused writes ([`Error::Refused`]) instead of running, and a call that
    /// creates nothing (a step, a write) also reports the refusals its own request brought
    /// back, after it ran; a creating call keeps them for the next call, so its handle is
    /// never lost.
    pub(crate) fn call(&self, command: Command) -> Result<Reply, Error> {
        // The refusals of a pipelined flush are reported before the next call into their
        // plane, as those of any earlier request.
        self.collect_in_flight(true)?;
        // A plane that moved: its commands go to its new daemon, under its id there.
        let command = match self.reroute(command) {
            Rerouted::Here(command) => command,
            Rerouted::There(peer, command) => return peer.call(command),
        };
        let plane = match (&command, self.inner.options.refusals_at_next_call) {
            (Command::Plane { plane, op }, true) => {
                let refused = self.take_refused(Some(*plane));
                // A plane that goes away takes its refusals with it.
                if !refused.is_empty() && !matches!(op, PlaneOp::Destroy) {
                    return Err(Error::Refused(refused));
                }
                Some(*plane)
            }
            _ => None,
        };
        // A remote client's persistent plane outlives its daemon (`failover_switch`): keep
        // the command to send it again where the plane was taken over.
        let again = match &command {
            Command::Plane { plane, .. } if self.remote_options().is_some() => {
                Some((*plane, command.clone()))
            }
            _ => None,
        };
        let mut results = match (self.send(vec![command]), again) {
            (Err(Error::DaemonGone { .. }), Some((plane, command))) if self.fail_over(plane)? => {
                return self.call(command);
            }
            (results, _) => results?,
        };
        match results.pop() {
            Some(Ok(reply @ (Reply::Stepped { .. } | Reply::Applied { .. } | Reply::Done)))
                if plane.is_some() =>
            {
                let refused = self.take_refused(plane);
                match refused.is_empty() {
                    true => Ok(reply),
                    false => Err(Error::Refused(refused)),
                }
            }
            Some(Ok(reply)) => Ok(reply),
            Some(Err(e)) => Err(Error::Command(e)),
            None => Err(Error::Protocol("empty reply".into())),
        }
    }

    pub(crate) fn queue(&self, command: Command, confirms: Option<(PlaneId, Handle)>) {
        self.queue_with(command, confirms, None);
    }

    /// Queues an impulse on `handle` of `plane` whose reply carries the velocity after it,
    /// recorded under overlay ticket `ticket`.
    pub(crate) fn queue_impulse(
        &self,
        command: Command,
        plane: PlaneId,
        handle: Handle,
        ticket: u32,
    ) {
        self.queue_with(command, Some((plane, handle)), Some(ticket));
    }

    fn queue_with(
        &self,
        command: Command,
        confirms: Option<(PlaneId, Handle)>,
        impulse: Option<u32>,
    ) {
        let (command, confirms) = match self.reroute(command) {
            Rerouted::Here(command) => (command, confirms),
            Rerouted::There(peer, command) => {
                let confirms = confirms.map(|(_, h)| (command_plane(&command), h));
                return peer.queue_with(command, confirms, impulse);
            }
        };
        let confirms = confirms.map(|(_, h)| (command_plane(&command), h));
        self.inner.state.borrow_mut().queue.push(Queued {
            command,
            confirms,
            origin: self.inner.origin.borrow().as_ref().map_or(0, |f| f()),
            impulse,
        });
    }

    /// Sends the queued writes now, if any (their refusals are kept as for any send).
    pub(crate) fn send_queue(&self) -> Result<(), Error> {
        self.send_queues(false)
    }

    /// This connection's queued writes and those of the planes that moved to other
    /// daemons, each as one request: `pipelined`, without waiting for the answers
    /// ([`Client::flush`] with [`ConnectOptions::refusals_at_next_call`]).
    fn send_queues(&self, pipelined: bool) -> Result<(), Error> {
        if !self.inner.state.borrow().queue.is_empty() {
            match pipelined {
                true => self.send_pipelined()?,
                false => self.send(Vec::new()).map(|_| ())?,
            }
        }
        let peers: Vec<Client> = self.inner.peers.borrow().values().cloned().collect();
        for peer in peers {
            peer.send_queues(pipelined)?;
        }
        Ok(())
    }

    /// Moves the queued commands for plane `id` to `peer`'s queue under `new_id` (the plane
    /// moved there before they were sent).
    pub(crate) fn requeue_to(&self, id: PlaneId, peer: &Client, new_id: PlaneId) {
        let queue = std::mem::take(&mut self.inner.state.borrow_mut().queue);
        let (theirs, ours): (Vec<Queued>, Vec<Queued>) = queue
            .into_iter()
            .partition(|q| matches!(&q.command, Command::Plane { plane, .. } if *plane == id));
        self.inner.state.borrow_mut().queue = ours;
        let mut state = peer.inner.state.borrow_mut();
        for mut q in theirs {
            if let Command::Plane { plane, .. } = &mut q.command {
                *plane = new_id;
            }
            if let Some((plane, _)) = &mut q.confirms {
                *plane = new_id;
            }
            state.queue.push(q);
        }
    }

    /// This client with the cluster options it was connected with (peers connect alike).
    fn with_remote(self, remote: RemoteOptions) -> Client {
        match Rc::try_unwrap(self.inner) {
            Ok(mut inner) => {
                inner.remote = Some(remote);
                Client {
                    inner: Rc::new(inner),
                }
            }
            Err(inner) => Client { inner },
        }
    }

    /// How this client reached its cluster ([`Client::connect_cluster`]), if it did.
    pub(crate) fn remote_options(&self) -> Option<&RemoteOptions> {
        self.inner.remote.as_ref()
    }

    /// The options this client connected with.
    pub(crate) fn connect_options(&self) -> &ConnectOptions {
        &self.inner.options
    }

    /// The connections to the daemons this client's planes moved to, by daemon.
    pub(crate) fn peers(&self) -> &RefCell<HashMap<String, Client>> {
        &self.inner.peers
    }

    /// A handle that does not keep this client alive (a moved plane's route: the
    /// connection belongs to the client that switched it).
    pub(crate) fn downgrade(&self) -> std::rc::Weak<dyn std::any::Any> {
        let inner: Rc<dyn std::any::Any> = self.inner.clone();
        Rc::downgrade(&inner)
    }

    /// The client behind [`Client::downgrade`]'s handle, while it lives.
    pub(crate) fn upgrade(weak: &std::rc::Weak<dyn std::any::Any>) -> Option<Client> {
        let inner = weak.upgrade()?.downcast::<Inner>().ok()?;
        Some(Client { inner })
    }

    /// Where `command` goes: this connection, or the one its plane moved to.
    pub(crate) fn reroute(&self, command: Command) -> Rerouted {
        let Command::Plane { plane, op } = command else {
            return Rerouted::Here(command);
        };
        let route = self
            .attached(plane)
            .and_then(|s| s.route.borrow().clone())
            .and_then(|r| Some((Client::upgrade(&r.peer)?, r.id)));
        match route {
            None => Rerouted::Here(Command::Plane { plane, op }),
            Some((peer, id)) if peer.same(self) => Rerouted::Here(Command::Plane { plane: id, op }),
            Some((peer, id)) => Rerouted::There(peer, Command::Plane { plane: id, op }),
        }
    }

    /// Whether both are the same connection.
    pub(crate) fn same(&self, other: &Client) -> bool {
        Rc::ptr_eq(&self.inner, &other.inner)
    }

    /// One request: the queued commands first, then `extra`. Returns the results of `extra`.
    pub(crate) fn send(&self, extra: Vec<Command>) -> Result<Vec<CommandResult>, Error> {
        // A pipelined flush's reply comes first: replies are applied in request order.
        self.collect_in_flight(true)?;
        let (sent, commands) = self.take_queue(extra);
        let (results, commands) = self.inner.round_trip_keeping(commands)?;
        self.apply_results(sent, commands, results)
    }

    /// Sends the queued writes without waiting for the reply, which the next request, the
    /// next frame ([`Client::begin_frame`]) or the next read of a new sample collects
    /// (`collect_in_flight`). At most [`MAX_IN_FLIGHT`] such requests wait for their
    /// replies: a flush past that waits for the oldest (a daemon more than a frame behind
    /// slows its client's frames rather than gathering requests). Only on this host's
    /// transport; elsewhere a plain send.
    fn send_pipelined(&self) -> Result<(), Error> {
        let Some(local) = self.inner.transport.local() else {
            return self.send(Vec::new()).map(|_| ());
        };
        self.collect_in_flight(false)?;
        while self.inner.in_flight.borrow().len() >= MAX_IN_FLIGHT {
            self.collect_oldest(true)?;
        }
        if self.inner.state.borrow().gone {
            return Err(self.inner.gone());
        }
        let (sent, commands) = self.take_queue(Vec::new());
        let request = Request { commands };
        let bytes = self.inner.encode(&request);
        let pending = local.send(&bytes, self.inner.transport.id())?;
        self.inner.in_flight.borrow_mut().push_back(InFlight {
            pending,
            sent,
            commands: request.commands,
            since: Instant::now(),
        });
        Ok(())
    }

    /// Applies the replies of pipelined flushes, in order: every one (`wait`), or those
    /// that have arrived. An error met while applying them without a caller to tell (a
    /// frame's start) is kept for the next call that waits.
    pub(crate) fn collect_in_flight(&self, wait: bool) -> Result<(), Error> {
        if let Some(e) = self.inner.in_flight_error.borrow_mut().take() {
            return Err(e);
        }
        loop {
            match self.collect_oldest(wait) {
                Ok(true) => {}
                Ok(false) => return Ok(()),
                Err(e) if wait => return Err(e),
                Err(e) => {
                    *self.inner.in_flight_error.borrow_mut() = Some(e);
                    return Ok(());
                }
            }
        }
    }

    /// Applies the oldest pipelined flush's reply: waiting for it (`wait`), or only when it
    /// has arrived. False when there was none to apply.
    fn collect_oldest(&self, wait: bool) -> Result<bool, Error> {
        let Some(local) = self.inner.transport.local() else {
            return Ok(false);
        };
        let reply = {
            let in_flight = self.inner.in_flight.borrow();
            let Some(f) = in_flight.front() else {
                return Ok(false);
            };
            match wait {
                true => Some(self.inner.await_reply(local, &f.pending, f.since)),
                false => local.try_reply(&f.pending).map_err(Error::from).transpose(),
            }
        };
        let Some(reply) = reply else {
            return Ok(false);
        };
        let f = self
            .inner
            .in_flight
            .borrow_mut()
            .pop_front()
            .expect("checked above");
        let results = self.inner.results_of(&reply?, f.commands.len())?;
        let results = self.inner.rejoin_if_forgotten(&f.commands, results)?;
        self.apply_results(f.sent, f.commands, results)?;
        Ok(true)
    }

    /// Whether a pipelined flush's reply has not been applied yet.
    pub(crate) fn has_in_flight(&self) -> bool {
        !self.inner.in_flight.borrow().is_empty()
    }

    /// Takes the queue (plus `extra`) as one request's commands and what applying their
    /// results needs.
    fn take_queue(&self, extra: Vec<Command>) -> (Sent, Vec<Command>) {
        let queued = std::mem::take(&mut self.inner.state.borrow_mut().queue);
        let n_queued = queued.len();
        let mut sent = Sent {
            n_queued,
            confirms: Vec::with_capacity(n_queued),
            targets: Vec::with_capacity(n_queued),
            releases: Vec::with_capacity(n_queued),
            origins: Vec::with_capacity(n_queued),
        };
        let mut commands = Vec::with_capacity(n_queued + extra.len());
        for q in queued {
            sent.origins.push((q.origin, q.impulse));
            sent.confirms.push(q.confirms);
            sent.releases.push(is_release(&q.command));
            sent.targets.push(match &q.command {
                Command::Plane {
                    plane,
                    op: PlaneOp::Object { handle, op },
                } => Some((*plane, Some(*handle), matches!(op, ObjectOp::Destroy))),
                Command::Plane {
                    plane,
                    op:
                        PlaneOp::Gui(
                            GuiOp::Object {
                                handle,
                                op: GuiObjectOp::Destroy,
                            }
                            | GuiOp::Controller {
                                handle,
                                op: GuiControllerOp::Destroy,
                            },
                        ),
                } => Some((*plane, Some(*handle), true)),
                Command::Plane { plane, .. } => Some((*plane, None, false)),
                _ => None,
            });
            commands.push(q.command);
        }
        commands.extend(extra);
        (sent, commands)
    }

    /// Applies a request's results: the queued writes' confirmations and refusals (kept
    /// for later: `deferred`); returns the results of the commands after them.
    fn apply_results(
        &self,
        sent: Sent,
        commands: Vec<Command>,
        mut results: Vec<CommandResult>,
    ) -> Result<Vec<CommandResult>, Error> {
        let Sent {
            n_queued,
            confirms,
            targets,
            releases,
            origins,
        } = sent;
        // A reply is a sign of life as good as a beat.
        self.inner.last_beat.set(Instant::now());
        // Refused because their plane moved (not applied): switch over, send them again.
        self.resend_moved(&commands, &mut results)?;
        let extra_results = results.split_off(n_queued.min(results.len()));
        let mut state = self.inner.state.borrow_mut();
        let each = results.into_iter().zip(confirms).zip(targets).zip(releases);
        for ((((result, confirm), target), release), (origin, impulse)) in each.zip(origins) {
            if release {
                // The SDK's own release of a held add: nothing the caller asked for, and an
                // object already gone has nothing left to release.
                continue;
            }
            if let (Err(_), Some((plane, handle, _))) = (&result, target) {
                // A rejected write must not linger in the mirror either.
                if let Some(p) = state.planes.get(&plane) {
                    let mut mirror = p.mirror.borrow_mut();
                    match handle {
                        Some(h) => mirror.forget_object(h),
                        None => mirror.forget_plane(),
                    }
                }
            }
            if let Some((plane, Some(handle), true)) = target {
                // A removal counts in the plane's object count until a tick shows it.
                if let Some(p) = state.planes.get(&plane) {
                    let mut members = p.members.borrow_mut();
                    match &result {
                        Ok(Reply::Applied { tick }) => members.removal_applied(handle, *tick),
                        _ => members.removal_refused(handle),
                    }
                }
            }
            match (result, confirm) {
                (Ok(Reply::Velocity { tick, linear }), Some((plane, handle))) => {
                    if let (Some(p), Some(ticket)) = (state.planes.get(&plane), impulse) {
                        p.impulse_applied(handle, ticket, linear, tick);
                    }
                }
                (Ok(Reply::Applied { tick }), Some((plane, handle))) => {
                    if let Some(p) = state.planes.get(&plane) {
                        p.confirm(handle, tick);
                    }
                }
                (Ok(_), _) => {}
                (Err(mut error), confirm) => {
                    // A rejected write must not linger as if it had happened.
                    if let Some((plane, handle)) = confirm {
                        if let Some(p) = state.planes.get(&plane) {
                            p.discard(handle);
                        }
                    }
                    if origin > 0 {
                        error.message = format!("{} (written at line {origin})", error.message);
                    }
                    let plane = target.map(|(plane, _, _)| plane);
                    state.deferred.push(Refusal { plane, error });
                }
            }
        }
        Ok(extra_results)
    }

    /// Test support: sends raw request bytes and returns the raw reply.
    #[doc(hidden)]
    pub fn raw_request(&self, bytes: &[u8]) -> Result<Vec<u8>, Error> {
        self.collect_in_flight(true)?;
        self.inner.exchange(bytes, self.inner.transport.id())
    }

    /// Test support: [`Client::raw_request`] with `claimed` written where older clients put
    /// their id (the request's user header), as a forging client would.
    #[doc(hidden)]
    pub fn raw_request_claiming(&self, bytes: &[u8], claimed: u128) -> Result<Vec<u8>, Error> {
        self.collect_in_flight(true)?;
        self.inner.exchange(bytes, claimed)
    }

    /// Test support: this client's iceoryx2 node id.
    #[doc(hidden)]
    pub fn node_id(&self) -> u128 {
        self.inner.transport.id()
    }

    /// Whether the daemon is live, stalled or gone, without a request: for a host that only
    /// reads shared memory (which would otherwise run on against frozen poses). Cheap
    /// enough for every frame: one check of the heartbeat's queue; `/proc` and the node list
    /// are read only once the heartbeat has been silent for [`WATCH_STALL_AFTER`].
    pub fn watch_daemon(&self) -> DaemonHealth {
        let inner = &self.inner;
        if inner.state.borrow().gone {
            return DaemonHealth::Gone;
        }
        let now = Instant::now();
        match inner.transport.heartbeat_arrived() {
            Some(true) => inner.last_beat.set(now),
            // A remote daemon: its liveliness token says whether it lives.
            None if inner.check_daemon().is_err() => return DaemonHealth::Gone,
            None => return DaemonHealth::Live,
            Some(false) => {}
        }
        let silent = now.duration_since(inner.last_beat.get());
        if silent < WATCH_STALL_AFTER {
            return DaemonHealth::Live;
        }
        if now.duration_since(inner.last_node_check.get()) >= LIVENESS_PERIOD {
            inner.last_node_check.set(now);
            if inner.check_daemon().is_err() {
                return DaemonHealth::Gone;
            }
        }
        if silent > HUNG_AFTER || process_stopped(inner.daemon_pid) {
            DaemonHealth::Stalled { silent }
        } else {
            DaemonHealth::Live
        }
    }

    /// Fails with [`Error::DaemonGone`] when the daemon process no longer exists.
    pub fn check_daemon(&self) -> Result<(), Error> {
        self.inner.check_daemon()
    }

    pub(crate) fn forget_plane(&self, id: PlaneId) {
        let mut state = self.inner.state.borrow_mut();
        state.owned.retain(|p| *p != id);
        state.planes.remove(&id);
    }

    /// Reads the collision-group table.
    pub(crate) fn groups<R>(&self, f: impl FnOnce(&CollisionGroups) -> R) -> R {
        f(&self.inner.state.borrow().groups)
    }

    /// Changes the collision-group table through `f`; when it changed, every plane this
    /// client created gets the new table with the next request.
    pub(crate) fn change_groups<R>(
        &self,
        f: impl FnOnce(&mut CollisionGroups) -> Result<R, CommandError>,
    ) -> Result<R, Error> {
        let (result, table, owned) = {
            let mut state = self.inner.state.borrow_mut();
            let before = state.groups.clone();
            let result = f(&mut state.groups).map_err(Error::invalid_value)?;
            if state.groups == before {
                return Ok(result);
            }
            (result, state.groups.clone(), state.owned.clone())
        };
        for id in owned {
            self.queue(
                Command::plane(id, PlaneOp::CollisionGroups(table.clone())),
                None,
            );
        }
        Ok(result)
    }

    /// The ports of this client (planes open their subscribers through it).
    pub(crate) fn transport(&self) -> &Transport {
        &self.inner.transport
    }
}

impl Inner {
    fn round_trip(&self, commands: Vec<Command>) -> Result<Vec<CommandResult>, Error> {
        self.round_trip_keeping(commands)
            .map(|(results, _)| results)
    }

    /// [`Inner::round_trip`] that gives the commands back with their results.
    fn round_trip_keeping(
        &self,
        commands: Vec<Command>,
    ) -> Result<(Vec<CommandResult>, Vec<Command>), Error> {
        if self.state.borrow().gone {
            return Err(self.gone());
        }
        let request = Request { commands };
        let n = request.commands.len();
        let bytes = self.encode(&request);
        let reply = self.exchange(&bytes, self.transport.id())?;
        let results = self.results_of(&reply, n)?;
        let results = self.rejoin_if_forgotten(&request.commands, results)?;
        Ok((results, request.commands))
    }

    /// A daemon that forgot this client (it said Goodbye, or was released) answers
    /// `NotConnected` to every command from the first one it refused: say Hello again and
    /// send those commands once more. The commands before it were applied and are not sent
    /// twice. Planes released with the old connection stay gone (their commands then fail
    /// with `UnknownPlane`).
    fn rejoin_if_forgotten(
        &self,
        commands: &[Command],
        mut results: Vec<CommandResult>,
    ) -> Result<Vec<CommandResult>, Error> {
        let refused = results
            .iter()
            .position(|r| matches!(r, Err(e) if e.kind == ErrorKind::NotConnected));
        let Some(first) = refused else {
            return Ok(results);
        };
        if self.daemon_node == 0 || matches!(commands[first], Command::Hello { .. }) {
            return Ok(results);
        }
        tracing::debug!("the daemon forgot this client: saying Hello again");
        let hello = Command::Hello {
            crate_version: self.options.crate_version.clone(),
            pid: std::process::id(),
        };
        match self.round_trip_once(vec![hello])?.pop() {
            Some(Ok(Reply::Welcome { .. })) => {}
            Some(Err(e)) => return Err(e.into()),
            other => {
                return Err(Error::Protocol(format!(
                    "unexpected handshake reply {other:?}"
                )))
            }
        }
        let again = commands[first..].to_vec();
        let retried = self.round_trip_once(again)?;
        results.truncate(first);
        results.extend(retried);
        Ok(results)
    }

    /// One request and its results, without the re-handshake of [`Inner::round_trip`].
    fn round_trip_once(&self, commands: Vec<Command>) -> Result<Vec<CommandResult>, Error> {
        let n = commands.len();
        let request = Request { commands };
        let bytes = self.encode(&request);
        let reply = self.exchange(&bytes, self.transport.id())?;
        self.results_of(&reply, n)
    }

    /// The bytes of `request` in this client's layout version.
    fn encode(&self, request: &Request) -> Vec<u8> {
        if self.options.layout_version == LAYOUT_VERSION {
            codec::encode_request(request)
        } else {
            codec::encode_request_with_version(request, self.options.layout_version)
        }
    }

    /// The results of a reply to `n` commands.
    fn results_of(&self, reply: &[u8], n: usize) -> Result<Vec<CommandResult>, Error> {
        let frame = codec::Frame::parse(reply).map_err(|e| Error::Protocol(e.to_string()))?;
        if frame.version != self.options.layout_version {
            // The daemon answered in the version-neutral form: its crate version as text.
            return Err(Error::VersionMismatch(format!(
                "layout version mismatch: client has LAYOUT_VERSION {} (crate {}), daemon has \
                 LAYOUT_VERSION {} (crate {})",
                self.options.layout_version,
                self.options.crate_version,
                frame.version,
                String::from_utf8_lossy(frame.body),
            )));
        }
        match codec::decode_response(reply) {
            Ok(Response::Results(results)) if results.len() == n => Ok(results),
            Ok(Response::Results(results)) => Err(Error::Protocol(format!(
                "{n} commands sent, {} results received",
                results.len()
            ))),
            Ok(Response::Rejected(e)) => Err(Error::Command(e)),
            Err(e) => Err(Error::Protocol(e.to_string())),
        }
    }

    /// Sends raw request bytes and waits for the raw reply, checking the daemon's liveness
    /// while waiting so a dead daemon is an error within a bounded time, not a hang.
    /// A beat buffered from before the request can delay a stall verdict by one check
    /// (100 ms) at most, so the request's hot path does not drain the heartbeat first.
    fn exchange(&self, bytes: &[u8], header: u128) -> Result<Vec<u8>, Error> {
        let spin = self.reply_spin.take();
        self.transport.exchange(
            bytes,
            header,
            LIVENESS_PERIOD,
            spin,
            self.waiting(Instant::now()),
        )
    }

    /// Waits for a pipelined flush's reply as [`Inner::exchange`] waits for its own.
    fn await_reply(
        &self,
        local: &crate::transport::LocalTransport,
        pending: &crate::transport::PendingReply,
        since: Instant,
    ) -> Result<Vec<u8>, Error> {
        local.await_reply(
            pending,
            LIVENESS_PERIOD,
            Duration::ZERO,
            self.waiting(since),
        )
    }

    /// What a request waiting for its reply since `started` checks between sleeps: the
    /// daemon's liveness, a stall, the request timeout.
    fn waiting(&self, started: Instant) -> impl FnMut(bool) -> Result<(), Error> + '_ {
        let mut last_check = started;
        let mut last_beat = started;
        move |connected| {
            if !connected {
                self.check_daemon()?;
            }
            let now = Instant::now();
            if now.duration_since(last_check) >= LIVENESS_PERIOD {
                self.check_daemon()?;
                last_check = now;
                if self.transport.heartbeat_arrived() != Some(false) {
                    last_beat = now;
                    self.last_beat.set(now);
                }
            }
            let silent = now.duration_since(last_beat);
            let stalled =
                silent > HUNG_AFTER || (silent > STALL_AFTER && process_stopped(self.daemon_pid));
            if stalled && self.daemon_node != 0 {
                return Err(Error::Stalled {
                    domain: self.options.domain.clone(),
                    pid: self.daemon_pid,
                    silent,
                });
            }
            if now.duration_since(started) > self.options.request_timeout {
                return Err(Error::Timeout(self.options.request_timeout));
            }
            Ok(())
        }
    }

    pub(crate) fn check_daemon(&self) -> Result<(), Error> {
        match self.transport.daemon_alive(self.daemon_node) {
            Some(false) if self.daemon_node == 0 => Err(Error::NoDaemon {
                domain: self.options.domain.clone(),
                detail: "no live daemon process answers".into(),
            }),
            Some(false) => {
                self.state.borrow_mut().gone = true;
                Err(self.gone())
            }
            _ => Ok(()),
        }
    }

    fn gone(&self) -> Error {
        Error::DaemonGone {
            domain: self.options.domain.clone(),
            pid: self.daemon_pid,
        }
    }
}

impl Drop for Inner {
    fn drop(&mut self) {
        // An orderly goodbye releases our planes at once (a crash is noticed by the daemon's
        // dead-node detection instead). Failures do not matter any more.
        if !self.state.borrow().gone && self.daemon_node != 0 {
            let _ = self.round_trip(vec![Command::Goodbye]);
        }
    }
}

/// Whether process `pid` is stopped (SIGSTOP, or stopped by a tracer).
fn process_stopped(pid: u32) -> bool {
    std::fs::read_to_string(format!("/proc/{pid}/stat")).is_ok_and(|stat| {
        // The state follows the parenthesised command name.
        stat.rsplit_once(") ")
            .is_some_and(|(_, rest)| rest.starts_with('T') || rest.starts_with('t'))
    })
}

pub(crate) fn unexpected(reply: Reply) -> Error {
    Error::Protocol(format!("unexpected reply {reply:?}"))
}

impl std::fmt::Debug for Client {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Client")
            .field("domain", &self.domain())
            .field("daemon_pid", &self.daemon_pid())
            .finish()
    }
}

/// The plane a command names (0: none).
fn command_plane(command: &Command) -> PlaneId {
    match command {
        Command::Plane { plane, .. } => *plane,
        _ => 0,
    }
}

/// Where a command goes ([`Client::reroute`]).
pub(crate) enum Rerouted {
    /// On this connection (under the plane's id here, which differs when the plane moved
    /// onto it).
    Here(Command),
    /// On another connection.
    There(Client, Command),
}

/// Whether `command` is the release of a held add ([`ConnectOptions::hold_adds_until_flush`]).
fn is_release(command: &Command) -> bool {
    matches!(
        command,
        Command::Plane {
            op: PlaneOp::Object {
                op: ObjectOp::Set(shm_layout::ObjectProp::Held(false)),
                ..
            },
            ..
        } | Command::Plane {
            op: PlaneOp::Gui(GuiOp::Object {
                op: GuiObjectOp::Set(shm_layout::GuiObjectProp::Held(false)),
                ..
            }),
            ..
        }
    )
}

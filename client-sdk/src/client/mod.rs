//! The connection to the daemon: handshake, one request per flush, daemon liveness.
//!
//! This file holds the connection's state ([`Client`] and what it shares with its planes);
//! what a connection does is split by concern: `connect` (connecting, the handshake),
//! `batch` (queued writes, flushes, results and refusals), `pipelined` (flushes that do not
//! wait), `exchange` (round trips and the daemon's liveness), `moves` (planes that moved or
//! failed over to another daemon) and `groups` (collision groups).

use std::cell::RefCell;
use std::collections::HashMap;
use std::rc::Rc;
use std::time::{Duration, Instant};

use shm_layout::{
    CollisionGroups, Command, CommandError, Handle, PlaneId, Reply, CRATE_VERSION, LAYOUT_VERSION,
};

use crate::error::Error;
use crate::plane_shared::PlaneShared;
use crate::remote::RemoteOptions;
use crate::transport::Transport;

mod batch;
mod connect;
mod exchange;
mod groups;
mod moves;
mod pipelined;

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

impl Client {
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

    pub(crate) fn forget_plane(&self, id: PlaneId) {
        let mut state = self.inner.state.borrow_mut();
        state.owned.retain(|p| *p != id);
        state.planes.remove(&id);
    }

    /// The ports of this client (planes open their subscribers through it).
    pub(crate) fn transport(&self) -> &Transport {
        &self.inner.transport
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

/// Where a command goes ([`Client::reroute`]).
pub(crate) enum Rerouted {
    /// On this connection (under the plane's id here, which differs when the plane moved
    /// onto it).
    Here(Command),
    /// On another connection.
    There(Client, Command),
}

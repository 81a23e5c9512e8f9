//! The client side of this host's shared-memory transport: the ports a process opens to
//! talk to the daemon of its domain (the node, the request port with the daemon's wake-up
//! event and its own reply event, and per plane the body subscriber, the tick listener and
//! the event subscriber). `client-sdk` builds its local connections on it, and the daemon's
//! relay of remote clients reaches the daemon through it as a local client, so neither
//! depends on the other.

#![deny(missing_docs)]

use std::cell::RefCell;
use std::time::{Duration, Instant};

use iceoryx2::config::Config;
use iceoryx2::node::NodeView;
use iceoryx2::port::client::Client as RequestPort;
use iceoryx2::port::listener::Listener;
use iceoryx2::port::notifier::Notifier;
use iceoryx2::port::subscriber::Subscriber;
use iceoryx2::prelude::*;
use shm_layout::{names, BodyState, EventRecord, PlaneId, TickHeader};

/// How many ticks' worth of event samples a reader's queue holds (one sample per tick that
/// had events); past it the oldest are dropped and reported as lost.
pub const EVENT_BUFFER_TICKS: usize = 64;

/// How long `open` waits for a starting daemon to open its request server.
const SERVER_WAIT: Duration = Duration::from_secs(2);

/// Subscriber of a plane's body states in shared memory.
pub type ShmBodySubscriber = Subscriber<ipc::Service, [BodyState], TickHeader>;
/// Subscriber of a plane's per-tick events in shared memory.
pub type ShmEventSubscriber = Subscriber<ipc::Service, [EventRecord], TickHeader>;

/// Why the transport failed. The messages read as the client's own errors of the same kind.
#[derive(Debug, thiserror::Error)]
pub enum TransportError {
    /// No daemon answers in the domain.
    #[error("no physics daemon is serving domain {domain:?} ({detail})")]
    NoDaemon {
        /// The domain that was tried.
        domain: String,
        /// What went wrong.
        detail: String,
    },
    /// The domain name is not usable.
    #[error("invalid domain: {0}")]
    InvalidDomain(String),
    /// An iceoryx2 port failed.
    #[error("shared-memory transport: {0}")]
    Ipc(String),
}

impl TransportError {
    fn ipc(what: &str, e: impl core::fmt::Debug) -> TransportError {
        TransportError::Ipc(format!("{what}: {e:?}"))
    }
}

/// The ports of one client process.
pub struct LocalTransport {
    config: Config,
    node: Node<ipc::Service>,
    control: ControlFactory,
    /// Replaced when its memory is exhausted (see [`LocalTransport::send`]).
    port: RefCell<ControlPort>,
    daemon_wake: Notifier<ipc::Service>,
    replies: Listener<ipc::Service>,
    id: u128,
    /// The daemon's heartbeat, opened on first use (a starting daemon may not beat yet).
    heartbeat: RefCell<Option<Subscriber<ipc::Service, u64, ()>>>,
}

impl LocalTransport {
    /// Opens the ports of a client of `domain`'s daemon (waiting, bounded, for a starting
    /// daemon's request server).
    pub fn open(domain: &str) -> Result<LocalTransport, TransportError> {
        let config =
            names::config(domain).map_err(|e| TransportError::InvalidDomain(e.to_string()))?;
        let no_daemon = |detail: String| TransportError::NoDaemon {
            domain: domain.to_string(),
            detail,
        };
        // A crashed daemon leaves its services behind: look for a live daemon process first,
        // and remove what dead processes left, so the domain is clean for the next daemon.
        if daemon_alive(&config, 0) == Some(false) {
            let removed = remove_dead_nodes(&config);
            let detail = if removed > 0 {
                format!(
                    "no live daemon process in this domain (removed what {removed} dead \
                     processes' nodes left)"
                )
            } else {
                "no live daemon process in this domain".to_string()
            };
            return Err(no_daemon(detail));
        }
        let node = NodeBuilder::new()
            .name(&NodeName::new("physics-client").expect("valid node name"))
            .config(&config)
            .signal_handling_mode(SignalHandlingMode::Disabled)
            .create::<ipc::Service>()
            .map_err(|e| TransportError::ipc("cannot create node", e))?;
        let id = node.id().value();
        let control = node
            .service_builder(&names::control())
            .request_response::<[u8], [u8]>()
            .request_user_header::<u128>()
            .open()
            .map_err(|e| no_daemon(format!("{e:?}")))?;
        // A daemon that is starting has its node before its server port; a request sent in
        // between would reach no one. Wait (bounded) until the server is there.
        let deadline = Instant::now() + SERVER_WAIT;
        while control.dynamic_config().number_of_servers() == 0 {
            if Instant::now() >= deadline {
                return Err(no_daemon("the control service has no server".into()));
            }
            std::thread::sleep(Duration::from_millis(2));
        }
        let port = RefCell::new(request_port(&control)?);
        let daemon_wake = node
            .service_builder(&names::control_wake())
            .event()
            .open()
            .map_err(|e| no_daemon(format!("{e:?}")))?
            .notifier_builder()
            .create()
            .map_err(|e| TransportError::ipc("cannot create notifier", e))?;
        let replies = node
            .service_builder(&names::client_wake(id))
            .event()
            .max_notifiers(2)
            .max_listeners(1)
            .create()
            .map_err(|e| TransportError::ipc("cannot create reply event", e))?
            .listener_builder()
            .create()
            .map_err(|e| TransportError::ipc("cannot create reply listener", e))?;
        Ok(LocalTransport {
            control,
            config,
            node,
            port,
            daemon_wake,
            replies,
            id,
            heartbeat: RefCell::new(None),
        })
    }

    /// Sends request bytes and wakes the daemon; then polls for the reply, first without
    /// sleeping for up to `spin` (a client's reply spin), then sleeping on our reply event up to
    /// `period` at a time and calling `check` between sleeps (liveness, timeouts): a dead
    /// daemon is an error within a bounded time, not a hang.
    pub fn exchange<E: From<TransportError>>(
        &self,
        bytes: &[u8],
        header: u128,
        period: Duration,
        spin: Duration,
        check: impl FnMut(bool) -> Result<(), E>,
    ) -> Result<Vec<u8>, E> {
        let pending = self.send(bytes, header)?;
        self.await_reply(&pending, period, spin, check)
    }

    /// Sends request bytes and wakes the daemon, without waiting: the reply is collected
    /// later ([`LocalTransport::await_reply`], [`LocalTransport::try_reply`]).
    pub fn send(&self, bytes: &[u8], header: u128) -> Result<PendingReply, TransportError> {
        let loaned = self.port.borrow().loan_slice_uninit(bytes.len());
        let mut request = match loaned {
            Ok(r) => r,
            Err(e) => {
                // A port whose shared memory is exhausted (requests of very different sizes
                // can fragment it) is replaced by a fresh one, once.
                tracing::debug!(
                    "loan of {} request bytes failed ({e:?}): new request port",
                    bytes.len()
                );
                *self.port.borrow_mut() = request_port(&self.control)?;
                self.port
                    .borrow()
                    .loan_slice_uninit(bytes.len())
                    .map_err(|e| TransportError::ipc("loan request", e))?
            }
        };
        // The daemon identifies us by the transport's node id; the user header (our id,
        // normally) only keeps the control service's layout the same for every version (so
        // a version mismatch still reaches the handshake).
        *request.user_header_mut() = header;
        let pending = request
            .write_from_slice(bytes)
            .send()
            .map_err(|e| TransportError::ipc("send request", e))?;
        self.daemon_wake
            .notify()
            .map_err(|e| TransportError::ipc("wake daemon", e))?;
        Ok(PendingReply(pending))
    }

    /// The reply of `pending` if it has arrived (never waits).
    pub fn try_reply(&self, pending: &PendingReply) -> Result<Option<Vec<u8>>, TransportError> {
        Ok(pending
            .0
            .receive()
            .map_err(|e| TransportError::ipc("receive reply", e))?
            .map(|response| response.payload().to_vec()))
    }

    /// Waits for the reply of `pending` ([`LocalTransport::exchange`]'s wait).
    pub fn await_reply<E: From<TransportError>>(
        &self,
        pending: &PendingReply,
        period: Duration,
        spin: Duration,
        mut check: impl FnMut(bool) -> Result<(), E>,
    ) -> Result<Vec<u8>, E> {
        if !spin.is_zero() {
            let until = std::time::Instant::now() + spin;
            while std::time::Instant::now() < until {
                if let Some(reply) = self.try_reply(pending)? {
                    // The reply event stays set: the next wait consumes it and looks again.
                    return Ok(reply);
                }
                // Yield rather than spin: on a machine with few cores the daemon's threads
                // that produce the reply may need this one.
                std::thread::yield_now();
            }
        }
        loop {
            if let Some(reply) = self.try_reply(pending)? {
                return Ok(reply);
            }
            check(pending.0.is_connected())?;
            let _ = self.replies.timed_wait(|_| {}, period);
        }
    }

    /// This client's iceoryx2 node id (what the daemon knows it by).
    pub fn id(&self) -> u128 {
        self.id
    }

    /// Whether a heartbeat of the daemon arrived since the last call; `None` when the
    /// heartbeat service cannot be opened (then nothing can be said).
    pub fn heartbeat_arrived(&self) -> Option<bool> {
        let mut slot = self.heartbeat.borrow_mut();
        if slot.is_none() {
            let opened = self
                .node
                .service_builder(&names::heartbeat())
                .publish_subscribe::<u64>()
                .open()
                .ok()
                .and_then(|s| s.subscriber_builder().buffer_size(1).create().ok());
            *slot = Some(opened?);
        }
        let sub = slot.as_ref()?;
        let mut arrived = false;
        while let Ok(Some(_)) = sub.receive() {
            arrived = true;
        }
        Some(arrived)
    }

    /// Whether the daemon node `daemon_node` (0: any node named like a daemon) is alive;
    /// `None` when the node list cannot be read.
    pub fn daemon_alive(&self, daemon_node: u128) -> Option<bool> {
        daemon_alive(&self.config, daemon_node)
    }

    /// Subscribes to plane `id`'s body states (newest tick only).
    pub fn plane_bodies(&self, id: PlaneId) -> Result<ShmBodySubscriber, TransportError> {
        self.node
            .service_builder(&names::plane_bodies(id))
            .publish_subscribe::<[BodyState]>()
            .user_header::<TickHeader>()
            .open()
            .map_err(|e| TransportError::ipc("open plane body service", e))?
            .subscriber_builder()
            .buffer_size(1)
            .create()
            .map_err(|e| TransportError::ipc("create plane subscriber", e))
    }

    /// A listener woken by every tick of plane `id`.
    pub fn plane_ticks(&self, id: PlaneId) -> Result<Listener<ipc::Service>, TransportError> {
        self.node
            .service_builder(&names::plane_tick(id))
            .event()
            .open()
            .map_err(|e| TransportError::ipc("open tick event", e))?
            .listener_builder()
            .create()
            .map_err(|e| TransportError::ipc("create tick listener", e))
    }

    /// Subscribes to plane `id`'s per-tick events.
    pub fn plane_events(&self, id: PlaneId) -> Result<ShmEventSubscriber, TransportError> {
        self.node
            .service_builder(&names::plane_events(id))
            .publish_subscribe::<[EventRecord]>()
            .user_header::<TickHeader>()
            .open()
            .map_err(|e| TransportError::ipc("open event service", e))?
            .subscriber_builder()
            .buffer_size(EVENT_BUFFER_TICKS)
            .create()
            .map_err(|e| TransportError::ipc("create event subscriber", e))
    }
}

/// A request port of the control service.
type ControlPort = RequestPort<ipc::Service, [u8], u128, [u8], ()>;

/// The control service, as opened by a client.
type ControlFactory = iceoryx2::service::port_factory::request_response::PortFactory<
    ipc::Service,
    [u8],
    u128,
    [u8],
    (),
>;

/// A request sent whose reply has not been read yet (a pipelined flush keeps one).
pub struct PendingReply(
    iceoryx2::pending_response::PendingResponse<ipc::Service, [u8], u128, [u8], ()>,
);

/// A request port on the control service, growing its memory by powers of two.
fn request_port(control: &ControlFactory) -> Result<ControlPort, TransportError> {
    control
        .client_builder()
        .initial_max_slice_len(4096)
        .allocation_strategy(AllocationStrategy::PowerOfTwo)
        .create()
        .map_err(|e| TransportError::ipc("cannot create request port", e))
}

/// Whether the daemon's node is alive: found by id once the handshake told us the id, by
/// name before. `None` when the node list cannot be read (then we assume nothing).
fn daemon_alive(config: &Config, daemon_node: u128) -> Option<bool> {
    let mut alive = false;
    Node::<ipc::Service>::list(config, |state| {
        if daemon_node != 0 && state.node_id().value() == daemon_node {
            alive = matches!(state, NodeState::Alive(_));
            return CallbackProgression::Stop;
        }
        if let (0, NodeState::Alive(view)) = (daemon_node, &state) {
            if view
                .details()
                .as_ref()
                .is_some_and(|d| d.name().as_str() == names::DAEMON_NODE_NAME)
            {
                alive = true;
                return CallbackProgression::Stop;
            }
        }
        CallbackProgression::Continue
    })
    .ok()?;
    Some(alive)
}

/// Removes the resources of dead nodes of the domain (a killed daemon's or client's);
/// returns how many dead nodes were found.
fn remove_dead_nodes(config: &Config) -> usize {
    let mut dead = Vec::new();
    let _ = Node::<ipc::Service>::list(config, |state| {
        if let NodeState::Dead(view) = state {
            dead.push(view);
        }
        CallbackProgression::Continue
    });
    let n = dead.len();
    for view in dead {
        if let Err(e) = view.try_remove_stale_resources() {
            tracing::debug!("cleanup of a dead node: {e:?}");
        }
    }
    n
}

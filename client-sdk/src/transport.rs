//! Every port of the SDK is reached here: this host's iceoryx2 ports (the node, the request
//! port with the daemon's wake-up event and our reply event, and per plane the body
//! subscriber, the tick listener and the event subscriber: built by the `local-transport`
//! crate) or a cluster member's relay ([`crate::remote`]). `Client` and `Plane` hold what
//! this module returns and never name a service themselves.

use std::time::Duration;

use iceoryx2::port::listener::Listener;
use iceoryx2::prelude::*;
use iceoryx2::sample::Sample;
pub use local_transport::EVENT_BUFFER_TICKS;
pub(crate) use local_transport::{LocalTransport, PendingReply};
use local_transport::{ShmBodySubscriber, ShmEventSubscriber};
use shm_layout::{BodyState, EventRecord, PlaneId, TickHeader};

use crate::error::Error;

/// Lets only iceoryx2's errors reach stderr (`IOX2_LOG_LEVEL` still overrides): a game or
/// a script runner prints what it prints, not the transport's notes about dead nodes or a
/// missing config file, which the SDK handles itself.
pub fn quiet_transport_logs() {
    iceoryx2::prelude::set_log_level_from_env_or(LogLevel::Error);
}

/// How often a waiting client checks that the daemon process is still alive.
pub(crate) const LIVENESS_PERIOD: Duration = Duration::from_millis(100);

/// A shared-memory sample of a plane's body states.
type ShmBodySample = Sample<ipc::Service, [BodyState], TickHeader>;

/// A plane's body states of one tick: read in place from shared memory, or rebuilt from a
/// remote daemon's frames.
pub(crate) enum BodySample {
    /// This host's daemon's sample, in place.
    Shm(ShmBodySample),
    /// A remote daemon's tick, rebuilt bit for bit ([`shm_layout::remote::BodyMirror`]).
    Owned(Box<(TickHeader, Vec<BodyState>)>),
}

impl BodySample {
    /// Every slot of the tick.
    pub(crate) fn payload(&self) -> &[BodyState] {
        match self {
            BodySample::Shm(s) => s.payload(),
            BodySample::Owned(o) => &o.1,
        }
    }

    /// The tick's header.
    pub(crate) fn user_header(&self) -> &TickHeader {
        match self {
            BodySample::Shm(s) => s.user_header(),
            BodySample::Owned(o) => &o.0,
        }
    }
}

/// Subscriber of a plane's body states (newest tick only).
pub(crate) enum BodySubscriber {
    /// Shared memory of this host's daemon.
    Shm(ShmBodySubscriber),
    /// Frames of a remote daemon's relay.
    Remote(crate::remote::Bodies),
}

impl BodySubscriber {
    /// The next tick waiting, if any (`None` also when every borrow slot is held by
    /// snapshots the caller keeps: the caller keeps the newest it has).
    pub(crate) fn receive(&self) -> Result<Option<BodySample>, Error> {
        match self {
            BodySubscriber::Shm(s) => match s.receive() {
                Ok(sample) => Ok(sample.map(BodySample::Shm)),
                Err(iceoryx2::port::ReceiveError::ExceedsMaxBorrows) => Ok(None),
                Err(e) => Err(Error::ipc("receive tick", e)),
            },
            BodySubscriber::Remote(r) => Ok(r.receive().map(|o| BodySample::Owned(Box::new(o)))),
        }
    }
}

/// One tick's events.
pub(crate) enum EventSample {
    /// In place in shared memory.
    Shm(Sample<ipc::Service, [EventRecord], TickHeader>),
    /// From a remote daemon's relay.
    Owned(Vec<EventRecord>),
}

impl EventSample {
    /// The tick's events, in order.
    pub(crate) fn payload(&self) -> &[EventRecord] {
        match self {
            EventSample::Shm(s) => s.payload(),
            EventSample::Owned(r) => r,
        }
    }
}

/// Subscriber of a plane's per-tick events.
pub(crate) enum EventSubscriber {
    /// Shared memory of this host's daemon.
    Shm(ShmEventSubscriber),
    /// Frames of a remote daemon's relay, and the event number its stream starts at.
    Remote(crate::remote::Events),
}

impl EventSubscriber {
    /// The next tick's events waiting, if any.
    pub(crate) fn receive(&self) -> Result<Option<EventSample>, Error> {
        match self {
            EventSubscriber::Shm(s) => s
                .receive()
                .map(|o| o.map(EventSample::Shm))
                .map_err(|e| Error::ipc("receive events", e)),
            EventSubscriber::Remote(r) => Ok(r.receive().map(EventSample::Owned)),
        }
    }

    /// Where a remote stream starts (the relay subscribed then); `None` for shared memory.
    pub(crate) fn start(&self) -> Option<u32> {
        match self {
            EventSubscriber::Shm(_) => None,
            EventSubscriber::Remote(r) => Some(r.start),
        }
    }
}

/// Woken on every tick of a plane.
pub(crate) enum TickListener {
    /// The plane's tick event on this host.
    Shm(Box<Listener<ipc::Service>>),
    /// A remote plane's frames arriving.
    Remote(crate::remote::Ticks),
}

impl TickListener {
    /// Waits up to `wait` for a tick.
    pub(crate) fn timed_wait(&self, wait: Duration) {
        match self {
            TickListener::Shm(l) => {
                let _ = l.timed_wait(|_| {}, wait);
            }
            TickListener::Remote(t) => t.timed_wait(wait),
        }
    }
}

/// How a client reaches its daemon: this host's shared memory, or a cluster member's relay.
pub(crate) enum Transport {
    /// The daemon of this host's domain.
    Local(Box<LocalTransport>),
    /// A daemon of a cluster, through Zenoh.
    Remote(crate::remote::RemoteTransport),
}

impl Transport {
    /// Opens the ports of a client of `domain`'s daemon on this host.
    pub(crate) fn open(domain: &str) -> Result<Transport, Error> {
        Ok(Transport::Local(Box::new(LocalTransport::open(domain)?)))
    }

    /// Sends request bytes and returns the reply bytes ([`LocalTransport::exchange`]).
    pub(crate) fn exchange(
        &self,
        bytes: &[u8],
        header: u128,
        period: Duration,
        spin: Duration,
        check: impl FnMut(bool) -> Result<(), Error>,
    ) -> Result<Vec<u8>, Error> {
        match self {
            Transport::Local(t) => t.exchange(bytes, header, period, spin, check),
            Transport::Remote(t) => t.exchange(bytes, period, check),
        }
    }

    /// This host's transport, when it is one (only its requests can be pipelined: see
    /// `Client::flush`).
    pub(crate) fn local(&self) -> Option<&LocalTransport> {
        match self {
            Transport::Local(t) => Some(t),
            Transport::Remote(_) => None,
        }
    }

    /// What the daemon knows this client by.
    pub(crate) fn id(&self) -> u128 {
        match self {
            Transport::Local(t) => t.id(),
            Transport::Remote(t) => t.id(),
        }
    }

    /// Whether a heartbeat of the daemon arrived since the last call; `None` when nothing
    /// can be said (a remote daemon: its liveliness token speaks for it instead).
    pub(crate) fn heartbeat_arrived(&self) -> Option<bool> {
        match self {
            Transport::Local(t) => t.heartbeat_arrived(),
            Transport::Remote(_) => None,
        }
    }

    /// Whether the daemon is alive; `None` when that cannot be read.
    pub(crate) fn daemon_alive(&self, daemon_node: u128) -> Option<bool> {
        match self {
            Transport::Local(t) => t.daemon_alive(daemon_node),
            Transport::Remote(t) => t.daemon_alive(),
        }
    }

    /// Whether the daemon runs on this host (its pid means something here).
    pub(crate) fn is_local(&self) -> bool {
        matches!(self, Transport::Local(_))
    }

    /// Subscribes to plane `id`'s body states (newest tick only).
    pub(crate) fn plane_bodies(&self, id: PlaneId) -> Result<BodySubscriber, Error> {
        match self {
            Transport::Local(t) => Ok(BodySubscriber::Shm(t.plane_bodies(id)?)),
            Transport::Remote(t) => t.plane_bodies(id).map(BodySubscriber::Remote),
        }
    }

    /// A listener woken by every tick of plane `id`.
    pub(crate) fn plane_ticks(&self, id: PlaneId) -> Result<TickListener, Error> {
        match self {
            Transport::Local(t) => Ok(TickListener::Shm(Box::new(t.plane_ticks(id)?))),
            Transport::Remote(t) => t.plane_ticks(id).map(TickListener::Remote),
        }
    }

    /// Subscribes to plane `id`'s per-tick events.
    pub(crate) fn plane_events(&self, id: PlaneId) -> Result<EventSubscriber, Error> {
        match self {
            Transport::Local(t) => Ok(EventSubscriber::Shm(t.plane_events(id)?)),
            Transport::Remote(t) => t.plane_events(id).map(EventSubscriber::Remote),
        }
    }
}

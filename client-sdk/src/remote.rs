//! A client of a daemon on another host (docs/cluster.md, "Remote clients"): the same
//! requests, replies and ticks as a local client, carried by Zenoh to the daemon's relay
//! (`physics_daemon::cluster::relay`) instead of by shared memory. The wire is
//! `shm_layout::remote`.
//!
//! - Requests are Zenoh queries whose payload is the request frame a local client sends;
//!   the relay answers with the daemon's response frame.
//! - A plane's ticks arrive as [`BodyFrame`]s (changed slots only) and are rebuilt bit for
//!   bit ([`BodyMirror`], checked against each tick's `state_hash`); a lost or corrupt frame
//!   makes the reader ask for a keyframe and keep its last good tick meanwhile.
//! - The daemon's liveliness token tells whether it is alive; our own token tells the relay
//!   that we are (our planes are released once it ends).

use std::cell::{Cell, RefCell};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use shm_layout::remote::{
    self as wire, Applied, BodyFrame, BodyMirror, EventFrame, WatchOp, WatchReply,
};
use shm_layout::{BodyState, EventRecord, PlaneId, TickHeader};
use zenoh::handlers::{RingChannel, RingChannelHandler};
use zenoh::liveliness::LivelinessToken;
use zenoh::pubsub::Subscriber;
use zenoh::sample::{Sample, SampleKind};
use zenoh::{Session, Wait};

use crate::cluster::{Cluster, ClusterOptions};
use crate::error::Error;

/// How long a watch request waits for the relay's answer.
const WATCH_TIMEOUT: Duration = Duration::from_secs(5);
/// The longest a request's query stays open (the client's own request timeout, checked
/// while waiting, is normally shorter).
const QUERY_TIMEOUT: Duration = Duration::from_secs(600);
/// How long connecting waits to learn that the chosen daemon is alive.
const ALIVE_WAIT: Duration = Duration::from_secs(2);
/// Frames a body reader keeps before the oldest are dropped (then it asks for a keyframe).
const BODY_FRAMES: usize = 64;
/// Ticks of events a reader keeps before the oldest are dropped (and counted as lost), as
/// a local reader's queue (`EVENT_BUFFER_TICKS`).
const EVENT_FRAMES: usize = 64;
/// At most one keyframe request per plane this often.
const KEYFRAME_EVERY: Duration = Duration::from_millis(100);

/// Where a remote client goes: the cluster, and the daemon (`None`: the least loaded).
#[derive(Debug, Clone, Default)]
pub struct RemoteOptions {
    /// How to reach the cluster.
    pub cluster: ClusterOptions,
    /// The daemon to use, by `--name`; `None` picks the live daemon with the smallest share
    /// of its tick budget used.
    pub daemon: Option<String>,
}

/// The Zenoh side of one remote client.
pub(crate) struct RemoteTransport {
    session: Session,
    cluster: String,
    daemon: String,
    key: String,
    id: u128,
    alive: Arc<AtomicBool>,
    _token: LivelinessToken,
    _daemon_token: Subscriber<()>,
}

impl RemoteTransport {
    /// Connects to the cluster, picks the daemon and declares this client's token.
    pub(crate) fn open(options: &RemoteOptions) -> Result<RemoteTransport, Error> {
        let cluster = Cluster::connect_with(&options.cluster)?;
        let daemon = match &options.daemon {
            Some(name) => {
                shm_layout::cluster::check_name("daemon", name)
                    .map_err(|e| Error::Cluster(e.to_string()))?;
                name.clone()
            }
            None => least_loaded(&cluster)?,
        };
        let name = cluster.name().to_string();
        let session = cluster.into_session();
        let zerr = |what: &str, e: zenoh::Error| Error::Cluster(format!("{what}: {e}"));
        let key = session_key()?;
        let token = session
            .liveliness()
            .declare_token(wire::client_key(&name, &key))
            .wait()
            .map_err(|e| zerr("cannot declare the client's token", e))?;
        let alive = Arc::new(AtomicBool::new(false));
        let seen = Arc::new(AtomicBool::new(false));
        let (a, s) = (alive.clone(), seen.clone());
        let daemon_token = session
            .liveliness()
            .declare_subscriber(shm_layout::cluster::daemon_key(&name, &daemon))
            .history(true)
            .callback(move |sample: Sample| {
                a.store(sample.kind() == SampleKind::Put, Ordering::SeqCst);
                s.store(true, Ordering::SeqCst);
            })
            .wait()
            .map_err(|e| zerr("cannot watch the daemon's token", e))?;
        let deadline = Instant::now() + ALIVE_WAIT;
        while !alive.load(Ordering::SeqCst) {
            if Instant::now() >= deadline {
                return Err(Error::NoDaemon {
                    domain: format!("cluster {name:?}"),
                    detail: format!("no daemon named {daemon:?} is alive in the cluster"),
                });
            }
            std::thread::sleep(Duration::from_millis(5));
        }
        let id = u128::from_str_radix(&key, 16).unwrap_or_default();
        Ok(RemoteTransport {
            session,
            cluster: name,
            daemon,
            key,
            id,
            alive,
            _token: token,
            _daemon_token: daemon_token,
        })
    }

    /// The daemon this client uses.
    pub(crate) fn daemon(&self) -> &str {
        &self.daemon
    }

    /// The cluster.
    pub(crate) fn cluster(&self) -> &str {
        &self.cluster
    }

    /// Sends request bytes to the relay and waits for the reply, calling `check` every
    /// `period` (liveness, timeouts).
    pub(crate) fn exchange(
        &self,
        bytes: &[u8],
        period: Duration,
        mut check: impl FnMut(bool) -> Result<(), Error>,
    ) -> Result<Vec<u8>, Error> {
        let replies = self
            .session
            .get(wire::request_key(&self.cluster, &self.daemon, &self.key))
            .payload(bytes.to_vec())
            .timeout(QUERY_TIMEOUT)
            .wait()
            .map_err(|e| Error::Cluster(format!("cannot send a request: {e}")))?;
        loop {
            match replies.recv_timeout(period) {
                Ok(Some(reply)) => {
                    return match reply.into_result() {
                        Ok(sample) => Ok(sample.payload().to_bytes().into_owned()),
                        Err(e) => Err(self.relay_error(e.payload())),
                    }
                }
                Ok(None) => check(self.alive.load(Ordering::SeqCst))?,
                Err(_) => {
                    // The query ended without a reply: the daemon left, or never had a relay.
                    // A daemon that died ends its queries at once, and the end of its
                    // liveliness token can reach this session a little later: wait for that
                    // verdict (bounded) so a death reads as `DaemonGone` (which the failover
                    // switch-over acts on), not as a daemon that does not answer.
                    let deadline = Instant::now() + ALIVE_WAIT;
                    while self.alive.load(Ordering::SeqCst) && Instant::now() < deadline {
                        std::thread::sleep(Duration::from_millis(5));
                    }
                    check(false)?;
                    return Err(Error::Cluster(format!(
                        "daemon {:?} did not answer (is it a member of cluster {:?} with a \
                         relay?)",
                        self.daemon, self.cluster
                    )));
                }
            }
        }
    }

    fn relay_error(&self, payload: &zenoh::bytes::ZBytes) -> Error {
        let text = payload
            .try_to_string()
            .map(|s| s.into_owned())
            .unwrap_or_else(|_| "(not text)".into());
        Error::Cluster(format!("daemon {:?}: {text}", self.daemon))
    }

    /// What the daemon knows this client by (its session key).
    pub(crate) fn id(&self) -> u128 {
        self.id
    }

    /// Whether the daemon's liveliness token exists.
    pub(crate) fn daemon_alive(&self) -> Option<bool> {
        Some(self.alive.load(Ordering::SeqCst))
    }

    /// The members that hold replicas of other members' persistent planes (failover),
    /// by name; empty when the cluster does not answer.
    pub(crate) fn holders(&self) -> Vec<String> {
        let replies = self
            .session
            .liveliness()
            .get(format!(
                "{}/{}/holder/*",
                shm_layout::cluster::ROOT,
                self.cluster
            ))
            .timeout(Duration::from_secs(1))
            .wait();
        let mut names = Vec::new();
        if let Ok(replies) = replies {
            while let Ok(reply) = replies.recv() {
                if let Ok(sample) = reply.result() {
                    names.push(
                        shm_layout::cluster::last_segment(sample.key_expr().as_str()).to_string(),
                    );
                }
            }
        }
        names
    }

    fn watch(&self, op: WatchOp) -> Result<WatchReply, Error> {
        let replies = self
            .session
            .get(wire::watch_key(&self.cluster, &self.daemon, &self.key))
            .payload(op.encode())
            .timeout(WATCH_TIMEOUT)
            .wait()
            .map_err(|e| Error::Cluster(format!("cannot ask for a plane's ticks: {e}")))?;
        let reply = replies.recv().map_err(|_| {
            Error::Cluster(format!(
                "daemon {:?} did not answer a watch of {op:?} in {WATCH_TIMEOUT:?}",
                self.daemon
            ))
        })?;
        let sample = reply
            .into_result()
            .map_err(|e| self.relay_error(e.payload()))?;
        match WatchReply::decode(&sample.payload().to_bytes()) {
            Some(WatchReply::Refused(message)) => Err(Error::Cluster(message)),
            Some(reply) => Ok(reply),
            None => Err(Error::Protocol("malformed watch reply".into())),
        }
    }

    /// Subscribes to plane `id`'s ticks (a keyframe first).
    pub(crate) fn plane_bodies(&self, id: PlaneId) -> Result<Bodies, Error> {
        let key = wire::bodies_key(&self.cluster, &self.daemon, &self.key, id);
        let frames = self
            .session
            .declare_subscriber(key)
            .with(RingChannel::new(BODY_FRAMES))
            .wait()
            .map_err(|e| Error::Cluster(format!("cannot subscribe to plane {}: {e}", id)))?;
        self.watch(WatchOp::Bodies { plane: id })?;
        Ok(Bodies {
            frames,
            mirror: RefCell::default(),
            asker: Asker {
                session: self.session.clone(),
                key: wire::watch_key(&self.cluster, &self.daemon, &self.key),
                plane: id,
                last: Cell::new(None),
            },
        })
    }

    /// Woken by plane `id`'s frames arriving.
    pub(crate) fn plane_ticks(&self, id: PlaneId) -> Result<Ticks, Error> {
        let key = wire::bodies_key(&self.cluster, &self.daemon, &self.key, id);
        let frames = self
            .session
            .declare_subscriber(key)
            .with(RingChannel::new(1))
            .wait()
            .map_err(|e| Error::Cluster(format!("cannot subscribe to plane {}: {e}", id)))?;
        Ok(Ticks { frames })
    }

    /// Subscribes to plane `id`'s events.
    pub(crate) fn plane_events(&self, id: PlaneId) -> Result<Events, Error> {
        let key = wire::events_key(&self.cluster, &self.daemon, &self.key, id);
        let frames = self
            .session
            .declare_subscriber(key)
            .with(RingChannel::new(EVENT_FRAMES))
            .wait()
            .map_err(|e| Error::Cluster(format!("cannot subscribe to plane {}: {e}", id)))?;
        let start = match self.watch(WatchOp::Events { plane: id })? {
            WatchReply::EventsFrom(start) => start,
            other => return Err(Error::Protocol(format!("unexpected watch reply {other:?}"))),
        };
        Ok(Events { frames, start })
    }
}

/// Asks the relay for a keyframe, at most every [`KEYFRAME_EVERY`].
struct Asker {
    session: Session,
    key: String,
    plane: u32,
    last: Cell<Option<Instant>>,
}

impl Asker {
    fn ask(&self) {
        if self
            .last
            .get()
            .is_some_and(|t| t.elapsed() < KEYFRAME_EVERY)
        {
            return;
        }
        self.last.set(Some(Instant::now()));
        // Fire and forget: the keyframe itself is the answer.
        let _ = self
            .session
            .get(&self.key)
            .payload(WatchOp::Keyframe { plane: self.plane }.encode())
            .timeout(WATCH_TIMEOUT)
            .callback(|_| {})
            .wait();
    }
}

/// A remote plane's ticks, rebuilt.
pub(crate) struct Bodies {
    frames: Subscriber<RingChannelHandler<Sample>>,
    mirror: RefCell<BodyMirror>,
    asker: Asker,
}

impl Bodies {
    /// The newest tick, when frames arrived since the last call.
    pub(crate) fn receive(&self) -> Option<(TickHeader, Vec<BodyState>)> {
        let mut mirror = self.mirror.borrow_mut();
        let mut newer = false;
        while let Ok(Some(sample)) = self.frames.try_recv() {
            let Some(frame) = BodyFrame::decode(&sample.payload().to_bytes()) else {
                tracing::debug!("a malformed body frame was dropped");
                self.asker.ask();
                continue;
            };
            match mirror.apply(frame) {
                Applied::Newer => newer = true,
                Applied::NeedKeyframe | Applied::Mismatch => self.asker.ask(),
            }
        }
        if newer {
            mirror.current.clone()
        } else {
            None
        }
    }
}

impl Drop for Bodies {
    fn drop(&mut self) {
        // The relay stops streaming the plane (and frees its place for other sessions).
        let _ = self
            .asker
            .session
            .get(&self.asker.key)
            .payload(
                WatchOp::Stop {
                    plane: self.asker.plane,
                }
                .encode(),
            )
            .timeout(WATCH_TIMEOUT)
            .callback(|_| {})
            .wait();
    }
}

/// Woken by a remote plane's frames.
pub(crate) struct Ticks {
    frames: Subscriber<RingChannelHandler<Sample>>,
}

impl Ticks {
    /// Waits up to `wait` for a frame.
    pub(crate) fn timed_wait(&self, wait: Duration) {
        let _ = self.frames.recv_timeout(wait);
    }
}

/// A remote plane's events.
pub(crate) struct Events {
    frames: Subscriber<RingChannelHandler<Sample>>,
    /// The event number the relay's stream starts at.
    pub(crate) start: u32,
}

impl Events {
    /// The next tick's events waiting, if any.
    pub(crate) fn receive(&self) -> Option<Vec<EventRecord>> {
        while let Ok(Some(sample)) = self.frames.try_recv() {
            if let Some(frame) = EventFrame::decode(&sample.payload().to_bytes()) {
                return Some(frame.records);
            }
        }
        None
    }
}

/// The daemon with the smallest share of its tick budget used.
fn least_loaded(cluster: &Cluster) -> Result<String, Error> {
    let daemons = cluster.daemons()?;
    daemons
        .iter()
        .min_by(|a, b| {
            let used = |d: &crate::cluster::DaemonInfo| {
                d.load.as_ref().map_or(f32::INFINITY, |l| l.budget_used)
            };
            used(a).total_cmp(&used(b)).then(a.name.cmp(&b.name))
        })
        .map(|d| d.name.clone())
        .ok_or_else(|| Error::NoDaemon {
            domain: format!("cluster {:?}", cluster.name()),
            detail: "no daemon of the cluster is alive".into(),
        })
}

/// 128 random bits as 32 hex digits (the session's capability).
fn session_key() -> Result<String, Error> {
    use std::io::Read;
    let mut bytes = [0u8; 16];
    std::fs::File::open("/dev/urandom")
        .and_then(|mut f| f.read_exact(&mut bytes))
        .map_err(|e| Error::Cluster(format!("cannot read /dev/urandom for a session key: {e}")))?;
    Ok(bytes.iter().map(|b| format!("{b:02x}")).collect())
}

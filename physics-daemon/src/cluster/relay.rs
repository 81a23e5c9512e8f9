//! The daemon's side of remote clients (docs/cluster.md, "Remote clients"): run by
//! `physics-daemon --cluster`, it answers the cluster's clients of this daemon through Zenoh
//! and reaches the daemon as a local client, one per remote session. So the daemon applies
//! to a remote client exactly what it applies to a local one (handshake, version check,
//! quotas, ownership, validation), and its server loop knows nothing of Zenoh.
//!
//! Per remote session one thread holds a local connection of its own: it relays the
//! session's requests in order, and streams each watched plane's ticks as
//! [`BodyFrame`]s (only the slots changed since the frame it last sent; a keyframe on
//! request) and its events as [`EventFrame`]s. A session ends when its client says
//! Goodbye, or when its liveliness token ends (the client's process or host died): the
//! relay then says Goodbye for it, and the daemon releases its planes as for any client.

use std::collections::HashMap;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{self, Receiver, RecvTimeoutError, Sender};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use shm_layout::remote::{self as wire, BodyFrame, EventFrame, WatchOp, WatchReply};
use shm_layout::{codec, BodyState, Command, PlaneOp, RecordOp, TickHeader};
use zenoh::query::{Query, Queryable};
use zenoh::sample::{Sample, SampleKind};
use zenoh::{Session, Wait};

use local_transport::{LocalTransport, ShmBodySubscriber, ShmEventSubscriber, TransportError};

use super::error::ClusterError;

/// Why a relayed exchange with the daemon failed.
#[derive(Debug, thiserror::Error)]
enum Error {
    /// The local transport failed.
    #[error(transparent)]
    Transport(#[from] TransportError),
    /// No reply came within the given time.
    #[error("timed out after {0:?}")]
    Timeout(Duration),
}

/// How often a session thread looks for new ticks while no request arrives (it waits on
/// its request queue meanwhile; a request wakes it at once).
const POLL: Duration = Duration::from_millis(1);
/// How long it waits on its request queue while it watches no plane.
const IDLE_WAIT: Duration = Duration::from_millis(50);
/// How long a relayed request may take before the relay answers with an error.
const REQUEST_TIMEOUT: Duration = Duration::from_secs(120);
/// How long a new session waits to see its client's liveliness token.
const TOKEN_WAIT: Duration = Duration::from_secs(2);
/// Most planes one remote session streams at once.
pub const MAX_WATCHES_PER_SESSION: usize = 16;
/// Most remote sessions one plane streams to at once. Each takes one of the plane's reader
/// places (two with events), and the relay's ports are the daemon's own, which the
/// per-process port bounds do not evict: this keeps most of a plane's 64 reader places for
/// local readers.
pub const MAX_SESSIONS_PER_PLANE: usize = 16;

/// How many sessions stream each plane (relay-wide).
type Streams = Arc<Mutex<HashMap<u32, usize>>>;

/// What every session thread of a relay shares.
struct Shared {
    session: Session,
    options: RelayOptions,
    stop: Arc<AtomicBool>,
    streams: Streams,
}

/// What the relay serves.
#[derive(Debug, Clone)]
pub struct RelayOptions {
    /// The cluster's name.
    pub cluster: String,
    /// This daemon's name in it.
    pub daemon: String,
    /// The daemon's deployment domain on this host.
    pub domain: String,
    /// Most remote sessions at once (the daemon's client table bounds them too).
    pub max_sessions: usize,
}

enum Job {
    Request(Query),
    Watch(Query),
    /// The client's token ended.
    Leave,
}

type Sessions = Arc<Mutex<HashMap<String, Sender<Job>>>>;

/// Serves remote clients while it lives.
pub struct Relay {
    stop: Arc<AtomicBool>,
    sessions: Sessions,
    _requests: Queryable<()>,
    _watches: Queryable<()>,
    _leaving: zenoh::pubsub::Subscriber<()>,
}

impl Relay {
    /// Starts answering remote clients of daemon `options.daemon` on `session`.
    pub fn start(session: &Session, options: RelayOptions) -> Result<Relay, ClusterError> {
        let stop = Arc::new(AtomicBool::new(false));
        let sessions: Sessions = Arc::default();
        let zerr = |e: zenoh::Error| ClusterError::Zenoh(format!("cluster: relay: {e}"));
        let shared = Arc::new(Shared {
            session: session.clone(),
            options: options.clone(),
            stop: stop.clone(),
            streams: Arc::default(),
        });
        let (s1, sh1) = (sessions.clone(), shared.clone());
        let requests = session
            .declare_queryable(wire::requests_key(&options.cluster, &options.daemon))
            .callback(move |q| route(&s1, &sh1, q, true))
            .wait()
            .map_err(zerr)?;
        let (s2, sh2) = (sessions.clone(), shared.clone());
        let watches = session
            .declare_queryable(wire::watches_key(&options.cluster, &options.daemon))
            .callback(move |q| route(&s2, &sh2, q, false))
            .wait()
            .map_err(zerr)?;
        let s3 = sessions.clone();
        let leaving = session
            .liveliness()
            .declare_subscriber(wire::client_key(&options.cluster, "*"))
            .callback(move |sample: Sample| {
                if sample.kind() == SampleKind::Delete {
                    let key = shm_layout::cluster::last_segment(sample.key_expr().as_str());
                    if let Some(tx) = s3.lock().ok().and_then(|m| m.get(key).cloned()) {
                        let _ = tx.send(Job::Leave);
                    }
                }
            })
            .wait()
            .map_err(zerr)?;
        Ok(Relay {
            stop,
            sessions,
            _requests: requests,
            _watches: watches,
            _leaving: leaving,
        })
    }

    /// Remote sessions being served now.
    pub fn sessions(&self) -> usize {
        self.sessions.lock().map(|m| m.len()).unwrap_or(0)
    }

    /// Stops serving: every session says Goodbye for its client and ends.
    pub fn stop(self) {
        self.stop.store(true, Ordering::SeqCst);
    }
}

/// Hands a query to its session's thread, starting one for a new session's request.
fn route(sessions: &Sessions, shared: &Arc<Shared>, query: Query, request: bool) {
    let key = shm_layout::cluster::last_segment(query.key_expr().as_str()).to_string();
    if let Err(e) = wire::check_session(&key) {
        let _ = query.reply_err(e).wait();
        return;
    }
    let Ok(mut map) = sessions.lock() else { return };
    let tx = match map.get(&key) {
        Some(tx) => tx.clone(),
        None if request => {
            let shared = shared.clone();
            let options = &shared.options;
            if map.len() >= options.max_sessions {
                let _ = query
                    .reply_err(format!(
                        "the relay of daemon {:?} serves {} remote sessions already (its limit)",
                        options.daemon, options.max_sessions
                    ))
                    .wait();
                return;
            }
            let (tx, rx) = mpsc::channel();
            map.insert(key.clone(), tx.clone());
            let sessions = sessions.clone();
            let spawned = std::thread::Builder::new()
                .name("relay-session".into())
                .spawn(move || {
                    serve(&shared, &key, rx);
                    if let Ok(mut m) = sessions.lock() {
                        m.remove(&key);
                    }
                });
            if spawned.is_err() {
                let _ = query.reply_err("the relay cannot start a thread").wait();
                return;
            }
            tx
        }
        None => {
            let _ = query
                .reply_err(format!("no session {key}: send a request (Hello) first"))
                .wait();
            return;
        }
    };
    drop(map);
    let _ = tx.send(if request {
        Job::Request(query)
    } else {
        Job::Watch(query)
    });
}

/// One watched plane of a session.
struct Watch {
    bodies: ShmBodySubscriber,
    publisher: zenoh::pubsub::Publisher<'static>,
    /// The tick last sent, and its slots (`None`: nothing sent yet).
    sent: Option<(TickHeader, Vec<BodyState>)>,
    events: Option<(ShmEventSubscriber, zenoh::pubsub::Publisher<'static>)>,
}

/// Serves one remote session until its client leaves or the relay stops.
fn serve(shared: &Shared, key: &str, rx: Receiver<Job>) {
    let (session, options, stop) = (&shared.session, &shared.options, &shared.stop);
    let token = session
        .liveliness()
        .get(wire::client_key(&options.cluster, key))
        .timeout(TOKEN_WAIT)
        .wait()
        .ok()
        .and_then(|r| r.recv().ok())
        .is_some_and(|r| r.result().is_ok());
    let local = if token {
        LocalTransport::open(&options.domain).map_err(|e| e.to_string())
    } else {
        Err(format!(
            "session {key} has no liveliness token {}: declare it before the first request",
            wire::client_key(&options.cluster, key)
        ))
    };
    let local = match local {
        Ok(t) => t,
        Err(message) => {
            // Answer what is waiting, then end (the next request starts afresh).
            while let Ok(job) = rx.recv_timeout(Duration::from_millis(50)) {
                if let Job::Request(q) | Job::Watch(q) = job {
                    let _ = q.reply_err(message.clone()).wait();
                }
            }
            return;
        }
    };
    let mut watches: HashMap<u32, Watch> = HashMap::new();
    let mut connected = false;
    loop {
        if stop.load(Ordering::SeqCst) {
            break;
        }
        let wait = if watches.is_empty() { IDLE_WAIT } else { POLL };
        match rx.recv_timeout(wait) {
            Ok(Job::Request(q)) => {
                let (said, ended) = relay_request(&local, &q, &mut watches);
                connected |= said;
                if ended {
                    connected = false;
                    break;
                }
            }
            Ok(Job::Watch(q)) => watch(shared, key, &local, &mut watches, &q),
            Ok(Job::Leave) | Err(RecvTimeoutError::Disconnected) => break,
            Err(RecvTimeoutError::Timeout) => {}
        }
        for (plane, w) in watches.iter_mut() {
            forward(*plane, w);
        }
    }
    for plane in watches.keys() {
        unstream(&shared.streams, *plane);
    }
    if connected {
        // The client left without a word: release what it held, as the daemon would for a
        // local client whose process died.
        let bytes = codec::encode_request(&shm_layout::Request {
            commands: vec![Command::Goodbye],
        });
        let until = Instant::now() + Duration::from_secs(2);
        let _ = local.exchange(
            &bytes,
            local.id(),
            Duration::from_millis(100),
            Duration::ZERO,
            |_| {
                // A daemon shutting down may answer no more: do not wait on it.
                if Instant::now() > until {
                    return Err(Error::Timeout(Duration::from_secs(2)));
                }
                Ok(())
            },
        );
    }
}

/// Relays one request; returns (whether it said Hello, whether it said Goodbye). Ticks the
/// request published (a Step's) are sent before its reply, as a local client finds them
/// published when its reply comes.
fn relay_request(
    local: &LocalTransport,
    query: &Query,
    watches: &mut HashMap<u32, Watch>,
) -> (bool, bool) {
    let bytes = query
        .payload()
        .map(|p| p.to_bytes().into_owned())
        .unwrap_or_default();
    let (bytes, hello, goodbye) = own_pid(bytes);
    let started = Instant::now();
    let reply = local.exchange(
        &bytes,
        local.id(),
        Duration::from_millis(100),
        Duration::ZERO,
        |_| {
            if started.elapsed() > REQUEST_TIMEOUT {
                return Err(Error::Timeout(REQUEST_TIMEOUT));
            }
            Ok(())
        },
    );
    for (plane, w) in watches.iter_mut() {
        forward(*plane, w);
    }
    match reply {
        Ok(reply) => {
            let _ = query.reply(query.key_expr().clone(), reply).wait();
        }
        Err(e) => {
            let _ = query.reply_err(format!("relay: {e}")).wait();
        }
    }
    (hello, goodbye)
}

/// The request with every Hello's pid set to this process's (the daemon checks a client's
/// process on its own host: for a relayed client that is the relay, whose life bounds the
/// session's), a recording's path emptied (a remote client names no file on this host), and
/// whether it holds a Hello and a Goodbye. Bytes that do not decode are passed on
/// untouched: the daemon's answer names what is wrong with them.
fn own_pid(bytes: Vec<u8>) -> (Vec<u8>, bool, bool) {
    let Ok(mut request) = codec::decode_request(&bytes) else {
        return (bytes, false, false);
    };
    let mut hello = false;
    let mut rewritten = false;
    let goodbye = request
        .commands
        .iter()
        .any(|c| matches!(c, Command::Goodbye));
    for c in &mut request.commands {
        match c {
            Command::Hello { pid, .. } => {
                *pid = std::process::id();
                hello = true;
                rewritten = true;
            }
            // A remote client names no file on this host: its recording goes where the
            // daemon puts recordings (the reply names the file).
            Command::Plane {
                op: PlaneOp::Record(RecordOp::Start { path }),
                ..
            } if !path.is_empty() => {
                path.clear();
                rewritten = true;
            }
            _ => {}
        }
    }
    if !rewritten {
        return (bytes, false, goodbye);
    }
    let version = bytes
        .get(4..8)
        .and_then(|v| v.try_into().ok())
        .map(u32::from_le_bytes)
        .unwrap_or(shm_layout::LAYOUT_VERSION);
    (
        codec::encode_request_with_version(&request, version),
        hello,
        goodbye,
    )
}

/// Answers a watch op.
fn watch(
    shared: &Shared,
    key: &str,
    local: &LocalTransport,
    watches: &mut HashMap<u32, Watch>,
    query: &Query,
) {
    let (session, options) = (&shared.session, &shared.options);
    let op = query.payload().and_then(|p| WatchOp::decode(&p.to_bytes()));
    let reply = match op {
        None => WatchReply::Refused("malformed watch op".into()),
        Some(WatchOp::Bodies { plane }) if watches.contains_key(&plane) => {
            // Watched already: start again from a keyframe.
            if let Some(w) = watches.get_mut(&plane) {
                w.sent = None;
                forward(plane, w);
            }
            WatchReply::Ok
        }
        Some(WatchOp::Bodies { .. }) if watches.len() >= MAX_WATCHES_PER_SESSION => {
            WatchReply::Refused(format!(
                "this session streams {MAX_WATCHES_PER_SESSION} planes already (the relay's \
                 limit): destroy or detach one first"
            ))
        }
        Some(WatchOp::Bodies { plane }) => match stream(&shared.streams, plane) {
            Err(e) => WatchReply::Refused(e),
            Ok(()) => match open_watch(session, options, key, local, plane) {
                Ok(w) => {
                    watches.insert(plane, w);
                    WatchReply::Ok
                }
                Err(e) => {
                    unstream(&shared.streams, plane);
                    WatchReply::Refused(e)
                }
            },
        },
        Some(WatchOp::Keyframe { plane }) => {
            if let Some(w) = watches.get(&plane) {
                if let Some((header, bodies)) = &w.sent {
                    let _ = w
                        .publisher
                        .put(BodyFrame::between(header, None, bodies).encode())
                        .wait();
                }
            }
            WatchReply::Ok
        }
        Some(WatchOp::Events { plane }) => match watches.get_mut(&plane) {
            None => WatchReply::Refused(format!(
                "plane {plane} is not watched: watch its bodies first"
            )),
            Some(w) => match open_events(session, options, key, local, plane) {
                Ok(events) => {
                    w.events = Some(events);
                    // Every event after the newest tick reaches the new subscriber: send
                    // that tick, and start the stream at its count.
                    forward(plane, w);
                    let start = w.sent.as_ref().map_or(0, |(h, _)| h.event_count);
                    WatchReply::EventsFrom(start)
                }
                Err(e) => WatchReply::Refused(e),
            },
        },
        Some(WatchOp::Stop { plane }) => {
            if watches.remove(&plane).is_some() {
                unstream(&shared.streams, plane);
            }
            WatchReply::Ok
        }
    };
    let _ = query.reply(query.key_expr().clone(), reply.encode()).wait();
}

/// Counts one more session streaming `plane`, within [`MAX_SESSIONS_PER_PLANE`].
fn stream(streams: &Streams, plane: u32) -> Result<(), String> {
    let mut map = streams.lock().unwrap_or_else(|p| p.into_inner());
    let n = map.entry(plane).or_default();
    if *n >= MAX_SESSIONS_PER_PLANE {
        return Err(format!(
            "plane {plane} streams to {MAX_SESSIONS_PER_PLANE} remote sessions already (the \
             relay's limit, which keeps its reader places for local readers)"
        ));
    }
    *n += 1;
    Ok(())
}

/// Counts one session fewer streaming `plane`.
fn unstream(streams: &Streams, plane: u32) {
    let mut map = streams.lock().unwrap_or_else(|p| p.into_inner());
    if let Some(n) = map.get_mut(&plane) {
        *n = n.saturating_sub(1);
        if *n == 0 {
            map.remove(&plane);
        }
    }
}

fn open_watch(
    session: &Session,
    options: &RelayOptions,
    key: &str,
    local: &LocalTransport,
    plane: u32,
) -> Result<Watch, String> {
    let bodies = local
        .plane_bodies(plane)
        .map_err(|e| format!("plane {plane} of daemon {:?}: {e}", options.daemon))?;
    let publisher = session
        .declare_publisher(wire::bodies_key(
            &options.cluster,
            &options.daemon,
            key,
            plane,
        ))
        .wait()
        .map_err(|e| format!("relay: {e}"))?;
    Ok(Watch {
        bodies,
        publisher,
        sent: None,
        events: None,
    })
}

fn open_events(
    session: &Session,
    options: &RelayOptions,
    key: &str,
    local: &LocalTransport,
    plane: u32,
) -> Result<(ShmEventSubscriber, zenoh::pubsub::Publisher<'static>), String> {
    let events = local.plane_events(plane).map_err(|e| {
        format!(
            "events of plane {plane} of daemon {:?}: {e}",
            options.daemon
        )
    })?;
    let publisher = session
        .declare_publisher(wire::events_key(
            &options.cluster,
            &options.daemon,
            key,
            plane,
        ))
        .wait()
        .map_err(|e| format!("relay: {e}"))?;
    Ok((events, publisher))
}

/// Sends the plane's newest tick (if a new one came) and its events.
fn forward(plane: u32, w: &mut Watch) {
    if let Some((events, publisher)) = &w.events {
        while let Ok(Some(sample)) = events.receive() {
            let frame = EventFrame {
                header: *sample.user_header(),
                records: sample.payload().to_vec(),
            };
            let _ = publisher.put(frame.encode()).wait();
        }
    }
    let sample = match w.bodies.receive() {
        Ok(Some(s)) => s,
        Ok(None) => return,
        Err(e) => {
            tracing::debug!(plane, "relay: receive tick: {e:?}");
            return;
        }
    };
    let header = *sample.user_header();
    let bodies = sample.payload();
    let last = w.sent.as_ref().map(|(h, b)| (h.tick, b.as_slice()));
    let frame = BodyFrame::between(&header, last, bodies);
    let _ = w.publisher.put(frame.encode()).wait();
    w.sent = Some((header, bodies.to_vec()));
}

#[cfg(test)]
mod tests {
    use shm_layout::{codec, Command, PlaneOp, RecordOp, Request};

    use super::own_pid;

    fn request(commands: Vec<Command>) -> Vec<u8> {
        codec::encode_request(&Request { commands })
    }

    #[test]
    fn a_remote_recording_path_is_emptied_and_hello_takes_the_relays_pid() {
        let start = |path: &str| {
            Command::plane(
                3,
                PlaneOp::Record(RecordOp::Start {
                    path: path.to_string(),
                }),
            )
        };
        let (bytes, hello, goodbye) = own_pid(request(vec![start("/etc/passwd")]));
        assert!(!hello && !goodbye);
        let sent = codec::decode_request(&bytes).unwrap();
        assert_eq!(sent.commands, vec![start("")]);
        // Nothing to rewrite: the bytes pass untouched.
        let plain = request(vec![start(""), Command::Goodbye]);
        assert_eq!(own_pid(plain.clone()), (plain, false, true));
    }
}

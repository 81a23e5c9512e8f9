//! The connection to the daemon: handshake, one request per flush, daemon liveness.

use std::cell::RefCell;
use std::collections::HashMap;
use std::rc::Rc;
use std::time::{Duration, Instant};

use iceoryx2::config::Config;
use iceoryx2::node::NodeView;
use iceoryx2::port::client::Client as RequestPort;
use iceoryx2::port::listener::Listener;
use iceoryx2::port::notifier::Notifier;
use iceoryx2::prelude::*;
use shm_layout::codec;
use shm_layout::{
    names, Command, CommandError, CommandResult, ErrorKind, Handle, PlaneId, Reply, Request,
    Response, CRATE_VERSION, LAYOUT_VERSION,
};

use crate::plane::{PlaneOptions, PlaneShared};
use crate::{Error, Plane};

/// How often a waiting client checks that the daemon process is still alive.
pub(crate) const LIVENESS_PERIOD: Duration = Duration::from_millis(100);
/// How long `connect` waits for a starting daemon to open its request server.
const SERVER_WAIT: Duration = Duration::from_secs(2);

#[derive(Debug, Clone)]
pub struct ConnectOptions {
    pub domain: String,
    /// Longest wait for one reply (a Step of a huge plane may legitimately take a while).
    pub request_timeout: Duration,
    /// Test support: claim another crate version in the handshake.
    #[doc(hidden)]
    pub crate_version: String,
    /// Test support: claim another layout version in every request.
    #[doc(hidden)]
    pub layout_version: u32,
}

impl ConnectOptions {
    pub fn new(domain: &str) -> Self {
        ConnectOptions {
            domain: domain.to_string(),
            request_timeout: Duration::from_secs(30),
            crate_version: CRATE_VERSION.to_string(),
            layout_version: LAYOUT_VERSION,
        }
    }
}

/// A queued command and the overlay entry its reply confirms.
struct Queued {
    command: Command,
    confirms: Option<(PlaneId, Handle)>,
}

#[derive(Default)]
struct State {
    queue: Vec<Queued>,
    /// Failures of queued commands sent along with another call, reported by `flush`.
    deferred: Vec<CommandError>,
    planes: HashMap<PlaneId, Rc<PlaneShared>>,
    gone: bool,
}

pub(crate) struct Inner {
    pub(crate) options: ConnectOptions,
    pub(crate) config: Config,
    pub(crate) node: Node<ipc::Service>,
    port: RequestPort<ipc::Service, [u8], u128, [u8], ()>,
    daemon_wake: Notifier<ipc::Service>,
    replies: Listener<ipc::Service>,
    id: u128,
    daemon_node: u128,
    daemon_pid: u32,
    state: RefCell<State>,
}

/// A connection to the physics daemon of one domain. Cheap to clone; not `Send` (shared
/// memory ports belong to the thread that opened them).
#[derive(Clone)]
pub struct Client {
    pub(crate) inner: Rc<Inner>,
}

impl Client {
    /// Connects to the daemon of `domain` and performs the version handshake.
    pub fn connect(domain: &str) -> Result<Client, Error> {
        Self::connect_with(ConnectOptions::new(domain))
    }

    pub fn connect_with(options: ConnectOptions) -> Result<Client, Error> {
        let domain = options.domain.clone();
        let config = names::config(&domain).map_err(|e| Error::Invalid {
            field: "domain".into(),
            message: e.to_string(),
        })?;
        let no_daemon = |detail: String| Error::NoDaemon {
            domain: domain.clone(),
            detail,
        };
        // A crashed daemon leaves its services behind: look for a live daemon process first.
        if daemon_alive(&config, 0) == Some(false) {
            return Err(no_daemon("no live daemon process in this domain".into()));
        }
        let node = NodeBuilder::new()
            .name(&NodeName::new("physics-client").expect("valid node name"))
            .config(&config)
            .signal_handling_mode(SignalHandlingMode::Disabled)
            .create::<ipc::Service>()
            .map_err(|e| Error::ipc("cannot create node", e))?;
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
        let port = control
            .client_builder()
            .initial_max_slice_len(4096)
            .allocation_strategy(AllocationStrategy::PowerOfTwo)
            .create()
            .map_err(|e| Error::ipc("cannot create request port", e))?;
        let daemon_wake = node
            .service_builder(&names::control_wake())
            .event()
            .open()
            .map_err(|e| no_daemon(format!("{e:?}")))?
            .notifier_builder()
            .create()
            .map_err(|e| Error::ipc("cannot create notifier", e))?;
        let replies = node
            .service_builder(&names::client_wake(id))
            .event()
            .max_notifiers(2)
            .max_listeners(1)
            .create()
            .map_err(|e| Error::ipc("cannot create reply event", e))?
            .listener_builder()
            .create()
            .map_err(|e| Error::ipc("cannot create reply listener", e))?;
        let mut inner = Inner {
            options,
            config,
            node,
            port,
            daemon_wake,
            replies,
            id,
            daemon_node: 0,
            daemon_pid: 0,
            state: RefCell::default(),
        };
        let hello = Command::Hello {
            crate_version: inner.options.crate_version.clone(),
            pid: std::process::id(),
        };
        match inner.round_trip(vec![hello])?.pop() {
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

    pub fn domain(&self) -> &str {
        &self.inner.options.domain
    }

    /// Process id of the daemon this client talks to.
    pub fn daemon_pid(&self) -> u32 {
        self.inner.daemon_pid
    }

    /// Creates a plane owned by this client (released when the client goes away).
    pub fn create_plane(&self, options: &PlaneOptions) -> Result<Plane, Error> {
        match self.call(Command::CreatePlane {
            props: options.props(),
        })? {
            Reply::Plane(info) => self.attach_plane(info.id),
            other => Err(unexpected(other)),
        }
    }

    /// Opens an existing plane (created by any client) for reading and writing. Returns once
    /// the plane's newest tick is readable.
    pub fn attach_plane(&self, id: PlaneId) -> Result<Plane, Error> {
        if let Some(shared) = self.inner.state.borrow().planes.get(&id) {
            return Ok(Plane::new(self.clone(), shared.clone()));
        }
        let shared = match PlaneShared::open(&self.inner.node, id) {
            Ok(s) => Rc::new(s),
            // No such service: let the daemon say why (unknown plane, or gone).
            Err(e) => {
                self.call(Command::PlaneInfo { plane: id })?;
                return Err(e);
            }
        };
        // Asking after subscribing makes the daemon hand the newest tick to the new reader.
        self.call(Command::PlaneInfo { plane: id })?;
        self.inner
            .state
            .borrow_mut()
            .planes
            .insert(id, shared.clone());
        Ok(Plane::new(self.clone(), shared))
    }

    /// Sends every queued write as one request. Errors of individual commands (including
    /// ones sent along with earlier calls) come back together; the others were applied.
    pub fn flush(&self) -> Result<(), Error> {
        if !self.inner.state.borrow().queue.is_empty() {
            self.send(Vec::new())?;
        }
        let deferred = std::mem::take(&mut self.inner.state.borrow_mut().deferred);
        if deferred.is_empty() {
            Ok(())
        } else {
            Err(Error::Batch(deferred))
        }
    }

    /// Number of writes waiting for the next flush.
    pub fn queued(&self) -> usize {
        self.inner.state.borrow().queue.len()
    }

    /// Sends the queue plus `command` and returns the reply to `command`.
    pub(crate) fn call(&self, command: Command) -> Result<Reply, Error> {
        let mut results = self.send(vec![command])?;
        match results.pop() {
            Some(Ok(reply)) => Ok(reply),
            Some(Err(e)) => Err(Error::Command(e)),
            None => Err(Error::Protocol("empty reply".into())),
        }
    }

    pub(crate) fn queue(&self, command: Command, confirms: Option<(PlaneId, Handle)>) {
        self.inner
            .state
            .borrow_mut()
            .queue
            .push(Queued { command, confirms });
    }

    /// One request: the queued commands first, then `extra`. Returns the results of `extra`.
    fn send(&self, extra: Vec<Command>) -> Result<Vec<CommandResult>, Error> {
        let queued = std::mem::take(&mut self.inner.state.borrow_mut().queue);
        let n_queued = queued.len();
        let mut confirms = Vec::with_capacity(n_queued);
        let mut commands = Vec::with_capacity(n_queued + extra.len());
        for q in queued {
            confirms.push(q.confirms);
            commands.push(q.command);
        }
        commands.extend(extra);
        let mut results = self.inner.round_trip(commands)?;
        let extra_results = results.split_off(n_queued.min(results.len()));
        let mut state = self.inner.state.borrow_mut();
        for (result, confirm) in results.into_iter().zip(confirms) {
            match (result, confirm) {
                (Ok(Reply::Applied { tick }), Some((plane, handle))) => {
                    if let Some(p) = state.planes.get(&plane) {
                        p.overlay.borrow_mut().confirm(handle, tick);
                    }
                }
                (Ok(_), _) => {}
                (Err(e), confirm) => {
                    // A rejected write must not linger as if it had happened.
                    if let Some((plane, handle)) = confirm {
                        if let Some(p) = state.planes.get(&plane) {
                            p.overlay.borrow_mut().discard(handle);
                        }
                    }
                    state.deferred.push(e);
                }
            }
        }
        Ok(extra_results)
    }

    /// Test support: sends raw request bytes and returns the raw reply.
    #[doc(hidden)]
    pub fn raw_request(&self, bytes: &[u8]) -> Result<Vec<u8>, Error> {
        self.inner.exchange(bytes)
    }

    /// Fails with [`Error::DaemonGone`] when the daemon process no longer exists.
    pub fn check_daemon(&self) -> Result<(), Error> {
        self.inner.check_daemon()
    }

    pub(crate) fn forget_plane(&self, id: PlaneId) {
        self.inner.state.borrow_mut().planes.remove(&id);
    }
}

impl Inner {
    fn round_trip(&self, commands: Vec<Command>) -> Result<Vec<CommandResult>, Error> {
        if self.state.borrow().gone {
            return Err(self.gone());
        }
        let request = Request { commands };
        let n = request.commands.len();
        let bytes = if self.options.layout_version == LAYOUT_VERSION {
            codec::encode_request(&request)
        } else {
            codec::encode_request_with_version(&request, self.options.layout_version)
        };
        let reply = self.exchange(&bytes)?;
        let frame = codec::Frame::parse(&reply).map_err(|e| Error::Protocol(e.to_string()))?;
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
        match codec::decode_response(&reply) {
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
    pub(crate) fn exchange(&self, bytes: &[u8]) -> Result<Vec<u8>, Error> {
        let mut request = self
            .port
            .loan_slice_uninit(bytes.len())
            .map_err(|e| Error::ipc("loan request", e))?;
        *request.user_header_mut() = self.id;
        let pending = request
            .write_from_slice(bytes)
            .send()
            .map_err(|e| Error::ipc("send request", e))?;
        self.daemon_wake
            .notify()
            .map_err(|e| Error::ipc("wake daemon", e))?;
        let started = Instant::now();
        let mut last_check = started;
        loop {
            if let Some(response) = pending
                .receive()
                .map_err(|e| Error::ipc("receive reply", e))?
            {
                return Ok(response.payload().to_vec());
            }
            if !pending.is_connected() {
                self.check_daemon()?;
            }
            let _ = self.replies.timed_wait(|_| {}, LIVENESS_PERIOD);
            let now = Instant::now();
            if now.duration_since(last_check) >= LIVENESS_PERIOD {
                self.check_daemon()?;
                last_check = now;
            }
            if now.duration_since(started) > self.options.request_timeout {
                return Err(Error::Timeout(self.options.request_timeout));
            }
        }
    }

    pub(crate) fn check_daemon(&self) -> Result<(), Error> {
        match daemon_alive(&self.config, self.daemon_node) {
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

fn unexpected(reply: Reply) -> Error {
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

//! The daemon's event loop. It sleeps in an iceoryx2 WaitSet until a client announces a
//! request or the earliest plane tick is due, so an idle daemon costs no CPU.
//!
//! - `clients`: who is connected, and noticing clients that died.
//! - `dispatch`: decoding requests and routing each command to its plane by id.
//!
//! The server knows planes only through [`Backend`]: it never names an engine type, an
//! object property or a per-feature op.

pub mod clients;
mod dispatch;
pub mod files;
pub mod heartbeat;
pub mod limits;

use std::collections::BTreeMap;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use iceoryx2::config::Config;
use iceoryx2::port::server::Server;
use iceoryx2::prelude::*;
use iceoryx2::service::header::payload_header::PayloadHeader;
use shm_layout::{names, CommandError, ErrorKind, PlaneId};

use crate::backend::Backend;
use crate::publish::{PlaneOutput, MAX_NODES};
use crate::DaemonError;
use clients::{Clients, MAX_CLIENTS};
pub use limits::Limits;

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
}

/// How often dead clients are looked for while clients are connected. Without clients the
/// daemon has nothing to look for and sleeps until a request (or a shutdown wake-up).
const HOUSEKEEPING: Duration = Duration::from_millis(500);
/// Planes one daemon hosts at once.
pub const MAX_PLANES: usize = 1024;

/// The user header (u128) is what older clients sent as their id; it is ignored (identity
/// comes from the transport) but kept so the service layout never changes across versions.
type ControlServer = Server<ipc::Service, [u8], u128, [u8], ()>;

struct PlaneEntry {
    plane: Box<dyn Backend>,
    /// Client that created the plane; the plane is released when that client goes away.
    owner: u128,
    /// Other clients may change the plane (only the owner destroys it).
    shared: bool,
    out: PlaneOutput,
    /// The tick period the schedule was made for; `None` for manual or disabled planes.
    period: Option<Duration>,
    /// When the next automatic tick is due; `None` for manual or disabled planes.
    next_tick: Option<Instant>,
}

impl PlaneEntry {
    /// The period the plane asks for now: `None` when manual, disabled, or not
    /// representable (validation keeps rates within bounds; this never panics).
    fn wanted_period(&self) -> Option<Duration> {
        let rate = self.plane.tick_rate();
        if !(rate > 0.0 && self.plane.enabled()) {
            return None;
        }
        Duration::try_from_secs_f64(1.0 / rate as f64)
            .ok()
            .filter(|p| !p.is_zero())
    }

    /// Restarts the schedule when the plane's rate or Enabled changed.
    fn reschedule_if_changed(&mut self, now: Instant) {
        let period = self.wanted_period();
        if period != self.period {
            self.period = period;
            self.next_tick = period.and_then(|p| now.checked_add(p));
        }
    }
}

/// Everything the daemon owns except the WaitSet and the request listener, which stay on
/// the stack of [`run`] (the WaitSet borrows the listener).
pub struct Daemon {
    domain: String,
    config: Config,
    node: Node<ipc::Service>,
    server: ControlServer,
    clients: Clients,
    planes: BTreeMap<PlaneId, PlaneEntry>,
    next_plane_id: PlaneId,
    options: Options,
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
    let stop_beating = AtomicBool::new(false);
    std::thread::scope(|s| {
        s.spawn(|| heartbeat::run(&config, &stop_beating));
        let served = serve(domain, &config, shutdown, options);
        stop_beating.store(true, Ordering::Relaxed);
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
            return;
        }
        if Instant::now() > deadline {
            return;
        }
        std::thread::sleep(Duration::from_millis(5));
    }
}

fn serve(
    domain: &str,
    config: &Config,
    shutdown: &AtomicBool,
    options: Options,
) -> Result<(), DaemonError> {
    let node = NodeBuilder::new()
        .name(&NodeName::new(names::DAEMON_NODE_NAME).expect("valid node name"))
        .config(config)
        .signal_handling_mode(SignalHandlingMode::Disabled)
        .create::<ipc::Service>()
        .map_err(|e| DaemonError::Ipc(format!("cannot create node: {e:?}")))?;
    let listener = node
        .service_builder(&names::control_wake())
        .event()
        .max_listeners(2)
        .max_notifiers(MAX_CLIENTS * 2)
        .max_nodes(MAX_NODES)
        .open_or_create()
        .map_err(|e| DaemonError::Ipc(format!("cannot create the request event: {e:?}")))?
        .listener_builder()
        .create()
        .map_err(|e| DaemonError::Ipc(format!("cannot create the request listener: {e:?}")))?;
    let server = node
        .service_builder(&names::control())
        .request_response::<[u8], [u8]>()
        .request_user_header::<u128>()
        .max_servers(1)
        // Room beyond MAX_CLIENTS: ports that never say Hello (or a process at its
        // per-process limit) leave ports for other processes.
        .max_clients(MAX_CLIENTS * 2)
        .max_nodes(MAX_NODES)
        .max_active_requests_per_client(4)
        .open_or_create()
        .map_err(|e| DaemonError::Ipc(format!("cannot create the control service: {e:?}")))?
        .server_builder()
        .initial_max_slice_len(4096)
        .allocation_strategy(AllocationStrategy::PowerOfTwo)
        .create()
        .map_err(|_| DaemonError::AlreadyRunning {
            domain: domain.to_string(),
        })?;
    let waitset = WaitSetBuilder::new()
        .signal_handling_mode(SignalHandlingMode::Disabled)
        .create::<ipc::Service>()
        .map_err(|e| DaemonError::Ipc(format!("cannot create the waitset: {e:?}")))?;
    let _request_guard = waitset
        .attach_notification(&listener)
        .map_err(|e| DaemonError::Ipc(format!("cannot attach the request listener: {e:?}")))?;

    let mut daemon = Daemon {
        domain: domain.to_string(),
        config: config.clone(),
        node,
        server,
        clients: Clients::default(),
        planes: BTreeMap::new(),
        next_plane_id: 1,
        options,
    };
    // iceoryx2 creates its node-counter segment world-writable: narrow it to this user.
    files::restrict(domain);
    tracing::info!(domain, pid = std::process::id(), "physics daemon ready");

    let mut next_housekeeping = Instant::now() + HOUSEKEEPING;
    while !shutdown.load(Ordering::Relaxed) {
        let now = Instant::now();
        let wake_at = daemon
            .next_tick()
            .map_or(next_housekeeping, |t| t.min(next_housekeeping));
        let timeout = wake_at.saturating_duration_since(now);
        if let Err(e) =
            waitset.wait_and_process_once_with_timeout(|_| CallbackProgression::Continue, timeout)
        {
            tracing::warn!("waitset: {e:?}");
        }
        // Consume the wake-ups, then serve everything that is queued.
        if let Err(e) = listener.try_wait(|_| {}) {
            tracing::warn!("request listener: {e:?}");
        }
        daemon.serve_requests();
        daemon.tick_due_planes(Instant::now());
        if daemon.clients.is_empty() {
            if Instant::now() >= next_housekeeping && daemon.starter_gone() {
                tracing::info!(
                    starter = daemon.options.starter_pid,
                    "the process that started this daemon is gone and no client is left"
                );
                break;
            }
            next_housekeeping = Instant::now() + HOUSEKEEPING;
        } else if Instant::now() >= next_housekeeping {
            daemon.release_gone_clients();
            next_housekeeping = Instant::now() + HOUSEKEEPING;
        }
    }
    tracing::info!(domain = daemon.domain, "shutting down");
    Ok(())
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
    fn next_tick(&self) -> Option<Instant> {
        self.planes.values().filter_map(|p| p.next_tick).min()
    }

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
            // Who sent it comes from the transport (the request's origin node), never from
            // the payload: a client cannot speak for another.
            let node = request.header().node_id();
            let client = node.value();
            let pid = node.pid::<ipc::Service>().map_or(0, |p| p.value() as u32);
            let reply = self.handle_bytes(Origin { id: client, pid }, request.payload());
            let sent = request
                .loan_slice_uninit(reply.len())
                .map_err(|e| format!("{e:?}"))
                .and_then(|r| {
                    r.write_from_slice(&reply)
                        .send()
                        .map_err(|e| format!("{e:?}"))
                });
            if let Err(e) = sent {
                tracing::warn!(client = format!("{client:032x}"), "reply failed: {e}");
            }
            self.clients.wake(&self.node, client);
        }
    }

    fn tick_due_planes(&mut self, now: Instant) {
        let mut failed = Vec::new();
        for (id, entry) in self.planes.iter_mut() {
            let (Some(due), Some(period)) = (entry.next_tick.filter(|t| *t <= now), entry.period)
            else {
                continue;
            };
            let stepped = catch_unwind(AssertUnwindSafe(|| {
                entry.plane.step(period.as_secs_f32()).and_then(|stepped| {
                    if stepped {
                        entry
                            .out
                            .publish(entry.plane.as_mut())
                            .map_err(dispatch::internal)?;
                    }
                    Ok(())
                })
            }));
            match stepped {
                Ok(Ok(())) => {}
                Ok(Err(e)) => tracing::warn!(plane = id, "tick failed: {e}"),
                Err(panic) => {
                    failed.push((*id, panic));
                    continue;
                }
            }
            // Keep the cadence; after a stall, restart from now instead of catching up.
            let next = due + period;
            entry.next_tick = Some(if next + period * 4 < now {
                now + period
            } else {
                next
            });
        }
        for (id, panic) in failed {
            self.fail_plane(id, panic);
        }
    }

    /// Removes a plane whose code panicked (its state cannot be trusted) and returns the
    /// error its clients get. The daemon and every other plane serve on.
    fn fail_plane(&mut self, id: PlaneId, panic: Box<dyn std::any::Any + Send>) -> CommandError {
        let message = dispatch::panic_message(panic.as_ref());
        tracing::error!(plane = id, "plane failed and was removed: {message}");
        self.remove_plane(id);
        CommandError::new(
            ErrorKind::Internal,
            format!("plane {id} failed and was removed: {message}"),
        )
    }

    /// Drops a plane and forgets it in its owner's list.
    fn remove_plane(&mut self, id: PlaneId) {
        if let Some(entry) = self.planes.remove(&id) {
            if let Some(c) = self.clients.get_mut(entry.owner) {
                c.planes.retain(|p| *p != id);
            }
        }
    }

    fn release_client(&mut self, client: u128) {
        let before = self.planes.len();
        self.planes.retain(|_, p| p.owner != client);
        self.clients.disconnect(client);
        tracing::info!(
            client = format!("{client:032x}"),
            planes_released = before - self.planes.len(),
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

    fn release_gone_clients(&mut self) {
        for client in self.clients.reap(&self.config) {
            tracing::warn!(client = format!("{client:032x}"), "client process is gone");
            self.release_client(client);
        }
    }
}

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

use std::collections::BTreeMap;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use iceoryx2::config::Config;
use iceoryx2::port::server::Server;
use iceoryx2::prelude::*;
use shm_layout::{names, PlaneId};

use crate::backend::Backend;
use crate::publish::{PlaneOutput, MAX_NODES};
use crate::DaemonError;
use clients::{Clients, MAX_CLIENTS};

/// How often dead clients are looked for while clients are connected. Without clients the
/// daemon has nothing to look for and sleeps until a request (or a shutdown wake-up).
const HOUSEKEEPING: Duration = Duration::from_millis(500);
/// Planes one daemon hosts at once.
pub const MAX_PLANES: usize = 1024;

type ControlServer = Server<ipc::Service, [u8], u128, [u8], ()>;

struct PlaneEntry {
    plane: Box<dyn Backend>,
    /// Client that created the plane; the plane is released when that client goes away.
    owner: u128,
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
    let config = names::config(domain)?;
    remove_dead_nodes(&config);
    serve(domain, &config, shutdown)?;
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

fn serve(domain: &str, config: &Config, shutdown: &AtomicBool) -> Result<(), DaemonError> {
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
        .max_notifiers(MAX_CLIENTS + 8)
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
        .max_clients(MAX_CLIENTS + 8)
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
    };
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
            let client = *request.user_header();
            let reply = self.handle_bytes(client, request.payload());
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
        for (id, entry) in self.planes.iter_mut() {
            let (Some(due), Some(period)) = (entry.next_tick.filter(|t| *t <= now), entry.period)
            else {
                continue;
            };
            let result = entry.plane.step(period.as_secs_f32()).and_then(|stepped| {
                if stepped {
                    entry
                        .out
                        .publish(entry.plane.as_mut())
                        .map_err(dispatch::internal)?;
                }
                Ok(())
            });
            if let Err(e) = result {
                tracing::warn!(plane = id, "tick failed: {e}");
            }
            // Keep the cadence; after a stall, restart from now instead of catching up.
            let next = due + period;
            entry.next_tick = Some(if next + period * 4 < now {
                now + period
            } else {
                next
            });
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

    fn release_gone_clients(&mut self) {
        for client in self.clients.reap(&self.config) {
            tracing::warn!(client = format!("{client:032x}"), "client process is gone");
            self.release_client(client);
        }
    }
}

//! The daemon's request loop. It sleeps in an iceoryx2 WaitSet until a client announces a
//! request, a plane worker reports, or (while clients are connected) housekeeping is due, so
//! an idle daemon costs no CPU.
//!
//! Every plane lives on a worker thread of its own (`worker`): it applies the command runs
//! the loop hands it, in order, steps and publishes. The loop itself never steps: a request
//! whose commands wait on a plane is parked (its client's later requests queue behind it)
//! while the loop serves everyone else, and its reply goes out when the last of its commands
//! is answered. So planes step in parallel, a heavy tick of one plane never delays a request
//! for another, and `Step` replies once its tick is published.
//!
//! A short run that neither steps nor touches shared memory (a write, a query) is applied
//! by the loop itself when the plane's worker is idle and no run is queued for it: it then
//! lands exactly where a hand-over would have put it, and its round trip costs no thread
//! wake-ups. A busy worker (stepping, publishing, or with runs queued) gets the run handed
//! over as before, so the loop never waits for a plane.
//!
//! The server is grouped by job; `daemon` holds the state they share, and each job adds
//! the daemon's methods for it in files of its own:
//!
//! - [`requests`]: the request loop (ports, the WaitSet, the stages of a round), each
//!   client's queue of requests, decoding and routing by plane id, who sent a request, the
//!   connected clients.
//! - `worker`: one thread per plane that applies its command runs, steps and publishes.
//! - [`quotas`]: per-client limits and quota counters, fair CPU shares, the load gauge a
//!   cluster reads, and the guard of iceoryx2 resources.
//! - [`persistence`]: persistent and named planes, the state writer, snapshots in pieces.
//! - [`moves`]: planes moving to and arriving from other daemons (`MoveTo`).
//! - [`liveness`]: noticing gone clients (process watches, the loop's alarm, the node
//!   folder) and the daemon's own heartbeat.
//! - [`files`] and [`trim`]: the domain's files, and giving freed memory back.
//!
//! The server knows planes only through [`crate::backend::Backend`]: it never names an
//! engine type, an object property or a per-feature op.

mod daemon;
pub mod files;
pub mod liveness;
pub mod moves;
pub mod persistence;
pub mod quotas;
pub mod requests;
pub mod trim;
mod worker;

use std::sync::atomic::AtomicBool;
use std::sync::Arc;
use std::time::{Duration, Instant};

use iceoryx2::config::Config;
use iceoryx2::prelude::*;
use shm_layout::names;

use crate::DaemonError;
pub use daemon::{Daemon, Options, MAX_PLANES};
/// Persistent planes (`server::persist::PersistArgs`, ...).
pub use persistence::persist;
pub use quotas::limits::Limits;
/// The per-client quota counters (`server::quota::PLANE_BYTES`, ...).
pub use quotas::quota;

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
    let watch = Arc::new(quotas::resources::Watch::default());
    let trims = trim::Trims::default();
    let limits = options.limits;
    std::thread::scope(|s| {
        s.spawn(|| quotas::resources::run(&config, &limits, &watch));
        s.spawn(|| trim::run(&trims));
        let served =
            requests::serve::serve(domain, &config, shutdown, options, watch.clone(), &trims);
        watch.stop();
        trims.stop();
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
            // The domain's own node directory, once empty (another process of the domain
            // starting now recreates it).
            let _ = std::fs::remove_dir(config.global.node_dir().to_string());
            return;
        }
        if Instant::now() > deadline {
            return;
        }
        std::thread::sleep(Duration::from_millis(5));
    }
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

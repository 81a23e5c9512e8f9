//! The daemon's heartbeat: a thread with a node of its own publishes a counter every
//! [`PERIOD`]. It keeps beating while the loop steps a huge plane, and stops when the
//! process is stopped or hung as a whole (SIGSTOP, swapped out, frozen), so a waiting client
//! can tell "slow" from "stalled" within about a second instead of its request timeout.

use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use iceoryx2::config::Config;
use iceoryx2::prelude::*;
use shm_layout::names;

use crate::publish::MAX_NODES;
use crate::DaemonError;

/// Time between beats. Clients call the daemon stalled after
/// `client_sdk`'s stall threshold (1 s) without one.
pub const PERIOD: Duration = Duration::from_millis(200);

/// Publishes beats until `stop` is set. Errors are logged: without a heartbeat the daemon
/// still serves (clients then only have their request timeout).
pub fn run(config: &Config, stop: &AtomicBool) {
    if let Err(e) = beat(config, stop) {
        tracing::warn!("heartbeat stopped: {e}");
    }
}

fn beat(config: &Config, stop: &AtomicBool) -> Result<(), DaemonError> {
    let ipc = |what: &str, e: &dyn core::fmt::Debug| {
        DaemonError::Ipc(format!("heartbeat: cannot create the {what}: {e:?}"))
    };
    let node = NodeBuilder::new()
        .config(config)
        .signal_handling_mode(SignalHandlingMode::Disabled)
        .create::<ipc::Service>()
        .map_err(|e| ipc("node", &e))?;
    let publisher = node
        .service_builder(&names::heartbeat())
        .publish_subscribe::<u64>()
        .enable_safe_overflow(true)
        .history_size(1)
        .subscriber_max_buffer_size(1)
        .max_publishers(1)
        .max_subscribers(super::clients::MAX_CLIENTS * 2)
        .max_nodes(MAX_NODES)
        .open_or_create()
        .map_err(|e| ipc("service", &e))?
        .publisher_builder()
        .create()
        .map_err(|e| ipc("publisher", &e))?;
    let mut count: u64 = 0;
    while !stop.load(Ordering::Relaxed) {
        count += 1;
        if let Err(e) = publisher.send_copy(count) {
            tracing::debug!("heartbeat send failed: {e:?}");
        }
        std::thread::sleep(PERIOD);
    }
    Ok(())
}

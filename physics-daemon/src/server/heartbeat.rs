//! The daemon's heartbeat: a thread with a node of its own publishes a counter every
//! [`PERIOD`]. It keeps beating while the loop steps a huge plane, and stops when the
//! process is stopped or hung as a whole (SIGSTOP, swapped out, frozen), so a waiting client
//! can tell "slow" from "stalled" within about a second instead of its request timeout.
//! Without clients nobody listens: it pauses (the daemon then wakes for nothing but a request
//! or a shutdown) and the loop resumes it when a client connects.

use std::sync::{Condvar, Mutex};
use std::time::Duration;

use iceoryx2::config::Config;
use iceoryx2::prelude::*;
use shm_layout::names;

use crate::publish::MAX_NODES;
use crate::DaemonError;

/// Time between beats. Clients call the daemon stalled after
/// `client_sdk`'s stall threshold (1 s) without one.
pub const PERIOD: Duration = Duration::from_millis(200);

/// Tells the heartbeat thread when to beat and when to end.
#[derive(Debug, Default)]
pub struct Control {
    /// (beat, stop)
    state: Mutex<(bool, bool)>,
    changed: Condvar,
}

impl Control {
    /// Beats while `on` (clients are connected), pauses otherwise.
    pub fn beat(&self, on: bool) {
        if let Ok(mut state) = self.state.lock() {
            if state.0 != on {
                state.0 = on;
                self.changed.notify_all();
            }
        }
    }

    /// Ends the heartbeat thread.
    pub fn stop(&self) {
        if let Ok(mut state) = self.state.lock() {
            state.1 = true;
            self.changed.notify_all();
        }
    }

    /// Waits until beats are wanted; false once stopped.
    fn wait_wanted(&self) -> bool {
        let Ok(mut state) = self.state.lock() else {
            return false;
        };
        while !state.0 && !state.1 {
            state = match self.changed.wait(state) {
                Ok(s) => s,
                Err(_) => return false,
            };
        }
        !state.1
    }
}

/// Publishes beats until `control` says stop. Errors are logged: without a heartbeat the
/// daemon still serves (clients then only have their request timeout). The service has
/// reader places for twice `max_clients` (`--max-clients`).
pub fn run(config: &Config, control: &Control, max_clients: usize) {
    if let Err(e) = beat(config, control, max_clients) {
        tracing::warn!("heartbeat stopped: {e}");
    }
}

fn beat(config: &Config, control: &Control, max_clients: usize) -> Result<(), DaemonError> {
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
        .max_subscribers(max_clients * 2)
        .max_nodes((max_clients * 2).max(MAX_NODES))
        .open_or_create()
        .map_err(|e| ipc("service", &e))?
        .publisher_builder()
        .create()
        .map_err(|e| ipc("publisher", &e))?;
    let mut count: u64 = 0;
    while control.wait_wanted() {
        count += 1;
        if let Err(e) = publisher.send_copy(count) {
            tracing::debug!("heartbeat send failed: {e:?}");
        }
        std::thread::sleep(PERIOD);
    }
    Ok(())
}

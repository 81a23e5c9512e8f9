//! The daemon's heartbeat: a counter published every [`PERIOD`] while clients are
//! connected, so a waiting client can tell "slow" from "stalled" (SIGSTOP, swapped out,
//! frozen) within about a second instead of its request timeout.
//!
//! The resource guard's thread beats, at the start of each of its looks ([`crate::server::quotas::resources`]):
//! it has a node of its own, never waits for the request loop, and looks every period while
//! any other process has a node in the domain, which every connected local client has. One
//! thread waking twice a second for both instead of a thread of its own waking five times:
//! an idle daemon's CPU is the count of its wake-ups. Without clients nobody listens: no
//! beats (the loop says when through [`crate::server::quotas::resources::Watch::beat`]).

use std::time::Duration;

use iceoryx2::port::publisher::Publisher;
use iceoryx2::prelude::*;
use shm_layout::names;

use crate::publish::MAX_NODES;
use crate::DaemonError;

/// Time between beats (the resource guard, which beats, looks at this period). Clients call
/// a stopped daemon stalled after `client_sdk`'s thresholds (600 ms for a reader's watch,
/// 1 s for a waiting request) without one, and a daemon that runs but does not beat after
/// 3 s.
pub const PERIOD: Duration = Duration::from_millis(500);

/// The heartbeat's publisher.
pub struct Heart {
    publisher: Publisher<ipc::Service, u64, ()>,
    count: u64,
}

impl std::fmt::Debug for Heart {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Heart").field("count", &self.count).finish()
    }
}

impl Heart {
    /// Opens the heartbeat service on `node`, with reader places for twice `max_clients`
    /// (`--max-clients`).
    pub fn open(node: &Node<ipc::Service>, max_clients: usize) -> Result<Heart, DaemonError> {
        let ipc = |what: &str, e: &dyn core::fmt::Debug| {
            DaemonError::Ipc(format!("heartbeat: cannot create the {what}: {e:?}"))
        };
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
        Ok(Heart {
            publisher,
            count: 0,
        })
    }

    /// Publishes the next beat (a failed send is logged: readers then only have their
    /// request timeout).
    pub fn beat(&mut self) {
        self.count += 1;
        if let Err(e) = self.publisher.send_copy(self.count) {
            tracing::debug!("heartbeat send failed: {e:?}");
        }
    }
}

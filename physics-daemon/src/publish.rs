//! Per-plane output: body states and events into shared memory, plus a tick notification.

use iceoryx2::port::notifier::Notifier;
use iceoryx2::port::publisher::Publisher;
use iceoryx2::port::update_connections::UpdateConnections;
use iceoryx2::prelude::*;
use shm_layout::{monotonic_ns, names, BodyState, EventRecord, PlaneId, TickHeader};

use crate::plane::Plane;
use crate::DaemonError;

/// Subscribers (client ports) one plane accepts.
pub const MAX_READERS: usize = 64;
/// Nodes (processes) that may open one plane's services.
pub const MAX_NODES: usize = 128;

pub struct PlaneOutput {
    bodies: Publisher<ipc::Service, [BodyState], TickHeader>,
    events: Publisher<ipc::Service, [EventRecord], TickHeader>,
    tick: Notifier<ipc::Service>,
}

impl PlaneOutput {
    pub fn new(node: &Node<ipc::Service>, plane: PlaneId) -> Result<PlaneOutput, DaemonError> {
        let ipc = |what: &str, e: &dyn core::fmt::Debug| {
            DaemonError::Ipc(format!("plane {plane}: cannot create the {what}: {e:?}"))
        };
        // Latest-tick semantics: a reader holds at most the newest sample, a slow reader
        // never blocks the daemon, and a late joiner gets the last tick from the history.
        let bodies = node
            .service_builder(&names::plane_bodies(plane))
            .publish_subscribe::<[BodyState]>()
            .user_header::<TickHeader>()
            .enable_safe_overflow(true)
            .history_size(1)
            .subscriber_max_buffer_size(1)
            .subscriber_max_borrowed_samples(2)
            .max_publishers(1)
            .max_subscribers(MAX_READERS)
            .max_nodes(MAX_NODES)
            .open_or_create()
            .map_err(|e| ipc("body service", &e))?
            .publisher_builder()
            .initial_max_slice_len(1024)
            .allocation_strategy(AllocationStrategy::PowerOfTwo)
            .create()
            .map_err(|e| ipc("body publisher", &e))?;
        let events = node
            .service_builder(&names::plane_events(plane))
            .publish_subscribe::<[EventRecord]>()
            .user_header::<TickHeader>()
            .enable_safe_overflow(true)
            .subscriber_max_buffer_size(16)
            .max_publishers(1)
            .max_subscribers(MAX_READERS)
            .max_nodes(MAX_NODES)
            .open_or_create()
            .map_err(|e| ipc("event service", &e))?
            .publisher_builder()
            .initial_max_slice_len(64)
            .allocation_strategy(AllocationStrategy::PowerOfTwo)
            .create()
            .map_err(|e| ipc("event publisher", &e))?;
        let tick = node
            .service_builder(&names::plane_tick(plane))
            .event()
            .max_listeners(MAX_READERS)
            .max_nodes(MAX_NODES)
            .open_or_create()
            .map_err(|e| ipc("tick event", &e))?
            .notifier_builder()
            .create()
            .map_err(|e| ipc("tick notifier", &e))?;
        Ok(PlaneOutput {
            bodies,
            events,
            tick,
        })
    }

    /// Connects readers that subscribed since the last tick and hands them the newest one
    /// (a manual plane may not tick again for a long time).
    pub fn connect_readers(&self) {
        if let Err(e) = self.bodies.update_connections() {
            tracing::warn!("connecting new readers failed: {e:?}");
        }
    }

    /// Writes every slot straight into one loaned sample (the only copy), sends it, sends the
    /// tick's events if there are any, and wakes readers waiting for a tick.
    pub fn publish(&self, plane: &Plane) -> Result<(), DaemonError> {
        let mut header = plane.header();
        header.tick_end_ns = monotonic_ns();
        let mut sample = self
            .bodies
            .loan_slice_uninit(plane.slot_count())
            .map_err(|e| DaemonError::Ipc(format!("plane {}: loan failed: {e:?}", plane.id)))?;
        *sample.user_header_mut() = header;
        let sample = sample.write_from_fn(|i| plane.body_state(i));
        sample
            .send()
            .map_err(|e| DaemonError::Ipc(format!("plane {}: send failed: {e:?}", plane.id)))?;
        let events = plane.events();
        if !events.is_empty() {
            let mut sample = self.events.loan_slice_uninit(events.len()).map_err(|e| {
                DaemonError::Ipc(format!("plane {}: event loan failed: {e:?}", plane.id))
            })?;
            *sample.user_header_mut() = header;
            sample.write_from_slice(events).send().map_err(|e| {
                DaemonError::Ipc(format!("plane {}: event send failed: {e:?}", plane.id))
            })?;
        }
        self.tick.notify().map_err(|e| {
            DaemonError::Ipc(format!("plane {}: tick notify failed: {e:?}", plane.id))
        })?;
        Ok(())
    }
}

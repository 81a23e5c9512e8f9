//! Per-plane output: body states and events into shared memory, plus a tick notification.
//!
//! Samples are recycled: a loaned sample still holds the tick it carried when it was last
//! sent. Slots that have not changed since then (sleeping bodies, untouched empty slots) are
//! left as they are, so a settled world costs almost nothing to publish; only what changed
//! is copied from rapier, straight into the sample.

mod changes;

use std::cell::RefCell;
use std::mem::MaybeUninit;

use iceoryx2::port::notifier::Notifier;
use iceoryx2::port::publisher::Publisher;
use iceoryx2::port::update_connections::UpdateConnections;
use iceoryx2::prelude::*;
use shm_layout::{monotonic_ns, names, BodyState, EventRecord, PlaneId, TickHeader};

use crate::backend::Backend;
use crate::DaemonError;
use changes::Changes;

/// Subscribers (client ports) one plane accepts.
pub const MAX_READERS: usize = 64;
/// Ticks with events a reader's event queue holds (the SDK subscribes with the same size).
pub const EVENT_BUFFER_TICKS: usize = 64;
/// Nodes (processes) that may open one plane's services.
pub const MAX_NODES: usize = 128;

/// The shared-memory output of one plane: body states, events and the tick notification.
pub struct PlaneOutput {
    bodies: Publisher<ipc::Service, [BodyState], TickHeader>,
    events: Publisher<ipc::Service, [EventRecord], TickHeader>,
    tick: Notifier<ipc::Service>,
    changes: RefCell<Changes>,
}

impl PlaneOutput {
    /// Opens (or creates) the plane's body and event services and its tick event, with a
    /// publisher or notifier on each.
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
            // A reader's queue holds this many ticks' events; past it the oldest go, and the
            // reader counts them from the gap in the records' running numbers.
            .enable_safe_overflow(true)
            .subscriber_max_buffer_size(EVENT_BUFFER_TICKS)
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
            changes: RefCell::default(),
        })
    }

    /// Connects readers that subscribed since the last tick and hands them the newest one
    /// (a manual plane may not tick again for a long time).
    pub fn connect_readers(&self) {
        if let Err(e) = self.bodies.update_connections() {
            tracing::warn!("connecting new readers failed: {e:?}");
        }
    }

    /// Writes every slot that changed since the loaned sample last carried a tick straight
    /// into it (the only copy), sends it, sends the tick's events if there are any, and wakes
    /// readers waiting for a tick.
    pub fn publish(&self, plane: &mut dyn Backend) -> Result<(), DaemonError> {
        let mut header = plane.header();
        header.tick_end_ns = monotonic_ns();
        let id = header.plane_id;
        let mut changes = self.changes.borrow_mut();
        let seq = changes.begin(plane);
        let mut sample = self
            .bodies
            .loan_slice_uninit(plane.slot_count())
            .map_err(|e| DaemonError::Ipc(format!("plane {id}: loan failed: {e:?}")))?;
        *sample.user_header_mut() = header;
        let payload: &mut [MaybeUninit<BodyState>] = sample.payload_mut();
        let addr = payload.as_ptr() as usize;
        plane.write_states(payload, changes.filter(addr));
        changes.remember(addr, seq);
        // SAFETY: every element is initialised. Either it was written above (`write_states`
        // writes every slot its filter wants), or this sample was entirely written by
        // publish `written` of the same slot count (a new slot count forgets all samples)
        // and the slot has not changed since: it is not awake now, was not awake at any
        // publish since (`awake_before`), and the plane marked no op on it.
        let sample = unsafe { sample.assume_init() };
        sample
            .send()
            .map_err(|e| DaemonError::Ipc(format!("plane {id}: send failed: {e:?}")))?;
        let events = plane.events();
        if !events.is_empty() {
            let mut sample = self
                .events
                .loan_slice_uninit(events.len())
                .map_err(|e| DaemonError::Ipc(format!("plane {id}: event loan failed: {e:?}")))?;
            *sample.user_header_mut() = header;
            sample
                .write_from_slice(events)
                .send()
                .map_err(|e| DaemonError::Ipc(format!("plane {id}: event send failed: {e:?}")))?;
        }
        self.tick
            .notify()
            .map_err(|e| DaemonError::Ipc(format!("plane {id}: tick notify failed: {e:?}")))?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rapier3d::Plane;
    use shm_layout::{Handle, ObjectOp, ObjectProp, PlaneOp, PlaneProp, Pose, Reply, Shape};

    /// Applies an op the way the server does: handed to the plane, which marks what changed.
    fn apply(plane: &mut Plane, op: PlaneOp) -> Reply {
        Backend::apply(plane, op).expect("op applies")
    }

    #[test]
    fn recycled_samples_always_carry_the_full_current_state() {
        let domain = format!("pubtest-{}", std::process::id());
        let config = names::config(&domain).unwrap();
        let node = NodeBuilder::new()
            .config(&config)
            .signal_handling_mode(SignalHandlingMode::Disabled)
            .create::<ipc::Service>()
            .unwrap();
        let mut plane = Plane::new(1, &[PlaneProp::TickRate(0.0)]).unwrap();
        let cube = Shape::Cube { size: [1.0; 3] };
        plane
            .add_object(
                &Shape::Cube {
                    size: [40.0, 1.0, 40.0],
                },
                Pose::at([0.0, -0.5, 0.0]),
                &[ObjectProp::Anchored(true)],
            )
            .unwrap();
        let mut handles: Vec<Handle> = (0..60)
            .map(|i| {
                let (x, y) = ((i / 3) as f32 * 1.5 - 15.0, 0.5 + (i % 3) as f32);
                plane.add_object(&cube, Pose::at([x, y, 0.0]), &[]).unwrap()
            })
            .collect();
        let out = PlaneOutput::new(&node, plane.id).unwrap();
        let reader = node
            .service_builder(&names::plane_bodies(plane.id))
            .publish_subscribe::<[BodyState]>()
            .user_header::<TickHeader>()
            .open()
            .unwrap()
            .subscriber_builder()
            .create()
            .unwrap();
        let mut held = Vec::new();
        let mut asleep_seen = false;
        for tick in 0..400u32 {
            plane.step(1.0 / 60.0).unwrap();
            // Poke sleeping and awake bodies alike, in every way that changes a slot.
            let victim = handles[(tick as usize * 7) % handles.len()];
            let op = match tick % 50 {
                10 => Some(ObjectOp::Set(ObjectProp::Pose(Pose::at([0.0, 8.0, 5.0])))),
                20 => Some(ObjectOp::Set(ObjectProp::Anchored(true))),
                30 => Some(ObjectOp::Destroy),
                40 => Some(ObjectOp::Wake),
                _ => None,
            };
            if let Some(op) = op {
                let destroyed = op == ObjectOp::Destroy;
                apply(&mut plane, PlaneOp::Object { handle: victim, op });
                if destroyed {
                    handles.retain(|h| *h != victim);
                    let free = plane.slot_count(); // the freed slot is reused below
                    apply(
                        &mut plane,
                        PlaneOp::AddObject {
                            shape: cube.clone(),
                            pose: Pose::at([3.0, 6.0, 3.0]),
                            props: vec![],
                        },
                    );
                    assert_eq!(plane.slot_count(), free, "slot reused");
                    handles.push(Handle {
                        slot: victim.slot,
                        generation: victim.generation + 1,
                    });
                }
            }
            out.publish(&mut plane).unwrap();
            let sample = reader.receive().unwrap().expect("a sample per publish");
            let expected: Vec<BodyState> = (0..plane.slot_count())
                .map(|i| plane.body_state(i))
                .collect();
            assert_eq!(sample.payload(), &expected[..], "tick {tick}");
            asleep_seen |= expected.iter().filter(|b| b.is_sleeping()).count() > 30;
            // Keep a few samples borrowed now and then so the publisher recycles others.
            held.push(sample);
            while held.len() > tick as usize % 2 {
                held.remove(0);
            }
        }
        assert!(asleep_seen, "the pile should fall asleep during the test");
        // Samples still held keep the node's segments alive: release them first.
        drop((held, reader, out, node));
        let _ = crate::cleanup_domain(&domain);
    }
}

//! Per-plane output: body states and events into shared memory, plus a tick notification.
//!
//! Samples are recycled: a loaned sample still holds the tick it carried when it was last
//! sent. Slots that have not changed since then (sleeping bodies, untouched empty slots) are
//! left as they are, so a settled world costs almost nothing to publish; only what changed
//! is copied from rapier, straight into the sample.

use std::cell::RefCell;
use std::mem::MaybeUninit;

use iceoryx2::port::notifier::Notifier;
use iceoryx2::port::publisher::Publisher;
use iceoryx2::port::update_connections::UpdateConnections;
use iceoryx2::prelude::*;
use shm_layout::{
    monotonic_ns, names, BodyState, Command, CommandResult, EventRecord, PlaneId, Reply, TickHeader,
};

use crate::plane::Plane;
use crate::DaemonError;

/// Subscribers (client ports) one plane accepts.
pub const MAX_READERS: usize = 64;
/// Nodes (processes) that may open one plane's services.
pub const MAX_NODES: usize = 128;

/// Samples a plane's publisher may recycle that are remembered; more means the publisher
/// allocates something unexpected, and remembering is dropped (full writes stay correct).
const MAX_TRACKED_SAMPLES: usize = 1024;

pub struct PlaneOutput {
    bodies: Publisher<ipc::Service, [BodyState], TickHeader>,
    events: Publisher<ipc::Service, [EventRecord], TickHeader>,
    tick: Notifier<ipc::Service>,
    changes: RefCell<Changes>,
}

/// What changed since each recycled sample was last written.
#[derive(Default)]
struct Changes {
    /// Publishes so far.
    seq: u64,
    /// Slot count the bookkeeping is for; a new count starts over with full writes.
    slot_count: usize,
    /// Per slot: the publish from which on its state may differ from earlier publishes.
    changed_at: Vec<u64>,
    /// Slots awake at the last publish: they may have moved, or fallen asleep, since.
    awake_before: Vec<usize>,
    /// Most bodies were awake at the last publish: every slot counted as changed.
    mostly_awake_before: bool,
    /// Slots touched by commands since the last publish.
    touched: Vec<usize>,
    /// A command touched something it does not name: rewrite every slot.
    touched_all: bool,
    /// Payload address of a recycled sample → the publish that last wrote all of it.
    samples: Vec<(usize, u64)>,
}

impl Changes {
    /// Advances to a new publish of `plane`; returns its sequence number.
    fn begin(&mut self, plane: &Plane) -> u64 {
        self.seq += 1;
        let seq = self.seq;
        let n = plane.slot_count();
        if n != self.slot_count || self.touched_all {
            // The publisher may have grown its samples: forget every recycled one.
            self.slot_count = n;
            self.samples.clear();
            self.changed_at.clear();
            self.changed_at.resize(n, seq);
            self.touched_all = false;
        }
        let changed_at = &mut self.changed_at;
        for slot in self.touched.drain(..).chain(self.awake_before.drain(..)) {
            if let Some(c) = changed_at.get_mut(slot) {
                *c = seq;
            }
        }
        // When most bodies are awake, looking up each one costs more than rewriting all.
        let mostly_awake = plane.awake_count() * 2 >= n;
        if mostly_awake || self.mostly_awake_before {
            changed_at.fill(seq);
            self.awake_before.clear();
        }
        if !mostly_awake {
            for slot in plane.awake_slots() {
                if let Some(c) = changed_at.get_mut(slot) {
                    *c = seq;
                    self.awake_before.push(slot);
                }
            }
        }
        self.mostly_awake_before = mostly_awake;
        seq
    }

    /// The publish that last wrote the whole sample at `addr`, if it is one we wrote.
    fn written_at(&self, addr: usize) -> Option<u64> {
        self.samples
            .iter()
            .find(|(a, _)| *a == addr)
            .map(|(_, s)| *s)
    }

    fn remember(&mut self, addr: usize, seq: u64) {
        let tracked = self.samples.len();
        match self.samples.iter_mut().find(|(a, _)| *a == addr) {
            Some(entry) => entry.1 = seq,
            None if tracked < MAX_TRACKED_SAMPLES => self.samples.push((addr, seq)),
            None => self.samples.clear(),
        }
    }
}

/// Which slots of which plane a command may change, for [`PlaneOutput::touched`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Touch {
    /// Reads or steps only (a step's changes are found in rapier's awake set).
    Nothing,
    Slot(PlaneId, u32),
    /// The slot of the object the reply names (a new object).
    Created(PlaneId),
    /// Anything in the plane.
    Plane(PlaneId),
}

impl Touch {
    /// What `command` may change. The match has no catch-all: a new command must say.
    pub fn of(command: &Command) -> Touch {
        match command {
            Command::Hello { .. }
            | Command::Goodbye
            | Command::CreatePlane { .. }
            | Command::PlaneInfo { .. }
            | Command::Step { .. }
            | Command::ObjectInfo { .. }
            | Command::DestroyPlane { .. } => Touch::Nothing,
            Command::SetObject { plane, object, .. }
            | Command::ApplyImpulse { plane, object, .. }
            | Command::RecalculateCenterOfMass { plane, object }
            | Command::DestroyObject { plane, object } => Touch::Slot(*plane, object.slot),
            Command::AddObject { plane, .. } => Touch::Created(*plane),
            Command::SetPlane { plane, .. } => Touch::Plane(*plane),
        }
    }

    /// The plane concerned and the slot, once the result is known.
    pub fn resolve(self, result: &CommandResult) -> Option<(PlaneId, Option<u32>)> {
        match (self, result) {
            (Touch::Nothing, _) => None,
            (Touch::Slot(p, s), _) => Some((p, Some(s))),
            (Touch::Created(p), Ok(Reply::Object { handle, .. })) => Some((p, Some(handle.slot))),
            (Touch::Created(_), _) => None,
            (Touch::Plane(p), _) => Some((p, None)),
        }
    }
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
            changes: RefCell::default(),
        })
    }

    /// Notes that a command may have changed `slot` (`None`: any slot) since the last tick.
    pub fn touched(&self, slot: Option<u32>) {
        let mut changes = self.changes.borrow_mut();
        match slot {
            Some(s) => changes.touched.push(s as usize),
            None => changes.touched_all = true,
        }
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
    pub fn publish(&self, plane: &Plane) -> Result<(), DaemonError> {
        let mut header = plane.header();
        header.tick_end_ns = monotonic_ns();
        let mut changes = self.changes.borrow_mut();
        let seq = changes.begin(plane);
        let mut sample = self
            .bodies
            .loan_slice_uninit(plane.slot_count())
            .map_err(|e| DaemonError::Ipc(format!("plane {}: loan failed: {e:?}", plane.id)))?;
        *sample.user_header_mut() = header;
        let payload: &mut [MaybeUninit<BodyState>] = sample.payload_mut();
        let addr = payload.as_ptr() as usize;
        match changes.written_at(addr) {
            Some(written) if !changes.mostly_awake_before => {
                for (i, (dst, changed)) in payload.iter_mut().zip(&changes.changed_at).enumerate() {
                    if *changed > written {
                        dst.write(plane.body_state(i));
                    }
                }
            }
            _ => {
                for (i, dst) in payload.iter_mut().enumerate() {
                    dst.write(plane.body_state(i));
                }
            }
        }
        changes.remember(addr, seq);
        // SAFETY: every element is initialised. Either it was written above, or this sample
        // was entirely written by publish `written` of the same slot count (a new slot count
        // forgets all samples) and the slot has not changed since: it is not awake now, was
        // not awake at any publish since (`awake_before`), and no command touched it.
        let sample = unsafe { sample.assume_init() };
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

#[cfg(test)]
mod tests {
    use super::*;
    use shm_layout::{Handle, ObjectProp, PlaneProp, Pose, Shape};

    /// Applies a command the way the server does: to the plane, then noted for the publisher.
    fn apply(plane: &mut Plane, out: &PlaneOutput, command: Command) {
        let touch = Touch::of(&command);
        let result = match command {
            Command::SetObject { object, prop, .. } => plane
                .set_object(object, prop)
                .map(|_| Reply::Applied { tick: 0 }),
            Command::DestroyObject { object, .. } => plane
                .destroy_object(object)
                .map(|_| Reply::Applied { tick: 0 }),
            Command::AddObject {
                shape, pose, props, ..
            } => plane
                .add_object(&shape, pose, &props)
                .map(|handle| Reply::Object { handle, tick: 0 }),
            other => panic!("not used here: {other:?}"),
        };
        if let Some((_, slot)) = touch.resolve(&result) {
            out.touched(slot);
        }
        result.expect("command applies");
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
        let mut plane = Plane::new(1, 0, &[PlaneProp::TickRate(0.0)]).unwrap();
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
            let cmd = match tick % 50 {
                10 => Some(Command::SetObject {
                    plane: 1,
                    object: victim,
                    prop: ObjectProp::Pose(Pose::at([0.0, 8.0, 5.0])),
                }),
                20 => Some(Command::SetObject {
                    plane: 1,
                    object: victim,
                    prop: ObjectProp::Anchored(true),
                }),
                30 => Some(Command::DestroyObject {
                    plane: 1,
                    object: victim,
                }),
                _ => None,
            };
            if let Some(cmd) = cmd {
                let destroyed = matches!(cmd, Command::DestroyObject { .. });
                apply(&mut plane, &out, cmd);
                if destroyed {
                    handles.retain(|h| *h != victim);
                    let free = plane.slot_count(); // the freed slot is reused below
                    apply(
                        &mut plane,
                        &out,
                        Command::AddObject {
                            plane: 1,
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
            out.publish(&plane).unwrap();
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

//! The plane's event log: the events of the last step (contact started / stopped, joint
//! broke, controller events), the running event number, and what the contact events need
//! across a step: the objects asking for them and the colliders removed since the last step.

use std::sync::mpsc;

use rapier3d::prelude::*;
use shm_layout::{EventRecord, Handle};

/// What the event log keeps across ticks (snapshot state, in this order).
#[derive(Debug, Clone, Default, serde::Serialize, serde::Deserialize)]
pub(crate) struct Kept {
    /// Objects asking for contact events; the event collector runs only when > 0.
    reporting: u32,
    /// Running number of the next event (EventRecord::seq).
    seq: u64,
    /// Colliders removed since the last step with the object they belonged to, so their
    /// contact-stopped events still name it.
    removed: Vec<(ColliderHandle, Handle)>,
}

/// The plane's events (see the module doc).
pub(crate) struct Events {
    /// What is kept across ticks (snapshot state).
    pub(crate) kept: Kept,
    collision_tx: mpsc::Sender<CollisionEvent>,
    collision_rx: mpsc::Receiver<CollisionEvent>,
    force_tx: mpsc::Sender<ContactForceEvent>,
    tear_tx: mpsc::Sender<SoftBodyTearEvent>,
    /// The last step's events.
    records: Vec<EventRecord>,
    /// Events produced before the step (controllers), published with the step's events.
    pending: Vec<EventRecord>,
}

impl Default for Events {
    fn default() -> Self {
        let (collision_tx, collision_rx) = mpsc::channel();
        let (force_tx, _) = mpsc::channel();
        let (tear_tx, _) = mpsc::channel();
        Events {
            kept: Kept::default(),
            collision_tx,
            collision_rx,
            force_tx,
            tear_tx,
            records: Vec::new(),
            pending: Vec::new(),
        }
    }
}

impl Events {
    /// Whether the step must collect rapier's collision events: an object asks for them, or
    /// colliders removed since the last step still end their contacts with an event.
    pub(crate) fn listening(&self) -> bool {
        self.kept.reporting > 0 || !self.kept.removed.is_empty()
    }

    /// The collector a step hands rapier while [`Events::listening`].
    pub(crate) fn collector(&self) -> ChannelEventCollector {
        ChannelEventCollector::new(
            self.collision_tx.clone(),
            self.force_tx.clone(),
            self.tear_tx.clone(),
        )
    }

    /// One more (`on`) or one fewer object asks for contact events.
    pub(crate) fn count_reporting(&mut self, on: bool) {
        match on {
            true => self.kept.reporting += 1,
            false => self.kept.reporting -= 1,
        }
    }

    /// Collider `c` of object `handle` was removed: its contacts still end with an event.
    pub(crate) fn collider_removed(&mut self, c: ColliderHandle, handle: Handle) {
        self.kept.removed.push((c, handle));
    }

    /// The object a collider removed since the last step belonged to.
    pub(crate) fn removed_owner(&self, c: ColliderHandle) -> Option<Handle> {
        self.kept
            .removed
            .iter()
            .find(|(r, _)| *r == c)
            .map(|(_, h)| *h)
    }

    /// After a step: the colliders removed before it have ended their contacts.
    pub(crate) fn step_done(&mut self) {
        self.kept.removed.clear();
    }

    /// Queues an event produced before the step (numbered and stamped with the step).
    pub(crate) fn queue(&mut self, record: EventRecord) {
        self.pending.push(record);
    }

    /// Starts the events of tick `tick`: the last step's go, the queued ones come first, in
    /// their order.
    pub(crate) fn begin_tick(&mut self, tick: u64) {
        self.records.clear();
        for mut record in std::mem::take(&mut self.pending) {
            record.tick = tick;
            self.record(record);
        }
    }

    /// The next collision event rapier reported in the step.
    pub(crate) fn next_collision(&self) -> Option<CollisionEvent> {
        self.collision_rx.try_recv().ok()
    }

    /// Adds `record` to the step's events under the next event number.
    pub(crate) fn record(&mut self, mut record: EventRecord) {
        record.seq = self.kept.seq;
        self.kept.seq += 1;
        self.records.push(record);
    }

    /// Events of the last step.
    pub(crate) fn records(&self) -> &[EventRecord] {
        &self.records
    }

    /// Events recorded so far (the tick header's event count).
    pub(crate) fn count(&self) -> u64 {
        self.kept.seq
    }

    /// A step taken elsewhere (another engine): no events, no contacts to end.
    pub(crate) fn clear_step(&mut self) {
        self.records.clear();
        self.kept.removed.clear();
    }

    /// After a restore: no events of the last step or queued, none left in the channel.
    pub(crate) fn reset(&mut self) {
        self.records.clear();
        self.pending.clear();
        while self.collision_rx.try_recv().is_ok() {}
    }
}

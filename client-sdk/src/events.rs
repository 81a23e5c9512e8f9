//! Per-tick events of a plane (contact started / stopped), read from shared memory in tick
//! order. The daemon numbers every event; a reader that fell more than
//! [`EVENT_BUFFER_TICKS`] ticks with events behind loses the oldest and is told how many.

use shm_layout::{EventRecord, Handle, Vec3, EVENT_CONTACT_STARTED, EVENT_CONTACT_STOPPED};

use crate::plane_shared::EventReader;
use crate::{error::Error, plane::Plane};

pub use crate::transport::EVENT_BUFFER_TICKS;

/// What `Plane::events` returns: the events since the last call, in order, and how many
/// events were lost before them because the reader fell behind.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Events {
    /// The events, in tick order.
    pub records: Vec<EventRecord>,
    /// Events dropped before `records` because the queue overflowed (0 normally).
    pub lost: u64,
}

/// A contact event as the API names it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Contact {
    /// `a` and `b` started touching.
    Started {
        /// One object.
        a: Handle,
        /// The other.
        b: Handle,
        /// World-space contact point.
        position: Vec3,
        /// Unit normal from `a` toward `b`.
        normal: Vec3,
        /// Normal impulse of the tick the contact started.
        impulse: f32,
        /// The tick.
        tick: u64,
    },
    /// `a` and `b` stopped touching (or one of them was removed).
    Ended {
        /// One object.
        a: Handle,
        /// The other.
        b: Handle,
        /// The tick.
        tick: u64,
    },
}

impl Contact {
    /// The contact event a record carries, if it is one.
    pub fn from_record(r: &EventRecord) -> Option<Contact> {
        match r.kind {
            EVENT_CONTACT_STARTED => Some(Contact::Started {
                a: r.a(),
                b: r.b(),
                position: r.position,
                normal: r.normal,
                impulse: r.impulse,
                tick: r.tick,
            }),
            EVENT_CONTACT_STOPPED => Some(Contact::Ended {
                a: r.a(),
                b: r.b(),
                tick: r.tick,
            }),
            _ => None,
        }
    }
}

impl EventReader {
    /// Drains the queue into `out`, counting the events missing between samples.
    pub(crate) fn drain(&self, out: &mut Events) -> Result<(), Error> {
        while let Some(sample) = self.subscriber.receive()? {
            let records = sample.payload();
            let Some(first) = records.first() else {
                continue;
            };
            // Wrapping arithmetic on the low 32 bits: a sample older than expected (sent while
            // the reader was being set up) counts as nothing lost.
            let gap = (first.seq as u32).wrapping_sub(self.next_seq.get()) as i32;
            out.lost += gap.max(0) as u64;
            if let Some(last) = records.last() {
                self.next_seq.set((last.seq as u32).wrapping_add(1));
            }
            out.records.extend_from_slice(records);
        }
        Ok(())
    }
}

impl Plane {
    /// Subscribes to the plane's events now (the first [`Plane::events`] call does it too):
    /// events of later ticks are kept for the next `events` call.
    pub fn subscribe_events(&self) -> Result<(), Error> {
        if self.shared.events.borrow().is_some() {
            return Ok(());
        }
        // Subscribe first, then read where the stream stands: every event after that point
        // reaches the subscriber, so a gap is a real loss.
        let (via, id) = self.via();
        let sub = via.transport().plane_events(id)?;
        let start = match sub.start() {
            Some(start) => start,
            None => self.snapshot().map_or(0, |s| s.header().event_count),
        };
        *self.shared.events.borrow_mut() = Some(EventReader::new(sub, start));
        Ok(())
    }

    /// Events (contact started / stopped) published since the last call, in tick order, with
    /// the count of events lost if this reader fell more than [`EVENT_BUFFER_TICKS`] ticks
    /// behind. The first call subscribes; events before it are not seen.
    pub fn events(&self) -> Result<Events, Error> {
        self.subscribe_events()?;
        let mut out = Events::default();
        if let Some(reader) = self.shared.events.borrow().as_ref() {
            reader.drain(&mut out)?;
        }
        Ok(out)
    }
}

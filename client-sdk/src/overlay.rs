//! Read-your-writes: values written by this process that the published samples do not show
//! yet. An entry lives until a sample newer than the tick at which the daemon applied the
//! write is visible.

use std::collections::HashMap;

use shm_layout::{BodyState, Handle, ObjectProp, Pose, Vec3, FLAG_ALIVE, FLAG_ANCHORED};

#[derive(Debug, Default, Clone)]
pub struct Entry {
    pub pose: Option<Pose>,
    pub velocity: Option<Vec3>,
    pub angular_velocity: Option<Vec3>,
    pub anchored: Option<bool>,
    pub destroyed: bool,
    /// Counts this entry's velocity writes and impulses: an impulse's reply (the velocity
    /// right after it) counts only if nothing changed the velocity after it was queued.
    pub velocity_ticket: u32,
    /// An impulse is queued or in flight: only the daemon knows the velocity after it
    /// (mass, locks, anchoring), so a read of this object flushes the queue first.
    pub impulse_pending: bool,
    /// Set once the daemon confirmed every write of this entry: samples with a tick greater
    /// than this show them. `None` while a write is still queued or in flight.
    pub applied_at: Option<u64>,
}

impl Entry {
    /// Records what `prop` changes in the published state (other properties are not
    /// published per tick, so there is nothing to overlay).
    pub fn record(&mut self, prop: &ObjectProp) {
        match *prop {
            ObjectProp::Pose(p) => self.pose = Some(p),
            ObjectProp::Velocity(v) => {
                self.velocity = Some(v);
                self.velocity_ticket += 1;
                self.impulse_pending = false;
            }
            ObjectProp::AngularVelocity(w) => self.angular_velocity = Some(w),
            ObjectProp::Anchored(a) => {
                self.anchored = Some(a);
                self.velocity = Some([0.0; 3]);
                self.angular_velocity = Some([0.0; 3]);
                self.velocity_ticket += 1;
                self.impulse_pending = false;
            }
            _ => {}
        }
    }

    /// Records a queued impulse; returns its ticket for [`Overlay::impulse_applied`].
    pub fn impulse(&mut self) -> u32 {
        self.velocity_ticket += 1;
        self.impulse_pending = true;
        self.velocity_ticket
    }

    /// `base` with this entry's writes on top.
    pub fn apply(&self, handle: Handle, base: Option<BodyState>) -> Option<BodyState> {
        if self.destroyed {
            return None;
        }
        let mut s = base.unwrap_or(BodyState {
            flags: FLAG_ALIVE,
            generation: handle.generation,
            rotation: [0.0, 0.0, 0.0, 1.0],
            ..Default::default()
        });
        if let Some(p) = self.pose {
            s.position = p.position;
            s.rotation = p.rotation;
        }
        if let Some(v) = self.velocity {
            s.linear_velocity = v;
        }
        if let Some(w) = self.angular_velocity {
            s.angular_velocity = w;
        }
        if let Some(a) = self.anchored {
            s.flags = if a {
                s.flags | FLAG_ANCHORED
            } else {
                s.flags & !FLAG_ANCHORED
            };
        }
        Some(s)
    }
}

#[derive(Debug, Default)]
pub struct Overlay {
    entries: HashMap<Handle, Entry>,
}

impl Overlay {
    /// Records a write (not yet confirmed).
    pub fn write(&mut self, handle: Handle, f: impl FnOnce(&mut Entry)) {
        let e = self.entries.entry(handle).or_default();
        f(e);
        e.applied_at = None;
    }

    /// Records an impulse on `handle` (unconfirmed); returns its ticket.
    pub fn write_ticketed(&mut self, handle: Handle) -> u32 {
        let e = self.entries.entry(handle).or_default();
        e.applied_at = None;
        e.impulse()
    }

    /// The daemon applied the writes of `handle` after tick `tick`.
    pub fn confirm(&mut self, handle: Handle, tick: u64) {
        if let Some(e) = self.entries.get_mut(&handle) {
            e.applied_at = Some(tick);
        }
    }

    /// The daemon applied the impulse of `ticket` after tick `tick`, leaving the linear
    /// velocity `linear`: the read-back value unless a later write changed the velocity.
    pub fn impulse_applied(&mut self, handle: Handle, ticket: u32, linear: Vec3, tick: u64) {
        if let Some(e) = self.entries.get_mut(&handle) {
            if e.velocity_ticket == ticket {
                e.velocity = Some(linear);
                e.impulse_pending = false;
            }
            e.applied_at = Some(tick);
        }
    }

    /// Drops the entry of a write the daemon rejected.
    pub fn discard(&mut self, handle: Handle) {
        self.entries.remove(&handle);
    }

    /// The entry of `handle` if it still matters at `sample_tick`.
    pub fn get(&mut self, handle: Handle, sample_tick: u64) -> Option<&Entry> {
        // Most reads find no pending write at all: skip hashing the handle twice.
        if self.entries.is_empty() {
            return None;
        }
        if matches!(self.entries.get(&handle), Some(Entry { applied_at: Some(t), .. }) if sample_tick > *t)
        {
            self.entries.remove(&handle);
        }
        self.entries.get(&handle)
    }

    /// Whether a write on `handle` may still wait for its tick (its reads then need
    /// [`Overlay::get`]).
    pub fn has(&self, handle: Handle) -> bool {
        !self.entries.is_empty() && self.entries.contains_key(&handle)
    }

    #[cfg(test)]
    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const H: Handle = Handle {
        slot: 2,
        generation: 5,
    };

    #[test]
    fn entry_lives_until_a_newer_sample() {
        let mut o = Overlay::default();
        o.write(H, |e| e.velocity = Some([1.0, 2.0, 3.0]));
        assert!(o.get(H, 100).is_some(), "unconfirmed writes always show");
        o.confirm(H, 10);
        assert!(
            o.get(H, 10).is_some(),
            "the sample of the apply tick predates the write"
        );
        assert!(o.get(H, 11).is_none(), "tick 11 reflects the write");
        assert!(o.is_empty());
    }

    #[test]
    fn entry_overrides_only_written_fields() {
        let base = BodyState {
            position: [9.0; 3],
            flags: FLAG_ALIVE,
            generation: 5,
            ..Default::default()
        };
        let e = Entry {
            velocity: Some([1.0, 0.0, 0.0]),
            ..Default::default()
        };
        let s = e.apply(H, Some(base)).unwrap();
        assert_eq!(s.position, [9.0; 3]);
        assert_eq!(s.linear_velocity, [1.0, 0.0, 0.0]);
        let gone = Entry {
            destroyed: true,
            ..Default::default()
        };
        assert!(gone.apply(H, Some(base)).is_none());
    }
}

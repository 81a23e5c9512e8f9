//! The remote client's wire (docs/cluster.md, "Remote clients"): how a client on another
//! host reaches a daemon of the cluster through Zenoh. Shared by the daemon's relay
//! (`client_sdk::relay`, run by `physics-daemon --cluster`) and the SDK's remote transport
//! so both sides spell every key and frame the same way. No I/O.
//!
//! A remote client picks a random session key (32 hex digits, [`check_session`]) and
//! declares the liveliness token [`client_key`] for as long as it lives. Then:
//! - **Requests** are Zenoh queries on [`request_key`] whose payload is exactly the request
//!   frame a local client sends the control service ([`crate::codec`]); the reply's payload
//!   is the response frame. The relay hands them to the daemon through a local client of its
//!   own, one per remote session: the daemon applies the same handshake, quotas, ownership
//!   and validation as to any local client.
//! - **Watching a plane** ([`WatchOp`] on [`watch_key`]) makes the relay publish each tick of
//!   that plane on [`bodies_key`] as a [`BodyFrame`]: the slots that changed since the frame
//!   it last sent this session (a keyframe, every slot, when the watch starts or the client
//!   asks for one after a gap). Events go as [`EventFrame`]s on [`events_key`] once asked.
//!
//! The reconstruction is exact: a remote reader's slots are bit for bit the daemon's, so a
//! stepped tick's [`TickHeader::state_hash`] holds for them (a sample published between
//! steps, after an add, keeps the last step's hash, so the mirror does not check it).

use serde::{Deserialize, Serialize};

use crate::cluster::ROOT;
use crate::records::{BodyState, EventRecord, TickHeader};

/// Length of a session key: 32 lowercase hex digits (128 random bits: the key is the
/// session's capability, so it must not be guessable).
pub const SESSION_KEY_LEN: usize = 32;

/// Most slots a body frame may describe (a frame past it is dropped as malformed).
pub const MAX_FRAME_SLOTS: u32 = 1 << 22;

/// Checks a session key: 32 lowercase hex digits.
pub fn check_session(key: &str) -> Result<(), String> {
    if key.len() == SESSION_KEY_LEN
        && key
            .bytes()
            .all(|b| b.is_ascii_digit() || (b'a'..=b'f').contains(&b))
    {
        Ok(())
    } else {
        Err(format!(
            "session key {:?} is not {SESSION_KEY_LEN} lowercase hex digits",
            key.chars().take(40).collect::<String>()
        ))
    }
}

/// The liveliness token of remote session `session`.
pub fn client_key(cluster: &str, session: &str) -> String {
    format!("{ROOT}/{cluster}/client/{session}")
}

/// Where session `session` sends its requests to daemon `daemon`.
pub fn request_key(cluster: &str, daemon: &str, session: &str) -> String {
    format!("{ROOT}/{cluster}/relay/{daemon}/request/{session}")
}

/// Every request key of daemon `daemon` (its relay's queryable).
pub fn requests_key(cluster: &str, daemon: &str) -> String {
    format!("{ROOT}/{cluster}/relay/{daemon}/request/*")
}

/// Where session `session` asks daemon `daemon` to stream a plane.
pub fn watch_key(cluster: &str, daemon: &str, session: &str) -> String {
    format!("{ROOT}/{cluster}/relay/{daemon}/watch/{session}")
}

/// Every watch key of daemon `daemon`.
pub fn watches_key(cluster: &str, daemon: &str) -> String {
    format!("{ROOT}/{cluster}/relay/{daemon}/watch/*")
}

/// Where daemon `daemon` streams plane `plane`'s ticks to session `session`.
pub fn bodies_key(cluster: &str, daemon: &str, session: &str, plane: u32) -> String {
    format!("{ROOT}/{cluster}/relay/{daemon}/bodies/{session}/{plane}")
}

/// Where daemon `daemon` streams plane `plane`'s events to session `session`.
pub fn events_key(cluster: &str, daemon: &str, session: &str, plane: u32) -> String {
    format!("{ROOT}/{cluster}/relay/{daemon}/events/{session}/{plane}")
}

/// What a remote session asks of the relay about a plane.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum WatchOp {
    /// Stream the plane's ticks (a keyframe first).
    Bodies {
        /// The plane.
        plane: u32,
    },
    /// Send every slot with the next frame (the client missed a frame).
    Keyframe {
        /// The plane.
        plane: u32,
    },
    /// Stream the plane's events too; answered with [`WatchReply::EventsFrom`].
    Events {
        /// The plane.
        plane: u32,
    },
    /// Stop streaming the plane.
    Stop {
        /// The plane.
        plane: u32,
    },
}

impl WatchOp {
    /// The op's bytes (postcard).
    pub fn encode(&self) -> Vec<u8> {
        postcard::to_stdvec(self).unwrap_or_default()
    }

    /// Reads an op; `None` for bytes that are none.
    pub fn decode(bytes: &[u8]) -> Option<WatchOp> {
        postcard::from_bytes(bytes).ok()
    }
}

/// The relay's answer to a [`WatchOp`].
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub enum WatchReply {
    /// Done.
    Ok,
    /// Events are streamed from this event number on (modulo 2³², as
    /// [`TickHeader::event_count`]): events before it are not, events after it are unless
    /// reported lost.
    EventsFrom(u32),
    /// Refused; the message names why (a plane that does not exist, a malformed op).
    Refused(String),
}

impl WatchReply {
    /// The reply's bytes (postcard).
    pub fn encode(&self) -> Vec<u8> {
        postcard::to_stdvec(self).unwrap_or_default()
    }

    /// Reads a reply; `None` for bytes that are none.
    pub fn decode(bytes: &[u8]) -> Option<WatchReply> {
        postcard::from_bytes(bytes).ok()
    }
}

/// One tick of a plane for one remote session.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BodyFrame {
    /// The tick's header as the daemon published it (`slot_count` is the array's length).
    pub header: TickHeader,
    /// `None`: a keyframe (`changed` holds every slot). `Some(t)`: the slots that differ
    /// from the frame of tick `t` this session was sent last.
    pub base_tick: Option<u64>,
    /// `(slot, state)` pairs, in slot order.
    pub changed: Vec<(u32, BodyState)>,
}

impl BodyFrame {
    /// The frame carrying `bodies` of `header`'s tick to a session that holds `last` (the
    /// slots of the tick it was sent last, `None` for a keyframe).
    pub fn between(
        header: &TickHeader,
        last: Option<(u64, &[BodyState])>,
        bodies: &[BodyState],
    ) -> BodyFrame {
        let (base_tick, changed) = match last {
            None => (
                None,
                bodies
                    .iter()
                    .copied()
                    .enumerate()
                    .map(|(i, b)| (i as u32, b))
                    .collect(),
            ),
            Some((tick, old)) => (
                Some(tick),
                bodies
                    .iter()
                    .enumerate()
                    .filter(|(i, b)| old.get(*i).is_none_or(|o| !same_bits(o, b)))
                    .map(|(i, b)| (i as u32, *b))
                    .collect(),
            ),
        };
        BodyFrame {
            header: *header,
            base_tick,
            changed,
        }
    }

    /// The frame's bytes (postcard).
    pub fn encode(&self) -> Vec<u8> {
        postcard::to_stdvec(self).unwrap_or_default()
    }

    /// Reads a frame; `None` for bytes that are none or a frame naming slots past its own
    /// count (forged or corrupt).
    pub fn decode(bytes: &[u8]) -> Option<BodyFrame> {
        let f: BodyFrame = postcard::from_bytes(bytes).ok()?;
        let n = f.header.slot_count;
        (n <= MAX_FRAME_SLOTS && f.changed.iter().all(|(slot, _)| *slot < n)).then_some(f)
    }
}

/// Whether two slot states are the same bit for bit (NaNs and signed zeros included).
fn same_bits(a: &BodyState, b: &BodyState) -> bool {
    let bits = |v: [f32; 3]| v.map(f32::to_bits);
    bits(a.position) == bits(b.position)
        && a.rotation.map(f32::to_bits) == b.rotation.map(f32::to_bits)
        && bits(a.linear_velocity) == bits(b.linear_velocity)
        && bits(a.angular_velocity) == bits(b.angular_velocity)
        && (a.flags, a.generation, a._reserved) == (b.flags, b.generation, b._reserved)
}

/// What a remote reader rebuilds from [`BodyFrame`]s: the newest tick's header and slots.
#[derive(Debug, Clone, Default)]
pub struct BodyMirror {
    /// The newest tick applied, and its slots; `None` before the first keyframe.
    pub current: Option<(TickHeader, Vec<BodyState>)>,
}

/// What applying a frame did.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Applied {
    /// The mirror holds the frame's tick now.
    Newer,
    /// The frame was for a base this mirror does not hold (a frame was lost): ask for a
    /// keyframe; the mirror keeps its last tick.
    NeedKeyframe,
    /// A keyframe that does not hold every slot (malformed): ask for another; the mirror
    /// keeps its last tick.
    Mismatch,
}

impl BodyMirror {
    /// Applies `frame`.
    pub fn apply(&mut self, frame: BodyFrame) -> Applied {
        let n = frame.header.slot_count as usize;
        if frame.base_tick.is_none() && frame.changed.len() != n {
            return Applied::Mismatch;
        }
        let mut bodies = match (frame.base_tick, self.current.take()) {
            (None, _) => vec![BodyState::default(); n],
            // The slots are updated in place: a delta costs its changed slots.
            (Some(base), Some((h, mut old))) if h.tick == base => {
                old.resize(n, BodyState::default());
                old
            }
            (_, kept) => {
                self.current = kept;
                return Applied::NeedKeyframe;
            }
        };
        for (slot, state) in frame.changed {
            if let Some(b) = bodies.get_mut(slot as usize) {
                *b = state;
            }
        }
        self.current = Some((frame.header, bodies));
        Applied::Newer
    }
}

/// A tick's events for one remote session.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EventFrame {
    /// The tick's header.
    pub header: TickHeader,
    /// Its events, in order.
    pub records: Vec<EventRecord>,
}

impl EventFrame {
    /// The frame's bytes (postcard).
    pub fn encode(&self) -> Vec<u8> {
        postcard::to_stdvec(self).unwrap_or_default()
    }

    /// Reads a frame; `None` for bytes that are none.
    pub fn decode(bytes: &[u8]) -> Option<EventFrame> {
        postcard::from_bytes(bytes).ok()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::records::StateHasher;

    fn body(x: f32) -> BodyState {
        BodyState {
            position: [x, 1.0, 2.0],
            flags: crate::records::FLAG_ALIVE,
            rotation: [0.0, 0.0, 0.0, 1.0],
            generation: 1,
            ..Default::default()
        }
    }

    fn header(tick: u64, bodies: &[BodyState]) -> TickHeader {
        TickHeader {
            tick,
            slot_count: bodies.len() as u32,
            state_hash: StateHasher::of(bodies),
            ..Default::default()
        }
    }

    #[test]
    fn deltas_rebuild_every_tick_bit_for_bit_and_gaps_ask_for_a_keyframe() {
        let t1: Vec<_> = (0..5).map(|i| body(i as f32)).collect();
        let mut t2 = t1.clone();
        t2[3].position[1] = -0.0;
        t2.push(body(9.0));
        let mut t3 = t2.clone();
        t3.truncate(4);
        let mut m = BodyMirror::default();
        let k = BodyFrame::between(&header(1, &t1), None, &t1);
        let d2 = BodyFrame::between(&header(2, &t2), Some((1, &t1)), &t2);
        assert_eq!(
            d2.changed.len(),
            2,
            "slot 3 (a signed zero) and the new slot 5"
        );
        let d3 = BodyFrame::between(&header(3, &t3), Some((2, &t2)), &t3);
        assert_eq!(m.apply(d2.clone()), Applied::NeedKeyframe);
        for f in [k, d2, d3] {
            let f = BodyFrame::decode(&f.encode()).unwrap();
            assert_eq!(m.apply(f), Applied::Newer);
        }
        let (h, b) = m.current.clone().unwrap();
        assert_eq!((h.tick, b.as_slice()), (3, t3.as_slice()));
        // A keyframe missing slots is refused; the mirror keeps tick 3.
        let mut short = BodyFrame::between(&header(4, &t3), None, &t3);
        short.changed.pop();
        assert_eq!(m.apply(short), Applied::Mismatch);
        assert_eq!(m.current.as_ref().unwrap().0.tick, 3);
    }

    #[test]
    fn forged_frames_and_keys_are_refused() {
        let t1 = vec![body(0.0)];
        let mut f = BodyFrame::between(&header(1, &t1), None, &t1);
        f.changed[0].0 = 5;
        assert!(
            BodyFrame::decode(&f.encode()).is_none(),
            "slot past the count"
        );
        assert!(BodyFrame::decode(&[0xff; 7]).is_none());
        assert!(WatchOp::decode(&[0xff, 0xff]).is_none());
        assert!(check_session(&"a".repeat(32)).is_ok());
        for bad in ["", "A".repeat(32).as_str(), "a/*", &"a".repeat(33)] {
            assert!(check_session(bad).is_err(), "{bad}");
        }
    }
}

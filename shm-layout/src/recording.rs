//! Plane recordings as bytes: a session file that reproduces a plane bit for bit. The plane
//! writes a keyframe (a [`crate::snapshot`]) when recording starts, then, in the order they
//! happened, every batch of ops applied to it with the tick it was applied at, each tick's
//! step and state hash, and every so many ticks another keyframe, so a long recording can
//! be entered anywhere.
//!
//! ```text
//! MAGIC "PHYSREC1" | format u32 LE | layout version u32 LE | entry*
//! entry: tag u8 | len u32 LE | payload (len bytes) | checksum u64 LE (of tag, len, payload)
//! ```
//!
//! Entries ([`EntryTag`]): `Start` (postcard [`RecordingStart`]), `Keyframe` (why u8 |
//! snapshot bytes), `Batch` (tick u64 | op count u32 | the ops, postcard one after the other),
//! `Tick` (tick u64 | dt f32 | state hash u64), `End` (postcard reason string). Every entry
//! carries its own checksum, so a damaged file is refused naming the byte offset of the
//! entry that fails, and a file cut short inside an entry is refused naming where that
//! entry starts. A file without its `End` entry (a daemon killed between two entries) reads
//! as far as it goes ([`Recording::end`] is `None`).

use serde::{Deserialize, Serialize};

use crate::error::{CommandError, ErrorKind};
use crate::plane_kind::PlaneKind;
use crate::plane_op::PlaneOp;
use crate::snapshot::checksum;
use crate::version::LAYOUT_VERSION;

/// The eight bytes every recording starts with.
pub const RECORDING_MAGIC: [u8; 8] = *b"PHYSREC1";
/// Version of the recording framing. Bumped whenever an entry changes shape.
pub const RECORDING_FORMAT: u32 = 1;
/// Bytes before the first entry.
pub const PREAMBLE_LEN: usize = 16;
/// Bytes of an entry besides its payload (tag, length, checksum).
pub const ENTRY_OVERHEAD: usize = 13;
/// Ticks between keyframes unless the daemon is told otherwise.
pub const DEFAULT_KEYFRAME_EVERY: u32 = 600;

/// What an entry is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u8)]
pub enum EntryTag {
    /// What was recorded ([`RecordingStart`]); the first entry.
    Start = 1,
    /// A snapshot of the plane ([`KeyframeWhy`] byte, then the snapshot).
    Keyframe = 2,
    /// Ops applied between two ticks.
    Batch = 3,
    /// One step: the tick it made, its dt and the state hash after it.
    Tick = 4,
    /// The recording stopped (the reason); the last entry.
    End = 5,
}

impl EntryTag {
    fn of(byte: u8) -> Option<EntryTag> {
        Some(match byte {
            1 => EntryTag::Start,
            2 => EntryTag::Keyframe,
            3 => EntryTag::Batch,
            4 => EntryTag::Tick,
            5 => EntryTag::End,
            _ => return None,
        })
    }

    /// The entry's name in messages.
    pub fn word(self) -> &'static str {
        match self {
            EntryTag::Start => "start",
            EntryTag::Keyframe => "keyframe",
            EntryTag::Batch => "batch",
            EntryTag::Tick => "tick",
            EntryTag::End => "end",
        }
    }
}

/// Why a keyframe was written.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u8)]
pub enum KeyframeWhy {
    /// The state the recording starts from.
    Start = 0,
    /// Every `keyframe_every` ticks: a place to enter a long recording (a replay going
    /// through it only checks it).
    Periodic = 1,
    /// The plane became another state (a `Restore` or `Rewind`): a replay restores it.
    Jump = 2,
}

/// What the `Start` entry says.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RecordingStart {
    /// The kind of plane.
    pub kind: PlaneKind,
    /// Its id on the daemon that recorded it.
    pub plane: u32,
    /// Its tick when recording started.
    pub tick: u64,
    /// Ticks between periodic keyframes.
    pub keyframe_every: u32,
    /// The recording daemon's name (`--name`) or its domain.
    pub daemon: String,
    /// When recording started (milliseconds since the Unix epoch).
    pub started_unix_ms: u64,
}

/// The file's first bytes.
pub fn preamble() -> [u8; PREAMBLE_LEN] {
    let mut out = [0u8; PREAMBLE_LEN];
    out[..8].copy_from_slice(&RECORDING_MAGIC);
    out[8..12].copy_from_slice(&RECORDING_FORMAT.to_le_bytes());
    out[12..16].copy_from_slice(&LAYOUT_VERSION.to_le_bytes());
    out
}

/// Appends one entry (tag, length, `payload`, checksum) to `out`.
pub fn push_entry(out: &mut Vec<u8>, tag: EntryTag, payload: &[u8]) {
    let start = out.len();
    out.push(tag as u8);
    out.extend_from_slice(&(payload.len() as u32).to_le_bytes());
    out.extend_from_slice(payload);
    let sum = checksum(&out[start..]);
    out.extend_from_slice(&sum.to_le_bytes());
}

/// Appends the `Start` entry.
pub fn push_start(out: &mut Vec<u8>, start: &RecordingStart) {
    let payload = postcard::to_allocvec(start).expect("a start entry always encodes");
    push_entry(out, EntryTag::Start, &payload);
}

/// Appends a `Keyframe` entry holding `snapshot`.
pub fn push_keyframe(out: &mut Vec<u8>, why: KeyframeWhy, snapshot: &[u8]) {
    let mut payload = Vec::with_capacity(1 + snapshot.len());
    payload.push(why as u8);
    payload.extend_from_slice(snapshot);
    push_entry(out, EntryTag::Keyframe, &payload);
}

/// Appends a `Tick` entry.
pub fn push_tick(out: &mut Vec<u8>, tick: u64, dt: f32, hash: u64) {
    let mut payload = [0u8; 20];
    payload[..8].copy_from_slice(&tick.to_le_bytes());
    payload[8..12].copy_from_slice(&dt.to_le_bytes());
    payload[12..].copy_from_slice(&hash.to_le_bytes());
    push_entry(out, EntryTag::Tick, &payload);
}

/// Appends an `End` entry.
pub fn push_end(out: &mut Vec<u8>, reason: &str) {
    let payload = postcard::to_allocvec(reason).expect("a string always encodes");
    push_entry(out, EntryTag::End, &payload);
}

/// A batch being gathered: ops encoded as they are applied, framed once the plane steps.
#[derive(Debug, Default)]
pub struct BatchWriter {
    /// The plane's tick when the batch's first op was applied.
    tick: u64,
    count: u32,
    /// tick u64 | count u32 (filled in by [`BatchWriter::push_to`]) | ops.
    payload: Vec<u8>,
}

impl BatchWriter {
    /// Adds `op`, applied at `tick` (the plane's tick then).
    pub fn add(&mut self, tick: u64, op: &PlaneOp) {
        if self.count == 0 {
            self.tick = tick;
            self.payload.clear();
            self.payload.extend_from_slice(&[0u8; 12]);
        }
        postcard::to_extend(op, std::mem::take(&mut self.payload))
            .map(|p| self.payload = p)
            .expect("an op always encodes");
        self.count += 1;
    }

    /// Ops gathered and not yet written.
    pub fn len(&self) -> usize {
        self.count as usize
    }

    /// Whether no op waits.
    pub fn is_empty(&self) -> bool {
        self.count == 0
    }

    /// Appends the gathered ops as one `Batch` entry to `out` (nothing when there are
    /// none) and starts a new batch.
    pub fn push_to(&mut self, out: &mut Vec<u8>) {
        if self.count == 0 {
            return;
        }
        self.payload[..8].copy_from_slice(&self.tick.to_le_bytes());
        self.payload[8..12].copy_from_slice(&self.count.to_le_bytes());
        push_entry(out, EntryTag::Batch, &self.payload);
        self.count = 0;
    }
}

/// One entry of a recording, in file order, with where it lies.
#[derive(Debug, Clone, PartialEq)]
pub enum Event {
    /// A snapshot (its bytes are `bytes[range]` of the recording).
    Keyframe {
        /// Why it was written.
        why: KeyframeWhy,
        /// Its tick (from the snapshot's header).
        tick: u64,
        /// Its state hash (from the snapshot's header).
        state_hash: u64,
        /// Where its snapshot bytes lie in the file.
        range: std::ops::Range<usize>,
    },
    /// Ops applied at `tick` (after that tick's step, before the next).
    Batch {
        /// The plane's tick when they were applied.
        tick: u64,
        /// How many ops.
        count: u32,
        /// Where the encoded ops lie in the file.
        range: std::ops::Range<usize>,
        /// The entry's byte offset (for messages).
        offset: usize,
    },
    /// A step that made tick `tick`.
    Tick {
        /// The tick made.
        tick: u64,
        /// Its dt.
        dt: f32,
        /// The state hash after it.
        state_hash: u64,
    },
}

/// A recording read and checked: every entry's checksum, the order of ticks, the keyframes'
/// snapshot framing. Ops are decoded when asked for ([`Recording::ops`]).
#[derive(Debug, Clone)]
pub struct Recording {
    /// The whole file.
    pub bytes: Vec<u8>,
    /// What the `Start` entry says.
    pub start: RecordingStart,
    /// The entries after `Start`, in order (the first is the start keyframe).
    pub events: Vec<Event>,
    /// The `End` entry's reason; `None` when the file has none (its daemon stopped while
    /// recording).
    pub end: Option<String>,
}

fn refused(what: impl Into<String>) -> CommandError {
    CommandError::new(
        ErrorKind::InvalidValue,
        format!("recording refused: {}", what.into()),
    )
}

impl Recording {
    /// Reads and checks `bytes`. A damaged entry, or one the file ends inside, is refused
    /// naming its byte offset.
    pub fn parse(bytes: Vec<u8>) -> Result<Recording, CommandError> {
        if bytes.len() < PREAMBLE_LEN {
            return Err(refused(format!(
                "{} bytes is shorter than a recording's {PREAMBLE_LEN}-byte start",
                bytes.len()
            )));
        }
        if bytes[..8] != RECORDING_MAGIC {
            return Err(refused(format!(
                "not a plane recording (it starts with {:02x?}, a recording with \"PHYSREC1\")",
                &bytes[..8]
            )));
        }
        let format = u32::from_le_bytes(bytes[8..12].try_into().expect("4 bytes"));
        if format != RECORDING_FORMAT {
            return Err(refused(format!(
                "format {format} at byte offset 8 (this build reads format {RECORDING_FORMAT})"
            )));
        }
        let layout = u32::from_le_bytes(bytes[12..16].try_into().expect("4 bytes"));
        if layout != LAYOUT_VERSION {
            return Err(refused(format!(
                "written with layout version {layout} (byte offset 12; this build has \
                 {LAYOUT_VERSION})"
            )));
        }
        let mut at = PREAMBLE_LEN;
        let mut start: Option<RecordingStart> = None;
        let mut events = Vec::new();
        let mut end = None;
        let mut last_tick: Option<u64> = None;
        while at < bytes.len() {
            if end.is_some() {
                return Err(refused(format!(
                    "bytes after the end entry, at byte offset {at}"
                )));
            }
            let cut = || {
                refused(format!(
                    "the file ends inside the entry at byte offset {at} ({} bytes; cut short)",
                    bytes.len()
                ))
            };
            if bytes.len() - at < ENTRY_OVERHEAD {
                return Err(cut());
            }
            let tag_byte = bytes[at];
            let len =
                u32::from_le_bytes(bytes[at + 1..at + 5].try_into().expect("4 bytes")) as usize;
            let Some(tag) = EntryTag::of(tag_byte) else {
                return Err(refused(format!(
                    "unknown entry tag {tag_byte} at byte offset {at} (corrupted)"
                )));
            };
            let Some(entry_end) = (at + 5).checked_add(len).and_then(|e| e.checked_add(8)) else {
                return Err(refused(format!("entry length {len} at byte offset {at}")));
            };
            if entry_end > bytes.len() {
                return Err(cut());
            }
            let payload_range = at + 5..at + 5 + len;
            let stored = u64::from_le_bytes(bytes[entry_end - 8..entry_end].try_into().expect("8"));
            let sum = checksum(&bytes[at..entry_end - 8]);
            if sum != stored {
                return Err(refused(format!(
                    "the {} entry at byte offset {at} fails its checksum ({sum:016x}, stored \
                     {stored:016x}): the file is corrupted there",
                    tag.word()
                )));
            }
            let payload = &bytes[payload_range.clone()];
            let bad = |what: String| {
                refused(format!(
                    "the {} entry at byte offset {at}: {what}",
                    tag.word()
                ))
            };
            if start.is_none() && tag != EntryTag::Start {
                return Err(bad("the first entry must be the start entry".into()));
            }
            match tag {
                EntryTag::Start => {
                    if start.is_some() {
                        return Err(bad("a second start entry".into()));
                    }
                    let s: RecordingStart = postcard::from_bytes(payload)
                        .map_err(|e| bad(format!("does not decode: {e}")))?;
                    start = Some(s);
                }
                EntryTag::Keyframe => {
                    let Some((&why, snap)) = payload.split_first() else {
                        return Err(bad("empty".into()));
                    };
                    let why = match why {
                        0 => KeyframeWhy::Start,
                        1 => KeyframeWhy::Periodic,
                        2 => KeyframeWhy::Jump,
                        w => return Err(bad(format!("unknown keyframe kind {w}"))),
                    };
                    if events.is_empty() != (why == KeyframeWhy::Start) {
                        return Err(bad("the start keyframe must come first, and once".into()));
                    }
                    let (header, _) = crate::snapshot::verify(snap)
                        .map_err(|e| bad(format!("its snapshot: {}", e.message)))?;
                    let kind = start.as_ref().map(|s| s.kind);
                    if Some(header.kind) != kind {
                        return Err(bad(format!(
                            "its snapshot holds a {} plane",
                            header.kind.words()
                        )));
                    }
                    if why != KeyframeWhy::Jump {
                        if let Some(t) = last_tick.filter(|t| *t != header.tick) {
                            return Err(bad(format!(
                                "its snapshot is of tick {}, the plane was at tick {t}",
                                header.tick
                            )));
                        }
                    }
                    last_tick = Some(header.tick);
                    events.push(Event::Keyframe {
                        why,
                        tick: header.tick,
                        state_hash: header.state_hash,
                        range: payload_range.start + 1..payload_range.end,
                    });
                }
                EntryTag::Batch => {
                    if events.is_empty() {
                        return Err(bad("a batch before the start keyframe".into()));
                    }
                    if payload.len() < 12 {
                        return Err(bad(format!("{} bytes is shorter than 12", payload.len())));
                    }
                    let tick = u64::from_le_bytes(payload[..8].try_into().expect("8"));
                    let count = u32::from_le_bytes(payload[8..12].try_into().expect("4"));
                    if Some(tick) != last_tick {
                        return Err(bad(format!(
                            "applied at tick {tick}, the plane was at tick {}",
                            last_tick.unwrap_or_default()
                        )));
                    }
                    events.push(Event::Batch {
                        tick,
                        count,
                        range: payload_range.start + 12..payload_range.end,
                        offset: at,
                    });
                }
                EntryTag::Tick => {
                    if payload.len() != 20 {
                        return Err(bad(format!("{} bytes, a tick entry has 20", payload.len())));
                    }
                    let tick = u64::from_le_bytes(payload[..8].try_into().expect("8"));
                    let dt = f32::from_le_bytes(payload[8..12].try_into().expect("4"));
                    let state_hash = u64::from_le_bytes(payload[12..].try_into().expect("8"));
                    if last_tick.map(|t| t + 1) != Some(tick) {
                        return Err(bad(format!(
                            "tick {tick} follows tick {}",
                            last_tick.unwrap_or_default()
                        )));
                    }
                    last_tick = Some(tick);
                    events.push(Event::Tick {
                        tick,
                        dt,
                        state_hash,
                    });
                }
                EntryTag::End => {
                    let reason: String = postcard::from_bytes(payload)
                        .map_err(|e| bad(format!("does not decode: {e}")))?;
                    end = Some(reason);
                }
            }
            at = entry_end;
        }
        let Some(start) = start else {
            return Err(refused(format!(
                "no start entry (the file ends at byte offset {})",
                bytes.len()
            )));
        };
        if events.is_empty() {
            return Err(refused(format!(
                "no start keyframe (the file ends at byte offset {})",
                bytes.len()
            )));
        }
        Ok(Recording {
            bytes,
            start,
            events,
            end,
        })
    }

    /// The snapshot bytes of a keyframe event.
    pub fn snapshot(&self, range: &std::ops::Range<usize>) -> &[u8] {
        &self.bytes[range.clone()]
    }

    /// The ops of a batch event, decoded; an op that does not decode is refused naming the
    /// byte offset where it starts.
    pub fn ops(&self, event: &Event) -> Result<Vec<PlaneOp>, CommandError> {
        Ok(self
            .sized_ops(event)?
            .into_iter()
            .map(|(op, _)| op)
            .collect())
    }

    /// [`Recording::ops`], each with the bytes of its encoding (a replay sends a large
    /// batch in requests of bounded size).
    pub fn sized_ops(&self, event: &Event) -> Result<Vec<(PlaneOp, usize)>, CommandError> {
        let Event::Batch {
            count,
            range,
            offset,
            ..
        } = event
        else {
            return Ok(Vec::new());
        };
        let mut rest = &self.bytes[range.clone()];
        let mut ops = Vec::with_capacity((*count as usize).min(rest.len()));
        for i in 0..*count {
            let at = range.end - rest.len();
            let (op, tail) = postcard::take_from_bytes::<PlaneOp>(rest).map_err(|e| {
                refused(format!(
                    "op {i} of the batch entry at byte offset {offset} (byte offset {at}) does \
                     not decode: {e}"
                ))
            })?;
            ops.push((op, rest.len() - tail.len()));
            rest = tail;
        }
        if !rest.is_empty() {
            return Err(refused(format!(
                "the batch entry at byte offset {offset} holds {} bytes after its {count} ops",
                rest.len()
            )));
        }
        Ok(ops)
    }

    /// The first tick (the start keyframe's).
    pub fn first_tick(&self) -> u64 {
        match self.events.first() {
            Some(Event::Keyframe { tick, .. }) => *tick,
            _ => self.start.tick,
        }
    }

    /// The last tick recorded.
    pub fn last_tick(&self) -> u64 {
        self.events
            .iter()
            .rev()
            .find_map(|e| match e {
                Event::Tick { tick, .. } => Some(*tick),
                Event::Keyframe { tick, .. } => Some(*tick),
                Event::Batch { .. } => None,
            })
            .unwrap_or(self.start.tick)
    }

    /// Ticks recorded (steps).
    pub fn tick_count(&self) -> u64 {
        self.events
            .iter()
            .filter(|e| matches!(e, Event::Tick { .. }))
            .count() as u64
    }

    /// The index of the keyframe to enter the recording at to reach `tick`: the last
    /// keyframe at or before it in file order (0, the start, when none later is).
    pub fn keyframe_for(&self, tick: u64) -> usize {
        let mut best = 0;
        for (i, e) in self.events.iter().enumerate() {
            match e {
                Event::Keyframe { tick: t, .. } if *t <= tick => best = i,
                Event::Tick { tick: t, .. } if *t > tick => break,
                _ => {}
            }
        }
        best
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::snapshot::{encode, SnapshotHeader};

    fn snap(tick: u64) -> Vec<u8> {
        encode(
            SnapshotHeader {
                kind: PlaneKind::Rapier3d,
                tick,
                state_hash: 7,
                ..Default::default()
            },
            b"body",
        )
    }

    fn sample() -> Vec<u8> {
        let mut out = preamble().to_vec();
        push_start(
            &mut out,
            &RecordingStart {
                kind: PlaneKind::Rapier3d,
                plane: 3,
                tick: 5,
                keyframe_every: 2,
                daemon: "d".into(),
                started_unix_ms: 1,
            },
        );
        push_keyframe(&mut out, KeyframeWhy::Start, &snap(5));
        let mut batch = BatchWriter::default();
        batch.add(5, &PlaneOp::Info);
        batch.add(5, &PlaneOp::Step { dt: 0.5 });
        batch.push_to(&mut out);
        push_tick(&mut out, 6, 1.0 / 60.0, 11);
        push_tick(&mut out, 7, 1.0 / 60.0, 12);
        push_keyframe(&mut out, KeyframeWhy::Periodic, &snap(7));
        push_end(&mut out, "stopped");
        out
    }

    #[test]
    fn a_recording_reads_back() {
        let r = Recording::parse(sample()).unwrap();
        assert_eq!(r.start.plane, 3);
        assert_eq!(r.events.len(), 5);
        assert_eq!(
            r.ops(&r.events[1]).unwrap(),
            vec![PlaneOp::Info, PlaneOp::Step { dt: 0.5 }]
        );
        assert_eq!((r.first_tick(), r.last_tick(), r.tick_count()), (5, 7, 2));
        assert_eq!(r.end.as_deref(), Some("stopped"));
        assert_eq!(r.keyframe_for(6), 0);
        assert_eq!(r.keyframe_for(7), 4);
    }

    #[test]
    fn every_flipped_byte_is_refused_naming_an_offset() {
        let good = sample();
        for i in PREAMBLE_LEN..good.len() {
            let mut bad = good.clone();
            bad[i] ^= 0x40;
            let e = Recording::parse(bad).expect_err("a flipped byte is noticed");
            assert!(e.message.contains("byte offset"), "{i}: {}", e.message);
        }
    }

    #[test]
    fn a_corrupted_entry_names_its_offset() {
        let good = sample();
        let r = Recording::parse(good.clone()).unwrap();
        let Event::Batch { offset, .. } = r.events[1] else {
            panic!("a batch")
        };
        let mut bad = good;
        bad[offset + 7] ^= 1;
        let e = Recording::parse(bad).unwrap_err();
        assert!(
            e.message
                .contains(&format!("batch entry at byte offset {offset}")),
            "{}",
            e.message
        );
    }

    #[test]
    fn a_file_cut_short_is_refused_and_one_without_its_end_reads() {
        let good = sample();
        let r = Recording::parse(good.clone()).unwrap();
        let Event::Keyframe { range, .. } = &r.events[4] else {
            panic!("a keyframe")
        };
        // The periodic keyframe's entry starts 6 bytes before its snapshot.
        let keyframe_at = range.start - 6;
        let e = Recording::parse(good[..range.start + 3].to_vec()).unwrap_err();
        assert!(
            e.message
                .contains(&format!("inside the entry at byte offset {keyframe_at}")),
            "{}",
            e.message
        );
        let r = Recording::parse(good[..range.end + 8].to_vec()).unwrap();
        assert!(r.end.is_none());
        assert_eq!(r.last_tick(), 7);
        let e = Recording::parse(b"PHYSNAP1xxxxxxxxxxxx".to_vec()).unwrap_err();
        assert!(e.message.contains("not a plane recording"), "{}", e.message);
    }
}

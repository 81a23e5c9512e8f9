//! Plane snapshots as bytes: a fixed header any process can read (what plane kind, which
//! tick, the tick's state hash, the engine that wrote it) followed by the backend's own
//! state, checked by a checksum over the whole file.
//!
//! ```text
//! MAGIC "PHYSNAP1" | header_len u32 LE | postcard SnapshotHeader | body
//! ```
//!
//! The header says which format and engine wrote the body; a reader refuses another format,
//! another engine build or another layout before it decodes anything engine-specific, and a
//! checksum mismatch (a truncated, corrupted or edited file) before it decodes at all. The
//! body is the backend's business (rapier's serde state plus the plane's own tables).

use serde::{Deserialize, Serialize};

use crate::error::{CommandError, ErrorKind};
use crate::plane_kind::PlaneKind;
use crate::version::LAYOUT_VERSION;

/// The eight bytes every snapshot starts with.
pub const SNAPSHOT_MAGIC: [u8; 8] = *b"PHYSNAP1";
/// Version of the snapshot framing and of every backend's body encoding. Bumped whenever
/// what a backend writes changes shape.
pub const SNAPSHOT_FORMAT: u32 = 1;
/// Most bytes a header may claim (headers are a few dozen bytes).
const MAX_HEADER: usize = 4096;

/// What a snapshot is, readable without decoding its body.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct SnapshotHeader {
    /// [`SNAPSHOT_FORMAT`] of the writer.
    pub format: u32,
    /// [`LAYOUT_VERSION`] of the writer.
    pub layout_version: u32,
    /// The engine and its version that wrote the body (e.g. "rapier3d 0.36"): the body is
    /// that engine's serialised state and only the same engine reads it.
    pub engine: String,
    /// The kind of plane.
    pub kind: PlaneKind,
    /// The tick the plane had stepped when the snapshot was taken.
    pub tick: u64,
    /// The tick header's state hash of that tick.
    pub state_hash: u64,
    /// Live objects (joints included) the plane holds: a restore reserves them against
    /// the client's quota before it decodes the body, and refuses a body that holds more.
    pub objects: u64,
    /// Mesh vertices the plane holds (quota).
    pub mesh_vertices: u64,
    /// Bytes of other counted state (controller paths; quota).
    pub state_bytes: u64,
    /// Bytes of the body.
    pub body_len: u64,
    /// [`checksum`] of the body.
    pub checksum: u64,
}

/// 64-bit FNV-1a over `bytes`, eight at a time (a check against truncation and corruption,
/// not against a forger: the decoder is hardened separately).
pub fn checksum(bytes: &[u8]) -> u64 {
    const PRIME: u64 = 0x0000_0100_0000_01b3;
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    let mut chunks = bytes.chunks_exact(8);
    for c in &mut chunks {
        h = (h ^ u64::from_le_bytes(c.try_into().expect("8 bytes"))).wrapping_mul(PRIME);
    }
    for &b in chunks.remainder() {
        h = (h ^ b as u64).wrapping_mul(PRIME);
    }
    (h ^ bytes.len() as u64).wrapping_mul(PRIME)
}

fn bad(what: impl Into<String>) -> CommandError {
    CommandError::new(
        ErrorKind::InvalidValue,
        format!("snapshot refused: {}", what.into()),
    )
}

/// Frames `body` with `header` (its format, layout version, length and checksum are
/// filled in here).
pub fn encode(mut header: SnapshotHeader, body: &[u8]) -> Vec<u8> {
    header.format = SNAPSHOT_FORMAT;
    header.layout_version = LAYOUT_VERSION;
    header.body_len = body.len() as u64;
    header.checksum = checksum(body);
    let header = postcard::to_allocvec(&header).expect("a header always encodes");
    let mut out = Vec::with_capacity(12 + header.len() + body.len());
    out.extend_from_slice(&SNAPSHOT_MAGIC);
    out.extend_from_slice(&(header.len() as u32).to_le_bytes());
    out.extend_from_slice(&header);
    out.extend_from_slice(body);
    out
}

/// The header of a snapshot, after checking the magic, the framing and the format (the
/// body is not checked: see [`decode`]).
pub fn header(bytes: &[u8]) -> Result<(SnapshotHeader, usize), CommandError> {
    if bytes.len() < 12 {
        return Err(bad(format!(
            "{} bytes is shorter than a snapshot's 12-byte start",
            bytes.len()
        )));
    }
    if bytes[..8] != SNAPSHOT_MAGIC {
        return Err(bad(format!(
            "not a plane snapshot (it starts with {:02x?}, a snapshot with \"PHYSNAP1\")",
            &bytes[..8]
        )));
    }
    let len = u32::from_le_bytes(bytes[8..12].try_into().expect("4 bytes")) as usize;
    if len > MAX_HEADER || 12 + len > bytes.len() {
        return Err(bad(format!(
            "header length {len} does not fit the {} bytes given (truncated?)",
            bytes.len()
        )));
    }
    let header: SnapshotHeader = postcard::from_bytes(&bytes[12..12 + len])
        .map_err(|e| bad(format!("header does not decode: {e}")))?;
    if header.format != SNAPSHOT_FORMAT {
        return Err(bad(format!(
            "format {} (this build reads format {SNAPSHOT_FORMAT})",
            header.format
        )));
    }
    if header.layout_version != LAYOUT_VERSION {
        return Err(bad(format!(
            "written with layout version {} (this build has {LAYOUT_VERSION})",
            header.layout_version
        )));
    }
    Ok((header, 12 + len))
}

/// The header and the body of a snapshot whose body the checksum confirms (any kind, any
/// engine).
pub fn verify(bytes: &[u8]) -> Result<(SnapshotHeader, &[u8]), CommandError> {
    let (header, start) = header(bytes)?;
    let body = &bytes[start..];
    if body.len() as u64 != header.body_len {
        return Err(bad(format!(
            "body of {} bytes, the header says {} (truncated or padded)",
            body.len(),
            header.body_len
        )));
    }
    let sum = checksum(body);
    if sum != header.checksum {
        return Err(bad(format!(
            "checksum {sum:016x} does not match the header's {:016x} (corrupted)",
            header.checksum
        )));
    }
    Ok((header, body))
}

/// [`verify`], for a plane of `kind` run by `engine`.
pub fn decode<'a>(
    bytes: &'a [u8],
    kind: PlaneKind,
    engine: &str,
) -> Result<(SnapshotHeader, &'a [u8]), CommandError> {
    let (header, body) = verify(bytes)?;
    if header.kind != kind {
        return Err(bad(format!(
            "it holds a {} plane, not a {} one",
            header.kind.words(),
            kind.words()
        )));
    }
    if header.engine != engine {
        return Err(bad(format!(
            "written by engine \"{}\" (this daemon runs \"{engine}\")",
            header.engine
        )));
    }
    Ok((header, body))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_and_every_kind_of_damage_is_named() {
        let body = vec![7u8; 1000];
        let header = SnapshotHeader {
            engine: "rapier3d 0.36".into(),
            kind: PlaneKind::Rapier3d,
            tick: 42,
            state_hash: 99,
            ..SnapshotHeader::default()
        };
        let bytes = encode(header, &body);
        let (h, b) = decode(&bytes, PlaneKind::Rapier3d, "rapier3d 0.36").unwrap();
        assert_eq!((h.tick, h.state_hash, b), (42, 99, &body[..]));

        let err = |bytes: &[u8]| {
            decode(bytes, PlaneKind::Rapier3d, "rapier3d 0.36")
                .unwrap_err()
                .message
        };
        assert!(err(&bytes[..5]).contains("shorter"));
        assert!(err(b"hello world, not a snapshot").contains("not a plane snapshot"));
        assert!(err(&bytes[..bytes.len() - 1]).contains("truncated"));
        let mut flipped = bytes.clone();
        *flipped.last_mut().unwrap() ^= 1;
        assert!(err(&flipped).contains("checksum"));
        assert!(decode(&bytes, PlaneKind::Gui2d, "rapier3d 0.36")
            .unwrap_err()
            .message
            .contains("not a GUI one"));
        assert!(decode(&bytes, PlaneKind::Rapier3d, "rapier3d 0.37")
            .unwrap_err()
            .message
            .contains("engine"));
        let mut huge = bytes.clone();
        huge[8..12].copy_from_slice(&u32::MAX.to_le_bytes());
        assert!(err(&huge).contains("header length"));
    }
}

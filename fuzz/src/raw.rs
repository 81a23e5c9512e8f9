//! Raw input: random bytes, and valid frames truncated, bit-flipped, spliced or given a
//! wrong magic or layout version; plus what the daemon must answer to any frame.

use shm_layout::codec::{self, Frame, MAGIC};
use shm_layout::{ErrorKind, LAYOUT_VERSION};

use super::rng::Rng;

/// A raw frame derived from `valid` (a well-formed request frame) or from nothing.
pub fn frame(rng: &mut Rng, valid: &[u8]) -> Vec<u8> {
    let random = |rng: &mut Rng, n: usize| -> Vec<u8> { (0..n).map(|_| rng.byte()).collect() };
    let header = || {
        let mut h = MAGIC.to_vec();
        h.extend_from_slice(&LAYOUT_VERSION.to_le_bytes());
        h
    };
    let mut bytes = valid.to_vec();
    match rng.below(14) {
        0 => {
            let n = rng.below(65);
            random(rng, n)
        }
        1 => {
            let n = rng.below(4097);
            random(rng, n)
        }
        2 => {
            let mut b = header();
            let n = rng.below(513);
            b.extend(random(rng, n));
            b
        }
        3 => {
            bytes.truncate(rng.below(bytes.len()));
            bytes
        }
        4 => {
            for _ in 0..rng.range(1, 8) {
                let i = 8 + rng.below(bytes.len() - 8);
                bytes[i] ^= 1 << rng.below(8);
            }
            bytes
        }
        5 => {
            for _ in 0..rng.range(1, 8) {
                let i = 8 + rng.below(bytes.len() - 7);
                bytes.insert(i.min(bytes.len()), rng.byte());
            }
            bytes
        }
        6 => {
            let from = 8 + rng.below(bytes.len() - 8);
            let to = (from + rng.range(1, 16)).min(bytes.len());
            bytes.drain(from..to);
            bytes
        }
        7 => {
            let i = rng.below(4);
            bytes[i] = bytes[i].wrapping_add(1 + rng.below(255) as u8);
            bytes
        }
        8 => {
            let version = match rng.below(5) {
                0 => 0,
                1 => LAYOUT_VERSION.wrapping_sub(1),
                2 => LAYOUT_VERSION + 1,
                3 => u32::MAX,
                _ => rng.u32() | 0x100,
            };
            bytes[4..8].copy_from_slice(&version.to_le_bytes());
            bytes
        }
        9 => header()[..rng.below(9)].to_vec(),
        10 => {
            // A command count of four billion, then junk.
            let mut b = header();
            b.extend_from_slice(&[0xff, 0xff, 0xff, 0xff, 0x0f]);
            let n = rng.below(64);
            b.extend(random(rng, n));
            b
        }
        11 => {
            // Trailing bytes: two frames back to back.
            let copy = bytes.clone();
            bytes.extend_from_slice(&copy);
            bytes
        }
        12 => {
            // Overwrite a run with 0xff (maximal varints, huge lengths and indices).
            let from = 8 + rng.below(bytes.len() - 8);
            let to = (from + rng.range(1, 10)).min(bytes.len());
            bytes[from..to].fill(0xff);
            bytes
        }
        _ => {
            // Replace one byte with a boundary value.
            let i = 8 + rng.below(bytes.len() - 8);
            bytes[i] = *rng.pick(&[0x00, 0x01, 0x7f, 0x80, 0xfe, 0xff]);
            bytes
        }
    }
}

/// What the daemon must answer to a frame.
#[derive(Debug, Clone, PartialEq)]
pub enum Expected {
    /// The request as a whole refused with this kind.
    Rejected(ErrorKind),
    /// The version-neutral reply (the frame claims another layout version).
    VersionReply,
    /// One result per command.
    Results(usize),
}

/// The answer a daemon with these request limits owes `bytes`, decided with the same
/// codec the daemon uses.
pub fn expected(bytes: &[u8], max_bytes: usize, max_commands: usize) -> Expected {
    if bytes.len() > max_bytes {
        return Expected::Rejected(ErrorKind::Quota);
    }
    match Frame::parse(bytes) {
        Err(_) => Expected::Rejected(ErrorKind::Malformed),
        Ok(f) if f.version != LAYOUT_VERSION => Expected::VersionReply,
        Ok(_) => match codec::decode_request(bytes) {
            Err(_) => Expected::Rejected(ErrorKind::Malformed),
            Ok(r) if r.commands.len() > max_commands => Expected::Rejected(ErrorKind::Quota),
            Ok(r) => Expected::Results(r.commands.len()),
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use shm_layout::{Command, PlaneOp, Request};

    #[test]
    fn mutations_never_panic_and_expectations_hold() {
        let valid = codec::encode_request(&Request {
            commands: vec![
                Command::plane(1, PlaneOp::Step { dt: 0.1 }),
                Command::Goodbye,
            ],
        });
        assert_eq!(expected(&valid, 1 << 20, 10), Expected::Results(2));
        assert_eq!(
            expected(&valid, 1 << 20, 1),
            Expected::Rejected(ErrorKind::Quota)
        );
        assert_eq!(
            expected(&valid, 4, 10),
            Expected::Rejected(ErrorKind::Quota)
        );
        assert_eq!(
            expected(b"NOPE", 1 << 20, 10),
            Expected::Rejected(ErrorKind::Malformed)
        );
        let mut rng = Rng::new(3);
        let mut kinds = std::collections::BTreeSet::new();
        for _ in 0..5_000 {
            let f = frame(&mut rng, &valid);
            kinds.insert(format!("{:?}", expected(&f, 1 << 20, 10)));
        }
        assert!(kinds.len() >= 3, "{kinds:?}");
    }
}

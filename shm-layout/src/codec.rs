//! Byte framing of requests and responses.
//!
//! Every frame is `MAGIC (4 bytes) | LAYOUT_VERSION (u32 LE) | postcard body`. The version
//! sits before the body so a mismatch is detected before anything version-specific is
//! decoded; a daemon answering a mismatched client sends its version followed by its crate
//! version as plain UTF-8, which any version can read.

use serde::{de::DeserializeOwned, Serialize};

use crate::command::{CommandResult, Request, Response};
use crate::version::{CRATE_VERSION, LAYOUT_VERSION};

/// The four bytes every frame starts with.
pub const MAGIC: [u8; 4] = *b"PHYS";
const HEADER_LEN: usize = 8;

/// Why a frame could not be decoded.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum DecodeError {
    #[error("frame of {len} bytes is shorter than the {HEADER_LEN}-byte header")]
    /// The frame does not even hold the header.
    TooShort {
        /// Length of the frame in bytes.
        len: usize,
    },
    #[error("bad magic {found:02x?}, expected {MAGIC:02x?}")]
    /// The frame does not start with [`MAGIC`].
    BadMagic {
        /// The first four bytes of the frame.
        found: [u8; 4],
    },
    #[error(
        "layout version mismatch: this side has LAYOUT_VERSION {ours} (crate {CRATE_VERSION}), \
         the peer has LAYOUT_VERSION {theirs} (crate {their_crate})"
    )]
    /// The peer speaks another layout version.
    VersionMismatch {
        /// Our `LAYOUT_VERSION`.
        ours: u32,
        /// The `LAYOUT_VERSION` in the peer's frame header.
        theirs: u32,
        /// The start of the body read as text: the peer's crate version when the frame is a
        /// version-mismatch reply.
        their_crate: String,
    },
    /// The body is not a valid postcard encoding of the expected type.
    #[error("malformed body: {0}")]
    Body(String),
}

/// A decoded frame header plus the untouched body.
pub struct Frame<'a> {
    /// The `LAYOUT_VERSION` the sender wrote.
    pub version: u32,
    /// Everything after the header.
    pub body: &'a [u8],
}

impl<'a> Frame<'a> {
    /// Checks the length and magic and splits off the header; the version is not checked.
    pub fn parse(bytes: &'a [u8]) -> Result<Frame<'a>, DecodeError> {
        if bytes.len() < HEADER_LEN {
            return Err(DecodeError::TooShort { len: bytes.len() });
        }
        let magic: [u8; 4] = bytes[..4].try_into().expect("4 bytes");
        if magic != MAGIC {
            return Err(DecodeError::BadMagic { found: magic });
        }
        let version = u32::from_le_bytes(bytes[4..8].try_into().expect("4 bytes"));
        Ok(Frame {
            version,
            body: &bytes[HEADER_LEN..],
        })
    }

    /// Decodes the body, first checking that the peer speaks our layout version.
    fn decode<T: DeserializeOwned>(&self) -> Result<T, DecodeError> {
        if self.version != LAYOUT_VERSION {
            return Err(DecodeError::VersionMismatch {
                ours: LAYOUT_VERSION,
                theirs: self.version,
                their_crate: String::from_utf8_lossy(self.body)
                    .chars()
                    .take(64)
                    .collect(),
            });
        }
        // Nothing may follow the value: a length that runs past it (a forged request header,
        // say) is an error, not bytes silently ignored.
        let (value, rest) =
            postcard::take_from_bytes(self.body).map_err(|e| DecodeError::Body(e.to_string()))?;
        if !rest.is_empty() {
            return Err(DecodeError::Body(format!(
                "{} bytes follow the encoded value",
                rest.len()
            )));
        }
        Ok(value)
    }
}

fn encode<T: Serialize>(value: &T) -> Vec<u8> {
    let mut out = Vec::with_capacity(64);
    out.extend_from_slice(&MAGIC);
    out.extend_from_slice(&LAYOUT_VERSION.to_le_bytes());
    postcard::to_io(value, &mut out).expect("writing to a Vec cannot fail");
    out
}

/// Frames a request batch.
pub fn encode_request(request: &Request) -> Vec<u8> {
    encode(request)
}

/// Decodes a request frame (header, version, then body).
pub fn decode_request(bytes: &[u8]) -> Result<Request, DecodeError> {
    Frame::parse(bytes)?.decode()
}

/// Frames a response.
pub fn encode_response(response: &Response) -> Vec<u8> {
    encode(response)
}

/// Decodes a response frame (header, version, then body).
pub fn decode_response(bytes: &[u8]) -> Result<Response, DecodeError> {
    Frame::parse(bytes)?.decode()
}

/// The reply a daemon sends to a client of another layout version: readable by any version.
pub fn encode_version_mismatch() -> Vec<u8> {
    let mut out = Vec::with_capacity(HEADER_LEN + CRATE_VERSION.len());
    out.extend_from_slice(&MAGIC);
    out.extend_from_slice(&LAYOUT_VERSION.to_le_bytes());
    out.extend_from_slice(CRATE_VERSION.as_bytes());
    out
}

/// Test support: a request frame claiming another layout version.
#[doc(hidden)]
pub fn encode_request_with_version(request: &Request, version: u32) -> Vec<u8> {
    let mut out = encode(request);
    out[4..8].copy_from_slice(&version.to_le_bytes());
    out
}

/// How many bytes `result` takes in an encoded response (what the daemon counts against a
/// request's reply budget). Never fails: a value postcard cannot size counts as huge.
pub fn result_size(result: &CommandResult) -> usize {
    postcard::experimental::serialized_size(result).unwrap_or(usize::MAX)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{
        Command, CommandError, ErrorKind, Handle, ObjectProp, PlaneOp, Pose, Reply, Shape,
    };

    fn sample_request() -> Request {
        Request {
            commands: vec![
                Command::plane(
                    1,
                    PlaneOp::AddObject {
                        shape: Shape::Cube {
                            size: [1.0, 2.0, 3.0],
                        },
                        pose: Pose::at([0.0, 5.0, 0.0]),
                        props: vec![ObjectProp::Anchored(true)],
                    },
                ),
                Command::plane(1, PlaneOp::Step { dt: 1.0 / 60.0 }),
            ],
        }
    }

    #[test]
    fn request_round_trips() {
        let r = sample_request();
        assert_eq!(decode_request(&encode_request(&r)).unwrap(), r);
    }

    #[test]
    fn response_round_trips() {
        let r = Response::Results(vec![
            Ok(Reply::Object {
                handle: Handle {
                    slot: 3,
                    generation: 7,
                },
                tick: 9,
            }),
            Err(CommandError::new(ErrorKind::StaleHandle, "gone")),
        ]);
        assert_eq!(decode_response(&encode_response(&r)).unwrap(), r);
    }

    #[test]
    fn short_and_foreign_frames_are_errors() {
        assert_eq!(
            decode_request(&[1, 2]).unwrap_err(),
            DecodeError::TooShort { len: 2 }
        );
        assert!(matches!(
            decode_request(b"NOPE\x01\x00\x00\x00").unwrap_err(),
            DecodeError::BadMagic { .. }
        ));
    }

    #[test]
    fn version_mismatch_names_both_versions() {
        let bytes = encode_request_with_version(&sample_request(), LAYOUT_VERSION + 1);
        let err = decode_request(&bytes).unwrap_err();
        assert!(
            matches!(err, DecodeError::VersionMismatch { theirs, .. } if theirs == LAYOUT_VERSION + 1)
        );
        let mut reply = encode_version_mismatch();
        reply[4..8].copy_from_slice(&(LAYOUT_VERSION + 7).to_le_bytes());
        let msg = decode_response(&reply).unwrap_err().to_string();
        assert!(
            msg.contains(&format!("LAYOUT_VERSION {}", LAYOUT_VERSION + 7)),
            "{msg}"
        );
        assert!(
            msg.contains(&format!("LAYOUT_VERSION {LAYOUT_VERSION}")),
            "{msg}"
        );
    }

    #[test]
    fn every_truncation_of_a_valid_request_fails_cleanly() {
        let bytes = encode_request(&sample_request());
        for n in 0..bytes.len() {
            assert!(
                decode_request(&bytes[..n]).is_err(),
                "prefix of {n} bytes decoded"
            );
        }
    }

    proptest::proptest! {
        #[test]
        fn arbitrary_bodies_never_panic(body in proptest::collection::vec(proptest::num::u8::ANY, 0..512)) {
            let mut bytes = MAGIC.to_vec();
            bytes.extend_from_slice(&LAYOUT_VERSION.to_le_bytes());
            bytes.extend_from_slice(&body);
            let _ = decode_request(&bytes);
            let _ = decode_response(&bytes);
        }
    }

    #[test]
    fn bytes_after_the_value_are_an_error() {
        let mut bytes = encode_request(&sample_request());
        assert!(decode_request(&bytes).is_ok());
        bytes.extend_from_slice(&[0u8; 7]);
        let e = decode_request(&bytes).expect_err("trailing bytes refused");
        assert!(e.to_string().contains("7 bytes follow"), "{e}");
    }
}

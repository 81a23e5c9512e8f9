//! Snapshots in pieces: a snapshot larger than one reply or one request travels as a
//! transfer, a buffer the daemon keeps for the connection that opened it, filled or emptied
//! a bounded piece at a time. So a plane of any size snapshots and restores at the daemon's
//! default `--max-reply-bytes` / `--max-request-bytes`.
//!
//! Down (daemon → client): a [`crate::PlaneOp::Snapshot`] whose bytes pass
//! [`STAGE_ABOVE`] (or what the reply may still hold) replies [`TransferReply::Staged`]; the
//! client reads the pieces in order with [`TransferOp::Get`]. Up (client → daemon): the
//! client opens a transfer with [`TransferOp::Open`], sends the pieces in order with
//! [`TransferOp::Put`] and restores from it with [`crate::PlaneOp::RestoreUploaded`] (a
//! restore or a plane started from a snapshot). The whole snapshot is checked as ever (its
//! own checksum, by the reader); the transfer's bytes count against the connection's
//! process's state-bytes quota while they are held; a transfer belongs to the connection
//! that opened it and goes with it.

use serde::{Deserialize, Serialize};

/// Snapshots up to this size travel whole (one reply, one request); larger ones in pieces.
pub const STAGE_ABOVE: usize = 1 << 20;
/// Most bytes of one piece (the daemon may ask for smaller ones: see
/// [`TransferReply::Opened`]).
pub const PIECE_BYTES: usize = 4 << 20;
/// Transfers one connection may hold open at once.
pub const MAX_OPEN_TRANSFERS: usize = 4;

/// An op on a snapshot transfer of the sending connection.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum TransferOp {
    /// Opens an upload of `total` bytes (reserved against the state-bytes quota at once).
    /// Replies [`TransferReply::Opened`].
    Open {
        /// Bytes the whole snapshot has.
        total: u64,
    },
    /// The piece of an upload at `offset`: pieces go in order (`offset` is what the transfer
    /// has received so far) and `total` repeats what `Open` said. Replies
    /// [`TransferReply::Received`].
    Put {
        /// The transfer, as `Open` named it.
        transfer: u32,
        /// The whole snapshot's bytes, as given to `Open`.
        total: u64,
        /// Where the piece starts.
        offset: u64,
        /// The piece.
        bytes: Vec<u8>,
    },
    /// The piece of a download at `offset` (as big as the reply may hold, at most
    /// [`PIECE_BYTES`]). The transfer closes after its last piece. Replies
    /// [`TransferReply::Piece`].
    Get {
        /// The transfer, as [`TransferReply::Staged`] named it.
        transfer: u32,
        /// Where the piece starts (what was read so far).
        offset: u64,
    },
    /// Drops a transfer (an upload given up, a download not read to the end). Replies
    /// [`crate::Reply::Done`].
    Close {
        /// The transfer.
        transfer: u32,
    },
}

/// The answer to a transfer op (and to a large snapshot).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum TransferReply {
    /// A snapshot too large for one reply waits in the daemon as download `transfer`.
    Staged {
        /// The transfer to read.
        transfer: u32,
        /// Bytes of the whole snapshot.
        len: u64,
        /// [`crate::snapshot::checksum`] of the whole snapshot.
        checksum: u64,
    },
    /// An upload is open.
    Opened {
        /// Its number (for `Put` and `RestoreUploaded`).
        transfer: u32,
        /// Most bytes of one piece the daemon takes (fits its `--max-request-bytes`).
        piece: u64,
    },
    /// A piece of an upload arrived.
    Received {
        /// Bytes received so far.
        received: u64,
    },
    /// A piece of a download.
    Piece {
        /// Where it starts.
        offset: u64,
        /// Its bytes.
        bytes: Vec<u8>,
    },
}

impl TransferOp {
    /// The op's name and transfer, for messages (never the piece's bytes).
    pub fn describe(&self) -> String {
        match self {
            TransferOp::Open { total } => format!("Open (total {total})"),
            TransferOp::Put {
                transfer, offset, ..
            } => format!("Put (transfer {transfer}, offset {offset})"),
            TransferOp::Get { transfer, offset } => {
                format!("Get (transfer {transfer}, offset {offset})")
            }
            TransferOp::Close { transfer } => format!("Close (transfer {transfer})"),
        }
    }
}

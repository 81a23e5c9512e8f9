//! Snapshots in pieces, the daemon's side (`shm_layout::snapshot_transfer`): each connection's
//! open transfers. A download holds a snapshot too large for one reply until the client has
//! read its last piece; an upload collects a snapshot a piece at a time until a
//! `RestoreUploaded` takes it. Each transfer's bytes count against its process's
//! state-bytes quota for as long as they are held; a connection's transfers go when it does
//! (goodbye, death), so a half-sent restore leaks nothing. Pieces are checked against the
//! transfer they name: its owner (another connection's transfer is not found), its
//! direction, its total and the offset it has reached; a forged piece is refused by name and
//! the transfer stays as it was.

use std::sync::atomic::{AtomicU32, Ordering};
use std::sync::{Arc, Mutex};

use shm_layout::snapshot::checksum;
use shm_layout::snapshot_transfer::{MAX_OPEN_TRANSFERS, PIECE_BYTES};
use shm_layout::{CommandError, CommandResult, ErrorKind, Reply, TransferOp, TransferReply};

use crate::server::quotas::limits::Limits;
use crate::server::quotas::quota::{HeldBytes, OwnerUsage};

/// Room a reply or request needs besides a piece's bytes (framing, the result's variant).
const OVERHEAD: usize = 256;

/// Transfer numbers, daemon-wide: a number names one transfer of one connection, never two.
static NEXT_TRANSFER: AtomicU32 = AtomicU32::new(1);

/// One open transfer.
#[derive(Debug)]
struct Transfer {
    id: u32,
    /// Daemon → client (a staged snapshot), or client → daemon.
    down: bool,
    /// A download's whole snapshot; an upload's bytes so far.
    bytes: Vec<u8>,
    /// A download: bytes read so far. An upload: unused (`bytes.len()` is what arrived).
    read: u64,
    /// The whole snapshot's size.
    total: u64,
    /// Its bytes, counted against the process's state quota until the transfer goes.
    _held: HeldBytes,
}

/// The open transfers of one connection.
#[derive(Debug)]
pub struct ClientTransfers {
    owner: Arc<OwnerUsage>,
    limits: Limits,
    open: Mutex<Vec<Transfer>>,
}

fn refused(message: String) -> CommandError {
    CommandError::new(
        ErrorKind::InvalidValue,
        format!("snapshot transfer refused: {message}"),
    )
}

impl ClientTransfers {
    /// No transfer yet; what they hold counts in `owner`'s total against `limits`.
    pub fn new(owner: Arc<OwnerUsage>, limits: Limits) -> ClientTransfers {
        ClientTransfers {
            owner,
            limits,
            open: Mutex::default(),
        }
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, Vec<Transfer>> {
        self.open.lock().unwrap_or_else(|p| p.into_inner())
    }

    /// Bytes held by this connection's transfers.
    #[cfg(test)]
    pub fn held(&self) -> u64 {
        self.lock().iter().map(|t| t.total).sum()
    }

    /// Opens a transfer of `total` bytes (refused past [`MAX_OPEN_TRANSFERS`] or the quota).
    fn add(&self, down: bool, total: u64, bytes: Vec<u8>) -> Result<u32, CommandError> {
        let mut open = self.lock();
        if open.len() >= MAX_OPEN_TRANSFERS {
            return Err(CommandError::new(
                ErrorKind::Quota,
                format!(
                    "quota exceeded: a connection may hold {MAX_OPEN_TRANSFERS} snapshot \
                     transfers open at once (transfers {:?} are open: read or close them)",
                    open.iter().map(|t| t.id).collect::<Vec<_>>()
                ),
            ));
        }
        let held = HeldBytes::reserve(&self.owner, &self.limits, total)?;
        let id = NEXT_TRANSFER.fetch_add(1, Ordering::Relaxed);
        open.push(Transfer {
            id,
            down,
            bytes,
            read: 0,
            total,
            _held: held,
        });
        Ok(id)
    }

    /// A snapshot too large for one reply, kept as a download: the reply that names it.
    pub fn stage(&self, bytes: Vec<u8>) -> CommandResult {
        let (len, sum) = (bytes.len() as u64, checksum(&bytes));
        let transfer = self.add(true, len, bytes)?;
        Ok(Reply::Transfer(TransferReply::Staged {
            transfer,
            len,
            checksum: sum,
        }))
    }

    /// Serves a transfer op. `reply_room`: bytes the request's reply may still hold (a
    /// download piece is at most that, less framing).
    pub fn apply(&self, op: TransferOp, reply_room: usize) -> CommandResult {
        match op {
            TransferOp::Open { total } => {
                if total == 0 {
                    return Err(refused("Open: total 0 (a snapshot has bytes)".into()));
                }
                if usize::try_from(total).is_err() {
                    return Err(refused(format!("Open: total {total} does not fit memory")));
                }
                let transfer = self.add(false, total, Vec::new())?;
                let piece = self
                    .limits
                    .request_bytes
                    .saturating_sub(OVERHEAD)
                    .clamp(1, PIECE_BYTES) as u64;
                Ok(Reply::Transfer(TransferReply::Opened { transfer, piece }))
            }
            TransferOp::Put {
                transfer,
                total,
                offset,
                bytes,
            } => {
                let mut open = self.lock();
                let t = find(&mut open, transfer, false)?;
                let received = t.bytes.len() as u64;
                if total != t.total {
                    return Err(refused(format!(
                        "Put: total {total}, transfer {transfer} was opened with total {}",
                        t.total
                    )));
                }
                if offset != received {
                    return Err(refused(format!(
                        "Put: offset {offset}, transfer {transfer} has received {received} \
                         bytes (pieces go in order)"
                    )));
                }
                let end = received.saturating_add(bytes.len() as u64);
                if end > t.total {
                    return Err(refused(format!(
                        "Put: a piece of {} bytes at offset {offset} passes the total {}",
                        bytes.len(),
                        t.total
                    )));
                }
                if t.bytes.capacity() == 0 {
                    t.bytes.reserve_exact(t.total as usize);
                }
                t.bytes.extend_from_slice(&bytes);
                Ok(Reply::Transfer(TransferReply::Received { received: end }))
            }
            TransferOp::Get { transfer, offset } => {
                let mut open = self.lock();
                let t = find(&mut open, transfer, true)?;
                if offset != t.read {
                    return Err(refused(format!(
                        "Get: offset {offset}, transfer {transfer} has been read to {} \
                         (pieces go in order)",
                        t.read
                    )));
                }
                let room = reply_room.saturating_sub(OVERHEAD).min(PIECE_BYTES);
                if room == 0 {
                    return Err(CommandError::new(
                        ErrorKind::Quota,
                        "quota exceeded: this request's reply has no room left for a snapshot \
                         piece (daemon flag --max-reply-bytes; send Get in a request of its own)",
                    ));
                }
                let start = offset as usize;
                let end = (start + room).min(t.bytes.len());
                let bytes = t.bytes[start..end].to_vec();
                t.read = end as u64;
                if end == t.bytes.len() {
                    open.retain(|t| t.id != transfer);
                }
                Ok(Reply::Transfer(TransferReply::Piece { offset, bytes }))
            }
            TransferOp::Close { transfer } => {
                let mut open = self.lock();
                let before = open.len();
                open.retain(|t| t.id != transfer);
                if open.len() == before {
                    return Err(not_found(&open, transfer));
                }
                Ok(Reply::Done)
            }
        }
    }

    /// Takes the finished upload `transfer` (gone after, finished or not).
    pub fn take_upload(&self, transfer: u32) -> Result<Vec<u8>, CommandError> {
        let mut open = self.lock();
        let t = find(&mut open, transfer, false)?;
        let (received, total) = (t.bytes.len() as u64, t.total);
        let bytes = std::mem::take(&mut t.bytes);
        open.retain(|t| t.id != transfer);
        if received != total {
            return Err(refused(format!(
                "RestoreUploaded: transfer {transfer} holds {received} of its {total} bytes \
                 (dropped)"
            )));
        }
        Ok(bytes)
    }
}

fn not_found(open: &[Transfer], transfer: u32) -> CommandError {
    refused(format!(
        "transfer {transfer} is not open on this connection (transfers belong to the \
         connection that opened them; open here: {:?})",
        open.iter().map(|t| t.id).collect::<Vec<_>>()
    ))
}

/// The open transfer `id` going the `down` way.
fn find(open: &mut [Transfer], id: u32, down: bool) -> Result<&mut Transfer, CommandError> {
    let Some(i) = open.iter().position(|t| t.id == id) else {
        return Err(not_found(open, id));
    };
    let t = &mut open[i];
    if t.down != down {
        let (is, op) = match t.down {
            true => ("a download (read it with Get)", "an upload op"),
            false => ("an upload (fill it with Put)", "Get"),
        };
        return Err(refused(format!("transfer {id} is {is}, not for {op}")));
    }
    Ok(t)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn limits(state_bytes: u64) -> Limits {
        Limits {
            state_bytes_per_client: state_bytes,
            ..Limits::DEFAULT
        }
    }

    fn transfers(state_bytes: u64) -> ClientTransfers {
        ClientTransfers::new(Arc::new(OwnerUsage::default()), limits(state_bytes))
    }

    fn put(t: &ClientTransfers, id: u32, total: u64, offset: u64, bytes: &[u8]) -> CommandResult {
        t.apply(
            TransferOp::Put {
                transfer: id,
                total,
                offset,
                bytes: bytes.to_vec(),
            },
            usize::MAX,
        )
    }

    fn open(t: &ClientTransfers, total: u64) -> u32 {
        match t.apply(TransferOp::Open { total }, usize::MAX) {
            Ok(Reply::Transfer(TransferReply::Opened { transfer, .. })) => transfer,
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn forged_pieces_are_refused_by_name_and_change_nothing() {
        let t = transfers(1 << 20);
        let id = open(&t, 10);
        put(&t, id, 10, 0, &[1, 2, 3, 4]).unwrap();
        let e = |r: CommandResult| r.unwrap_err().message;
        assert!(e(put(&t, id, 10, 0, &[9])).contains("offset 0, transfer"));
        assert!(e(put(&t, id, 11, 4, &[9])).contains("total 11"));
        assert!(e(put(&t, id, 10, 4, &[0; 7])).contains("passes the total 10"));
        assert!(e(put(&t, id + 1000, 10, 4, &[0])).contains("is not open on this connection"));
        // Another connection's transfer is not found on this one.
        let other = transfers(1 << 20);
        assert!(e(put(&other, id, 10, 4, &[5])).contains("not open on this connection"));
        assert!(e(other.take_upload(id).map(|_| Reply::Done)).contains("not open"));
        // A download is not filled, an upload not read.
        assert!(e(t.apply(
            TransferOp::Get {
                transfer: id,
                offset: 0
            },
            usize::MAX
        ))
        .contains("is an upload"));
        put(&t, id, 10, 4, &[5, 6, 7, 8, 9, 10]).unwrap();
        assert_eq!(t.take_upload(id).unwrap(), (1..=10).collect::<Vec<u8>>());
        assert_eq!(t.held(), 0);
    }

    #[test]
    fn held_bytes_count_against_the_quota_and_come_back() {
        let owner = Arc::new(OwnerUsage::default());
        let t = ClientTransfers::new(owner.clone(), limits(100));
        let a = open(&t, 60);
        let e = t.apply(TransferOp::Open { total: 60 }, usize::MAX);
        assert!(e.unwrap_err().message.contains("state bytes per client"));
        // Half sent, then taken: refused, and gone.
        put(&t, a, 60, 0, &[0; 30]).unwrap();
        let e = t.take_upload(a).unwrap_err().message;
        assert!(e.contains("holds 30 of its 60"), "{e}");
        let b = open(&t, 60);
        assert!(b > a);
        assert_eq!(owner.get().state_bytes, 60);
        drop(t); // the connection goes: its transfers and their bytes with it
        assert_eq!(owner.get().state_bytes, 0);
        let t = ClientTransfers::new(owner, limits(100));
        open(&t, 100);
    }

    #[test]
    fn downloads_come_in_bounded_pieces_in_order() {
        let t = transfers(1 << 30);
        let bytes: Vec<u8> = (0..10_000u32).map(|i| i as u8).collect();
        let Reply::Transfer(TransferReply::Staged { transfer, len, .. }) =
            t.stage(bytes.clone()).unwrap()
        else {
            panic!()
        };
        assert_eq!(len, 10_000);
        let mut got = Vec::new();
        while (got.len() as u64) < len {
            let r = t.apply(
                TransferOp::Get {
                    transfer,
                    offset: got.len() as u64,
                },
                OVERHEAD + 3000,
            );
            let Ok(Reply::Transfer(TransferReply::Piece { bytes, .. })) = r else {
                panic!("{r:?}")
            };
            assert!(bytes.len() <= 3000);
            got.extend(bytes);
        }
        assert_eq!(got, bytes);
        // Read to the end: closed.
        assert_eq!(t.held(), 0);
        let e = t.apply(TransferOp::Close { transfer }, usize::MAX);
        assert!(e.unwrap_err().message.contains("not open"));
    }
}

//! Snapshots in pieces, the client's side: [`Client::download`] reads a snapshot the daemon
//! staged because it was too large for one reply, [`Client::upload`] sends one too large for
//! one request, a bounded piece per request (`shm_layout::snapshot_transfer`). Both are
//! used by `Plane::take_snapshot` and `Plane::restore_with`; callers never see them.

use shm_layout::snapshot::checksum;
use shm_layout::{Command, Reply, TransferOp, TransferReply};

use crate::{client::Client, error::Error};

impl Client {
    /// Reads download `transfer` (`len` bytes whose checksum is `sum`) to its end.
    pub(crate) fn download(&self, transfer: u32, len: u64, sum: u64) -> Result<Vec<u8>, Error> {
        let read = || -> Result<Vec<u8>, Error> {
            let mut bytes = Vec::with_capacity(usize::try_from(len).unwrap_or(0));
            while (bytes.len() as u64) < len {
                let offset = bytes.len() as u64;
                match self.call(Command::Transfer(TransferOp::Get { transfer, offset }))? {
                    Reply::Transfer(TransferReply::Piece {
                        offset: at,
                        bytes: piece,
                    }) if at == offset && !piece.is_empty() => bytes.extend_from_slice(&piece),
                    other => {
                        return Err(Error::Protocol(format!(
                            "snapshot transfer {transfer}: unexpected reply {other:?} at offset \
                             {offset}"
                        )))
                    }
                }
            }
            Ok(bytes)
        };
        let bytes = read().inspect_err(|_| self.close_transfer(transfer))?;
        if bytes.len() as u64 != len || checksum(&bytes) != sum {
            return Err(Error::Protocol(format!(
                "snapshot transfer {transfer}: {} bytes with checksum {:016x} arrived, the daemon \
                 sent {len} with {sum:016x}",
                bytes.len(),
                checksum(&bytes)
            )));
        }
        Ok(bytes)
    }

    /// Sends `bytes` as an upload, in pieces as large as the daemon takes; its number.
    pub(crate) fn upload(&self, bytes: &[u8]) -> Result<u32, Error> {
        let total = bytes.len() as u64;
        let (transfer, piece) = match self.call(Command::Transfer(TransferOp::Open { total }))? {
            Reply::Transfer(TransferReply::Opened { transfer, piece }) => (transfer, piece),
            other => return Err(Error::Protocol(format!("unexpected reply {other:?}"))),
        };
        let piece = usize::try_from(piece).unwrap_or(usize::MAX).max(1);
        let send = || -> Result<(), Error> {
            for (i, chunk) in bytes.chunks(piece).enumerate() {
                let offset = (i * piece) as u64;
                let put = TransferOp::Put {
                    transfer,
                    total,
                    offset,
                    bytes: chunk.to_vec(),
                };
                match self.call(Command::Transfer(put))? {
                    Reply::Transfer(TransferReply::Received { .. }) => {}
                    other => return Err(Error::Protocol(format!("unexpected reply {other:?}"))),
                }
            }
            Ok(())
        };
        send().inspect_err(|_| self.close_transfer(transfer))?;
        Ok(transfer)
    }

    /// Drops a transfer given up on (best effort: the daemon drops it with the connection
    /// anyway).
    fn close_transfer(&self, transfer: u32) {
        let _ = self.call(Command::Transfer(TransferOp::Close { transfer }));
    }
}

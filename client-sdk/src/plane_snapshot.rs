//! A plane's whole state as a value ([`PlaneSnapshot`]): taken with
//! [`Plane::take_snapshot`], put back with [`Plane::restore`] (same objects, same handles,
//! the plane continues bit for bit), started as a new plane with
//! [`Client::plane_from_snapshot`], kept as bytes or in a file.
//!
//! The bytes are checked (magic, format, layout version, checksum) when made into a
//! snapshot and again by the daemon, which refuses a snapshot of another engine or kind
//! with an error naming what is wrong. Snapshots larger than one reply or request travel
//! in pieces (`snapshot_transfer`), unseen by the caller.

use std::io::Write as _;
use std::path::Path;
use std::sync::Arc;

use shm_layout::snapshot::{self, SnapshotHeader};
use shm_layout::snapshot_transfer::STAGE_ABOVE;
use shm_layout::{Command, PlaneKind, PlaneOp, PlaneProp, Reply, TransferReply};

use crate::{client::Client, error::Error, plane::Plane};

/// A plane's whole state at one tick. Cheap to clone (the bytes are shared).
#[derive(Clone)]
pub struct PlaneSnapshot {
    header: SnapshotHeader,
    bytes: Arc<[u8]>,
}

impl std::fmt::Debug for PlaneSnapshot {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "PlaneSnapshot({:?} plane, tick {}, {} bytes, hash {:016x})",
            self.header.kind,
            self.header.tick,
            self.bytes.len(),
            self.header.state_hash
        )
    }
}

impl PlaneSnapshot {
    /// A snapshot from bytes (as [`PlaneSnapshot::bytes`] gave them): the framing, format
    /// and checksum are checked here.
    pub fn from_bytes(bytes: Vec<u8>) -> Result<PlaneSnapshot, Error> {
        let (header, _) = snapshot::verify(&bytes)?;
        Ok(PlaneSnapshot {
            header,
            bytes: bytes.into(),
        })
    }

    /// The snapshot's bytes (header and state).
    pub fn bytes(&self) -> &[u8] {
        &self.bytes
    }

    /// The tick the plane had stepped when the snapshot was taken.
    pub fn tick(&self) -> u64 {
        self.header.tick
    }

    /// That tick's state hash (the tick header's `state_hash`).
    pub fn state_hash(&self) -> u64 {
        self.header.state_hash
    }

    /// The kind of plane it holds.
    pub fn kind(&self) -> PlaneKind {
        self.header.kind
    }

    /// Its size in bytes.
    pub fn len(&self) -> usize {
        self.bytes.len()
    }

    /// Never true (a snapshot has at least its header); for clippy's `len` convention.
    pub fn is_empty(&self) -> bool {
        self.bytes.is_empty()
    }

    /// Writes the snapshot to `path` atomically: a temporary file beside it, flushed to
    /// disk, then renamed over `path` (a crash leaves the old file or the new, never half).
    pub fn save(&self, path: impl AsRef<Path>) -> std::io::Result<()> {
        let path = path.as_ref();
        let name = path
            .file_name()
            .ok_or_else(|| std::io::Error::other(format!("{} names no file", path.display())))?;
        let mut tmp_name = std::ffi::OsString::from(".");
        tmp_name.push(name);
        tmp_name.push(format!(".{}.tmp", std::process::id()));
        let tmp = path.with_file_name(tmp_name);
        let written = (|| {
            let mut f = std::fs::File::create(&tmp)?;
            f.write_all(&self.bytes)?;
            f.sync_all()?;
            std::fs::rename(&tmp, path)
        })();
        if written.is_err() {
            let _ = std::fs::remove_file(&tmp);
        }
        written
    }

    /// Reads a snapshot [`PlaneSnapshot::save`] wrote (checked as by
    /// [`PlaneSnapshot::from_bytes`]).
    pub fn load(path: impl AsRef<Path>) -> Result<PlaneSnapshot, Error> {
        let path = path.as_ref();
        let bytes = std::fs::read(path).map_err(|e| Error::Invalid {
            field: "path".into(),
            message: format!("cannot read snapshot {}: {e}", path.display()),
        })?;
        PlaneSnapshot::from_bytes(bytes)
    }
}

impl Plane {
    /// The plane's whole state now (after the queued writes), as a value.
    pub fn take_snapshot(&self) -> Result<PlaneSnapshot, Error> {
        match self
            .client()
            .call(Command::plane(self.id(), PlaneOp::Snapshot))?
        {
            Reply::Snapshot(bytes) => PlaneSnapshot::from_bytes(bytes),
            Reply::Transfer(TransferReply::Staged {
                transfer,
                len,
                checksum,
            }) => PlaneSnapshot::from_bytes(self.client().download(transfer, len, checksum)?),
            other => Err(Error::Protocol(format!("unexpected reply {other:?}"))),
        }
    }

    /// The plane becomes exactly `snapshot`'s state: the same objects under the same
    /// handles (handles this process holds read the restored poses), the same tick. Writes
    /// this process made that are not in the snapshot are forgotten. Returns the tick.
    pub fn restore(&self, snapshot: &PlaneSnapshot) -> Result<u64, Error> {
        self.restore_with(snapshot, &[])
    }

    /// [`Plane::restore`], then `overrides` applied as at the plane's creation (Threads,
    /// TickRate, Enabled, Gravity...; not DeferGpu).
    pub fn restore_with(
        &self,
        snapshot: &PlaneSnapshot,
        overrides: &[PlaneProp],
    ) -> Result<u64, Error> {
        let overrides = overrides
            .iter()
            .map(|p| p.checked())
            .collect::<Result<Vec<_>, _>>()
            .map_err(Error::invalid_value)?;
        let op = if snapshot.bytes.len() > STAGE_ABOVE {
            PlaneOp::RestoreUploaded {
                transfer: self.client().upload(&snapshot.bytes)?,
                overrides,
            }
        } else {
            PlaneOp::Restore {
                bytes: snapshot.bytes.to_vec(),
                overrides,
            }
        };
        let reply = self.client().call(Command::plane(self.id(), op));
        self.forget_local_state();
        match reply? {
            Reply::Applied { tick } => Ok(tick),
            other => Err(Error::Protocol(format!("unexpected reply {other:?}"))),
        }
    }
}

impl Plane {
    /// Goes back `ticks` ticks (at most the plane's `RollbackTicks`): the plane becomes its
    /// state after that tick, handles included; re-apply the corrected inputs and step
    /// again. Returns the tick gone back to.
    pub fn rewind(&self, ticks: u32) -> Result<u64, Error> {
        let reply = self
            .client()
            .call(Command::plane(self.id(), PlaneOp::Rewind(ticks)));
        self.forget_local_state();
        match reply? {
            Reply::Applied { tick } => Ok(tick),
            other => Err(Error::Protocol(format!("unexpected reply {other:?}"))),
        }
    }
}

impl Client {
    /// A new plane holding `snapshot`'s state (of its kind: wrap a GUI plane with
    /// [`crate::GuiPlane::from_plane`]), then `overrides` applied (TickRate, Enabled,
    /// Threads, ...). It does not tick before it holds the state.
    pub fn plane_from_snapshot(
        &self,
        snapshot: &PlaneSnapshot,
        overrides: &[PlaneProp],
    ) -> Result<Plane, Error> {
        // A name and persistence belong to the new plane, not to its state: they go with
        // the creation (where names are checked for uniqueness).
        let (naming, overrides): (Vec<PlaneProp>, Vec<PlaneProp>) = overrides
            .iter()
            .partition(|p| matches!(p, PlaneProp::Name(_) | PlaneProp::Persistent(_)));
        let mut props = vec![PlaneProp::Enabled(false)];
        props.extend(naming);
        let info = match self.call(Command::CreatePlane {
            kind: snapshot.kind(),
            props,
        })? {
            Reply::Plane(info) => info,
            other => return Err(Error::Protocol(format!("unexpected reply {other:?}"))),
        };
        self.note_owned(info.id);
        let plane = self.attach_plane(info.id)?;
        if let Err(e) = plane.restore_with(snapshot, &overrides) {
            let _ = plane.destroy();
            return Err(e);
        }
        Ok(plane)
    }
}

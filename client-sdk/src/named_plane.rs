//! Named planes: [`Client::list_planes`] (the named planes of the domain, any client's) and
//! [`Client::open_plane`] (attach to one by name, live or restored from the daemon's state
//! directory), and [`Plane::save`] (write a persistent plane's file now).
//!
//! Who may write: opening an orphaned plane (a persistent plane whose owner left, or one the
//! daemon restored at start) makes this client its owner; a plane whose owner is connected
//! opens as a non-owner handle (read-only unless the plane is `Shared`).

use shm_layout::{Command, NamedPlane, PlaneName, PlaneOp, Reply};

use crate::{client::Client, error::Error, plane::Plane};

/// A named plane just opened.
pub struct OpenedPlane {
    /// The plane.
    pub plane: Plane,
    /// This client owns it (it was orphaned, or this client created it).
    pub owner: bool,
    /// `Some(lost_ticks)` when the plane came back from its file and this is the first
    /// open since: the last tick the old daemon recorded for it minus the tick of the
    /// snapshot it resumed from (0 when the snapshot was the newest state).
    pub recovered: Option<u64>,
}

impl std::fmt::Debug for OpenedPlane {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("OpenedPlane")
            .field("plane", &self.plane.id())
            .field("owner", &self.owner)
            .field("recovered", &self.recovered)
            .finish()
    }
}

impl Client {
    /// The named planes of the domain (name, id, kind, persistent, tick, orphaned), by name.
    pub fn list_planes(&self) -> Result<Vec<NamedPlane>, Error> {
        match self.call(Command::ListNamedPlanes)? {
            Reply::NamedPlanes(list) => Ok(list),
            other => Err(Error::Protocol(format!("unexpected reply {other:?}"))),
        }
    }

    /// Attaches to the plane named `name` (see [`Client::open_named`]).
    pub fn open_plane(&self, name: &str) -> Result<Plane, Error> {
        self.open_named(name).map(|o| o.plane)
    }

    /// Attaches to the plane named `name`, and says whether this client owns it now and
    /// whether it came back from a file ([`OpenedPlane::recovered`]). An unknown name is an
    /// error naming it.
    pub fn open_named(&self, name: &str) -> Result<OpenedPlane, Error> {
        PlaneName::new(name).map_err(Error::invalid_value)?;
        let opened = match self.call(Command::OpenPlane {
            name: name.to_string(),
        })? {
            Reply::Opened(o) => o,
            other => return Err(Error::Protocol(format!("unexpected reply {other:?}"))),
        };
        let plane = self.attach_plane(opened.id)?;
        if opened.owner {
            self.note_owned(opened.id);
        }
        Ok(OpenedPlane {
            plane,
            owner: opened.owner,
            recovered: opened.recovered,
        })
    }
}

impl Plane {
    /// Writes this persistent plane to its file in the daemon's state directory now (after
    /// the queued writes); returns once the file is on disk, with the tick it holds. A plane
    /// that is not persistent is an error naming `Persistent`.
    pub fn save(&self) -> Result<u64, Error> {
        match self
            .client()
            .call(Command::plane(self.id(), PlaneOp::Save))?
        {
            Reply::Saved { tick } => Ok(tick),
            other => Err(Error::Protocol(format!("unexpected reply {other:?}"))),
        }
    }

    /// The plane's `Name` (`None`: unnamed).
    pub fn name(&self) -> Result<Option<String>, Error> {
        let info = self.properties()?;
        Ok((!info.settings.name.is_none()).then(|| info.settings.name.as_str().to_string()))
    }
}

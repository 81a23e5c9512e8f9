//! Named planes: names unique within the domain (`New{ Name = "arena-1" }`), `ListPlanes`
//! (the named planes a client may open) and `Open(name)`, and the lifecycle of persistent
//! planes in the request loop: kept (orphaned) when their owner leaves, restored orphaned at
//! start from the state directory, adopted by the first client that opens them.
//!
//! Who may do what with a named plane: any client may list and open any named plane (all
//! clients of a domain run as the same user: the shared memory is theirs alone). Opening an
//! orphaned plane makes the opener its owner (it may write, restore, destroy it); opening a
//! plane whose owner is connected gives a non-owner handle, read-only unless the plane is
//! `Shared`.

use std::sync::atomic::Ordering;
use std::sync::{mpsc, Arc};

use shm_layout::{
    CommandError, CommandResult, ErrorKind, NamedPlane, OpenedPlane, PlaneId, PlaneName, PlaneProp,
    Reply,
};

use super::persist;
use crate::server::daemon::{Daemon, PlaneEntry, Routed};
use crate::server::persistence::persist::Loaded;
use crate::server::quotas::limits::exceeded;
use crate::server::requests::refusals::unknown_plane;
use crate::server::worker::{self, Job, PlaneCell, SharedUsage};

/// The owner of an orphaned plane: no client (iceoryx2 node ids are random 128-bit values).
pub(crate) const ORPHAN: u128 = 0;

/// The name and persistence a creation asks for.
pub(crate) struct Naming {
    pub name: Option<PlaneName>,
    pub persistent: bool,
}

impl Daemon {
    /// Checks a creation's `Name` and `Persistent`: a valid name not taken in the domain; a
    /// persistent plane needs a name and a daemon with a state directory.
    pub(crate) fn naming(&self, props: &[PlaneProp]) -> Result<Naming, CommandError> {
        let mut naming = Naming {
            name: None,
            persistent: false,
        };
        for prop in props {
            match prop {
                PlaneProp::Name(n) => {
                    let checked = PlaneProp::Name(*n).checked()?;
                    if let PlaneProp::Name(n) = checked {
                        naming.name = (!n.is_none()).then_some(n);
                    }
                }
                PlaneProp::Persistent(p) => naming.persistent = *p,
                _ => {}
            }
        }
        if let Some(name) = naming.name {
            if let Some((id, _)) = self.named(name.as_str()) {
                return Err(CommandError::invalid_field(
                    "Name",
                    format!(
                        "the name {:?} is taken: plane {id} of this domain has it (names are \
                         unique per domain; open it with Open({:?}))",
                        name.as_str(),
                        name.as_str()
                    ),
                ));
            }
        }
        if naming.persistent {
            if naming.name.is_none() {
                return Err(CommandError::invalid_field(
                    "Persistent",
                    "Persistent = true needs a Name (the plane's file and Open use it)",
                ));
            }
            if self.writer.is_none() {
                return Err(CommandError::invalid_field(
                    "Persistent",
                    "Persistent = true needs a daemon started with --state-dir DIR (this \
                     daemon has no state directory)",
                ));
            }
        }
        Ok(naming)
    }

    /// The plane named `name`, if any.
    pub(crate) fn named(&self, name: &str) -> Option<(PlaneId, &PlaneEntry)> {
        self.planes
            .iter()
            .find(|(_, e)| e.name.as_ref().is_some_and(|n| n.as_str() == name))
            .map(|(id, e)| (*id, e))
    }

    /// `ListPlanes`: every named plane, by name.
    pub(crate) fn named_planes(&self) -> Vec<NamedPlane> {
        let mut list: Vec<NamedPlane> = self
            .planes
            .iter()
            .filter_map(|(id, e)| {
                Some(NamedPlane {
                    name: e.name?.as_str().to_string(),
                    id: *id,
                    kind: e.kind,
                    persistent: e.persistent,
                    tick: e.cell.marks.tick.load(Ordering::SeqCst),
                    orphaned: e.owner == ORPHAN,
                })
            })
            .collect();
        list.sort_by(|a, b| a.name.cmp(&b.name));
        list
    }

    /// `Open(name)`: the plane's id; an orphaned plane becomes `client`'s (and a restored
    /// one starts ticking again, telling its new owner what it lost).
    pub(crate) fn open_plane(&mut self, client: u128, name: &str) -> CommandResult {
        // A forged name (any length, any bytes) is refused naming at most 64 characters.
        shm_layout::plane_name::check_text(name)?;
        let Some((id, entry)) = self.named(name) else {
            let known: Vec<String> = self.named_planes().into_iter().map(|p| p.name).collect();
            return Err(CommandError::new(
                ErrorKind::UnknownPlane,
                format!(
                    "no plane is named {name:?} in this domain (named planes: {})",
                    match known.is_empty() {
                        true => "none".to_string(),
                        false => known.join(", "),
                    }
                ),
            ));
        };
        let (kind, owner) = (entry.kind, entry.owner);
        if owner == client {
            return Ok(Reply::Opened(OpenedPlane {
                id,
                kind,
                owner: true,
                recovered: None,
            }));
        }
        if owner != ORPHAN {
            return Ok(Reply::Opened(OpenedPlane {
                id,
                kind,
                owner: false,
                recovered: None,
            }));
        }
        let owned = self.clients.planes_of_process(client).count();
        let max = self.options.limits.planes_per_client;
        if owned >= max {
            return Err(exceeded(
                "planes per client",
                max,
                "max-planes-per-client",
                owned + 1,
            ));
        }
        let Some(entry) = self.planes.get_mut(&id) else {
            return Err(unknown_plane(id));
        };
        entry.owner = client;
        let recovered = entry.recovered.take();
        if entry.cell.marks.held.swap(false, Ordering::SeqCst) {
            let _ = entry.jobs.send(Job::Reschedule);
        }
        if let Some(c) = self.clients.get_mut(client) {
            c.planes.push(id);
        }
        tracing::info!(
            plane = id,
            name,
            client = format!("{client:032x}"),
            ?recovered,
            "orphaned plane opened: the opener owns it"
        );
        Ok(Reply::Opened(OpenedPlane {
            id,
            kind,
            owner: true,
            recovered,
        }))
    }

    /// The client `client` leaves: its persistent planes stay, orphaned (they keep ticking
    /// at their TickRate); returns the planes to remove.
    pub(crate) fn orphan_persistent(&mut self, owned: Vec<PlaneId>) -> Vec<PlaneId> {
        owned
            .into_iter()
            .filter(|id| match self.planes.get_mut(id) {
                Some(e) if e.persistent => {
                    e.owner = ORPHAN;
                    tracing::info!(plane = id, "persistent plane orphaned: its owner left");
                    false
                }
                _ => true,
            })
            .collect()
    }

    /// `Save` on plane `id`: handed to its worker (after the runs queued before it).
    pub(crate) fn save_plane(&mut self, id: PlaneId) -> Routed {
        let Some(entry) = self.planes.get(&id) else {
            return Routed::Now(vec![Err(unknown_plane(id))]);
        };
        let ticket = self.next_ticket;
        self.next_ticket += 1;
        entry.cell.handed_over();
        match entry.jobs.send(Job::Save { ticket }) {
            Ok(()) => Routed::Wait(ticket),
            Err(_) => Routed::Now(vec![Err(unknown_plane(id))]),
        }
    }

    /// Restores the persistent planes of the state directory, orphaned and held until
    /// opened; waits until each is restored or failed (a client that opens one at once
    /// finds it ready).
    pub(crate) fn restore_saved(&mut self) {
        let Some(dir) = self.writer.as_ref().map(|w| w.dir().to_path_buf()) else {
            return;
        };
        self.restore_loaded(persist::load(&dir));
    }

    /// Takes the planes a cluster peer handed over (`Options::adopt`, failover): each is
    /// restored like a file of the state directory, orphaned until opened. One whose name
    /// is in use here, or that arrives on a daemon without `--state-dir`, is refused with
    /// an error in the log.
    pub(crate) fn adopt_planes(&mut self) {
        let Some(adopt) = self.options.adopt.clone() else {
            return;
        };
        let planes = adopt.take();
        if planes.is_empty() {
            return;
        }
        let mut kept = Vec::new();
        for loaded in planes {
            if self.writer.is_none() {
                tracing::error!(plane = %loaded.name, "cannot adopt a plane without --state-dir");
            } else if self.planes.values().any(|p| p.name == Some(loaded.name)) {
                tracing::error!(plane = %loaded.name, "cannot adopt a plane: the name is in use here");
            } else {
                kept.push(loaded);
            }
        }
        self.restore_loaded(kept);
    }

    pub(crate) fn restore_loaded(&mut self, planes: Vec<Loaded>) {
        let mut waiting = Vec::new();
        for loaded in planes {
            let name = loaded.name;
            match self.spawn_restored(loaded) {
                Ok(ticket) => waiting.push((ticket, name)),
                Err(e) => tracing::error!(plane = %name, "cannot restore: {e}"),
            }
        }
        let deadline = std::time::Instant::now() + std::time::Duration::from_secs(120);
        while !waiting.is_empty() {
            let left = deadline.saturating_duration_since(std::time::Instant::now());
            let event = match self.events.recv_timeout(left) {
                Ok(e) => e,
                Err(_) => break,
            };
            match event {
                worker::Event::Done {
                    ticket,
                    plane,
                    results,
                    failed,
                } => {
                    if let (Some(Ok(Reply::Plane(info))), Some(e)) =
                        (results.first(), self.planes.get_mut(&plane))
                    {
                        // Shared is the snapshot's.
                        e.shared = info.settings.shared;
                    }
                    waiting.retain(|(t, name)| {
                        if *t != ticket {
                            return true;
                        }
                        if let Some(Err(e)) = results.first() {
                            tracing::error!(
                                plane = %name,
                                "persistent plane skipped: its state does not restore: {e}"
                            );
                        }
                        false
                    });
                    if failed {
                        self.remove_plane(plane);
                    }
                }
                worker::Event::Failed { plane } => self.remove_plane(plane),
            }
        }
    }

    pub(crate) fn spawn_restored(&mut self, loaded: Loaded) -> Result<u64, CommandError> {
        let id = self.next_plane_id;
        let ticket = self.next_ticket;
        let usage = Arc::new(SharedUsage::admit(self.owners.of(0))?);
        let cell = Arc::new(PlaneCell::default());
        cell.marks.held.store(true, Ordering::SeqCst);
        let writer = self.writer.as_ref().expect("restore_saved checked it");
        let (jobs, receiver) = mpsc::channel();
        let props = vec![PlaneProp::Name(loaded.name), PlaneProp::Persistent(true)];
        let setup = worker::Setup {
            file: writer.plane_file(id, loaded.name.as_str(), &cell.marks, Some(loaded.tick)),
            restore: Some(loaded.bytes),
            ..self.worker_setup(id, loaded.kind, props, &cell, &usage)
        };
        self.start_worker(setup, receiver)
            .map_err(|e| CommandError::new(ErrorKind::Internal, e))?;
        self.planes.insert(
            id,
            PlaneEntry {
                owner: ORPHAN,
                shared: false,
                jobs,
                cell,
                usage,
                kind: loaded.kind,
                name: Some(loaded.name),
                persistent: true,
                recovered: Some(loaded.lost_ticks),
            },
        );
        tracing::info!(
            plane = id,
            name = %loaded.name,
            tick = loaded.tick,
            lost_ticks = loaded.lost_ticks,
            "persistent plane restored, waiting for Open"
        );
        Ok(ticket)
    }
}

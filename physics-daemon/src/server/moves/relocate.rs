//! Migration in the request loop (`plane:MoveTo("DAEMON")`, docs/cluster.md "Migration"):
//! the owner daemon stops a 3D plane between two ticks, snapshots it and hands it to the
//! target through the [`Migration`] hook, which the cluster side fills with Zenoh (the loop
//! never names it); the target restores it under a new id with the same tick, objects and
//! handles, owned by whoever brings the claim key. The old id keeps a tombstone here: every
//! later command for it is refused, not applied, with [`shm_layout::migrate::Moved`], so
//! clients switch over and send it again to the new daemon.
//!
//! The loop waits for the target's answer (the pause of the move, a few milliseconds on
//! one host): nothing of the plane can change in between, and a refused move leaves the
//! plane where it was, untouched.

use std::sync::{mpsc, Arc};
use std::time::{Duration, Instant};

use shm_layout::migrate::{MoveAnswer, Moved, MovingPlane};
use shm_layout::{CommandError, CommandResult, ErrorKind, PlaneId, PlaneKind, PlaneProp, Reply};

use crate::server::daemon::{Daemon, PlaneEntry, MAX_PLANES};
use crate::server::moves::migration::{RESTORE_WAIT, SETTLE};
use crate::server::requests::refusals::unknown_plane;
use crate::server::worker::{self, PlaneCell, SharedUsage};

/// How long a move waits for the plane's queued runs to be applied.
const IDLE_WAIT: Duration = Duration::from_secs(5);
/// 128 random bits (a claim key).
fn random_key() -> u128 {
    use std::io::Read;
    let mut bytes = [0u8; 16];
    let read = std::fs::File::open("/dev/urandom").and_then(|mut f| f.read_exact(&mut bytes));
    if read.is_err() {
        // Not secret then, but still unique: time and process.
        let nanos = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| d.as_nanos());
        return nanos ^ (u128::from(std::process::id()) << 96) | 1;
    }
    // Never the orphan's owner (0).
    u128::from_le_bytes(bytes) | 1
}

fn move_error(message: String) -> CommandError {
    CommandError::invalid_field("MoveTo", message)
}

impl Daemon {
    /// The refusal of `client`'s command for plane `id` when it moved away.
    pub(crate) fn moved_refusal(&self, client: u128, id: PlaneId) -> Option<CommandError> {
        if self.planes.contains_key(&id) {
            return None;
        }
        self.moved.refusal(id, client)
    }

    /// `Pin` of plane `id` (its owner asked): `--rebalance` leaves it here.
    pub(crate) fn pin_plane(&mut self, id: PlaneId) -> CommandResult {
        self.plane(id)?;
        self.moved.pinned.insert(id);
        Ok(Reply::Done)
    }

    /// Serves `--rebalance`'s requests: the largest 3D plane that is not pinned and did not
    /// arrive within [`SETTLE`] moves to the target, through the path of `MoveTo`.
    pub(crate) fn take_rebalance(&mut self) {
        let Some(migration) = self.options.migrate.clone() else {
            return;
        };
        let requests = std::mem::take(
            &mut *migration
                .rebalance
                .lock()
                .unwrap_or_else(|p| p.into_inner()),
        );
        for request in requests {
            let now = Instant::now();
            let candidate = self
                .planes
                .iter()
                .filter(|(id, e)| {
                    e.kind == PlaneKind::Rapier3d
                        && !self.moved.pinned.contains(id)
                        && self
                            .moved
                            .arrived
                            .get(id)
                            .is_none_or(|t| now.duration_since(*t) >= SETTLE)
                })
                .max_by_key(|(id, e)| (e.usage.objects(), std::cmp::Reverse(**id)))
                .map(|(id, _)| *id);
            let Some(id) = candidate else {
                tracing::info!("rebalance: no plane may move (pinned, or arrived lately)");
                continue;
            };
            match self.move_plane(id, &request.target) {
                Ok(_) => tracing::info!(plane = id, to = request.target, "rebalanced"),
                Err(e) => tracing::warn!(plane = id, to = request.target, "rebalance: {e}"),
            }
        }
    }

    /// `MoveTo(daemon)` of plane `id` (its owner asked: `check_access`).
    pub(crate) fn move_plane(&mut self, id: PlaneId, daemon: &str) -> CommandResult {
        let Some(migration) = self.options.migrate.clone() else {
            return Err(move_error(format!(
                "MoveTo({daemon:?}) needs a daemon in a cluster: this daemon runs without \
                 --cluster"
            )));
        };
        shm_layout::cluster::check_name("daemon", daemon)
            .map_err(|e| move_error(format!("MoveTo: {e}")))?;
        let entry = self.plane(id)?;
        if entry.kind != PlaneKind::Rapier3d {
            return Err(move_error(format!(
                "plane {id} is a {} plane (NewGUI), which cannot move: only 3D planes move",
                entry.kind.words()
            )));
        }
        if daemon == migration.me {
            return Ok(Reply::Moved {
                daemon: daemon.to_string(),
                plane: id,
                key: 0,
                cluster: migration.cluster.clone(),
                endpoint: migration.endpoint.clone(),
                tick: entry
                    .cell
                    .marks
                    .tick
                    .load(std::sync::atomic::Ordering::SeqCst),
            });
        }
        migration
            .courier
            .check_target(daemon)
            .map_err(|e| move_error(format!("MoveTo({daemon:?}): {e}")))?;
        let (cell, name, persistent, owner) = (
            entry.cell.clone(),
            entry.name,
            entry.persistent,
            entry.owner,
        );
        let started = Instant::now();
        let Some(mut guard) = cell.lock_idle(IDLE_WAIT) else {
            return Err(CommandError::new(
                ErrorKind::Internal,
                format!("plane {id} is still busy after {IDLE_WAIT:?}: not moved"),
            ));
        };
        let Some(plane) = guard.as_mut() else {
            return Err(unknown_plane(id));
        };
        let tick = plane.tick();
        let recording = plane.recording();
        let bytes = match plane.apply(shm_layout::PlaneOp::Snapshot)? {
            Reply::Snapshot(bytes) => bytes,
            other => {
                return Err(CommandError::new(
                    ErrorKind::Internal,
                    format!("plane {id}: a snapshot answered {other:?}"),
                ))
            }
        };
        let key = random_key();
        let moving = MovingPlane {
            from: migration.me.clone(),
            from_id: id,
            kind: PlaneKind::Rapier3d,
            name,
            persistent,
            claim: key,
            bytes,
            recording,
        };
        let size = moving.bytes.len();
        let new_id = migration.courier.deliver(daemon, &moving).map_err(|e| {
            CommandError::new(
                ErrorKind::Internal,
                format!("plane {id} could not move to {daemon:?} (it stays here): {e}"),
            )
        })?;
        // Gone from here between two ticks: the worker finds no plane and ends.
        if let Some(plane) = guard.as_mut() {
            plane.leaving(&format!(
                "the plane moved to daemon {daemon:?} (plane {new_id} there)"
            ));
        }
        *guard = None;
        drop(guard);
        self.forget_file(id);
        self.remove_plane(id);
        self.moved.insert(
            Moved {
                from_id: id,
                daemon: daemon.to_string(),
                plane: new_id,
                cluster: migration.cluster.clone(),
                endpoint: migration.endpoint.clone(),
                key,
            },
            owner,
        );
        tracing::info!(
            plane = id,
            to = daemon,
            new_id,
            tick,
            snapshot_bytes = size,
            took_ms = started.elapsed().as_secs_f64() * 1e3,
            "plane moved"
        );
        Ok(Reply::Moved {
            daemon: daemon.to_string(),
            plane: new_id,
            key,
            cluster: migration.cluster.clone(),
            endpoint: migration.endpoint.clone(),
            tick,
        })
    }

    /// `ClaimMoved(key)`: the plane that arrived with this key becomes `client`'s.
    pub(crate) fn claim_moved(&mut self, client: u128, id: PlaneId, key: u128) -> CommandResult {
        let refusal = self.moved.refusal(id, client);
        let entry = self
            .planes
            .get_mut(&id)
            .ok_or_else(|| refusal.unwrap_or_else(|| unknown_plane(id)))?;
        if entry.owner == client {
            return Ok(Reply::Done);
        }
        if key == 0 || entry.owner != key {
            return Err(CommandError::new(
                ErrorKind::NotOwner,
                format!("plane {id}: the claim key does not match (only its owner claims it)"),
            ));
        }
        entry.owner = client;
        if let Some(c) = self.clients.get_mut(client) {
            c.planes.push(id);
        }
        tracing::info!(
            plane = id,
            client = format!("{client:032x}"),
            "moved plane claimed"
        );
        Ok(Reply::Done)
    }

    /// Restores the planes that arrived from other daemons and answers each.
    pub(crate) fn take_arrivals(&mut self) {
        let Some(migration) = self.options.migrate.clone() else {
            return;
        };
        for arrival in migration.take() {
            let late = arrival.queued.elapsed();
            if late > RESTORE_WAIT / 2 {
                let _ = arrival.answer.send(Err(format!(
                    "the target's loop reached the plane {late:?} after it arrived: refused"
                )));
                continue;
            }
            let answer = self.arrive_plane(arrival.plane);
            let _ = arrival.answer.send(answer);
        }
    }

    pub(crate) fn arrive_plane(&mut self, moving: MovingPlane) -> MoveAnswer {
        if moving.kind != PlaneKind::Rapier3d {
            return Err(format!("a {} plane cannot move", moving.kind.words()));
        }
        if self.planes.len() >= MAX_PLANES {
            return Err(format!("the daemon already hosts {MAX_PLANES} planes"));
        }
        if let Some(name) = moving.name {
            if self.planes.values().any(|p| p.name == Some(name)) {
                return Err(format!("the name {:?} is in use there", name.as_str()));
            }
        }
        let id = self.next_plane_id;
        let ticket = self.next_ticket;
        let usage = Arc::new(SharedUsage::admit(self.owners.of(0)).map_err(|e| e.message)?);
        let cell = Arc::new(PlaneCell::default());
        let (jobs, receiver) = mpsc::channel();
        let persistent = moving.persistent && self.writer.is_some();
        let mut props = Vec::new();
        if let Some(name) = moving.name {
            props.push(PlaneProp::Name(name));
        }
        if persistent {
            props.push(PlaneProp::Persistent(true));
        }
        let file = match (&self.writer, moving.name, persistent) {
            (Some(w), Some(name), true) => w.plane_file(id, name.as_str(), &cell.marks, None),
            _ => None,
        };
        let setup = worker::Setup {
            file,
            restore: Some(moving.bytes),
            arrived_recording: moving.recording,
            ..self.worker_setup(id, moving.kind, props, &cell, &usage)
        };
        self.start_worker(setup, receiver)?;
        self.planes.insert(
            id,
            PlaneEntry {
                owner: moving.claim,
                shared: false,
                jobs,
                cell,
                usage,
                kind: moving.kind,
                name: moving.name,
                persistent,
                recovered: None,
            },
        );
        // The restore's answer; other events wait their turn behind it.
        let deadline = Instant::now() + RESTORE_WAIT;
        let mut others = Vec::new();
        let result = loop {
            let left = deadline.saturating_duration_since(Instant::now());
            match self.events.recv_timeout(left) {
                Ok(worker::Event::Done {
                    ticket: t,
                    results,
                    failed,
                    ..
                }) if t == ticket => break Some((results, failed)),
                Ok(event) => others.push(event),
                Err(_) => break None,
            }
        };
        for event in others {
            let _ = self.events_tx.send(event);
        }
        self.waker.wake();
        match result {
            Some((results, false)) => match results.into_iter().next() {
                Some(Ok(Reply::Plane(info))) => {
                    if let Some(e) = self.planes.get_mut(&id) {
                        e.shared = info.settings.shared;
                    }
                    self.moved.arrived.insert(id, Instant::now());
                    tracing::info!(
                        plane = id,
                        from = moving.from,
                        from_id = moving.from_id,
                        tick = info.tick,
                        "plane arrived"
                    );
                    Ok(id)
                }
                Some(Err(e)) => {
                    self.remove_plane(id);
                    Err(format!(
                        "its snapshot does not restore there: {}",
                        e.message
                    ))
                }
                other => {
                    self.remove_plane(id);
                    Err(format!("unexpected answer of the restore: {other:?}"))
                }
            },
            Some((results, true)) => {
                self.remove_plane(id);
                Err(format!("its restore failed there: {results:?}"))
            }
            None => {
                self.remove_plane(id);
                Err(format!("not restored within {RESTORE_WAIT:?}"))
            }
        }
    }
}

//! Requests: decoding, and routing each command by plane id to the plane's worker. Only the
//! lifecycle ops (create, destroy) are handled here; every other op goes to the plane's
//! worker unread (a run of consecutive commands for one plane as one job), so a new op
//! family never changes this file.

use std::collections::VecDeque;
use std::sync::{mpsc, Arc};

use shm_layout::codec::{self, Frame};
use shm_layout::{
    Command, CommandError, CommandResult, ErrorKind, PlaneId, PlaneKind, PlaneOp, PlaneProp, Reply,
    Response, CRATE_VERSION, LAYOUT_VERSION,
};

use super::clients;
use super::request_bytes;
use crate::server::daemon::{Daemon, PlaneEntry, Request, Routed, MAX_PLANES};
use crate::server::persistence::transfers;
use crate::server::quotas::limits::exceeded;
use crate::server::quotas::quota;
use crate::server::requests::origin::Origin;
use crate::server::requests::refusals::unknown_plane;
use crate::server::worker::{self, Budget, PlaneCell, SharedUsage};

impl Daemon {
    /// Copies a request's bytes out of the sender's memory (see `request_bytes`), or the
    /// reply that rejects it: over `--max-request-bytes` (checked before anything is read),
    /// or a length past the sender's readable memory.
    pub(crate) fn take_bytes(&self, request: &Request) -> Result<Vec<u8>, Vec<u8>> {
        let payload = request.payload();
        let limit = self.options.limits.request_bytes;
        if payload.len() > limit {
            return Err(codec::encode_response(&Response::Rejected(exceeded(
                "request bytes",
                limit,
                "max-request-bytes",
                payload.len(),
            ))));
        }
        request_bytes::copy(payload.as_ptr(), payload.len()).map_err(|e| {
            codec::encode_response(&Response::Rejected(CommandError::new(
                ErrorKind::Malformed,
                e.to_string(),
            )))
        })
    }

    /// Decodes one request into its commands, or the reply that rejects it. Never panics on
    /// any input.
    pub(crate) fn decode(&self, bytes: &[u8]) -> Result<Vec<Command>, Vec<u8>> {
        let limits = &self.options.limits;
        if bytes.len() > limits.request_bytes {
            return Err(codec::encode_response(&Response::Rejected(exceeded(
                "request bytes",
                limits.request_bytes,
                "max-request-bytes",
                bytes.len(),
            ))));
        }
        let rejected = |e: String| {
            codec::encode_response(&Response::Rejected(CommandError::new(
                ErrorKind::Malformed,
                e,
            )))
        };
        match Frame::parse(bytes) {
            Err(e) => return Err(rejected(e.to_string())),
            Ok(frame) if frame.version != LAYOUT_VERSION => {
                return Err(codec::encode_version_mismatch())
            }
            Ok(_) => {}
        }
        let request = codec::decode_request(bytes)
            .map_err(|e| rejected(format!("{e} (a request of {} bytes)", bytes.len())))?;
        let max_commands = limits.commands_per_request;
        if request.commands.len() > max_commands {
            return Err(codec::encode_response(&Response::Rejected(exceeded(
                "commands per request",
                max_commands,
                "max-commands-per-request",
                request.commands.len(),
            ))));
        }
        Ok(request.commands)
    }

    /// Serves `command` at once, or hands it (with the commands after it in `rest` that go
    /// to the same plane) to the plane's worker.
    pub(crate) fn route(
        &mut self,
        origin: Origin,
        command: Command,
        rest: &mut VecDeque<Command>,
    ) -> Routed {
        let client = origin.id;
        let now = |result: CommandResult| Routed::Now(vec![result]);
        if let Command::Hello { crate_version, .. } = &command {
            return now(self.hello(origin, crate_version));
        }
        if !self.clients.is_connected(client) {
            return now(Err(CommandError::new(
                ErrorKind::NotConnected,
                "the first command of a client must be Hello",
            )));
        }
        match command {
            Command::Hello { .. } => unreachable!("handled above"),
            Command::Goodbye => {
                self.release_client(client);
                now(Ok(Reply::Done))
            }
            Command::ListPlanes => {
                // The map is ordered: ids come ascending.
                now(Ok(Reply::PlaneIds(self.planes.keys().copied().collect())))
            }
            Command::CreatePlane { kind, props } => self.create_plane(client, kind, props),
            Command::Plane { plane, op } => {
                // A plane that moved away: refused (not applied) naming where it went.
                if let Some(e) = self.moved_refusal(client, plane) {
                    return now(Err(e));
                }
                if let PlaneOp::ClaimMoved { key } = op {
                    return now(self.claim_moved(client, plane, key));
                }
                // An upload becomes the restore it carries (`transfers`).
                let op = match op {
                    PlaneOp::RestoreUploaded {
                        transfer,
                        overrides,
                    } => match self.transfers_of(origin).take_upload(transfer) {
                        Ok(bytes) => PlaneOp::Restore { bytes, overrides },
                        Err(e) => return now(Err(e)),
                    },
                    op => op,
                };
                if let Err(e) = self.check_access(client, plane, &op) {
                    return now(Err(e));
                }
                if op == PlaneOp::Save {
                    return self.save_plane(plane);
                }
                if let PlaneOp::MoveTo { daemon } = &op {
                    return now(self.move_plane(plane, daemon));
                }
                if op == PlaneOp::Pin {
                    return now(self.pin_plane(plane));
                }
                if op == PlaneOp::Destroy {
                    self.forget_file(plane);
                    self.remove_plane(plane);
                    tracing::info!(plane, "plane destroyed");
                    return now(Ok(Reply::Done));
                }
                let mut ops = vec![op];
                while let Some(Command::Plane { plane: next, op }) = rest.front() {
                    if *next != plane
                        || *op == PlaneOp::Destroy
                        || *op == PlaneOp::Save
                        || matches!(op, PlaneOp::RestoreUploaded { .. })
                        || matches!(
                            op,
                            PlaneOp::MoveTo { .. } | PlaneOp::ClaimMoved { .. } | PlaneOp::Pin
                        )
                        || self.check_access(client, plane, op).is_err()
                    {
                        break;
                    }
                    let Some(Command::Plane { op, .. }) = rest.pop_front() else {
                        unreachable!("just looked at it")
                    };
                    ops.push(op);
                }
                self.guest = self.guest_of(origin, plane);
                self.stage_to = Some(self.transfers_of(origin));
                let routed = self.send_job(plane, ops);
                self.stage_to = None;
                routed
            }
            Command::ListNamedPlanes => now(Ok(Reply::NamedPlanes(self.named_planes()))),
            Command::OpenPlane { name } => now(self.open_plane(client, &name)),
            Command::Transfer(op) => now(self.transfers_of(origin).apply(op, self.reply_left)),
        }
    }

    /// The snapshot transfers of the connection `origin` (made on first use; its process
    /// pays for what they hold).
    pub(crate) fn transfers_of(&mut self, origin: Origin) -> Arc<transfers::ClientTransfers> {
        let limits = self.options.limits;
        let owner = self.owners.of(clients::owner_key(origin.pid, origin.id));
        self.transfers
            .entry(origin.id)
            .or_insert_with(|| Arc::new(transfers::ClientTransfers::new(owner, limits)))
            .clone()
    }

    /// Any client may read any plane; only the owner changes it unless the owner shared
    /// it; only the owner destroys it.
    pub(crate) fn check_access(
        &self,
        client: u128,
        id: PlaneId,
        op: &PlaneOp,
    ) -> Result<(), CommandError> {
        let entry = self.plane(id)?;
        if entry.owner == client || op.is_read_only() {
            return Ok(());
        }
        let refused = |why: &str| {
            Err(CommandError::new(
                ErrorKind::NotOwner,
                format!("plane {id} belongs to another client: {why}"),
            ))
        };
        match op {
            PlaneOp::Destroy => refused("only its owner may destroy it"),
            // A restore replaces everything (and trusts the snapshot's engine state).
            PlaneOp::Restore { .. } => refused("only its owner may restore it"),
            PlaneOp::Set(PlaneProp::SharedObjectLimit(_)) => {
                refused("only its owner may set SharedObjectLimit")
            }
            PlaneOp::MoveTo { .. } => refused("only its owner may move it"),
            PlaneOp::Pin => refused("only its owner may pin it"),
            // A recording writes a file on the daemon's machine.
            PlaneOp::Record(_) => refused("only its owner may record it"),
            _ if entry.shared => Ok(()),
            _ => refused(
                "it is not shared, so other clients may only read it (its owner can create it \
                 with Shared = true)",
            ),
        }
    }

    /// The total of the requesting process when it does not own plane `id` (it adds to a
    /// shared plane: what it adds counts against it).
    pub(crate) fn guest_of(
        &mut self,
        origin: Origin,
        id: PlaneId,
    ) -> Option<Arc<quota::OwnerUsage>> {
        let owner = self.planes.get(&id)?.owner;
        let owner_pid = self.clients.get(owner).map(|c| c.pid)?;
        let key = clients::owner_key(origin.pid, origin.id);
        (clients::owner_key(owner_pid, owner) != key).then(|| self.owners.of(key))
    }

    /// The quotas a run is checked against: the limits (the owner's totals are reserved
    /// atomically as ops run, see `quota`), and the reply bytes the request has left.
    pub(crate) fn budget(&self) -> Budget {
        Budget {
            limits: self.options.limits,
            reply_left: self.reply_left,
            guest: self.guest.clone(),
            transfers: self.stage_to.clone(),
        }
    }

    pub(crate) fn hello(&mut self, origin: Origin, crate_version: &str) -> CommandResult {
        let (client, pid) = (origin.id, origin.pid);
        if crate_version != CRATE_VERSION {
            return Err(CommandError::new(
                ErrorKind::VersionMismatch,
                format!(
                    "crate version mismatch: client {crate_version}, daemon {CRATE_VERSION} \
                     (LAYOUT_VERSION {LAYOUT_VERSION} on both)"
                ),
            ));
        }
        self.clients.connect(
            &self.node,
            client,
            pid,
            self.options.limits.clients_per_process,
        )?;
        // The resource guard must not take it for a node that never said Hello.
        self.update_watch();
        tracing::info!(client = format!("{client:032x}"), pid, "client connected");
        Ok(Reply::Welcome {
            daemon_pid: std::process::id(),
            daemon_node_id: self.node.id().value(),
            crate_version: CRATE_VERSION.to_string(),
        })
    }

    /// Plane `id` is being destroyed by its owner: a persistent plane's files go with it.
    pub(crate) fn forget_file(&mut self, id: PlaneId) {
        let Some(entry) = self.planes.get(&id) else {
            return;
        };
        if let (true, Some(name), Some(writer)) = (entry.persistent, entry.name, &self.writer) {
            entry
                .cell
                .marks
                .destroyed
                .store(true, std::sync::atomic::Ordering::SeqCst);
            writer.delete(id, name.as_str());
        }
    }

    pub(crate) fn plane(&self, id: PlaneId) -> Result<&PlaneEntry, CommandError> {
        self.planes.get(&id).ok_or_else(|| unknown_plane(id))
    }

    /// Starts the worker of a new plane; it answers the command once the plane exists
    /// (tick 0 published) or failed to.
    pub(crate) fn create_plane(
        &mut self,
        owner: u128,
        kind: PlaneKind,
        props: Vec<PlaneProp>,
    ) -> Routed {
        let refuse = |e: CommandError| Routed::Now(vec![Err(e)]);
        if self.planes.len() >= MAX_PLANES {
            return refuse(CommandError::new(
                ErrorKind::Quota,
                format!("the daemon already hosts {MAX_PLANES} planes"),
            ));
        }
        let owned = self.clients.planes_of_process(owner).count();
        let max = self.options.limits.planes_per_client;
        if owned >= max {
            return refuse(exceeded(
                "planes per client",
                max,
                "max-planes-per-client",
                owned + 1,
            ));
        }
        let naming = match self.naming(&props) {
            Ok(n) => n,
            Err(e) => return refuse(e),
        };
        let id = self.next_plane_id;
        let ticket = self.next_ticket;
        let owner_pid = self.clients.get(owner).map_or(0, |c| c.pid);
        let usage = match SharedUsage::admit(self.owners.of(clients::owner_key(owner_pid, owner))) {
            Ok(usage) => Arc::new(usage),
            Err(e) => return refuse(e),
        };
        let cell = Arc::new(PlaneCell::default());
        let (jobs, receiver) = mpsc::channel();
        let shared = PlaneProp::shared_in(&props);
        let file = match (&self.writer, naming.name, naming.persistent) {
            (Some(w), Some(name), true) => w.plane_file(id, name.as_str(), &cell.marks, None),
            _ => None,
        };
        let setup = worker::Setup {
            file,
            ..self.worker_setup(id, kind, props, &cell, &usage)
        };
        if let Err(e) = self.start_worker(setup, receiver) {
            return refuse(CommandError::new(ErrorKind::Internal, e));
        }
        self.planes.insert(
            id,
            PlaneEntry {
                owner,
                shared,
                jobs,
                cell,
                usage,
                kind,
                name: naming.name,
                persistent: naming.persistent,
                recovered: None,
            },
        );
        if let Some(c) = self.clients.get_mut(owner) {
            c.planes.push(id);
        }
        Routed::Wait(ticket)
    }
}

impl Daemon {
    /// The start of plane `id`'s worker with what every worker gets from the daemon, under
    /// the next ticket (no file, no snapshot to restore: set those on the result).
    pub(crate) fn worker_setup(
        &self,
        id: PlaneId,
        kind: PlaneKind,
        props: Vec<PlaneProp>,
        cell: &Arc<PlaneCell>,
        usage: &Arc<SharedUsage>,
    ) -> worker::Setup {
        worker::Setup {
            id,
            kind,
            props,
            ticket: self.next_ticket,
            config: self.config.clone(),
            cell: cell.clone(),
            usage: usage.clone(),
            events: self.events_tx.clone(),
            waker: self.waker.clone(),
            panic_on_step_dt: self.options.panic_on_step_dt,
            file: None,
            restore: None,
            record: self.options.record.clone(),
            arrived_recording: false,
        }
    }

    /// Starts the worker of `setup` (made by [`Daemon::worker_setup`]) on `jobs`; the plane
    /// id and the ticket it used are taken.
    pub(crate) fn start_worker(
        &mut self,
        setup: worker::Setup,
        jobs: mpsc::Receiver<worker::Job>,
    ) -> Result<(), String> {
        let id = setup.id;
        let handle = worker::spawn(setup, jobs)
            .map_err(|e| format!("cannot start the thread of plane {id}: {e}"))?;
        self.workers.push(handle);
        self.next_ticket += 1;
        self.next_plane_id += 1;
        Ok(())
    }
}

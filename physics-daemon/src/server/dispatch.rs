//! Requests: decoding, and routing each command by plane id to the plane's backend. Only
//! the lifecycle ops (create, step, destroy) are handled here; every other op goes to the
//! backend unread, so a new op family never changes this file.

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::time::Instant;

use shm_layout::codec::{self, Frame};
use shm_layout::{
    Command, CommandError, CommandResult, ErrorKind, PlaneId, PlaneKind, PlaneOp, PlaneProp, Reply,
    Response, CRATE_VERSION, LAYOUT_VERSION,
};

use super::limits::exceeded;
use super::{Daemon, Origin, PlaneEntry, MAX_PLANES};
use crate::backend;
use crate::publish::PlaneOutput;
use crate::DaemonError;

impl Daemon {
    /// Decodes one request and executes its commands. Never panics on any input.
    pub fn handle_bytes(&mut self, origin: Origin, bytes: &[u8]) -> Vec<u8> {
        let limits = &self.options.limits;
        if bytes.len() > limits.request_bytes {
            return codec::encode_response(&Response::Rejected(exceeded(
                "request bytes",
                limits.request_bytes,
                "max-request-bytes",
                bytes.len(),
            )));
        }
        let rejected = |e: String| {
            codec::encode_response(&Response::Rejected(CommandError::new(
                ErrorKind::Malformed,
                e,
            )))
        };
        match Frame::parse(bytes) {
            Err(e) => return rejected(e.to_string()),
            Ok(frame) if frame.version != LAYOUT_VERSION => {
                return codec::encode_version_mismatch()
            }
            Ok(_) => {}
        }
        let request = match codec::decode_request(bytes) {
            Ok(r) => r,
            Err(e) => return rejected(e.to_string()),
        };
        let max_commands = self.options.limits.commands_per_request;
        if request.commands.len() > max_commands {
            return codec::encode_response(&Response::Rejected(exceeded(
                "commands per request",
                max_commands,
                "max-commands-per-request",
                request.commands.len(),
            )));
        }
        let results: Vec<CommandResult> = request
            .commands
            .into_iter()
            .map(|c| self.execute(origin, c))
            .collect();
        codec::encode_response(&Response::Results(results))
    }

    fn execute(&mut self, origin: Origin, command: Command) -> CommandResult {
        let client = origin.id;
        if let Command::Hello { crate_version, .. } = &command {
            return self.hello(origin, crate_version);
        }
        if !self.clients.is_connected(client) {
            return Err(CommandError::new(
                ErrorKind::NotConnected,
                "the first command of a client must be Hello",
            ));
        }
        match command {
            Command::Hello { .. } => unreachable!("handled above"),
            Command::Goodbye => {
                self.release_client(client);
                Ok(Reply::Done)
            }
            Command::ListPlanes => {
                // The map is ordered: ids come ascending.
                Ok(Reply::PlaneIds(self.planes.keys().copied().collect()))
            }
            Command::CreatePlane { kind, props } => {
                self.create_plane(client, kind, &props, Instant::now())
            }
            Command::Plane { plane, op } => {
                self.check_access(client, plane, &op)?;
                self.check_quota(plane, &op)?;
                self.plane_op(plane, op)
            }
        }
    }

    /// Any client may read any plane; only the owner changes it unless the owner shared
    /// it; only the owner destroys it.
    fn check_access(
        &mut self,
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
            _ if entry.shared => Ok(()),
            _ => refused(
                "it is not shared, so other clients may only read it (its owner can create it \
                 with Shared = true)",
            ),
        }
    }

    /// What `op` adds must fit the quotas of the plane's owner.
    fn check_quota(&mut self, id: PlaneId, op: &PlaneOp) -> Result<(), CommandError> {
        let cost = op.cost();
        if cost == Default::default() {
            return Ok(());
        }
        let limits = &self.options.limits;
        if cost.mesh_vertices > limits.mesh_vertices_per_object {
            return Err(exceeded(
                "mesh vertices per object",
                limits.mesh_vertices_per_object,
                "max-mesh-vertices",
                cost.mesh_vertices,
            ));
        }
        let owner = self.plane(id)?.owner;
        let (mut objects, mut vertices) = (cost.objects as u64, cost.mesh_vertices);
        for p in self.clients.planes_of_process(owner) {
            if let Some(entry) = self.planes.get(&p) {
                let usage = entry.plane.usage();
                objects += usage.objects;
                vertices += usage.mesh_vertices;
            }
        }
        let limits = &self.options.limits;
        if objects > limits.objects_per_client {
            return Err(exceeded(
                "objects per client",
                limits.objects_per_client,
                "max-objects-per-client",
                objects,
            ));
        }
        if vertices > limits.mesh_vertices_per_client {
            return Err(exceeded(
                "mesh vertices per client",
                limits.mesh_vertices_per_client,
                "max-mesh-vertices-per-client",
                vertices,
            ));
        }
        Ok(())
    }

    /// Routes `op` to plane `id`. A panic inside the plane fails that plane alone: it is
    /// removed, the command gets an error naming it, and the daemon serves on.
    fn plane_op(&mut self, id: PlaneId, op: PlaneOp) -> CommandResult {
        if op == PlaneOp::Destroy {
            self.remove_plane(id);
            tracing::info!(plane = id, "plane destroyed");
            return Ok(Reply::Done);
        }
        let panic_dt = self.options.panic_on_step_dt;
        let entry = self.plane(id)?;
        let outcome = catch_unwind(AssertUnwindSafe(|| match op {
            PlaneOp::Step { dt } => {
                if panic_dt == Some(dt) {
                    panic!("injected fault: Step({dt})");
                }
                if entry.plane.step(dt)? {
                    entry.out.publish(entry.plane.as_mut()).map_err(internal)?;
                }
                Ok(Reply::Stepped {
                    tick: entry.plane.tick(),
                })
            }
            op => {
                if op == PlaneOp::Info {
                    // A reader that just subscribed gets the newest tick at once.
                    entry.out.connect_readers();
                }
                let result = entry.plane.apply(op);
                entry.reschedule_if_changed(Instant::now());
                result
            }
        }));
        outcome.unwrap_or_else(|panic| Err(self.fail_plane(id, panic)))
    }

    fn hello(&mut self, origin: Origin, crate_version: &str) -> CommandResult {
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
        tracing::info!(client = format!("{client:032x}"), pid, "client connected");
        Ok(Reply::Welcome {
            daemon_pid: std::process::id(),
            daemon_node_id: self.node.id().value(),
            crate_version: CRATE_VERSION.to_string(),
        })
    }

    fn plane(&mut self, id: PlaneId) -> Result<&mut PlaneEntry, CommandError> {
        self.planes.get_mut(&id).ok_or_else(|| {
            CommandError::new(
                ErrorKind::UnknownPlane,
                format!("plane {id} does not exist"),
            )
        })
    }

    fn create_plane(
        &mut self,
        owner: u128,
        kind: PlaneKind,
        props: &[PlaneProp],
        now: Instant,
    ) -> CommandResult {
        if self.planes.len() >= MAX_PLANES {
            return Err(CommandError::new(
                ErrorKind::Quota,
                format!("the daemon already hosts {MAX_PLANES} planes"),
            ));
        }
        let owned = self.clients.planes_of_process(owner).count();
        let max = self.options.limits.planes_per_client;
        if owned >= max {
            return Err(exceeded(
                "planes per client",
                max,
                "max-planes-per-client",
                owned + 1,
            ));
        }
        let id = self.next_plane_id;
        let created = catch_unwind(AssertUnwindSafe(|| backend::create(kind, id, props)));
        let mut plane = created.unwrap_or_else(|panic| {
            Err(CommandError::new(
                ErrorKind::Internal,
                format!("creating plane {id} failed: {}", panic_message(&panic)),
            ))
        })?;
        let out = PlaneOutput::new(&self.node, id).map_err(internal)?;
        // Publish tick 0 so readers see the plane (and late joiners get history) at once.
        out.publish(plane.as_mut()).map_err(internal)?;
        let info = plane.apply(PlaneOp::Info)?;
        let mut entry = PlaneEntry {
            plane,
            owner,
            shared: PlaneProp::shared_in(props),
            out,
            period: None,
            next_tick: None,
        };
        entry.reschedule_if_changed(now);
        self.planes.insert(id, entry);
        if let Some(c) = self.clients.get_mut(owner) {
            c.planes.push(id);
        }
        self.next_plane_id += 1;
        tracing::info!(plane = id, ?kind, ?info, "plane created");
        Ok(info)
    }
}

/// A daemon failure as the error of the command that met it.
pub(super) fn internal(e: DaemonError) -> CommandError {
    CommandError::new(ErrorKind::Internal, e.to_string())
}

/// The text of a caught panic.
pub(super) fn panic_message(panic: &(dyn std::any::Any + Send)) -> String {
    panic
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| panic.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "a panic without a message".to_string())
}

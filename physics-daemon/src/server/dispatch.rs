//! Requests: decoding, and routing each command by plane id to the plane's backend. Only
//! the lifecycle ops (create, step, destroy) are handled here; every other op goes to the
//! backend unread, so a new op family never changes this file.

use std::time::Instant;

use shm_layout::codec::{self, Frame};
use shm_layout::{
    Command, CommandError, CommandResult, ErrorKind, PlaneId, PlaneKind, PlaneOp, PlaneProp, Reply,
    Response, CRATE_VERSION, LAYOUT_VERSION,
};

use super::{Daemon, PlaneEntry, MAX_PLANES};
use crate::backend;
use crate::publish::PlaneOutput;
use crate::DaemonError;

impl Daemon {
    /// Decodes one request and executes its commands. Never panics on any input.
    pub fn handle_bytes(&mut self, client: u128, bytes: &[u8]) -> Vec<u8> {
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
        let results: Vec<CommandResult> = request
            .commands
            .into_iter()
            .map(|c| self.execute(client, c))
            .collect();
        codec::encode_response(&Response::Results(results))
    }

    fn execute(&mut self, client: u128, command: Command) -> CommandResult {
        if let Command::Hello { crate_version, pid } = &command {
            return self.hello(client, crate_version, *pid);
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
            Command::CreatePlane { kind, props } => {
                self.create_plane(client, kind, &props, Instant::now())
            }
            Command::Plane { plane, op } => self.plane_op(plane, op),
        }
    }

    /// Routes `op` to plane `id`.
    fn plane_op(&mut self, id: PlaneId, op: PlaneOp) -> CommandResult {
        let entry = self.plane(id)?;
        match op {
            PlaneOp::Step { dt } => {
                if entry.plane.step(dt)? {
                    entry.out.publish(entry.plane.as_mut()).map_err(internal)?;
                }
                Ok(Reply::Stepped {
                    tick: entry.plane.tick(),
                })
            }
            PlaneOp::Destroy => {
                self.planes.remove(&id);
                tracing::info!(plane = id, "plane destroyed");
                Ok(Reply::Done)
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
        }
    }

    fn hello(&mut self, client: u128, crate_version: &str, pid: u32) -> CommandResult {
        if crate_version != CRATE_VERSION {
            return Err(CommandError::new(
                ErrorKind::VersionMismatch,
                format!(
                    "crate version mismatch: client {crate_version}, daemon {CRATE_VERSION} \
                     (LAYOUT_VERSION {LAYOUT_VERSION} on both)"
                ),
            ));
        }
        self.clients
            .connect(&self.node, client, pid)
            .map_err(|e| CommandError::new(ErrorKind::Internal, e))?;
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
                ErrorKind::Internal,
                format!("the daemon already hosts {MAX_PLANES} planes"),
            ));
        }
        let id = self.next_plane_id;
        let mut plane = backend::create(kind, id, props)?;
        let out = PlaneOutput::new(&self.node, id).map_err(internal)?;
        // Publish tick 0 so readers see the plane (and late joiners get history) at once.
        out.publish(plane.as_mut()).map_err(internal)?;
        let info = plane.apply(PlaneOp::Info)?;
        let mut entry = PlaneEntry {
            plane,
            owner,
            out,
            period: None,
            next_tick: None,
        };
        entry.reschedule_if_changed(now);
        self.planes.insert(id, entry);
        self.next_plane_id += 1;
        tracing::info!(plane = id, ?kind, ?info, "plane created");
        Ok(info)
    }
}

/// A daemon failure as the error of the command that met it.
pub(super) fn internal(e: DaemonError) -> CommandError {
    CommandError::new(ErrorKind::Internal, e.to_string())
}

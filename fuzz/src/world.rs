//! What the fuzzer knows about the daemon's state, learned only from replies: which clients
//! are connected, the planes they created and the handles of the objects in them. The
//! generator draws valid targets from here so valid commands reach the deep code paths.

use std::collections::BTreeMap;

use shm_layout::{
    Command, CommandResult, ControllerOp, ErrorKind, GuiOp, Handle, ObjectOp, PlaneId, PlaneOp,
    Reply,
};

/// Handles remembered per plane, live and stale (older ones are forgotten).
const MAX_REMEMBERED: usize = 512;

/// A plane the fuzzer saw created.
#[derive(Debug, Clone)]
pub struct KnownPlane {
    /// The fuzzer's client that created it.
    pub owner: usize,
    /// Created with `Shared = true`.
    pub shared: bool,
    /// Objects added and not destroyed (as far as replies tell).
    pub live: Vec<Handle>,
    /// Objects destroyed: their handles must be refused as stale.
    pub stale: Vec<Handle>,
}

/// The fuzzer's view of the daemon.
#[derive(Debug, Clone)]
pub struct World {
    /// Whether each client has completed its handshake (a Goodbye ends it).
    pub connected: Vec<bool>,
    /// Planes created by the fuzzer's clients and not known to be gone.
    pub planes: BTreeMap<PlaneId, KnownPlane>,
    /// Ids of planes that are gone (destroyed, released, failed).
    pub gone: Vec<PlaneId>,
    /// The largest plane id seen.
    pub max_id: PlaneId,
}

impl World {
    /// `clients` clients, all connected (they connected through the SDK).
    pub fn new(clients: usize) -> World {
        World {
            connected: vec![true; clients],
            planes: BTreeMap::new(),
            gone: Vec::new(),
            max_id: 0,
        }
    }

    /// Ids of the planes `client` created.
    pub fn own_planes(&self, client: usize) -> Vec<PlaneId> {
        self.planes
            .iter()
            .filter(|(_, p)| p.owner == client)
            .map(|(id, _)| *id)
            .collect()
    }

    /// Ids of the planes other clients created.
    pub fn foreign_planes(&self, client: usize) -> Vec<PlaneId> {
        self.planes
            .iter()
            .filter(|(_, p)| p.owner != client)
            .map(|(id, _)| *id)
            .collect()
    }

    /// Live objects in the planes `client` created.
    pub fn own_objects(&self, client: usize) -> usize {
        self.planes
            .values()
            .filter(|p| p.owner == client)
            .map(|p| p.live.len())
            .sum()
    }

    fn forget_plane(&mut self, id: PlaneId) {
        if self.planes.remove(&id).is_some() {
            self.gone.push(id);
            if self.gone.len() > MAX_REMEMBERED {
                self.gone.remove(0);
            }
        }
    }

    fn release(&mut self, client: usize) {
        for id in self.own_planes(client) {
            self.forget_plane(id);
        }
    }

    /// Learns from the results of `commands`, sent by `client`.
    pub fn learn(&mut self, client: usize, commands: &[Command], results: &[CommandResult]) {
        for (command, result) in commands.iter().zip(results) {
            if let Err(e) = result {
                if e.kind == ErrorKind::NotConnected {
                    self.connected[client] = false;
                }
            }
            match (command, result) {
                (Command::Hello { .. }, Ok(_)) => self.connected[client] = true,
                (Command::Goodbye, Ok(_)) => {
                    self.connected[client] = false;
                    self.release(client);
                }
                (Command::CreatePlane { props, .. }, Ok(Reply::Plane(info))) => {
                    self.max_id = self.max_id.max(info.id);
                    self.planes.insert(
                        info.id,
                        KnownPlane {
                            owner: client,
                            shared: shm_layout::PlaneProp::shared_in(props),
                            live: Vec::new(),
                            stale: Vec::new(),
                        },
                    );
                }
                (Command::Plane { plane, op }, result) => self.learn_plane(*plane, op, result),
                _ => {}
            }
        }
    }

    fn learn_plane(&mut self, id: PlaneId, op: &PlaneOp, result: &CommandResult) {
        match result {
            Err(e) if e.kind == ErrorKind::UnknownPlane => return self.forget_plane(id),
            Err(e) if e.kind == ErrorKind::Internal && e.message.contains("removed") => {
                return self.forget_plane(id)
            }
            _ => {}
        }
        if matches!((op, result), (PlaneOp::Destroy, Ok(_))) {
            return self.forget_plane(id);
        }
        let Some(plane) = self.planes.get_mut(&id) else {
            return;
        };
        match (op, result) {
            // Controllers and GUI bodies are objects too (they count against the same quota
            // and die by the same ObjectOp::Destroy).
            (
                PlaneOp::AddObject { .. }
                | PlaneOp::Controller(ControllerOp::Create { .. })
                | PlaneOp::Gui(GuiOp::Add { .. }),
                Ok(Reply::Object { handle, .. }),
            ) => {
                plane.live.push(*handle);
                if plane.live.len() > MAX_REMEMBERED * 16 {
                    plane.live.remove(0);
                }
            }
            (
                PlaneOp::Object {
                    handle,
                    op: ObjectOp::Destroy,
                },
                Ok(_),
            ) => {
                plane.live.retain(|h| h != handle);
                plane.stale.push(*handle);
                if plane.stale.len() > MAX_REMEMBERED {
                    plane.stale.remove(0);
                }
            }
            (PlaneOp::Object { handle, .. }, Err(e)) if e.kind == ErrorKind::StaleHandle => {
                plane.live.retain(|h| h != handle);
            }
            _ => {}
        }
    }
}

//! Connected clients: the notifier that wakes each one when its reply is ready, and the
//! detection of clients whose process died (iceoryx2 dead-node detection).

use std::collections::HashMap;

use iceoryx2::config::Config;
use iceoryx2::node::{NodeCleanupFailure, NodeView};
use iceoryx2::port::notifier::Notifier;
use iceoryx2::prelude::*;
use shm_layout::names;

use crate::server::quotas::limits;
use crate::server::quotas::limits::MAX_CLIENTS;

/// One connected client.
pub struct Client {
    /// Process id of the client's node (from the transport, not from the client's words).
    pub pid: u32,
    /// Planes the client owns.
    pub planes: Vec<shm_layout::PlaneId>,
    notifier: Notifier<ipc::Service>,
}

/// The connected clients, by iceoryx2 node id.
pub struct Clients {
    connected: HashMap<u128, Client>,
    /// Most clients served at once (`--max-clients`).
    max: usize,
}

impl Default for Clients {
    fn default() -> Self {
        Clients::new(MAX_CLIENTS)
    }
}

impl Clients {
    /// No client yet; at most `max` at once.
    pub fn new(max: usize) -> Clients {
        Clients {
            connected: HashMap::new(),
            max,
        }
    }

    /// Whether the client `id` has completed its handshake.
    pub fn is_connected(&self, id: u128) -> bool {
        self.connected.contains_key(&id)
    }

    /// The node ids of the connected clients.
    pub fn ids(&self) -> impl Iterator<Item = u128> + '_ {
        self.connected.keys().copied()
    }

    /// Whether no client is connected.
    pub fn is_empty(&self) -> bool {
        self.connected.is_empty()
    }

    /// Registers a client after its handshake. Fails when the daemon is full, when the
    /// client's process already holds `per_process` clients, or when the client has no
    /// wake-up event.
    pub fn connect(
        &mut self,
        node: &Node<ipc::Service>,
        id: u128,
        pid: u32,
        per_process: usize,
    ) -> Result<(), shm_layout::CommandError> {
        if self.is_connected(id) {
            return Ok(());
        }
        if self.connected.len() >= self.max {
            return Err(limits::exceeded(
                "clients of the daemon",
                self.max,
                "max-clients",
                format!("{} clients", self.connected.len() + 1),
            ));
        }
        // The cluster relay (this process) connects once per remote session: each such
        // session is a client of its own for the per-process bounds (the relay bounds how
        // many sessions it serves).
        let same_process = self.connected.values().filter(|c| c.pid == pid).count();
        if same_process >= per_process && pid != std::process::id() {
            return Err(limits::exceeded(
                "clients per process",
                per_process,
                "max-clients-per-process",
                format!("{} for process {pid}", same_process + 1),
            ));
        }
        let notifier = open_notifier(node, id)
            .map_err(|e| shm_layout::CommandError::new(shm_layout::ErrorKind::Internal, e))?;
        self.connected.insert(
            id,
            Client {
                pid,
                planes: Vec::new(),
                notifier,
            },
        );
        Ok(())
    }

    /// Who pays for client `id`'s usage (quotas, CPU share): its process, or for a relayed
    /// remote session (a connection of this process, see `client_sdk::relay`) the session.
    pub fn owner_key(&self, id: u128) -> u128 {
        owner_key(self.connected.get(&id).map_or(0, |c| c.pid), id)
    }

    /// Planes owned by the connections of the process of client `id` (quotas count per
    /// process, so opening more connections does not multiply them).
    pub fn planes_of_process(&self, id: u128) -> impl Iterator<Item = shm_layout::PlaneId> + '_ {
        let pid = self.connected.get(&id).map(|c| c.pid);
        // A relayed remote session (this process's own connection) counts alone.
        let relayed = pid == Some(std::process::id());
        self.connected
            .iter()
            .filter(move |(other, c)| Some(c.pid) == pid && (!relayed || **other == id))
            .flat_map(|(_, c)| c.planes.iter().copied())
    }

    /// The connected client `id`.
    pub fn get(&self, id: u128) -> Option<&Client> {
        self.connected.get(&id)
    }

    /// The connected client `id`, mutably.
    pub fn get_mut(&mut self, id: u128) -> Option<&mut Client> {
        self.connected.get_mut(&id)
    }

    /// Forgets the client `id`; returns whether it was connected.
    pub fn disconnect(&mut self, id: u128) -> bool {
        self.connected.remove(&id).is_some()
    }

    /// Wakes the client `id` (its reply is ready). Clients that are not connected yet (a
    /// malformed first request, say) get a notifier opened for this one reply.
    pub fn wake(&self, node: &Node<ipc::Service>, id: u128) {
        let result = match self.connected.get(&id) {
            Some(c) => c
                .notifier
                .notify()
                .map(|_| ())
                .map_err(|e| format!("{e:?}")),
            None => open_notifier(node, id)
                .and_then(|n| n.notify().map(|_| ()).map_err(|e| format!("{e:?}"))),
        };
        if let Err(e) = result {
            tracing::debug!(client = format!("{id:032x}"), "cannot wake client: {e}");
        }
    }

    /// Finds dead client processes, removes their stale iceoryx2 resources and returns the
    /// ids of the connected clients that are gone.
    pub fn reap(&mut self, config: &Config) -> Vec<u128> {
        let mut present = Vec::new();
        let mut dead = Vec::new();
        let listed = Node::<ipc::Service>::list(config, |state| {
            match state {
                NodeState::Dead(view) => dead.push(view),
                other => present.push(other.node_id().value()),
            }
            CallbackProgression::Continue
        });
        if let Err(e) = listed {
            tracing::warn!("cannot list nodes: {e:?}");
            return Vec::new();
        }
        for view in dead {
            let id = view.id().value();
            tracing::info!(
                node = format!("{id:032x}"),
                "removing resources of a dead process"
            );
            match view.try_remove_stale_resources() {
                // The resource guard looks at the same exits: whoever comes second finds the
                // work done.
                Ok(_)
                | Err(
                    NodeCleanupFailure::ResourcesAlreadyCleanedUp
                    | NodeCleanupFailure::AnotherInstanceIsCleaningUpTheNode,
                ) => {}
                Err(e) => tracing::warn!("cleanup of dead node failed: {e:?}"),
            }
        }
        let gone: Vec<u128> = self
            .connected
            .keys()
            .copied()
            .filter(|id| !present.contains(id))
            .collect();
        for id in &gone {
            self.connected.remove(id);
        }
        gone
    }
}

fn open_notifier(node: &Node<ipc::Service>, id: u128) -> Result<Notifier<ipc::Service>, String> {
    node.service_builder(&names::client_wake(id))
        .event()
        .open()
        .map_err(|e| format!("client wake-up event missing: {e:?}"))?
        .notifier_builder()
        .create()
        .map_err(|e| format!("cannot notify client: {e:?}"))
}

/// Who pays for the connection `id` of process `pid` ([`Clients::owner_key`]): the process,
/// or for a connection of this process (a relayed remote session) the connection itself
/// (its id with the top bit set, so it never equals a pid).
pub fn owner_key(pid: u32, id: u128) -> u128 {
    if pid == std::process::id() {
        id | (1 << 127)
    } else {
        pid as u128
    }
}

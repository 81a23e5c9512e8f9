//! Who sent a request. The request header lives in the sender's own shared memory, so its
//! node id (header offset 0) is whatever the sender wrote there: the daemon never reads it.
//! Instead it takes the id of the client port whose connection delivered the request (the
//! server's own record of its connections, see `vendor/iceoryx2-0.10.0/PATCHED.md`) and looks
//! that port's node up in the control service's port list, which iceoryx2 fills when the
//! port is created. A client that writes another client's node id into its header is still
//! served as itself.

use std::collections::HashMap;

use iceoryx2::prelude::*;

/// The sender of a request, as the transport reports it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Origin {
    /// The sender's iceoryx2 node id.
    pub id: u128,
    /// The sender's process id.
    pub pid: u32,
}

/// The control service as the daemon opened it (its port list names each client port's
/// node).
pub(crate) type ControlService = iceoryx2::service::port_factory::request_response::PortFactory<
    ipc::Service,
    [u8],
    u128,
    [u8],
    (),
>;

/// Client port id → the node (and process) that created the port, refreshed from the
/// service's port list when a port is not known yet. Port ids are never reused, so a
/// remembered port cannot come to mean another client.
#[derive(Default)]
pub(crate) struct Origins {
    ports: HashMap<u128, Origin>,
}

impl Origins {
    /// The node and process of client port `port`; `None` when the service lists no such
    /// port (it closed, or its process died, before the request was served).
    pub(crate) fn of(&mut self, service: &ControlService, port: u128) -> Option<Origin> {
        if let Some(origin) = self.ports.get(&port) {
            return Some(*origin);
        }
        // Rebuilt, not extended: it holds at most the ports the service has.
        self.ports.clear();
        service.dynamic_config().list_clients(|details| {
            let node = details.node_id;
            let pid = node.pid::<ipc::Service>().map_or(0, |p| p.value() as u32);
            self.ports.insert(
                details.client_id.value(),
                Origin {
                    id: node.value(),
                    pid,
                },
            );
            CallbackProgression::Continue
        });
        self.ports.get(&port).copied()
    }
}

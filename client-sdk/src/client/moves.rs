//! Planes that moved or failed over to another daemon: the connections to the other
//! daemons (peers), rerouting a plane's commands there, and moving queued writes along.

use std::cell::RefCell;
use std::collections::HashMap;
use std::rc::Rc;

use shm_layout::{Command, PlaneId};

use crate::remote::RemoteOptions;

use super::{Client, ConnectOptions, Inner, Queued, Rerouted};

impl Client {
    /// Moves the queued commands for plane `id` to `peer`'s queue under `new_id` (the plane
    /// moved there before they were sent).
    pub(crate) fn requeue_to(&self, id: PlaneId, peer: &Client, new_id: PlaneId) {
        let queue = std::mem::take(&mut self.inner.state.borrow_mut().queue);
        let (theirs, ours): (Vec<Queued>, Vec<Queued>) = queue
            .into_iter()
            .partition(|q| matches!(&q.command, Command::Plane { plane, .. } if *plane == id));
        self.inner.state.borrow_mut().queue = ours;
        let mut state = peer.inner.state.borrow_mut();
        for mut q in theirs {
            if let Command::Plane { plane, .. } = &mut q.command {
                *plane = new_id;
            }
            if let Some((plane, _)) = &mut q.confirms {
                *plane = new_id;
            }
            state.queue.push(q);
        }
    }

    /// How this client reached its cluster ([`Client::connect_cluster`]), if it did.
    pub(crate) fn remote_options(&self) -> Option<&RemoteOptions> {
        self.inner.remote.as_ref()
    }

    /// The options this client connected with.
    pub(crate) fn connect_options(&self) -> &ConnectOptions {
        &self.inner.options
    }

    /// The connections to the daemons this client's planes moved to, by daemon.
    pub(crate) fn peers(&self) -> &RefCell<HashMap<String, Client>> {
        &self.inner.peers
    }

    /// A handle that does not keep this client alive (a moved plane's route: the
    /// connection belongs to the client that switched it).
    pub(crate) fn downgrade(&self) -> std::rc::Weak<dyn std::any::Any> {
        let inner: Rc<dyn std::any::Any> = self.inner.clone();
        Rc::downgrade(&inner)
    }

    /// The client behind [`Client::downgrade`]'s handle, while it lives.
    pub(crate) fn upgrade(weak: &std::rc::Weak<dyn std::any::Any>) -> Option<Client> {
        let inner = weak.upgrade()?.downcast::<Inner>().ok()?;
        Some(Client { inner })
    }

    /// Where `command` goes: this connection, or the one its plane moved to.
    pub(crate) fn reroute(&self, command: Command) -> Rerouted {
        let Command::Plane { plane, op } = command else {
            return Rerouted::Here(command);
        };
        let route = self
            .attached(plane)
            .and_then(|s| s.route.borrow().clone())
            .and_then(|r| Some((Client::upgrade(&r.peer)?, r.id)));
        match route {
            None => Rerouted::Here(Command::Plane { plane, op }),
            Some((peer, id)) if peer.same(self) => Rerouted::Here(Command::Plane { plane: id, op }),
            Some((peer, id)) => Rerouted::There(peer, Command::Plane { plane: id, op }),
        }
    }

    /// Whether both are the same connection.
    pub(crate) fn same(&self, other: &Client) -> bool {
        Rc::ptr_eq(&self.inner, &other.inner)
    }
}

//! Serving requests in order: each client's requests queue in arrival order and run one at
//! a time; a request whose run is with a plane worker is parked while the loop serves
//! everyone else, and its reply goes out when its last command is answered. Also what the
//! loop does when a plane or a client goes.

use std::collections::VecDeque;

use shm_layout::PlaneId;

use crate::server::daemon::{Daemon, Pending, Routed};
use crate::server::liveness::schedule;
use crate::server::requests::refusals::unknown_plane;
use crate::server::worker::{Event, Inline, Job};

impl Daemon {
    /// Takes every request that arrived: each joins its client's queue and runs at once
    /// unless an earlier request of the same client is still being served.
    pub(crate) fn serve_requests(&mut self) {
        loop {
            let request = match self.server.receive() {
                Ok(Some(request)) => request,
                Ok(None) => break,
                Err(e) => {
                    tracing::warn!("receive failed: {e:?}");
                    break;
                }
            };
            // Who sent it comes from the connection it arrived on (see `origin`), never from
            // the request header or the payload, which the sender writes: a client cannot
            // speak for another.
            let port = request.origin_client_id();
            let Some(origin) = self.origins.of(&self.control, port) else {
                tracing::warn!(
                    port = format!("{port:032x}"),
                    "request from a client port the service no longer lists: dropped"
                );
                continue;
            };
            let client = origin.id;
            let pending = match self.take_bytes(&request).and_then(|b| self.decode(&b)) {
                Ok(commands) => Pending {
                    request,
                    origin,
                    results: Vec::with_capacity(commands.len()),
                    commands: commands.into(),
                    waiting: None,
                    early: None,
                    reply_bytes: 0,
                },
                Err(reply) => Pending {
                    request,
                    origin,
                    commands: VecDeque::new(),
                    results: Vec::new(),
                    waiting: None,
                    early: Some(reply),
                    reply_bytes: 0,
                },
            };
            let queue = self.queues.entry(client).or_default();
            queue.push_back(pending);
            if queue.len() == 1 {
                self.advance(client);
            }
        }
    }

    /// Serves the requests of `client` in order until one waits for a worker or none is
    /// left.
    pub(crate) fn advance(&mut self, client: u128) {
        loop {
            let Some(mut pending) = self.queues.get_mut(&client).and_then(|q| q.pop_front()) else {
                self.queues.remove(&client);
                return;
            };
            if pending.waiting.is_some() {
                self.queues.entry(client).or_default().push_front(pending);
                return;
            }
            while let Some(command) = pending.commands.pop_front() {
                self.reply_left = self
                    .options
                    .limits
                    .reply_bytes
                    .saturating_sub(pending.reply_bytes);
                match self.route(pending.origin, command, &mut pending.commands) {
                    Routed::Now(results) => pending.count(results),
                    Routed::Wait(ticket) => {
                        pending.waiting = Some(ticket);
                        self.tickets.insert(ticket, client);
                        break;
                    }
                }
            }
            if pending.waiting.is_some() {
                self.queues.entry(client).or_default().push_front(pending);
                return;
            }
            self.reply(pending);
        }
    }

    /// Sends the reply of a finished request and wakes its client.
    pub(crate) fn reply(&self, pending: Pending) {
        let client = pending.origin.id;
        let bytes = pending.early.unwrap_or_else(|| {
            shm_layout::codec::encode_response(&shm_layout::Response::Results(pending.results))
        });
        let sent = pending
            .request
            .loan_slice_uninit(bytes.len())
            .map_err(|e| format!("{e:?}"))
            .and_then(|r| {
                r.write_from_slice(&bytes)
                    .send()
                    .map_err(|e| format!("{e:?}"))
            });
        if let Err(e) = sent {
            tracing::warn!(client = format!("{client:032x}"), "reply failed: {e}");
        }
        self.clients.wake(&self.node, client);
    }

    /// What the plane workers reported: answers of parked requests, failed planes.
    pub(crate) fn handle_events(&mut self) {
        while let Ok(event) = self.events.try_recv() {
            match event {
                Event::Done {
                    ticket,
                    plane,
                    results,
                    failed,
                } => {
                    if failed {
                        self.remove_plane(plane);
                    }
                    let Some(client) = self.tickets.remove(&ticket) else {
                        continue;
                    };
                    let Some(pending) = self
                        .queues
                        .get_mut(&client)
                        .and_then(|q| q.front_mut())
                        .filter(|p| p.waiting == Some(ticket))
                    else {
                        continue;
                    };
                    pending.count(results);
                    pending.waiting = None;
                    self.advance(client);
                }
                Event::Failed { plane } => self.remove_plane(plane),
            }
        }
    }

    /// Applies a run of ops for plane `id` at once when its worker is idle and nothing is
    /// queued for it (see [`PlaneCell::try_apply`]); otherwise hands it to the worker, and
    /// the ticket names its answer.
    pub(crate) fn send_job(&mut self, id: PlaneId, ops: Vec<shm_layout::PlaneOp>) -> Routed {
        let budget = self.budget();
        let n = ops.len();
        let Some(entry) = self.planes.get(&id) else {
            return Routed::Now((0..n).map(|_| Err(unknown_plane(id))).collect());
        };
        let ops = match entry.cell.try_apply(id, ops, &budget, &entry.usage) {
            Inline::Applied {
                results,
                failed,
                reschedule,
            } => {
                if failed {
                    self.remove_plane(id);
                } else if reschedule {
                    let _ = entry.jobs.send(Job::Reschedule);
                }
                return Routed::Now(results);
            }
            Inline::HandOver(ops) => ops,
        };
        let ticket = self.next_ticket;
        self.next_ticket += 1;
        entry.cell.handed_over();
        match entry.jobs.send(Job::Run {
            ticket,
            ops,
            budget,
        }) {
            Ok(()) => Routed::Wait(ticket),
            Err(_) => Routed::Now((0..n).map(|_| Err(unknown_plane(id))).collect()),
        }
    }

    /// Drops a plane (its worker finishes what is queued, then ends) and forgets it in its
    /// owner's list.
    pub(crate) fn remove_plane(&mut self, id: PlaneId) {
        if let Some(entry) = self.planes.remove(&id) {
            let _ = entry.jobs.send(Job::Stop);
            if let Some(c) = self.clients.get_mut(entry.owner) {
                c.planes.retain(|p| *p != id);
            }
        }
    }

    /// Ends every worker and waits for them (their planes' shared memory is gone after).
    pub(crate) fn stop_workers(&mut self) {
        let ids: Vec<PlaneId> = self.planes.keys().copied().collect();
        for id in ids {
            self.remove_plane(id);
        }
        for worker in self.workers.drain(..) {
            let _ = worker.join();
        }
    }

    pub(crate) fn release_client(&mut self, client: u128) {
        let owned: Vec<PlaneId> = self
            .planes
            .iter()
            .filter(|(_, p)| p.owner == client)
            .map(|(id, _)| *id)
            .collect();
        let owned = self.orphan_persistent(owned);
        for id in &owned {
            self.remove_plane(*id);
        }
        self.clients.disconnect(client);
        // The resource guard's Hello clock for its node starts again now (a Goodbye and a
        // Hello again on the same node are not a node that never said Hello).
        self.update_watch();
        // Its snapshot transfers (a half-sent restore, an unread download) go with it.
        self.transfers.remove(&client);
        tracing::info!(
            client = format!("{client:032x}"),
            planes_released = owned.len(),
            "client released"
        );
    }

    /// Whether this daemon was started on demand by a process that no longer runs (a
    /// zombie counts as gone).
    pub(crate) fn starter_gone(&self) -> bool {
        let Some(pid) = self.options.starter_pid else {
            return false;
        };
        match std::fs::read_to_string(format!("/proc/{pid}/stat")) {
            // The state follows the parenthesised command name.
            Ok(stat) => stat
                .rsplit_once(") ")
                .is_some_and(|(_, rest)| rest.starts_with('Z') || rest.starts_with('X')),
            Err(_) => true,
        }
    }

    /// Tells the resource guard who is connected and which planes exist.
    pub(crate) fn update_watch(&self) {
        self.watch
            .update(self.clients.ids(), self.planes.keys().copied());
    }

    pub(crate) fn release_gone_clients(&mut self) {
        // Listing nodes reads every node of the domain: only when a client's process exited,
        // a node came or went, or rarely (`schedule::Schedule`).
        let clients = &self.clients;
        let all_alive = || {
            clients.ids().all(|id| {
                clients
                    .get(id)
                    .is_some_and(|c| schedule::process_alive(c.pid))
            })
        };
        let pids = clients
            .ids()
            .filter_map(|id| clients.get(id).map(|c| c.pid));
        let folder = self.config.global.node_dir().to_string();
        if !self.liveness.list_now(pids, &folder, all_alive) {
            return;
        }
        for client in self.clients.reap(&self.config) {
            tracing::warn!(client = format!("{client:032x}"), "client process is gone");
            // Its requests go unanswered: nobody waits for them.
            self.queues.remove(&client);
            self.release_client(client);
        }
    }
}

//! Planes that move between the daemons of a cluster (`Plane::move_to`, docs/cluster.md
//! "Migration"). The user keeps the same `Plane` and `Object` values: a moved plane's
//! per-plane state (`PlaneShared`) gets a `Route` to a connection to its new daemon (a
//! remote client of the cluster, kept by the client that switched it) and its id there;
//! every command for it is sent there from then on, and its ticks are read from there.
//!
//! A client learns of a move from its own `move_to`, or from the old daemon's refusal
//! ([`shm_layout::migrate::Moved`]) of a command that reached it after the cut: the command
//! was not applied, so it is sent again to the new daemon once switched (exactly once in
//! all). A reader that only waits for ticks asks the old daemon when a wait brings none.

use shm_layout::migrate::Moved;
use shm_layout::{Command, CommandResult, PlaneId, PlaneOp, Reply};

use crate::client::{unexpected, Rerouted};
use crate::cluster::ClusterOptions;
use crate::plane_shared::Route;
use crate::remote::RemoteOptions;
use crate::{client::Client, error::Error, plane::Plane};

impl Client {
    /// Sends again, to the plane's new daemon, every command the old one refused because
    /// its plane moved (switching this client's plane over first).
    pub(crate) fn resend_moved(
        &self,
        commands: &[Command],
        results: &mut [CommandResult],
    ) -> Result<(), Error> {
        for (command, result) in commands.iter().zip(results.iter_mut()) {
            let (Command::Plane { plane, .. }, Err(e)) = (command, &*result) else {
                continue;
            };
            let Some(moved) = Moved::from_error(*plane, e) else {
                continue;
            };
            let Some(shared) = self.attached(*plane) else {
                // Not a plane of this client's: the refusal says where it went.
                continue;
            };
            let switched = shared.route.borrow().as_ref().is_some_and(|r| {
                r.id == moved.plane
                    && Client::upgrade(&r.peer)
                        .is_some_and(|p| p.cluster_daemon() == Some(moved.daemon.as_str()))
            });
            if !switched {
                // The owner of a plane moved by `--rebalance` learns its claim key here.
                self.switch_plane(*plane, &moved, moved.key)?;
            }
            let again = match self.reroute(command.clone()) {
                Rerouted::Here(c) => self.send(vec![c])?,
                Rerouted::There(peer, c) => peer.send(vec![c])?,
            };
            if let Some(r) = again.into_iter().next() {
                *result = r;
            }
        }
        Ok(())
    }

    /// Switches this client's plane `id` over to where `moved` says it lives; `key`
    /// (non-zero for its owner) claims it there.
    pub(crate) fn switch_plane(&self, id: PlaneId, moved: &Moved, key: u128) -> Result<(), Error> {
        let Some(shared) = self.attached(id) else {
            return Ok(());
        };
        let peer = self.peer_for(moved)?;
        let bodies = peer.transport().plane_bodies(moved.plane)?;
        *shared.bodies.borrow_mut() = bodies;
        *shared.ticks.borrow_mut() = None;
        *shared.events.borrow_mut() = None;
        *shared.route.borrow_mut() = Some(Route {
            peer: peer.downgrade(),
            id: moved.plane,
        });
        peer.remember_plane(moved.plane, shared.clone());
        if key != 0 {
            peer.call(Command::plane(moved.plane, PlaneOp::ClaimMoved { key }))?;
            peer.note_owned(moved.plane);
        }
        if !peer.same(self) || id != moved.plane {
            self.requeue_to(id, &peer, moved.plane);
        }
        // Asking after subscribing makes the daemon hand the newest tick to the new reader.
        peer.call(Command::plane(moved.plane, PlaneOp::Info))?;
        tracing::debug!(
            plane = id,
            daemon = moved.daemon,
            id_there = moved.plane,
            "plane moved: switched over"
        );
        Ok(())
    }

    /// The connection to `moved.daemon` (see [`Client::peer_named`]).
    fn peer_for(&self, moved: &Moved) -> Result<Client, Error> {
        self.peer_named(&moved.daemon, &moved.cluster, Some(&moved.endpoint))
    }

    /// The connection to daemon `daemon` of `cluster`: this one, one made before, or a new
    /// remote client of the cluster (through this client's own cluster options, or
    /// `endpoint`: one the old daemon named).
    pub(crate) fn peer_named(
        &self,
        daemon: &str,
        cluster: &str,
        endpoint: Option<&str>,
    ) -> Result<Client, Error> {
        if self.cluster_daemon() == Some(daemon) {
            return Ok(self.clone());
        }
        if let Some(peer) = self.peers().borrow().get(daemon) {
            return Ok(peer.clone());
        }
        let remote = match (self.remote_options(), endpoint) {
            (Some(r), _) => RemoteOptions {
                daemon: Some(daemon.to_string()),
                ..r.clone()
            },
            (None, Some(endpoint)) => RemoteOptions {
                cluster: ClusterOptions {
                    cluster: cluster.to_string(),
                    endpoints: vec![endpoint.to_string()],
                    ..Default::default()
                },
                daemon: Some(daemon.to_string()),
            },
            (None, None) => {
                return Err(Error::Cluster(format!(
                    "cannot reach daemon {daemon:?}: this client knows no endpoint of cluster \
                     {cluster:?}"
                )))
            }
        };
        let peer = Client::connect_cluster_with(&remote, self.connect_options().clone())?;
        self.peers()
            .borrow_mut()
            .insert(daemon.to_string(), peer.clone());
        Ok(peer)
    }
}

impl Plane {
    /// Moves the plane to daemon `daemon` of the cluster (owner only; 3D planes only): the
    /// queued writes are sent first (they are in the moved state), the plane stops between
    /// two ticks on its daemon and goes on from the same tick on `daemon` with the same
    /// objects and handles; this handle, its objects and every other client of the plane
    /// switch over. Moving to the daemon it is on does nothing.
    pub fn move_to(&self, daemon: &str) -> Result<(), Error> {
        self.move_to_at(daemon).map(|_| ())
    }

    /// [`Plane::move_to`] that returns the tick the plane stopped at (its last on the old
    /// daemon; the new daemon's first is the next).
    pub fn move_to_at(&self, daemon: &str) -> Result<u64, Error> {
        let (via, id) = self.via();
        let reply = via.call(Command::plane(
            id,
            PlaneOp::MoveTo {
                daemon: daemon.to_string(),
            },
        ))?;
        match reply {
            Reply::Moved { key: 0, tick, .. } => Ok(tick),
            Reply::Moved {
                daemon,
                plane,
                key,
                cluster,
                endpoint,
                tick,
            } => {
                let moved = Moved {
                    from_id: id,
                    daemon,
                    plane,
                    cluster,
                    endpoint,
                    key,
                };
                via.switch_plane(id, &moved, key).map(|_| tick)
            }
            other => Err(unexpected(other)),
        }
    }

    /// Pins the plane to its daemon (owner only): `--rebalance` never moves it away (a plane
    /// placed on a daemon by name). [`Plane::move_to`] still moves it.
    pub fn pin(&self) -> Result<(), Error> {
        let (via, id) = self.via();
        via.call(Command::plane(id, PlaneOp::Pin)).map(|_| ())
    }

    /// The cluster daemon the plane lives on (`None`: this host's daemon, outside a
    /// cluster connection). Follows moves.
    pub fn daemon(&self) -> Option<String> {
        self.via().0.cluster_daemon().map(str::to_string)
    }

    /// The connection the plane's commands go to now, and its id there.
    pub(crate) fn via(&self) -> (Client, PlaneId) {
        let route = self
            .shared
            .route
            .borrow()
            .as_ref()
            .and_then(|r| Some((Client::upgrade(&r.peer)?, r.id)));
        route.unwrap_or_else(|| (self.client().clone(), self.id()))
    }

    /// While a wait brings no tick: fails when the plane's daemon is gone, and otherwise
    /// asks it about the plane, so a plane that moved is switched over (the refusal does it).
    pub(crate) fn look_for_move(&self) -> Result<(), Error> {
        let (via, id) = self.via();
        if let Err(e) = via.check_daemon() {
            // A daemon that died: a persistent plane goes on where it was taken over.
            return match e {
                Error::DaemonGone { .. } if via.fail_over(id)? => Ok(()),
                e => Err(e),
            };
        }
        match via.send(vec![Command::plane(id, PlaneOp::Info)]) {
            Err(
                e @ (Error::DaemonGone { .. }
                | Error::NoDaemon { .. }
                | Error::Stalled { .. }
                | Error::Timeout(_)),
            ) => Err(e),
            _ => Ok(()),
        }
    }
}

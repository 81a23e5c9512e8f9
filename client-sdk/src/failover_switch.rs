//! Switching a remote client's persistent plane over to the member that took it over when
//! its daemon died (docs/cluster.md "Failover"): instead of `DaemonGone`, the client finds
//! the member that adopted the plane (the holder alive with the smallest name, as the
//! daemons choose it), opens the plane there by name, routes the same `Plane` and `Object`
//! values to it (as after a move, `moving`) and keeps the ticks the old daemon ran past the
//! replicated snapshot for [`Plane::take_recovered`] (`plane.Recovered` in Luau).
//!
//! Only remote clients switch (they know the cluster); a local client of a daemon that
//! died has no cluster to ask.

use std::time::{Duration, Instant};

use shm_layout::{Command, ErrorKind, PlaneId, PlaneOp, Reply};

use crate::plane_shared::Route;
use crate::transport::Transport;
use crate::{client::Client, error::Error, plane::Plane};

/// How long a client looks for the member that adopts its plane (the member sees the
/// daemon's token end at once for a killed process, within the 3 s lease for a host that
/// vanished; then restores the plane).
pub const FAILOVER_WAIT: Duration = Duration::from_secs(10);

impl Client {
    /// After this client's daemon died: switches its plane `id` to the member that adopted
    /// it. `Ok(false)`: nothing to switch (a local client, a plane that is not persistent,
    /// or no member took it within [`FAILOVER_WAIT`]).
    pub(crate) fn fail_over(&self, id: PlaneId) -> Result<bool, Error> {
        let Transport::Remote(transport) = self.transport() else {
            return Ok(false);
        };
        let Some(shared) = self.attached(id) else {
            return Ok(false);
        };
        let Some(name) = shared.persistent_name.borrow().clone() else {
            return Ok(false);
        };
        // The newest tick this client saw on the daemon that died.
        let seen = shared.current_tick();
        let gone = transport.daemon().to_string();
        let cluster = transport.cluster().to_string();
        let deadline = Instant::now() + FAILOVER_WAIT;
        while Instant::now() < deadline {
            let mut holders = transport.holders();
            holders.retain(|h| *h != gone);
            holders.sort();
            for holder in holders {
                let Ok(peer) = self.peer_named(&holder, &cluster, None) else {
                    continue;
                };
                let opened = match peer.call(Command::OpenPlane { name: name.clone() }) {
                    Ok(Reply::Opened(o)) => o,
                    Err(Error::Command(e)) if e.kind == ErrorKind::UnknownPlane => continue,
                    _ => continue,
                };
                let bodies = peer.transport().plane_bodies(opened.id)?;
                *shared.bodies.borrow_mut() = bodies;
                *shared.ticks.borrow_mut() = None;
                *shared.events.borrow_mut() = None;
                *shared.latest.borrow_mut() = None;
                *shared.overlay.borrow_mut() = Default::default();
                *shared.members.borrow_mut() = Default::default();
                shared.mirror.borrow_mut().forget_all();
                *shared.route.borrow_mut() = Some(Route {
                    peer: peer.downgrade(),
                    id: opened.id,
                });
                peer.remember_plane(opened.id, shared.clone());
                self.requeue_to(id, &peer, opened.id);
                if opened.owner {
                    peer.note_owned(opened.id);
                }
                // Asking after subscribing makes the daemon hand the newest tick at once.
                let resumed = match peer.call(Command::plane(opened.id, PlaneOp::Info))? {
                    Reply::Plane(info) => Some(info.tick),
                    _ => None,
                };
                // The daemon counts the lost ticks from the replicated tick record, which can
                // lag the old daemon by a few hundred milliseconds (and tells only the first
                // opener); the ticks this client saw past the tick the plane resumed at are
                // lost too, so they are a floor.
                let seen_lost = seen.zip(resumed).map_or(0, |(s, r)| s.saturating_sub(r));
                shared
                    .recovered
                    .set(Some(opened.recovered.unwrap_or_default().max(seen_lost)));
                tracing::warn!(
                    plane = id,
                    name,
                    from = gone,
                    to = holder,
                    recovered = ?opened.recovered,
                    "daemon gone: the plane goes on on the member that took it over"
                );
                return Ok(true);
            }
            std::thread::sleep(Duration::from_millis(50));
        }
        Ok(false)
    }
}

impl Plane {
    /// `Some(lost_ticks)` once after the plane came back on another member of the cluster
    /// because its daemon died (the ticks the old daemon ran past the replicated snapshot it
    /// resumed from); `None` otherwise.
    pub fn take_recovered(&self) -> Option<u64> {
        self.shared.recovered.take()
    }
}

//! The batch: writes queued until a flush (or a call that needs an answer), one request
//! per flush, and their results applied: confirmed handles, refusals kept for the next
//! call into their plane, frames.

use std::time::Instant;

use shm_layout::{
    Command, CommandError, CommandResult, GuiControllerOp, GuiObjectOp, GuiOp, Handle, ObjectOp,
    PlaneId, PlaneOp, Reply,
};

use crate::error::Error;

use super::{Client, Queued, Refusal, Rerouted, Sent};

impl Client {
    /// Sends every queued write as one request. Errors of individual commands (including
    /// ones sent along with earlier calls) come back together; the others were applied.
    ///
    /// With [`ConnectOptions::refusals_at_next_call`] the refusals stay with their planes
    /// for the next call into each (or [`Client::take_refused`]), and `flush` does not wait
    /// for the daemon: it sends the writes and returns (pipelined; on this host's
    /// transport). The daemon applies them in order before any later request of this
    /// client; their reply is collected by the next request, the next
    /// [`Client::begin_frame`] or the next read that takes a new sample, and until then
    /// reads show the writes (read-your-writes). A frame that ends with a flush therefore
    /// never waits for a step the daemon is in the middle of. `flush` then reports a
    /// failure to send, or a failure of the previous flush's request (the daemon gone).
    ///
    /// [`ConnectOptions::refusals_at_next_call`]: crate::ConnectOptions::refusals_at_next_call
    pub fn flush(&self) -> Result<(), Error> {
        if self.inner.options.refusals_at_next_call {
            return self.send_queues(true);
        }
        self.send_queue()?;
        let mut deferred = self.take_refused(None);
        // Refusals of writes to planes that moved to other daemons.
        for peer in self.inner.peers.borrow().values() {
            deferred.extend(peer.take_refused(None));
        }
        if deferred.is_empty() {
            Ok(())
        } else {
            Err(Error::Batch(deferred))
        }
    }

    /// Takes the refused writes not reported yet: of plane `plane`, or of every plane
    /// (`None`, which also takes refusals of commands that name no plane).
    pub fn take_refused(&self, plane: Option<PlaneId>) -> Vec<CommandError> {
        // A pipelined flush's refusals count too. A failure to collect them stays for the
        // next call to report.
        if let Err(e) = self.collect_in_flight(true) {
            *self.inner.in_flight_error.borrow_mut() = Some(e);
        }
        let mut state = self.inner.state.borrow_mut();
        if state.deferred.is_empty() {
            return Vec::new();
        }
        let (taken, kept) = std::mem::take(&mut state.deferred)
            .into_iter()
            .partition(|r| plane.is_none() || r.plane == plane);
        state.deferred = kept;
        taken.into_iter().map(|r| r.error).collect()
    }

    /// Gives the client a way to ask the host which line of its script queues a write
    /// (0: none), so that a write refused later names it ("written at line 12"). Asked
    /// once per queued write.
    pub fn set_origin(&self, origin: impl Fn() -> u32 + 'static) {
        *self.inner.origin.borrow_mut() = Some(Box::new(origin));
    }

    /// Starts a frame of a host's frame loop: from now until the next call, object reads
    /// (`pose`, `state`, ...) take each plane's newest sample once, at their first read in
    /// the frame, instead of looking for a newer one at every read (`Plane::step`,
    /// `wait_tick` and `snapshot` still take the newest at once). Without it every read
    /// looks.
    pub fn begin_frame(&self) {
        self.inner.frame.set(self.inner.frame.get() + 1);
        // The last frame's pipelined flush, if its reply is here (usually: a frame later).
        let _ = self.collect_in_flight(false);
    }

    /// The frame of [`Client::begin_frame`] (0 before the first).
    /// Lets the next request poll for its reply for up to `spin` before sleeping (a `Step`,
    /// whose reply is due after about the plane's last step time: see [`crate::spin`]).
    pub(crate) fn spin_next_reply(&self, spin: std::time::Duration) {
        self.inner.reply_spin.set(spin);
    }

    pub(crate) fn frame(&self) -> u64 {
        self.inner.frame.get()
    }

    /// Number of writes waiting for the next flush.
    pub fn queued(&self) -> usize {
        self.inner.state.borrow().queue.len()
    }

    /// Sends the queue plus `command` and returns the reply to `command`.
    ///
    /// With [`ConnectOptions::refusals_at_next_call`], a call into a plane first reports the
    /// plane's refused writes ([`Error::Refused`]) instead of running, and a call that
    /// creates nothing (a step, a write) also reports the refusals its own request brought
    /// back, after it ran; a creating call keeps them for the next call, so its handle is
    /// never lost.
    pub(crate) fn call(&self, command: Command) -> Result<Reply, Error> {
        // The refusals of a pipelined flush are reported before the next call into their
        // plane, as those of any earlier request.
        self.collect_in_flight(true)?;
        // A plane that moved: its commands go to its new daemon, under its id there.
        let command = match self.reroute(command) {
            Rerouted::Here(command) => command,
            Rerouted::There(peer, command) => return peer.call(command),
        };
        let plane = match (&command, self.inner.options.refusals_at_next_call) {
            (Command::Plane { plane, op }, true) => {
                let refused = self.take_refused(Some(*plane));
                // A plane that goes away takes its refusals with it.
                if !refused.is_empty() && !matches!(op, PlaneOp::Destroy) {
                    return Err(Error::Refused(refused));
                }
                Some(*plane)
            }
            _ => None,
        };
        // A remote client's persistent plane outlives its daemon (`failover_switch`): keep
        // the command to send it again where the plane was taken over.
        let again = match &command {
            Command::Plane { plane, .. } if self.remote_options().is_some() => {
                Some((*plane, command.clone()))
            }
            _ => None,
        };
        let mut results = match (self.send(vec![command]), again) {
            (Err(Error::DaemonGone { .. }), Some((plane, command))) if self.fail_over(plane)? => {
                return self.call(command);
            }
            (results, _) => results?,
        };
        match results.pop() {
            Some(Ok(reply @ (Reply::Stepped { .. } | Reply::Applied { .. } | Reply::Done)))
                if plane.is_some() =>
            {
                let refused = self.take_refused(plane);
                match refused.is_empty() {
                    true => Ok(reply),
                    false => Err(Error::Refused(refused)),
                }
            }
            Some(Ok(reply)) => Ok(reply),
            Some(Err(e)) => Err(Error::Command(e)),
            None => Err(Error::Protocol("empty reply".into())),
        }
    }

    pub(crate) fn queue(&self, command: Command, confirms: Option<(PlaneId, Handle)>) {
        self.queue_with(command, confirms, None);
    }

    /// Queues an impulse on `handle` of `plane` whose reply carries the velocity after it,
    /// recorded under overlay ticket `ticket`.
    pub(crate) fn queue_impulse(
        &self,
        command: Command,
        plane: PlaneId,
        handle: Handle,
        ticket: u32,
    ) {
        self.queue_with(command, Some((plane, handle)), Some(ticket));
    }

    pub(super) fn queue_with(
        &self,
        command: Command,
        confirms: Option<(PlaneId, Handle)>,
        impulse: Option<u32>,
    ) {
        let (command, confirms) = match self.reroute(command) {
            Rerouted::Here(command) => (command, confirms),
            Rerouted::There(peer, command) => {
                let confirms = confirms.map(|(_, h)| (command_plane(&command), h));
                return peer.queue_with(command, confirms, impulse);
            }
        };
        let confirms = confirms.map(|(_, h)| (command_plane(&command), h));
        self.inner.state.borrow_mut().queue.push(Queued {
            command,
            confirms,
            origin: self.inner.origin.borrow().as_ref().map_or(0, |f| f()),
            impulse,
        });
    }

    /// Sends the queued writes now, if any (their refusals are kept as for any send).
    pub(crate) fn send_queue(&self) -> Result<(), Error> {
        self.send_queues(false)
    }

    /// This connection's queued writes and those of the planes that moved to other
    /// daemons, each as one request: `pipelined`, without waiting for the answers
    /// ([`Client::flush`] with [`ConnectOptions::refusals_at_next_call`]).
    pub(super) fn send_queues(&self, pipelined: bool) -> Result<(), Error> {
        if !self.inner.state.borrow().queue.is_empty() {
            match pipelined {
                true => self.send_pipelined()?,
                false => self.send(Vec::new()).map(|_| ())?,
            }
        }
        let peers: Vec<Client> = self.inner.peers.borrow().values().cloned().collect();
        for peer in peers {
            peer.send_queues(pipelined)?;
        }
        Ok(())
    }

    /// One request: the queued commands first, then `extra`. Returns the results of `extra`.
    pub(crate) fn send(&self, extra: Vec<Command>) -> Result<Vec<CommandResult>, Error> {
        // A pipelined flush's reply comes first: replies are applied in request order.
        self.collect_in_flight(true)?;
        let (sent, commands) = self.take_queue(extra);
        let (results, commands) = self.inner.round_trip_keeping(commands)?;
        self.apply_results(sent, commands, results)
    }

    /// Takes the queue (plus `extra`) as one request's commands and what applying their
    /// results needs.
    pub(super) fn take_queue(&self, extra: Vec<Command>) -> (Sent, Vec<Command>) {
        let queued = std::mem::take(&mut self.inner.state.borrow_mut().queue);
        let n_queued = queued.len();
        let mut sent = Sent {
            n_queued,
            confirms: Vec::with_capacity(n_queued),
            targets: Vec::with_capacity(n_queued),
            releases: Vec::with_capacity(n_queued),
            origins: Vec::with_capacity(n_queued),
        };
        let mut commands = Vec::with_capacity(n_queued + extra.len());
        for q in queued {
            sent.origins.push((q.origin, q.impulse));
            sent.confirms.push(q.confirms);
            sent.releases.push(is_release(&q.command));
            sent.targets.push(match &q.command {
                Command::Plane {
                    plane,
                    op: PlaneOp::Object { handle, op },
                } => Some((*plane, Some(*handle), matches!(op, ObjectOp::Destroy))),
                Command::Plane {
                    plane,
                    op:
                        PlaneOp::Gui(
                            GuiOp::Object {
                                handle,
                                op: GuiObjectOp::Destroy,
                            }
                            | GuiOp::Controller {
                                handle,
                                op: GuiControllerOp::Destroy,
                            },
                        ),
                } => Some((*plane, Some(*handle), true)),
                Command::Plane { plane, .. } => Some((*plane, None, false)),
                _ => None,
            });
            commands.push(q.command);
        }
        commands.extend(extra);
        (sent, commands)
    }

    /// Applies a request's results: the queued writes' confirmations and refusals (kept
    /// for later: `deferred`); returns the results of the commands after them.
    pub(super) fn apply_results(
        &self,
        sent: Sent,
        commands: Vec<Command>,
        mut results: Vec<CommandResult>,
    ) -> Result<Vec<CommandResult>, Error> {
        let Sent {
            n_queued,
            confirms,
            targets,
            releases,
            origins,
        } = sent;
        // A reply is a sign of life as good as a beat.
        self.inner.last_beat.set(Instant::now());
        // Refused because their plane moved (not applied): switch over, send them again.
        self.resend_moved(&commands, &mut results)?;
        let extra_results = results.split_off(n_queued.min(results.len()));
        let mut state = self.inner.state.borrow_mut();
        let each = results.into_iter().zip(confirms).zip(targets).zip(releases);
        for ((((result, confirm), target), release), (origin, impulse)) in each.zip(origins) {
            if release {
                // The SDK's own release of a held add: nothing the caller asked for, and an
                // object already gone has nothing left to release.
                continue;
            }
            if let (Err(_), Some((plane, handle, _))) = (&result, target) {
                // A rejected write must not linger in the mirror either.
                if let Some(p) = state.planes.get(&plane) {
                    let mut mirror = p.mirror.borrow_mut();
                    match handle {
                        Some(h) => mirror.forget_object(h),
                        None => mirror.forget_plane(),
                    }
                }
            }
            if let Some((plane, Some(handle), true)) = target {
                // A removal counts in the plane's object count until a tick shows it.
                if let Some(p) = state.planes.get(&plane) {
                    let mut members = p.members.borrow_mut();
                    match &result {
                        Ok(Reply::Applied { tick }) => members.removal_applied(handle, *tick),
                        _ => members.removal_refused(handle),
                    }
                }
            }
            match (result, confirm) {
                (Ok(Reply::Velocity { tick, linear }), Some((plane, handle))) => {
                    if let (Some(p), Some(ticket)) = (state.planes.get(&plane), impulse) {
                        p.impulse_applied(handle, ticket, linear, tick);
                    }
                }
                (Ok(Reply::Applied { tick }), Some((plane, handle))) => {
                    if let Some(p) = state.planes.get(&plane) {
                        p.confirm(handle, tick);
                    }
                }
                (Ok(_), _) => {}
                (Err(mut error), confirm) => {
                    // A rejected write must not linger as if it had happened.
                    if let Some((plane, handle)) = confirm {
                        if let Some(p) = state.planes.get(&plane) {
                            p.discard(handle);
                        }
                    }
                    if origin > 0 {
                        error.message = format!("{} (written at line {origin})", error.message);
                    }
                    let plane = target.map(|(plane, _, _)| plane);
                    state.deferred.push(Refusal { plane, error });
                }
            }
        }
        Ok(extra_results)
    }
}

/// The plane a command names (0: none).
fn command_plane(command: &Command) -> PlaneId {
    match command {
        Command::Plane { plane, .. } => *plane,
        _ => 0,
    }
}

/// Whether `command` is the release of a held add ([`ConnectOptions::hold_adds_until_flush`]).
fn is_release(command: &Command) -> bool {
    matches!(
        command,
        Command::Plane {
            op: PlaneOp::Object {
                op: ObjectOp::Set(shm_layout::ObjectProp::Held(false)),
                ..
            },
            ..
        } | Command::Plane {
            op: PlaneOp::Gui(GuiOp::Object {
                op: GuiObjectOp::Set(shm_layout::GuiObjectProp::Held(false)),
                ..
            }),
            ..
        }
    )
}

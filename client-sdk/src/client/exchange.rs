//! Round trips: requests encoded and sent, replies decoded, and the wait for a reply that
//! watches the daemon's liveness (gone, stalled, hung) so a dead daemon is an error within
//! a bounded time, not a hang.

use std::time::{Duration, Instant};

use shm_layout::codec;
use shm_layout::{Command, CommandResult, ErrorKind, Reply, Request, Response, LAYOUT_VERSION};

use crate::error::Error;
use crate::transport::LIVENESS_PERIOD;

use super::{Client, DaemonHealth, Inner, HUNG_AFTER, STALL_AFTER, WATCH_STALL_AFTER};

impl Client {
    /// Test support: sends raw request bytes and returns the raw reply.
    #[doc(hidden)]
    pub fn raw_request(&self, bytes: &[u8]) -> Result<Vec<u8>, Error> {
        self.collect_in_flight(true)?;
        self.inner.exchange(bytes, self.inner.transport.id())
    }

    /// Test support: [`Client::raw_request`] with `claimed` written where older clients put
    /// their id (the request's user header), as a forging client would.
    #[doc(hidden)]
    pub fn raw_request_claiming(&self, bytes: &[u8], claimed: u128) -> Result<Vec<u8>, Error> {
        self.collect_in_flight(true)?;
        self.inner.exchange(bytes, claimed)
    }

    /// Test support: this client's iceoryx2 node id.
    #[doc(hidden)]
    pub fn node_id(&self) -> u128 {
        self.inner.transport.id()
    }

    /// Whether the daemon is live, stalled or gone, without a request: for a host that only
    /// reads shared memory (which would otherwise run on against frozen poses). Cheap
    /// enough for every frame: one check of the heartbeat's queue; `/proc` and the node list
    /// are read only once the heartbeat has been silent for [`WATCH_STALL_AFTER`].
    pub fn watch_daemon(&self) -> DaemonHealth {
        let inner = &self.inner;
        if inner.state.borrow().gone {
            return DaemonHealth::Gone;
        }
        let now = Instant::now();
        match inner.transport.heartbeat_arrived() {
            Some(true) => inner.last_beat.set(now),
            // A remote daemon: its liveliness token says whether it lives.
            None if inner.check_daemon().is_err() => return DaemonHealth::Gone,
            None => return DaemonHealth::Live,
            Some(false) => {}
        }
        let silent = now.duration_since(inner.last_beat.get());
        if silent < WATCH_STALL_AFTER {
            return DaemonHealth::Live;
        }
        if now.duration_since(inner.last_node_check.get()) >= LIVENESS_PERIOD {
            inner.last_node_check.set(now);
            if inner.check_daemon().is_err() {
                return DaemonHealth::Gone;
            }
        }
        if silent > HUNG_AFTER || process_stopped(inner.daemon_pid) {
            DaemonHealth::Stalled { silent }
        } else {
            DaemonHealth::Live
        }
    }

    /// Fails with [`Error::DaemonGone`] when the daemon process no longer exists.
    pub fn check_daemon(&self) -> Result<(), Error> {
        self.inner.check_daemon()
    }
}

impl Inner {
    pub(super) fn round_trip(&self, commands: Vec<Command>) -> Result<Vec<CommandResult>, Error> {
        self.round_trip_keeping(commands)
            .map(|(results, _)| results)
    }

    /// [`Inner::round_trip`] that gives the commands back with their results.
    pub(super) fn round_trip_keeping(
        &self,
        commands: Vec<Command>,
    ) -> Result<(Vec<CommandResult>, Vec<Command>), Error> {
        if self.state.borrow().gone {
            return Err(self.gone());
        }
        let request = Request { commands };
        let n = request.commands.len();
        let bytes = self.encode(&request);
        let reply = self.exchange(&bytes, self.transport.id())?;
        let results = self.results_of(&reply, n)?;
        let results = self.rejoin_if_forgotten(&request.commands, results)?;
        Ok((results, request.commands))
    }

    /// A daemon that forgot this client (it said Goodbye, or was released) answers
    /// `NotConnected` to every command from the first one it refused: say Hello again and
    /// send those commands once more. The commands before it were applied and are not sent
    /// twice. Planes released with the old connection stay gone (their commands then fail
    /// with `UnknownPlane`).
    pub(super) fn rejoin_if_forgotten(
        &self,
        commands: &[Command],
        mut results: Vec<CommandResult>,
    ) -> Result<Vec<CommandResult>, Error> {
        let refused = results
            .iter()
            .position(|r| matches!(r, Err(e) if e.kind == ErrorKind::NotConnected));
        let Some(first) = refused else {
            return Ok(results);
        };
        if self.daemon_node == 0 || matches!(commands[first], Command::Hello { .. }) {
            return Ok(results);
        }
        tracing::debug!("the daemon forgot this client: saying Hello again");
        let hello = Command::Hello {
            crate_version: self.options.crate_version.clone(),
            pid: std::process::id(),
        };
        match self.round_trip_once(vec![hello])?.pop() {
            Some(Ok(Reply::Welcome { .. })) => {}
            Some(Err(e)) => return Err(e.into()),
            other => {
                return Err(Error::Protocol(format!(
                    "unexpected handshake reply {other:?}"
                )))
            }
        }
        let again = commands[first..].to_vec();
        let retried = self.round_trip_once(again)?;
        results.truncate(first);
        results.extend(retried);
        Ok(results)
    }

    /// One request and its results, without the re-handshake of [`Inner::round_trip`].
    pub(super) fn round_trip_once(
        &self,
        commands: Vec<Command>,
    ) -> Result<Vec<CommandResult>, Error> {
        let n = commands.len();
        let request = Request { commands };
        let bytes = self.encode(&request);
        let reply = self.exchange(&bytes, self.transport.id())?;
        self.results_of(&reply, n)
    }

    /// The bytes of `request` in this client's layout version.
    pub(super) fn encode(&self, request: &Request) -> Vec<u8> {
        if self.options.layout_version == LAYOUT_VERSION {
            codec::encode_request(request)
        } else {
            codec::encode_request_with_version(request, self.options.layout_version)
        }
    }

    /// The results of a reply to `n` commands.
    pub(super) fn results_of(&self, reply: &[u8], n: usize) -> Result<Vec<CommandResult>, Error> {
        let frame = codec::Frame::parse(reply).map_err(|e| Error::Protocol(e.to_string()))?;
        if frame.version != self.options.layout_version {
            // The daemon answered in the version-neutral form: its crate version as text.
            return Err(Error::VersionMismatch(format!(
                "layout version mismatch: client has LAYOUT_VERSION {} (crate {}), daemon has \
                 LAYOUT_VERSION {} (crate {})",
                self.options.layout_version,
                self.options.crate_version,
                frame.version,
                String::from_utf8_lossy(frame.body),
            )));
        }
        match codec::decode_response(reply) {
            Ok(Response::Results(results)) if results.len() == n => Ok(results),
            Ok(Response::Results(results)) => Err(Error::Protocol(format!(
                "{n} commands sent, {} results received",
                results.len()
            ))),
            Ok(Response::Rejected(e)) => Err(Error::Command(e)),
            Err(e) => Err(Error::Protocol(e.to_string())),
        }
    }

    /// Sends raw request bytes and waits for the raw reply, checking the daemon's liveness
    /// while waiting so a dead daemon is an error within a bounded time, not a hang.
    /// A beat buffered from before the request can delay a stall verdict by one check
    /// (100 ms) at most, so the request's hot path does not drain the heartbeat first.
    pub(super) fn exchange(&self, bytes: &[u8], header: u128) -> Result<Vec<u8>, Error> {
        let spin = self.reply_spin.take();
        self.transport.exchange(
            bytes,
            header,
            LIVENESS_PERIOD,
            spin,
            self.waiting(Instant::now()),
        )
    }

    /// Waits for a pipelined flush's reply as [`Inner::exchange`] waits for its own.
    pub(super) fn await_reply(
        &self,
        local: &crate::transport::LocalTransport,
        pending: &crate::transport::PendingReply,
        since: Instant,
    ) -> Result<Vec<u8>, Error> {
        local.await_reply(
            pending,
            LIVENESS_PERIOD,
            Duration::ZERO,
            self.waiting(since),
        )
    }

    /// What a request waiting for its reply since `started` checks between sleeps: the
    /// daemon's liveness, a stall, the request timeout.
    pub(super) fn waiting(&self, started: Instant) -> impl FnMut(bool) -> Result<(), Error> + '_ {
        let mut last_check = started;
        let mut last_beat = started;
        move |connected| {
            if !connected {
                self.check_daemon()?;
            }
            let now = Instant::now();
            if now.duration_since(last_check) >= LIVENESS_PERIOD {
                self.check_daemon()?;
                last_check = now;
                if self.transport.heartbeat_arrived() != Some(false) {
                    last_beat = now;
                    self.last_beat.set(now);
                }
            }
            let silent = now.duration_since(last_beat);
            let stalled =
                silent > HUNG_AFTER || (silent > STALL_AFTER && process_stopped(self.daemon_pid));
            if stalled && self.daemon_node != 0 {
                return Err(Error::Stalled {
                    domain: self.options.domain.clone(),
                    pid: self.daemon_pid,
                    silent,
                });
            }
            if now.duration_since(started) > self.options.request_timeout {
                return Err(Error::Timeout(self.options.request_timeout));
            }
            Ok(())
        }
    }

    pub(crate) fn check_daemon(&self) -> Result<(), Error> {
        match self.transport.daemon_alive(self.daemon_node) {
            Some(false) if self.daemon_node == 0 => Err(Error::NoDaemon {
                domain: self.options.domain.clone(),
                detail: "no live daemon process answers".into(),
            }),
            Some(false) => {
                self.state.borrow_mut().gone = true;
                Err(self.gone())
            }
            _ => Ok(()),
        }
    }

    pub(super) fn gone(&self) -> Error {
        Error::DaemonGone {
            domain: self.options.domain.clone(),
            pid: self.daemon_pid,
        }
    }
}

/// Whether process `pid` is stopped (SIGSTOP, or stopped by a tracer).
fn process_stopped(pid: u32) -> bool {
    std::fs::read_to_string(format!("/proc/{pid}/stat")).is_ok_and(|stat| {
        // The state follows the parenthesised command name.
        stat.rsplit_once(") ")
            .is_some_and(|(_, rest)| rest.starts_with('T') || rest.starts_with('t'))
    })
}

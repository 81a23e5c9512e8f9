//! Connecting: to this host's daemon or to a cluster member through Zenoh, and the
//! handshake (Hello, with its retries while a remote session starts).

use std::cell::RefCell;
use std::rc::Rc;
use std::time::{Duration, Instant};

use shm_layout::{Command, ErrorKind, Reply};

use crate::error::Error;
use crate::remote::{RemoteOptions, RemoteTransport};
use crate::transport::Transport;

use super::{Client, ConnectOptions, Inner};

/// How long the handshake waits for an answer before it asks again.
const HELLO_RETRY: Duration = Duration::from_secs(1);

impl Client {
    /// Connects to the daemon of `domain` and performs the version handshake.
    pub fn connect(domain: &str) -> Result<Client, Error> {
        Self::connect_with(ConnectOptions::new(domain))
    }

    /// Connects with explicit options.
    pub fn connect_with(options: ConnectOptions) -> Result<Client, Error> {
        let transport = Transport::open(&options.domain)?;
        Self::handshake(options, transport)
    }

    /// Connects to a daemon of a physics cluster, on this host or another (docs/cluster.md):
    /// the same API as [`Client::connect`], carried by Zenoh to the daemon's relay. With
    /// `remote.daemon` unset, the live daemon with the smallest share of its tick budget
    /// used is chosen. [`Client::domain`] reads `cluster/daemon`.
    pub fn connect_cluster(remote: &RemoteOptions) -> Result<Client, Error> {
        Self::connect_cluster_with(remote, ConnectOptions::new(""))
    }

    /// [`Client::connect_cluster`] with explicit options (`options.domain` is replaced).
    pub fn connect_cluster_with(
        remote: &RemoteOptions,
        mut options: ConnectOptions,
    ) -> Result<Client, Error> {
        let transport = RemoteTransport::open(remote)?;
        options.domain = format!("{}/{}", transport.cluster(), transport.daemon());
        let client = Self::handshake(options, Transport::Remote(transport))?;
        Ok(client.with_remote(remote.clone()))
    }

    /// The cluster daemon this client uses (`None`: this host's daemon, not through a
    /// cluster).
    pub fn cluster_daemon(&self) -> Option<&str> {
        match &self.inner.transport {
            Transport::Remote(t) => Some(t.daemon()),
            Transport::Local(_) => None,
        }
    }

    pub(super) fn handshake(
        options: ConnectOptions,
        transport: Transport,
    ) -> Result<Client, Error> {
        let mut inner = Inner {
            options,
            transport,
            daemon_node: 0,
            daemon_pid: 0,
            state: RefCell::default(),
            frame: std::cell::Cell::new(0),
            origin: RefCell::new(None),
            last_beat: std::cell::Cell::new(Instant::now()),
            reply_spin: std::cell::Cell::new(std::time::Duration::ZERO),
            last_node_check: std::cell::Cell::new(Instant::now()),
            peers: RefCell::default(),
            remote: None,
            in_flight: RefCell::default(),
            in_flight_error: RefCell::default(),
        };
        let hello = Command::Hello {
            crate_version: inner.options.crate_version.clone(),
            pid: std::process::id(),
        };
        // A Hello can be lost while the daemon evicts another process's ports from the
        // control service (see the daemon's `server/resources.rs`): ask again with fresh
        // ports every HELLO_RETRY, within the request timeout. A remote Hello is a Zenoh query
        // that is not lost that way (the relay opens its session's local connection before it
        // answers, which can take seconds on a loaded host): it gets the whole timeout.
        let timeout = inner.options.request_timeout;
        let deadline = Instant::now() + timeout;
        if inner.transport.is_local() {
            inner.options.request_timeout = timeout.min(HELLO_RETRY);
        }
        let welcome = loop {
            match inner.round_trip(vec![hello.clone()]) {
                Err(Error::Timeout(_))
                    if Instant::now() < deadline && inner.transport.is_local() =>
                {
                    tracing::debug!("no answer to Hello: asking again with new ports");
                    inner.transport = Transport::open(&inner.options.domain)?;
                }
                other => break other,
            }
        };
        inner.options.request_timeout = timeout;
        match welcome?.pop() {
            Some(Ok(Reply::Welcome {
                daemon_pid,
                daemon_node_id,
                ..
            })) => {
                inner.daemon_pid = daemon_pid;
                inner.daemon_node = daemon_node_id;
            }
            Some(Err(e)) if e.kind == ErrorKind::VersionMismatch => {
                return Err(Error::VersionMismatch(e.message))
            }
            Some(Err(e)) => return Err(e.into()),
            other => {
                return Err(Error::Protocol(format!(
                    "unexpected handshake reply {other:?}"
                )))
            }
        }
        Ok(Client {
            inner: Rc::new(inner),
        })
    }

    /// This client with the cluster options it was connected with (peers connect alike).
    pub(super) fn with_remote(self, remote: RemoteOptions) -> Client {
        match Rc::try_unwrap(self.inner) {
            Ok(mut inner) => {
                inner.remote = Some(remote);
                Client {
                    inner: Rc::new(inner),
                }
            }
            Err(inner) => Client { inner },
        }
    }
}

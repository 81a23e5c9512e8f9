//! The daemon's state: [`Daemon`], what it owns (its planes, its clients, their queued
//! requests, the parts of each job), and the options it runs with. It holds only data; what
//! the daemon does lives with each job (`requests`, `persistence`, `moves`, `liveness`), in
//! `impl Daemon` blocks of their own that nothing imports.

use std::collections::{BTreeMap, HashMap, VecDeque};
use std::sync::mpsc::{Receiver, Sender};
use std::sync::Arc;
use std::thread::JoinHandle;

use iceoryx2::active_request::ActiveRequest;
use iceoryx2::config::Config;
use iceoryx2::port::server::Server;
use iceoryx2::prelude::*;
use shm_layout::{Command, CommandResult, PlaneId};

use crate::server::liveness::schedule;
use crate::server::moves::migration::{Migration, Tombstones};
use crate::server::persistence::{persist, transfers};
use crate::server::quotas::limits::Limits;
use crate::server::quotas::{gauge, quota, resources};
use crate::server::requests::clients::Clients;
use crate::server::requests::origin::{self, Origin};
use crate::server::worker::{Event, Job, PlaneCell, SharedUsage, Waker};

/// How the daemon runs beyond its domain.
#[derive(Debug, Clone, Default)]
pub struct Options {
    /// Per-client quotas.
    pub limits: Limits,
    /// The process that started this daemon on demand: once it is gone and no client is
    /// left, the daemon exits.
    pub starter_pid: Option<u32>,
    /// Fault injection for tests: a `Step` with exactly this dt panics inside the plane.
    #[doc(hidden)]
    pub panic_on_step_dt: Option<f32>,
    /// Where persistent planes are written (`--state-dir`, `--snapshot-every`); `None`:
    /// `Persistent = true` is refused.
    pub persistence: Option<persist::Persistence>,
    /// Fed the planes' usage for the cluster's load report (`--cluster`); `None` outside a
    /// cluster.
    pub load: Option<Arc<gauge::Gauge>>,
    /// Planes a cluster peer hands over at run time (failover, `--cluster` with
    /// `--state-dir`); `None` outside a cluster.
    pub adopt: Option<Arc<persist::Adoptions>>,
    /// How planes move to and arrive from other daemons (`--cluster`; `MoveTo`); `None`
    /// outside a cluster.
    pub migrate: Option<Arc<Migration>>,
    /// How planes record (`--record`, `--record-keyframe-every`).
    pub record: crate::record::RecordSettings,
}

/// Planes one daemon hosts at once.
pub const MAX_PLANES: usize = 1024;

/// The user header (u128) is what older clients sent as their id; it is ignored (identity
/// comes from the transport) but kept so the service layout never changes across versions.
pub(crate) type ControlServer = Server<ipc::Service, [u8], u128, [u8], ()>;
pub(crate) type Request = ActiveRequest<ipc::Service, [u8], u128, [u8], ()>;

/// The loop's view of a plane: who may do what, and the way to its worker.
pub(crate) struct PlaneEntry {
    /// Client that created the plane; the plane is released when that client goes away.
    pub(crate) owner: u128,
    /// Other clients may change the plane (only the owner destroys it).
    pub(crate) shared: bool,
    pub(crate) jobs: Sender<Job>,
    /// The plane, shared with its worker (short runs apply inline while the worker idles).
    pub(crate) cell: Arc<PlaneCell>,
    /// What the plane holds, as its worker last saw it (for the owner's other quotas).
    pub(crate) usage: Arc<SharedUsage>,
    /// Its kind.
    pub(crate) kind: shm_layout::PlaneKind,
    /// Its `Name`, unique in the domain (`named`).
    pub(crate) name: Option<shm_layout::PlaneName>,
    /// Written to the state directory and kept when its owner leaves (`persist`).
    pub(crate) persistent: bool,
    /// Restored from a file and not opened yet: the ticks it lost (`Recovered`).
    pub(crate) recovered: Option<u64>,
}

/// A request being served: its commands run in order; the loop parks it while one of its
/// runs is with a plane worker.
pub(crate) struct Pending {
    pub(crate) request: Request,
    pub(crate) origin: Origin,
    pub(crate) commands: VecDeque<Command>,
    pub(crate) results: Vec<CommandResult>,
    /// The job whose answer it waits for.
    pub(crate) waiting: Option<u64>,
    /// A reply decided without running commands (malformed, over a limit).
    pub(crate) early: Option<Vec<u8>>,
    /// Encoded bytes of `results` (counted against `--max-reply-bytes`).
    pub(crate) reply_bytes: usize,
}

/// Everything the daemon owns except the WaitSet, the request listener and the workers'
/// wake-up socket, which stay on the stack of [`run`](super::run) (the WaitSet borrows them).
pub struct Daemon {
    pub(crate) domain: String,
    pub(crate) config: Config,
    pub(crate) node: Node<ipc::Service>,
    pub(crate) server: ControlServer,
    pub(crate) clients: Clients,
    pub(crate) planes: BTreeMap<PlaneId, PlaneEntry>,
    pub(crate) next_plane_id: PlaneId,
    pub(crate) options: Options,
    /// Per client, its requests in arrival order; the first one is being served.
    pub(crate) queues: HashMap<u128, VecDeque<Pending>>,
    /// Jobs with a worker, and the client whose request waits for each.
    pub(crate) tickets: HashMap<u64, u128>,
    pub(crate) next_ticket: u64,
    pub(crate) events: Receiver<Event>,
    pub(crate) events_tx: Sender<Event>,
    pub(crate) waker: Arc<Waker>,
    pub(crate) workers: Vec<JoinHandle<()>>,
    /// Per client process, what its planes hold (quotas reserve against it atomically).
    pub(crate) owners: quota::Owners,
    /// Reply bytes the request being routed may still fill.
    pub(crate) reply_left: usize,
    /// The control service (its port list tells which node sent a request).
    pub(crate) control: origin::ControlService,
    /// Client port → node and process, for identifying senders.
    pub(crate) origins: origin::Origins,
    /// Who pays for what the command being routed adds, when not the plane's owner.
    pub(crate) guest: Option<Arc<quota::OwnerUsage>>,
    /// What the resource guard thread needs to know (who said Hello, which planes exist).
    pub(crate) watch: Arc<resources::Watch>,
    /// The writer of persistent planes (`--state-dir`).
    pub(crate) writer: Option<persist::Writer>,
    /// Each connection's open snapshot transfers (snapshots in pieces).
    pub(crate) transfers: HashMap<u128, Arc<transfers::ClientTransfers>>,
    /// Where a large snapshot of the command being routed is staged (its sender's transfers).
    pub(crate) stage_to: Option<Arc<transfers::ClientTransfers>>,
    /// When to list nodes to find gone clients (`liveness`).
    pub(crate) liveness: schedule::Schedule,
    /// Planes that moved to other daemons (`moves`).
    pub(crate) moved: Tombstones,
}

impl Pending {
    /// Adds `results`, counting their encoded bytes.
    pub(crate) fn count(&mut self, results: Vec<CommandResult>) {
        self.reply_bytes = results
            .iter()
            .map(shm_layout::codec::result_size)
            .fold(self.reply_bytes, usize::saturating_add);
        self.results.extend(results);
    }
}

/// How a command was served.
pub(crate) enum Routed {
    /// Answered at once (one result per command taken).
    Now(Vec<CommandResult>),
    /// Handed to a plane worker; the answer comes with this ticket.
    Wait(u64),
}

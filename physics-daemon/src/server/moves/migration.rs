//! The migration hook (`plane:MoveTo("DAEMON")`, docs/cluster.md "Migration"): how the
//! request loop reaches the other daemons of its cluster ([`Courier`], filled by the
//! cluster side with Zenoh: the loop never names it), the planes arriving from them and the
//! `--rebalance` requests ([`Migration`]), and the tombstones of planes that left.

use std::collections::{HashMap, VecDeque};
use std::sync::{mpsc, Mutex};
use std::time::{Duration, Instant};

use shm_layout::migrate::{MoveAnswer, Moved, MovingPlane};
use shm_layout::{CommandError, PlaneId};

/// How long the target takes at most to restore an arriving plane. An arrival its loop
/// reaches later than half of this is refused unrestored; the one that brought it waits
/// twice this for the answer, and the old daemon a little longer: a plane the old daemon
/// gave up on is never restored after all (two daemons moving planes to each other at
/// once both wait, then both refuse, and both planes stay).
pub const RESTORE_WAIT: Duration = Duration::from_secs(10);
/// Tombstones kept (the oldest go first): a client that has not touched a moved plane for
/// this many later moves gets `UnknownPlane` instead of the way to it.
const MAX_TOMBSTONES: usize = 4096;

/// How a daemon reaches the others of its cluster for migrations (the cluster side).
pub trait Courier: Send + Sync {
    /// Whether `daemon` is a live member; the error says why not (naming the live ones).
    fn check_target(&self, daemon: &str) -> Result<(), String>;
    /// Hands `plane` to `daemon` and waits (bounded) for its answer.
    fn deliver(&self, daemon: &str, plane: &MovingPlane) -> MoveAnswer;
}

/// A plane `--rebalance` wants moved: the largest movable plane goes to `target`.
#[derive(Debug, Clone)]
pub struct RebalanceRequest {
    /// The member with room.
    pub target: String,
}

/// Planes that arrived this recently are not moved on by `--rebalance` (no ping-pong).
pub const SETTLE: Duration = Duration::from_secs(30);

/// A plane arriving from another daemon, and where its answer goes.
pub struct Arrival {
    pub(crate) plane: MovingPlane,
    pub(crate) answer: mpsc::Sender<MoveAnswer>,
    pub(crate) queued: Instant,
}

/// The migration hook of a daemon in a cluster ([`crate::server::Options::migrate`]).
pub struct Migration {
    /// This daemon's `--name`.
    pub me: String,
    /// Its cluster.
    pub cluster: String,
    /// An endpoint of the cluster that clients of a moved plane connect through.
    pub endpoint: String,
    pub(crate) courier: Box<dyn Courier>,
    arrivals: Mutex<Vec<Arrival>>,
    pub(crate) rebalance: Mutex<Vec<RebalanceRequest>>,
}

impl Migration {
    /// The hook for daemon `me` of `cluster`, reaching the others through `courier`.
    pub fn new(me: &str, cluster: &str, endpoint: &str, courier: Box<dyn Courier>) -> Migration {
        Migration {
            me: me.to_string(),
            cluster: cluster.to_string(),
            endpoint: endpoint.to_string(),
            courier,
            arrivals: Mutex::default(),
            rebalance: Mutex::default(),
        }
    }

    /// Asks the loop to move its largest movable plane to `request.target` (`--rebalance`;
    /// wake the loop after: `crate::wake`).
    pub fn rebalance(&self, request: RebalanceRequest) {
        self.rebalance
            .lock()
            .unwrap_or_else(|p| p.into_inner())
            .push(request);
    }

    /// Queues a plane that arrives (wake the loop after: `crate::wake`); its answer comes
    /// on the receiver once the loop restored or refused it.
    pub fn arrive(&self, plane: MovingPlane) -> mpsc::Receiver<MoveAnswer> {
        let (answer, receiver) = mpsc::channel();
        self.arrivals
            .lock()
            .unwrap_or_else(|p| p.into_inner())
            .push(Arrival {
                plane,
                answer,
                queued: Instant::now(),
            });
        receiver
    }

    pub(crate) fn take(&self) -> Vec<Arrival> {
        std::mem::take(&mut *self.arrivals.lock().unwrap_or_else(|p| p.into_inner()))
    }
}

impl std::fmt::Debug for Migration {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Migration")
            .field("me", &self.me)
            .field("cluster", &self.cluster)
            .finish()
    }
}

/// What the loop keeps about moves: the planes that left (old id → where they went, and
/// the owner the claim key is for), the planes pinned to this daemon, and when planes
/// arrived.
#[derive(Default)]
pub(crate) struct Tombstones {
    pub(crate) map: HashMap<PlaneId, (Moved, u128)>,
    pub(crate) order: VecDeque<PlaneId>,
    pub(crate) pinned: std::collections::HashSet<PlaneId>,
    pub(crate) arrived: HashMap<PlaneId, Instant>,
}

impl Tombstones {
    pub(crate) fn insert(&mut self, moved: Moved, owner: u128) {
        if self.order.len() >= MAX_TOMBSTONES {
            if let Some(old) = self.order.pop_front() {
                self.map.remove(&old);
            }
        }
        self.order.push_back(moved.from_id);
        self.pinned.remove(&moved.from_id);
        self.arrived.remove(&moved.from_id);
        self.map.insert(moved.from_id, (moved, owner));
    }

    /// The refusal `client` gets for plane `id` that left (the claim key only for its
    /// owner).
    pub(crate) fn refusal(&self, id: PlaneId, client: u128) -> Option<CommandError> {
        let (moved, owner) = self.map.get(&id)?;
        let mut moved = moved.clone();
        if *owner != client {
            moved.key = 0;
        }
        Some(moved.to_error())
    }
}

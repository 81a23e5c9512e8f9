//! The seam between the server / publisher and the simulation: every plane kind implements
//! [`Backend`]; `crate::kinds::create`, one level up, is the one place that knows the
//! kinds (the seam does not import its implementations). The server routes ops by plane id
//! and never looks inside them; the publisher asks the backend what changed.
//!
//! Adding a plane kind: a folder of its own (like `rapier3d/`) with a type implementing
//! [`Backend`], a [`PlaneKind`] variant in shm-layout, and one line in `kinds::create`.
//!
//! Beside the seam, what the plane kinds share, none of which knows a plane type: the tick
//! [`clock`], [`SlotTable`] with its [`Dirty`] marks, [`Marks`], [`counted`] state bytes,
//! [`object_op`](mod@object_op) routing, thread [`pools`]; and for both rapier planes, generic over the
//! engine: [`rapier_world`] (the world copy, the query refresh, body motion), [`held`]
//! bodies, `plane_state` (the state-as-a-value macro), the [`rollback`] ring and
//! `snapshot_decode`.

pub mod clock;
pub mod counted;
mod dirty;
pub mod held;
pub mod marks;
pub mod object_op;
#[cfg(feature = "gui")]
pub(crate) mod plane_state;
pub mod pools;
pub mod rapier_world;
pub mod rollback;
mod slot_table;
pub(crate) mod snapshot_decode;

use std::mem::MaybeUninit;

pub use clock::{check_dt, engine_dt, Clock, HeaderFigures, MIN_DYNAMIC_DT};
pub use dirty::Dirty;
pub use marks::Marks;
pub use object_op::{object_op, ObjectPlane};
pub use slot_table::SlotTable;

use shm_layout::{
    BodyState, CommandError, CommandResult, EventRecord, PlaneKind, PlaneOp, TickHeader,
};

/// Which slots [`Backend::write_states`] must write.
#[derive(Debug, Clone, Copy)]
pub enum SlotFilter<'a> {
    /// Every slot.
    All,
    /// Only slots `i` with `changed_at[i] > written` (the rest of the sample already holds
    /// their current state).
    ChangedAfter {
        /// Per slot: the publish from which on its state may differ.
        changed_at: &'a [u64],
        /// The publish that last wrote the whole sample.
        written: u64,
    },
}

impl SlotFilter<'_> {
    /// Whether slot `i` must be written.
    #[inline]
    pub fn wants(&self, i: usize) -> bool {
        match self {
            SlotFilter::All => true,
            SlotFilter::ChangedAfter {
                changed_at,
                written,
            } => changed_at.get(i).is_none_or(|c| c > written),
        }
    }
}

/// What a plane holds, for the daemon's per-client quotas.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Usage {
    /// Live objects.
    pub objects: u64,
    /// Mesh vertices of all its parts.
    pub mesh_vertices: u64,
    /// Bytes of state clients grew beyond objects and meshes (controller paths, ticks kept
    /// for Rewind).
    pub state_bytes: u64,
}

/// A plane as the server and the publisher see it.
pub trait Backend: Send {
    /// Which kind of plane this is.
    fn kind(&self) -> PlaneKind;

    /// Applies one op other than `Step` and `Destroy` (which the server handles through
    /// [`Backend::step`] and by dropping the plane). Errors name the field and the value.
    fn apply(&mut self, op: PlaneOp) -> CommandResult;

    /// Advances by `dt` seconds. Returns false (and does nothing) when disabled.
    fn step(&mut self, dt: f32) -> Result<bool, CommandError>;

    /// Automatic ticks per second (0 = manual).
    fn tick_rate(&self) -> f32;

    /// Whether the plane advances at all.
    fn enabled(&self) -> bool;

    /// Ticks stepped so far.
    fn tick(&self) -> u64;

    /// The header of the newest tick.
    fn header(&self) -> TickHeader;

    /// Length of the published body array.
    fn slot_count(&self) -> usize;

    /// Number of slots that may move in the next step.
    fn awake_count(&self) -> usize;

    /// Calls `f` with every slot that may move in the next step (awake bodies). A slot
    /// outside this set has not moved since the step that put it to rest.
    fn for_each_awake(&self, f: &mut dyn FnMut(usize));

    /// Appends the slots changed by ops since the last call to `into`; true when the whole
    /// plane changed.
    fn drain_dirty(&mut self, into: &mut Vec<u32>) -> bool;

    /// The published state of slot `i` (dead slots carry only their generation).
    fn body_state(&self, i: usize) -> BodyState;

    /// Writes the state of the slots `filter` wants into `out` (one element per slot).
    fn write_states(&self, out: &mut [MaybeUninit<BodyState>], filter: SlotFilter<'_>) {
        for (i, dst) in out.iter_mut().enumerate() {
            if filter.wants(i) {
                dst.write(self.body_state(i));
            }
        }
    }

    /// Events of the last step.
    fn events(&self) -> &[EventRecord];

    /// What the plane holds now.
    fn usage(&self) -> Usage;

    /// The plane's snapshot split in two: a copy of its state taken now, on the plane's
    /// thread, and a job that encodes it later on any thread (the persistence writer, so the
    /// encode stays off the tick). `None`: this kind has no split; take
    /// `PlaneOp::Snapshot` instead.
    fn snapshot_later(&self) -> Option<Result<SnapshotJob, CommandError>> {
        None
    }

    /// Work the plane put off its tick's path (a copy kept for Rewind), done by its worker
    /// once the tick is published and answered; any op or step does it first as well.
    fn idle_work(&mut self) -> Result<(), CommandError> {
        Ok(())
    }

    /// Whether [`Backend::idle_work`] has something to do (runs then go to the worker, so
    /// the request loop never does it).
    fn has_idle_work(&self) -> bool {
        false
    }

    /// Whether a recording of the plane runs (`crate::record`).
    fn recording(&self) -> bool {
        false
    }

    /// The plane is about to go (`why`: moved to another daemon, destroyed, the daemon
    /// stopping): what writes on its behalf (a recording, `crate::record`) ends saying so.
    fn leaving(&mut self, _why: &str) {}
}

/// The encoding half of [`Backend::snapshot_later`]: gives the snapshot's bytes.
pub type SnapshotJob = Box<dyn FnOnce() -> Result<Vec<u8>, CommandError> + Send>;

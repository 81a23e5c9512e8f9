//! Rollback (`RollbackTicks = K`, `PlaneOp::Rewind(n)`): a plane with K > 0 keeps its state
//! after each of its last K ticks (an in-memory copy each: the engine's sets cloned, shapes
//! shared; counted in the owner's state bytes by an estimate) and can go back n ≤ K ticks;
//! the script then re-applies corrected inputs and steps again (rollback netcode). With
//! K = 0 (the default) nothing is kept and a step pays nothing.
//!
//! The copy is not made on the tick's path: a step only notes that its tick is to be kept,
//! and the plane's worker makes the copy right after the tick is published and answered
//! (`Backend::idle_work`), when no one waits for the plane; any op or step that comes first
//! makes it before it runs, so what is kept is always the state right after its tick. The
//! states are kept in a [`Ring`](crate::backend::rollback::Ring) that drops the oldest on a
//! thread of its own (freeing an awake pile's contact manifolds costs about as much as
//! copying them).

/// What one kept tick is counted as per object slot (a snapshot body takes about 1.5 KB a
/// body with its contacts; the copy is of the same order).
pub(crate) const BYTES_PER_SLOT: u64 = 1536;

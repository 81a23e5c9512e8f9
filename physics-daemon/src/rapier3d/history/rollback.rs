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
//!
//! Why a whole copy, not the awake bodies' poses and velocities (about 60 bytes a body):
//! a rewound plane must step on bit for bit as it did, and rapier's next step reads much
//! more than the bodies' motion. It reads each contact pair's manifolds (the contact
//! points with their feature ids, which parry updates in place instead of recomputing,
//! and the warm-start impulses), the order of the contact graph's edges and the solver's
//! per-color buckets of them, the broad phase's tree as its incremental optimizer left it
//! (with the pairs it has seen and when), the persistent islands and the order of the
//! awake set, every body's sleep timer and set ids, and the body and collider sets' lists
//! of what was modified since the last step (their order is the order the next step
//! applies the changes in). Rapier 0.36 lets none of these be written back piecewise:
//! every public write to a body or collider goes into those modified lists, and the
//! narrow and broad phases and the islands have no public way in at all, so a kept tick
//! is their clone. `physics-bench snapshot` counts what each part holds and costs a body
//! ([`Plane::rollback_record_part`](crate::rapier3d::Plane::rollback_record_part)).

/// What one kept tick is counted as per object slot (a snapshot body takes about 1.5 KB a
/// body with its contacts; the copy is of the same order).
pub(crate) const BYTES_PER_SLOT: u64 = 1536;

//! One object of the plane as the slot table holds it, and the plane's object limits.

use rapier3d::prelude::*;
use shm_layout::{BodyState, Pose, FLAG_ALIVE, FLAG_ANCHORED, FLAG_SLEEPING};

use crate::backend::SlotTable;

use crate::rapier3d::objects::part::Part;

/// Slots per plane; bounds memory a misbehaving client can make the daemon allocate.
pub const MAX_SLOTS: usize = 1 << 20;

/// One object: its rapier body and what the API says about it.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub(crate) struct Object {
    pub(crate) handle: RigidBodyHandle,
    /// Boxed: the slot table stays small, so the publisher's pass over every slot reads one
    /// short entry per body (the part's settings are read only where they matter).
    pub(crate) part: Box<Part>,
    /// `FLAG_*` bits the plane adds to the published state (controllers).
    pub(crate) flags: u32,
}

/// The rapier pose of an API pose.
pub(crate) fn rapier_pose(p: Pose) -> rapier3d::math::Pose {
    rapier3d::math::Pose::from_parts(Vector::from(p.position), Rotation::from_array(p.rotation))
}

/// The published state of slot `i` (dead slots carry only their generation).
pub(crate) fn body_state(slots: &SlotTable<Object>, bodies: &RigidBodySet, i: usize) -> BodyState {
    let generation = slots.generation(i);
    let Some((body, extra)) = slots
        .at(i)
        .and_then(|b| Some((bodies.get(b.handle)?, b.flags)))
    else {
        return BodyState {
            generation,
            ..BodyState::default()
        };
    };
    let pose = body.position();
    let mut flags = FLAG_ALIVE | extra;
    if body.is_sleeping() {
        flags |= FLAG_SLEEPING;
    }
    if body.is_fixed() {
        flags |= FLAG_ANCHORED;
    }
    BodyState {
        position: pose.translation.into(),
        flags,
        rotation: pose.rotation.into(),
        linear_velocity: body.linvel().into(),
        generation,
        angular_velocity: body.angvel().into(),
        _reserved: 0,
    }
}

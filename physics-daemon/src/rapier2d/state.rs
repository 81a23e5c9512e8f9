//! A GUI plane's state as a value: rapier2d's world and the plane's own tables, what a
//! snapshot encodes (in this order) and Rewind keeps (see `crate::backend::plane_state`).
//! The id, the events of the last step, the quota counter, the name and persistence stay
//! with the plane.

use rapier2d::prelude::*;
use shm_layout::settings::GuiPlaneSettings;

use super::object::{HeldBody, Object};
use crate::backend::{Clock, Marks, SlotTable};

crate::backend::plane_state::plane_state! {
    world: PhysicsWorld,
    settings: GuiPlaneSettings,
    bodies: SlotTable<Object>,
    controlled: Vec<u32>,
    driven: u32,
    query_stale: Marks<RigidBodyHandle>,
    held: Vec<HeldBody>,
    clock: Clock,
    event_seq: u64,
    rollback_ticks: u32,
}

//! One object of a GUI plane ([`Object`]: its rapier body and collider and what the API says
//! about it) and the limits and constants its slots live under.

use rapier2d::prelude::*;
use shm_layout::settings::{GuiObjectSettings, GuiShape};

use super::controller::Controller;

/// Slots per GUI plane.
pub const MAX_SLOTS: usize = 1 << 20;

/// Pixels per "metre" for rapier's tolerances (`length_unit`): GUI bodies are tens to
/// hundreds of pixels across.
pub const LENGTH_UNIT: f32 = 100.0;

/// `user_data` of the bounds walls' body (never a slot).
pub(super) const WALLS_SLOT: usize = u32::MAX as usize;

/// A held body of a GUI plane (see `crate::backend::held`).
pub(super) type HeldBody = crate::backend::held::HeldIn<PhysicsWorld>;

/// One object: its rapier body and collider and what the API says about it.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub(super) struct Object {
    pub(super) handle: RigidBodyHandle,
    pub(super) collider: ColliderHandle,
    pub(super) shape: GuiShape,
    pub(super) settings: GuiObjectSettings,
    pub(super) controller: Option<Box<Controller>>,
}

impl Object {
    /// Whether the force pass must visit it for its own sake.
    pub(super) fn is_driven(&self) -> bool {
        self.settings.constant_force != [0.0; 2] || self.settings.impulse_direction != [0.0; 2]
    }
}

/// `v` with the components of locked axes zeroed (the reference zeroes them every tick).
pub(super) fn unlocked(settings: &GuiObjectSettings, v: Vector) -> Vector {
    Vector::new(
        if settings.locked_x { 0.0 } else { v.x },
        if settings.locked_y { 0.0 } else { v.y },
    )
}

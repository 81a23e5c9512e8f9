//! Contact hooks of the GUI plane: ZIndex is the collision layer (two bodies collide only
//! when their ZIndex matches; the bounds walls meet every layer), and a wall contact takes
//! the body's own Friction (its Bounciness already wins: restitution combines by `Max` and
//! walls have 0).
//!
//! Each collider's `user_data` carries its layer: the ZIndex in the low 32 bits, and
//! [`WALL`] for the walls.

use rapier2d::prelude::*;

/// `user_data` bit of the bounds walls.
pub const WALL: u128 = 1 << 32;
/// `user_data` bit of a controller's body: its contacts have no friction (the controller
/// owns its velocity along the ground and brakes with its Acceleration).
pub const CONTROLLED: u128 = 1 << 33;
/// The bits of `user_data` that name the layer.
const LAYER: u128 = u32::MAX as u128;

/// The `user_data` of a body collider on layer `z`.
pub fn layer(z: i32) -> u128 {
    z as u32 as u128
}

/// Whether collider `c` is on layer `z` (walls are on every layer).
pub fn on_layer(c: &Collider, z: i32) -> bool {
    c.user_data & LAYER == layer(z) || is_wall(c)
}

fn is_wall(c: &Collider) -> bool {
    c.user_data & WALL != 0
}

/// The hooks every step of a GUI plane runs with.
pub struct Hooks;

impl PhysicsHooks for Hooks {
    fn filter_contact_pair(&self, context: &PairFilterContext) -> Option<SolverFlags> {
        let a = &context.colliders[context.collider1];
        let b = &context.colliders[context.collider2];
        if is_wall(a) || is_wall(b) || a.user_data & LAYER == b.user_data & LAYER {
            Some(SolverFlags::COMPUTE_RIGID_IMPULSES)
        } else {
            None
        }
    }

    fn modify_solver_contacts(&self, context: &mut ContactModificationContext) {
        let a = &context.colliders[context.collider1];
        let b = &context.colliders[context.collider2];
        if (a.user_data | b.user_data) & CONTROLLED != 0 {
            if let Some(m) = context.rigid_mut() {
                *m.friction = 0.0;
            }
            return;
        }
        let body = match (is_wall(a), is_wall(b)) {
            (true, false) => b,
            (false, true) => a,
            _ => return,
        };
        let friction = body.friction();
        if let Some(m) = context.rigid_mut() {
            *m.friction = friction;
        }
    }
}

//! The 2D GUI plane (`PhysicsService.NewGUI`): a rapier2d world in pixel space (+Y down)
//! behind the same backend seam as the 3D plane, published through the same shared-memory
//! records. Only a GUI plane pays for any of it; a build without the `gui` feature leaves the
//! module out.
//!
//! Layered: `body` (an object; `controller`, a controller's state, and `hooks`, the contact
//! hooks, below it) < `state` (the plane's state as a value) < `plane` ([`Plane`]: fields,
//! options, the step, what it publishes); the other files are methods of the plane:
//!
//! - `backend`: the [`Backend`](crate::backend::Backend) implementation (op routing).
//! - `objects`: bodies for GUI primitives, their properties and shapes, the bounds walls.
//! - `forces`: the per-tick pass (damping, drag, forces, one-shot impulses).
//! - `hooks`: ZIndex as the collision layer, and the bounds walls' per-body materials.
//! - `controllers`: `GUIController` (move, jump, waypoints, foot probe, signal events).
//! - `queries`: `Raycast` and the scene refresh queries need.
//! - `snapshot`: the plane's state as snapshot bytes, and back.
//! - `rollback`: `RollbackTicks` and `Rewind` (over `crate::backend::rollback`).
//!
//! How 2D maps onto [`BodyState`](shm_layout::BodyState): `position = [x, y, 0]` px, `rotation` the quaternion about
//! +Z, `linear_velocity = [vx, vy, 0]` px/s, `angular_velocity = [0, 0, ω]` rad/s.

mod backend;
mod controller;
mod controllers;
mod forces;
mod hooks;
mod object;
mod objects;
mod plane;
mod queries;
mod rollback;
mod snapshot;
mod state;

pub use object::{LENGTH_UNIT, MAX_SLOTS};
pub use plane::Plane;

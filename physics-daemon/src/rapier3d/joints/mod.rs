//! The plane's joints: the joint table (`table`), building a rapier joint from a joint's
//! settings (`build`, `axis_motors`), articulated trees (`articulations`). `ops.rs` (joint
//! ops) and `step.rs` (before and after each step) are the plane's `impl Plane` side; the
//! others know no plane.

pub(super) mod articulations;
mod axis_motors;
mod build;
#[cfg(test)]
mod edge_tests;
mod ops;
mod step;
pub(super) mod table;
#[cfg(test)]
mod tests;

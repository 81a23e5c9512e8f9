//! The plane's objects: the slot table's entries (`body`), their parts and how a part maps
//! onto rapier (`part`), the tallies over the parts (`tally`), the per-body pass before each
//! step (`body_pass`: forces, speed limits, contact prediction) and triangle-mesh maps
//! (`maps`, `map_store`). `ops.rs`, `properties.rs`, `maps_ops.rs` and `stepping.rs` are
//! the plane's `impl Plane` side; the others know no plane.

pub(super) mod body_pass;
pub(super) mod forces;
pub(super) mod limits;
pub(super) mod map_store;
pub(super) mod maps;
mod maps_ops;
pub(super) mod object;
mod ops;
pub(super) mod part;
mod properties;
mod stepping;
pub(super) mod tally;

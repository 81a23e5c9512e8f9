//! Scene queries of the plane: rays, sweeps and overlaps with their filters (`ops`), the
//! character probes built on them (`probes`), explosions (`explode`) and the plane's
//! collision-group table (`collision_groups`). All of it is the plane's `impl Plane` side.

mod collision_groups;
mod explode;
pub(super) mod ops;
pub(super) mod probes;

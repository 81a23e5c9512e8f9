//! Proximity queries and explosions on a plane: `ProbeGround` (a sphere cast down, with
//! whether the ground is walkable), `GetClosestPoint`, `GetClearance` (the gap between a
//! shape and the scene), `ProbeWall` (the wall beside a capsule) and `Explode` (knockback).
//! Each is one round trip that also carries the queued writes.

use shm_layout::{PlaneOp, Pose, QueryOp, Reply, Shape, Vec3};

use crate::{error::Error, object::Object, plane::Plane, query::QueryParams};

pub use shm_layout::probe::{Explosion, Falloff, ProbeHit, DEFAULT_MAX_SLOPE};
/// Farthest any query looks (units).
pub use shm_layout::query::MAX_QUERY_DISTANCE;

impl Plane {
    fn probe(&self, op: QueryOp) -> Result<Option<ProbeHit>, Error> {
        match self.query(op)? {
            Reply::Probe(hit) => Ok(hit),
            other => Err(Error::Protocol(format!("expected a probe, got {other:?}"))),
        }
    }

    /// Casts a sphere of `radius` straight down from `position` by at most `max_distance`:
    /// the ground it meets (its point, normal, the distance travelled, and whether it is
    /// walkable under `max_slope` degrees, [`DEFAULT_MAX_SLOPE`] when `None`), or `None`.
    pub fn probe_ground(
        &self,
        position: Vec3,
        radius: f32,
        max_distance: f32,
        max_slope: Option<f32>,
        params: Option<&QueryParams>,
    ) -> Result<Option<ProbeHit>, Error> {
        self.probe(QueryOp::ProbeGround {
            position,
            radius,
            max_distance,
            max_slope: max_slope.unwrap_or(DEFAULT_MAX_SLOPE),
            filter: self.wire_filter(params)?,
        })
    }

    /// The closest point of any object's surface to `position` within `max_distance`
    /// ([`MAX_QUERY_DISTANCE`] when `None`); the distance is negative inside a solid.
    pub fn closest_point(
        &self,
        position: Vec3,
        max_distance: Option<f32>,
        params: Option<&QueryParams>,
    ) -> Result<Option<ProbeHit>, Error> {
        self.probe(QueryOp::ClosestPoint {
            position,
            max_distance: max_distance.unwrap_or(MAX_QUERY_DISTANCE),
            filter: self.wire_filter(params)?,
        })
    }

    /// The object nearest to `shape` placed at `pose` within `max_distance`
    /// ([`MAX_QUERY_DISTANCE`] when `None`), with the two closest points; the distance is
    /// negative when they overlap (minus the penetration depth). `own`, the part the shape
    /// belongs to, is never found.
    pub fn clearance(
        &self,
        shape: Shape,
        pose: Pose,
        own: Option<&Object>,
        max_distance: Option<f32>,
        params: Option<&QueryParams>,
    ) -> Result<Option<ProbeHit>, Error> {
        self.probe(QueryOp::Clearance {
            shape,
            pose,
            max_distance: max_distance.unwrap_or(MAX_QUERY_DISTANCE),
            own: own.map(|o| o.handle()),
            filter: self.wire_filter(params)?,
        })
    }

    /// The nearest wall (steeper than `max_slope` degrees, not a ceiling) within
    /// `max_distance` of an upright capsule of `radius` and full `height` at `pose`.
    pub fn probe_wall(
        &self,
        pose: Pose,
        radius: f32,
        height: f32,
        max_distance: f32,
        max_slope: Option<f32>,
        params: Option<&QueryParams>,
    ) -> Result<Option<ProbeHit>, Error> {
        self.probe(QueryOp::ProbeWall {
            pose,
            radius,
            height,
            max_distance,
            max_slope: max_slope.unwrap_or(DEFAULT_MAX_SLOPE),
            filter: self.wire_filter(params)?,
        })
    }

    /// Pushes every dynamic object whose shape meets the sphere away from `center` (and
    /// kicks every controller there), the impulse falling off with distance as `falloff`
    /// says; anchored objects are left alone. Returns the handles of what it pushed.
    pub fn explode(
        &self,
        center: Vec3,
        radius: f32,
        impulse: f32,
        falloff: Falloff,
        params: Option<&QueryParams>,
    ) -> Result<Vec<shm_layout::Handle>, Error> {
        let explosion = Explosion {
            center,
            radius,
            impulse,
            falloff,
            filter: self.wire_filter(params)?,
        }
        .checked()
        .map_err(Error::invalid_value)?;
        match self.client().call(shm_layout::Command::plane(
            self.id(),
            PlaneOp::Explode(explosion),
        ))? {
            Reply::Objects(found) => Ok(found),
            other => Err(Error::Protocol(format!("expected objects, got {other:?}"))),
        }
    }
}

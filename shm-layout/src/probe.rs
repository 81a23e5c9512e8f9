//! Proximity queries and explosions: the ground under a sphere (`ProbeGround`), the
//! closest point of the scene to a point (`GetClosestPoint`), the gap between a shape and
//! the scene (`GetClearance`), the wall beside a capsule (`ProbeWall`), and an explosion's
//! knockback (`Explode`). The query variants live at the end of [`crate::QueryOp`]; their
//! answer is [`crate::Reply::Probe`]. An explosion changes the plane, so it is a
//! [`crate::PlaneOp::Explode`] of its own and answers [`crate::Reply::Objects`].

use serde::{Deserialize, Serialize};

use crate::error::CommandError;
use crate::geometry::Vec3;
use crate::ids::Handle;
use crate::query::{QueryFilter, MAX_QUERY_DISTANCE};
use crate::validate::{bounded3, in_range, MAX_COORDINATE};

/// The walkable-slope limit (degrees) probes use when none is given: the controllers'
/// `MaxSlope` default.
pub const DEFAULT_MAX_SLOPE: f32 = 45.0;

/// What a proximity query found: the point of the scene it is about, the surface there and
/// (for queries about a shape) the matching point of the shape.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ProbeHit {
    /// The object found.
    pub object: Handle,
    /// World-space point on the object found (the ground's contact point, the closest
    /// point, the wall's nearest point).
    pub position: Vec3,
    /// Unit normal of the object's surface at `position`, pointing out of it (toward the
    /// query's point or shape).
    pub normal: Vec3,
    /// The gap: how far the probe travelled (`ProbeGround`), or the distance between the
    /// query's point or shape and the object, negative when they overlap (its magnitude is
    /// then the penetration depth).
    pub distance: f32,
    /// World-space point of the query's shape closest to the object (the query's point
    /// itself for `ClosestPoint`; for `ProbeGround` the sphere's lowest point at the hit).
    pub point_on_shape: Vec3,
    /// Whether `normal` is within the slope limit of straight up (ground you can stand on).
    pub walkable: bool,
}

/// How an explosion's impulse falls off with distance `d` from its centre.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum Falloff {
    /// `impulse × (1 − d / radius)`: full at the centre, zero at the edge (the default).
    #[default]
    Linear,
    /// The full impulse anywhere within the radius.
    None,
    /// `impulse / max(d, 1)²`: the full impulse within one unit of the centre, a quarter of
    /// it at two units.
    InverseSquare,
}

/// An explosion: every dynamic object whose shape meets the sphere gets an impulse away
/// from the centre, every controller there a velocity kick; anchored objects are left alone.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Explosion {
    /// The centre.
    pub center: Vec3,
    /// The reach (units).
    pub radius: f32,
    /// Impulse magnitude (mass·units/s) before falloff.
    pub impulse: f32,
    /// How the impulse falls off with distance.
    pub falloff: Falloff,
    /// Which objects it may affect.
    pub filter: QueryFilter,
}

fn point(field: &str, p: Vec3) -> Result<Vec3, CommandError> {
    bounded3(field, p, MAX_COORDINATE)
}

impl Explosion {
    /// The explosion with every value checked, or an error naming the field and the value.
    pub fn checked(self) -> Result<Explosion, CommandError> {
        let impulse = crate::validate::finite("impulse", self.impulse)?;
        if impulse.abs() > 1e9 {
            return Err(CommandError::invalid_field(
                "impulse",
                format!("impulse must be within [-1e9, 1e9], got {impulse}"),
            ));
        }
        Ok(Explosion {
            center: point("center", self.center)?,
            radius: in_range("radius", self.radius, 1e-3, MAX_QUERY_DISTANCE)?,
            impulse,
            falloff: self.falloff,
            filter: self.filter.checked()?,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::query::QueryOp;

    #[test]
    fn the_default_slope_limit_is_the_controllers() {
        let c = crate::ControllerSettings::defaults([2.0, 5.0, 2.0], false);
        assert_eq!(DEFAULT_MAX_SLOPE, c.max_slope);
    }

    #[test]
    fn probe_fields_are_named_in_errors() {
        let op = QueryOp::ProbeGround {
            position: [0.0; 3],
            radius: 0.5,
            max_distance: f32::NAN,
            max_slope: 45.0,
            filter: QueryFilter::default(),
        };
        let e = op.checked().unwrap_err();
        assert_eq!(e.field.as_deref(), Some("maxDistance"));
        let op = QueryOp::ProbeWall {
            pose: crate::Pose::IDENTITY,
            radius: 0.5,
            height: 2.0,
            max_distance: 1.0,
            max_slope: 95.0,
            filter: QueryFilter::default(),
        };
        let e = op.checked().unwrap_err();
        assert_eq!(e.field.as_deref(), Some("MaxSlopeAngle"));
        let e = Explosion {
            center: [0.0; 3],
            radius: 5.0,
            impulse: f32::INFINITY,
            falloff: Falloff::Linear,
            filter: QueryFilter::default(),
        }
        .checked()
        .unwrap_err();
        assert_eq!(e.field.as_deref(), Some("impulse"));
    }
}

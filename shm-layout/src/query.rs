//! Scene queries: rays, swept shapes and overlap tests against a plane's latest tick, with
//! Roblox's `RaycastParams` / `OverlapParams` filter. One op answers many rays
//! ([`QueryOp::Raycast`] takes a batch), so hitscan for a whole server is one round trip.

use serde::{Deserialize, Serialize};

use crate::error::CommandError;
use crate::geometry::{Pose, Vec3};
use crate::ids::Handle;
use crate::settings::controller::MAX_SLOPE_LIMIT;
use crate::validate::{bounded3, extent, in_range, non_negative, pose, size, MAX_COORDINATE};

/// Most rays one [`QueryOp::Raycast`] may carry (bounds the work of one request).
pub const MAX_RAYS: usize = 65_536;
/// Most objects one filter may list.
pub const MAX_FILTER: usize = 65_536;
/// Most work one [`QueryOp::Raycast`] may ask for, counted as rays × (1 + objects in the
/// filter): a ray may meet every listed object before its hit, so this bounds the time one
/// query holds its plane (65,536 rays with a 63-object filter, or 4,096 rays with 1,023).
pub const MAX_RAY_WORK: usize = 1 << 22;
/// Most objects one overlap query (`BoundsInRadius`, `BoundsInBox`, `InPart`) returns: a
/// query that finds more returns the first ones by slot and says it was truncated
/// ([`crate::Reply::ObjectPage`]); [`QueryOp::Page`] asks for the ones after. This bounds the
/// reply of one query (8 bytes per object) whatever the plane holds.
pub const MAX_QUERY_RESULTS: usize = 4096;
/// Longest ray or sweep (units): a direction longer than this is almost certainly a bug.
pub const MAX_QUERY_DISTANCE: f32 = 2.0 * MAX_COORDINATE;

/// Whether the filter's list is what to skip or all that may be hit (Roblox's
/// `Enum.RaycastFilterType`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum FilterType {
    /// The listed objects are skipped (the default).
    #[default]
    Exclude,
    /// Only the listed objects may be hit.
    Include,
}

/// Which objects a query considers (Roblox's `RaycastParams` / `OverlapParams`).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct QueryFilter {
    /// What `list` means.
    pub filter_type: FilterType,
    /// The objects `filter_type` applies to (unknown or stale handles are ignored: a
    /// filter built from last frame's list must not fail).
    pub list: Vec<Handle>,
    /// When set, only objects whose collision group collides with this group (an index into
    /// the plane's collision-group table) are considered.
    pub collision_group: Option<u8>,
    /// When true, objects with CanCollide = false are skipped (Roblox's default is false:
    /// queries see every part).
    pub respect_can_collide: bool,
}

/// One ray: from `origin` along `direction`, whose length is the maximum distance.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Ray {
    /// Where the ray starts.
    pub origin: Vec3,
    /// Direction and length (Roblox convention: the length is the reach).
    pub direction: Vec3,
}

/// What a ray or a sweep hit first.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Hit {
    /// The object hit.
    pub object: Handle,
    /// World-space point of the hit (for sweeps: the contact point on the object hit).
    pub position: Vec3,
    /// Unit surface normal of the object hit at `position`, pointing out of it.
    pub normal: Vec3,
    /// Distance travelled from the origin to the hit along the direction.
    pub distance: f32,
}

/// A query on one plane. Read-only: any client may ask it of any plane.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum QueryOp {
    /// Casts every ray; the reply holds one optional hit per ray, in order. A ray that
    /// starts inside an object does not hit that object (Roblox convention).
    Raycast {
        /// The rays (at most [`MAX_RAYS`]).
        rays: Vec<Ray>,
        /// Which objects may be hit.
        filter: QueryFilter,
    },
    /// Sweeps a sphere of `radius` from `origin` along `direction`.
    Spherecast {
        /// Centre at the start.
        origin: Vec3,
        /// The sphere's radius.
        radius: f32,
        /// Direction and length of the sweep.
        direction: Vec3,
        /// Which objects may be hit.
        filter: QueryFilter,
    },
    /// Sweeps a box of full `size` from `pose` along `direction`.
    Blockcast {
        /// The box's pose at the start.
        pose: Pose,
        /// Full size of the box.
        size: Vec3,
        /// Direction and length of the sweep.
        direction: Vec3,
        /// Which objects may be hit.
        filter: QueryFilter,
    },
    /// Sweeps the shape of `object` from its current pose along `direction` (the object
    /// itself is never hit).
    Shapecast {
        /// The object whose shape is swept.
        object: Handle,
        /// Direction and length of the sweep.
        direction: Vec3,
        /// Which objects may be hit.
        filter: QueryFilter,
    },
    /// Objects whose bounding box (world axis-aligned) touches the sphere.
    BoundsInRadius {
        /// The sphere's centre.
        position: Vec3,
        /// The sphere's radius.
        radius: f32,
        /// Which objects may be listed.
        filter: QueryFilter,
    },
    /// Objects whose bounding box (world axis-aligned) touches the oriented box.
    BoundsInBox {
        /// The box's pose.
        pose: Pose,
        /// Full size of the box.
        size: Vec3,
        /// Which objects may be listed.
        filter: QueryFilter,
    },
    /// Objects whose shape overlaps the shape of `object` (exact test; the object itself is
    /// not listed).
    InPart {
        /// The object whose shape is tested.
        object: Handle,
        /// Which objects may be listed.
        filter: QueryFilter,
    },
    /// Casts a sphere of `radius` straight down from `position` by at most `max_distance`;
    /// replies [`crate::Reply::Probe`] (see [`crate::probe`]).
    ProbeGround {
        /// The sphere's centre at the start.
        position: Vec3,
        /// The sphere's radius.
        radius: f32,
        /// How far down to look.
        max_distance: f32,
        /// Steepest walkable slope (degrees) for the hit's `walkable`.
        max_slope: f32,
        /// Which objects may be hit.
        filter: QueryFilter,
    },
    /// The closest point of any object's surface to `position`, within `max_distance`;
    /// replies [`crate::Reply::Probe`].
    ClosestPoint {
        /// The point.
        position: Vec3,
        /// Farthest surface considered.
        max_distance: f32,
        /// Which objects may be found.
        filter: QueryFilter,
    },
    /// The nearest object to `shape` placed at `pose` and the two closest points, within
    /// `max_distance`; replies [`crate::Reply::Probe`] (negative distance: overlapping).
    Clearance {
        /// The shape (a mesh counts as the convex hull of its vertices).
        shape: crate::shape::Shape,
        /// Where the shape is.
        pose: Pose,
        /// Farthest object considered.
        max_distance: f32,
        /// An object never found (the part whose shape this is).
        own: Option<Handle>,
        /// Which objects may be found.
        filter: QueryFilter,
    },
    /// The nearest wall (a surface steeper than `max_slope` and not a ceiling) within
    /// `max_distance` of an upright capsule; replies [`crate::Reply::Probe`].
    ProbeWall {
        /// The capsule's pose (its axis along the pose's Y).
        pose: Pose,
        /// The capsule's radius.
        radius: f32,
        /// The capsule's full height, caps included (at least `2 × radius` counts as a ball).
        height: f32,
        /// How far from the capsule to look.
        max_distance: f32,
        /// Steepest walkable slope (degrees): steeper surfaces are walls.
        max_slope: f32,
        /// Which objects may be found.
        filter: QueryFilter,
    },
    /// The objects of the overlap query `query` whose slot is above `after_slot`, at most
    /// [`MAX_QUERY_RESULTS`] (ascending slots): the next page after a truncated answer.
    /// Replies [`crate::Reply::ObjectPage`].
    Page {
        /// An overlap query (`BoundsInRadius`, `BoundsInBox` or `InPart`).
        query: Box<QueryOp>,
        /// Only objects with a greater slot are listed (the last slot of the previous page).
        after_slot: u32,
    },
}

/// A direction whose length is a reach: finite and at most [`MAX_QUERY_DISTANCE`].
pub fn direction(field: &str, d: Vec3) -> Result<Vec3, CommandError> {
    bounded3(field, d, MAX_QUERY_DISTANCE)
}

impl QueryOp {
    /// The op with every value checked, or an error naming the field and the value.
    pub fn checked(self) -> Result<QueryOp, CommandError> {
        let point = |f: &str, p: Vec3| bounded3(f, p, MAX_COORDINATE);
        Ok(match self {
            QueryOp::Raycast { rays, filter } => {
                if rays.len() > MAX_RAYS {
                    return Err(CommandError::invalid_field(
                        "rays",
                        format!("rays must hold at most {MAX_RAYS} rays, got {}", rays.len()),
                    ));
                }
                let work = rays.len().saturating_mul(1 + filter.list.len());
                if work > MAX_RAY_WORK {
                    return Err(CommandError::invalid_field(
                        "rays",
                        format!(
                            "rays × (1 + Filter objects) must be at most {MAX_RAY_WORK}, got {} \
                             rays × (1 + {}) = {work}: cast fewer rays per request or filter \
                             fewer objects",
                            rays.len(),
                            filter.list.len()
                        ),
                    ));
                }
                for (i, r) in rays.iter().enumerate() {
                    point(&format!("rays[{i}].origin"), r.origin)?;
                    direction(&format!("rays[{i}].direction"), r.direction)?;
                }
                QueryOp::Raycast {
                    rays,
                    filter: filter.checked()?,
                }
            }
            QueryOp::Spherecast {
                origin,
                radius,
                direction: d,
                filter,
            } => QueryOp::Spherecast {
                origin: point("origin", origin)?,
                radius: extent("radius", radius)?,
                direction: direction("direction", d)?,
                filter: filter.checked()?,
            },
            QueryOp::Blockcast {
                pose: p,
                size: s,
                direction: d,
                filter,
            } => QueryOp::Blockcast {
                pose: pose("cframe", p)?,
                size: size("size", s)?,
                direction: direction("direction", d)?,
                filter: filter.checked()?,
            },
            QueryOp::Shapecast {
                object,
                direction: d,
                filter,
            } => QueryOp::Shapecast {
                object,
                direction: direction("direction", d)?,
                filter: filter.checked()?,
            },
            QueryOp::BoundsInRadius {
                position,
                radius,
                filter,
            } => QueryOp::BoundsInRadius {
                position: point("position", position)?,
                radius: extent("radius", radius)?,
                filter: filter.checked()?,
            },
            QueryOp::BoundsInBox {
                pose: p,
                size: s,
                filter,
            } => QueryOp::BoundsInBox {
                pose: pose("cframe", p)?,
                size: size("size", s)?,
                filter: filter.checked()?,
            },
            QueryOp::InPart { object, filter } => QueryOp::InPart {
                object,
                filter: filter.checked()?,
            },
            QueryOp::Page { query, after_slot } => {
                if !query.is_overlap() {
                    return Err(CommandError::invalid_field(
                        "query",
                        "a Page holds an overlap query (BoundsInRadius, BoundsInBox or InPart)",
                    ));
                }
                QueryOp::Page {
                    query: Box::new(query.checked()?),
                    after_slot,
                }
            }
            op => checked_probe(op)?,
        })
    }

    /// Whether the op lists objects (`BoundsInRadius`, `BoundsInBox`, `InPart`).
    pub fn is_overlap(&self) -> bool {
        matches!(
            self,
            QueryOp::BoundsInRadius { .. } | QueryOp::BoundsInBox { .. } | QueryOp::InPart { .. }
        )
    }

    /// The filter of the op (for a page, its query's).
    pub fn filter(&self) -> &QueryFilter {
        match self {
            QueryOp::Raycast { filter, .. }
            | QueryOp::Spherecast { filter, .. }
            | QueryOp::Blockcast { filter, .. }
            | QueryOp::Shapecast { filter, .. }
            | QueryOp::BoundsInRadius { filter, .. }
            | QueryOp::BoundsInBox { filter, .. }
            | QueryOp::InPart { filter, .. }
            | QueryOp::ProbeGround { filter, .. }
            | QueryOp::ClosestPoint { filter, .. }
            | QueryOp::Clearance { filter, .. }
            | QueryOp::ProbeWall { filter, .. } => filter,
            QueryOp::Page { query, .. } => query.filter(),
        }
    }
}

/// The page of an overlap query's answer that a reply carries: `found` (ascending slots)
/// reduced to the objects above `after_slot`, then to the first [`MAX_QUERY_RESULTS`];
/// `true` when some were cut off.
pub fn page_of(mut found: Vec<Handle>, after_slot: Option<u32>) -> (Vec<Handle>, bool) {
    if let Some(after) = after_slot {
        found.retain(|h| h.slot > after);
    }
    let truncated = found.len() > MAX_QUERY_RESULTS;
    found.truncate(MAX_QUERY_RESULTS);
    (found, truncated)
}

impl QueryFilter {
    /// The filter with a bounded list, or an error naming `Filter`.
    pub fn checked(self) -> Result<QueryFilter, CommandError> {
        if self.list.len() > MAX_FILTER {
            return Err(CommandError::invalid_field(
                "Filter",
                format!(
                    "Filter must list at most {MAX_FILTER} objects, got {}",
                    self.list.len()
                ),
            ));
        }
        Ok(self)
    }
}

fn point(field: &str, p: Vec3) -> Result<Vec3, CommandError> {
    bounded3(field, p, MAX_COORDINATE)
}

/// A slope limit in degrees, `[0, MAX_SLOPE_LIMIT]`.
fn slope(field: &str, v: f32) -> Result<f32, CommandError> {
    in_range(field, v, 0.0, MAX_SLOPE_LIMIT)
}

/// A reach: finite, ≥ 0 and at most [`MAX_QUERY_DISTANCE`].
fn reach(field: &str, v: f32) -> Result<f32, CommandError> {
    in_range(field, non_negative(field, v)?, 0.0, MAX_QUERY_DISTANCE)
}

/// The checks of the proximity variants of [`QueryOp`] (`ProbeGround`, `ClosestPoint`,
/// `Clearance`, `ProbeWall`: see [`crate::probe`]), called by `QueryOp::checked`.
fn checked_probe(op: QueryOp) -> Result<QueryOp, CommandError> {
    Ok(match op {
        QueryOp::ProbeGround {
            position,
            radius,
            max_distance,
            max_slope,
            filter,
        } => QueryOp::ProbeGround {
            position: point("position", position)?,
            radius: extent("radius", radius)?,
            max_distance: reach("maxDistance", max_distance)?,
            max_slope: slope("MaxSlopeAngle", max_slope)?,
            filter: filter.checked()?,
        },
        QueryOp::ClosestPoint {
            position,
            max_distance,
            filter,
        } => QueryOp::ClosestPoint {
            position: point("position", position)?,
            max_distance: reach("MaxDistance", max_distance)?,
            filter: filter.checked()?,
        },
        QueryOp::Clearance {
            shape,
            pose: p,
            max_distance,
            own,
            filter,
        } => {
            shape.check()?;
            QueryOp::Clearance {
                shape,
                pose: pose("cframe", p)?,
                max_distance: reach("MaxDistance", max_distance)?,
                own,
                filter: filter.checked()?,
            }
        }
        QueryOp::ProbeWall {
            pose: p,
            radius,
            height,
            max_distance,
            max_slope,
            filter,
        } => {
            let radius = extent("radius", radius)?;
            let height = extent("height", height)?;
            QueryOp::ProbeWall {
                pose: pose("cframe", p)?,
                radius,
                height,
                max_distance: reach("maxDistance", max_distance)?,
                max_slope: slope("MaxSlopeAngle", max_slope)?,
                filter: filter.checked()?,
            }
        }
        other => other,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bad_rays_name_their_index_and_field() {
        let op = QueryOp::Raycast {
            rays: vec![
                Ray {
                    origin: [0.0; 3],
                    direction: [0.0, -1.0, 0.0],
                },
                Ray {
                    origin: [0.0; 3],
                    direction: [f32::NAN, 0.0, 0.0],
                },
            ],
            filter: QueryFilter::default(),
        };
        let e = op.checked().unwrap_err();
        assert_eq!(e.field.as_deref(), Some("rays[1].direction"));
        assert!(e.message.contains("NaN"), "{}", e.message);
    }

    #[test]
    fn a_negative_radius_is_refused() {
        let op = QueryOp::Spherecast {
            origin: [0.0; 3],
            radius: -1.0,
            direction: [1.0, 0.0, 0.0],
            filter: QueryFilter::default(),
        };
        assert_eq!(op.checked().unwrap_err().field.as_deref(), Some("radius"));
    }
}

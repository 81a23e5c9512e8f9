//! Scene queries on a plane (Roblox's `Raycast`, `Spherecast`, `Blockcast`, `Shapecast`,
//! `GetPartBoundsInRadius`, `GetPartBoundsInBox`, `GetPartsInPart`), each one round trip that
//! also carries the queued writes, so a query sees what this client just did.
//!
//! The daemon answers an overlap query with at most `MAX_QUERY_RESULTS` objects per reply
//! and says when it cut the list; the SDK asks for the pages after it, so a query returns
//! every object it found (or the first `max_parts`, Roblox's `OverlapParams.MaxParts`) while
//! no single reply grows with the plane.

use shm_layout::{FilterType, Handle, Hit, PlaneOp, Pose, QueryFilter, QueryOp, Ray, Reply, Vec3};

use crate::{error::Error, object::Object, plane::Plane};

/// Which objects a query considers (Roblox's `RaycastParams` / `OverlapParams`).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct QueryParams {
    /// `Exclude` (default): `filter` is skipped; `Include`: only `filter` may be hit.
    pub filter_type: FilterType,
    /// The objects `filter_type` applies to.
    pub filter: Vec<Handle>,
    /// Only objects whose group collides with this registered group are considered.
    pub collision_group: Option<String>,
    /// Skip objects with CanCollide = false (default false: queries see every object).
    pub respect_can_collide: bool,
    /// Overlap queries return at most this many objects, the lowest slots first (Roblox's
    /// `OverlapParams.MaxParts`); 0 (the default): all of them.
    pub max_parts: usize,
}

/// What an overlap query found.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Found {
    /// The objects, ascending slots.
    pub objects: Vec<Handle>,
    /// More objects matched than `max_parts` allowed: `objects` is the first `max_parts`.
    pub truncated: bool,
}

impl QueryParams {
    /// Everything but `objects`.
    pub fn excluding(objects: &[&Object]) -> QueryParams {
        QueryParams {
            filter: objects.iter().map(|o| o.handle()).collect(),
            ..QueryParams::default()
        }
    }

    /// Only `objects`.
    pub fn including(objects: &[&Object]) -> QueryParams {
        QueryParams {
            filter_type: FilterType::Include,
            ..QueryParams::excluding(objects)
        }
    }
}

impl Plane {
    pub(crate) fn wire_filter(&self, params: Option<&QueryParams>) -> Result<QueryFilter, Error> {
        let Some(p) = params else {
            return Ok(QueryFilter::default());
        };
        let collision_group = match &p.collision_group {
            Some(name) => Some(self.client().collision_group_id(name)?),
            None => None,
        };
        Ok(QueryFilter {
            filter_type: p.filter_type,
            list: p.filter.clone(),
            collision_group,
            respect_can_collide: p.respect_can_collide,
        })
    }

    pub(crate) fn query(&self, op: QueryOp) -> Result<Reply, Error> {
        let op = op.checked().map_err(Error::invalid_value)?;
        self.client()
            .call(shm_layout::Command::plane(self.id(), PlaneOp::Query(op)))
    }

    fn hits(&self, op: QueryOp) -> Result<Vec<Option<Hit>>, Error> {
        match self.query(op)? {
            Reply::Hits(hits) => Ok(hits),
            other => Err(Error::Protocol(format!("expected hits, got {other:?}"))),
        }
    }

    fn first_hit(&self, op: QueryOp) -> Result<Option<Hit>, Error> {
        Ok(self.hits(op)?.into_iter().next().flatten())
    }

    /// Runs the overlap query `op`, following the daemon's pages until every object (or
    /// `max_parts`, when not 0) is in.
    fn objects(&self, op: QueryOp, max_parts: usize) -> Result<Found, Error> {
        let mut objects = Vec::new();
        let mut reply = self.query(op.clone())?;
        loop {
            let more = match reply {
                Reply::Objects(found) => {
                    objects.extend(found);
                    false
                }
                Reply::ObjectPage {
                    objects: found,
                    truncated,
                } => {
                    objects.extend(found);
                    truncated
                }
                other => return Err(Error::Protocol(format!("expected objects, got {other:?}"))),
            };
            if max_parts > 0 && objects.len() >= max_parts {
                let truncated = more || objects.len() > max_parts;
                objects.truncate(max_parts);
                return Ok(Found { objects, truncated });
            }
            let Some(last) = objects.last().filter(|_| more) else {
                return Ok(Found {
                    objects,
                    truncated: false,
                });
            };
            reply = self.query(QueryOp::Page {
                query: Box::new(op.clone()),
                after_slot: last.slot,
            })?;
        }
    }

    /// The first object along `direction` from `origin` (the length of `direction` is the
    /// reach). A ray starting inside an object does not hit it.
    pub fn raycast(
        &self,
        origin: Vec3,
        direction: Vec3,
        params: Option<&QueryParams>,
    ) -> Result<Option<Hit>, Error> {
        Ok(self
            .raycast_many(&[Ray { origin, direction }], params)?
            .pop()
            .flatten())
    }

    /// Many rays in one request: one optional hit per ray, in order.
    pub fn raycast_many(
        &self,
        rays: &[Ray],
        params: Option<&QueryParams>,
    ) -> Result<Vec<Option<Hit>>, Error> {
        let hits = self.hits(QueryOp::Raycast {
            rays: rays.to_vec(),
            filter: self.wire_filter(params)?,
        })?;
        if hits.len() != rays.len() {
            return Err(Error::Protocol(format!(
                "{} rays got {} results",
                rays.len(),
                hits.len()
            )));
        }
        Ok(hits)
    }

    /// Sweeps a sphere; the hit's position is the contact point.
    pub fn spherecast(
        &self,
        origin: Vec3,
        radius: f32,
        direction: Vec3,
        params: Option<&QueryParams>,
    ) -> Result<Option<Hit>, Error> {
        self.first_hit(QueryOp::Spherecast {
            origin,
            radius,
            direction,
            filter: self.wire_filter(params)?,
        })
    }

    /// Sweeps a box of full `size` starting at `pose`.
    pub fn blockcast(
        &self,
        pose: Pose,
        size: Vec3,
        direction: Vec3,
        params: Option<&QueryParams>,
    ) -> Result<Option<Hit>, Error> {
        self.first_hit(QueryOp::Blockcast {
            pose,
            size,
            direction,
            filter: self.wire_filter(params)?,
        })
    }

    /// Sweeps `object`'s own shape from where it is (it never hits itself).
    pub fn shapecast(
        &self,
        object: &Object,
        direction: Vec3,
        params: Option<&QueryParams>,
    ) -> Result<Option<Hit>, Error> {
        self.first_hit(QueryOp::Shapecast {
            object: object.handle(),
            direction,
            filter: self.wire_filter(params)?,
        })
    }

    /// Objects whose world bounding box touches the sphere.
    pub fn bounds_in_radius(
        &self,
        position: Vec3,
        radius: f32,
        params: Option<&QueryParams>,
    ) -> Result<Vec<Handle>, Error> {
        Ok(self
            .bounds_in_radius_found(position, radius, params)?
            .objects)
    }

    /// [`Plane::bounds_in_radius`], saying whether `max_parts` cut the list.
    pub fn bounds_in_radius_found(
        &self,
        position: Vec3,
        radius: f32,
        params: Option<&QueryParams>,
    ) -> Result<Found, Error> {
        let op = QueryOp::BoundsInRadius {
            position,
            radius,
            filter: self.wire_filter(params)?,
        };
        self.objects(op, params.map_or(0, |p| p.max_parts))
    }

    /// Objects whose world bounding box touches the oriented box.
    pub fn bounds_in_box(
        &self,
        pose: Pose,
        size: Vec3,
        params: Option<&QueryParams>,
    ) -> Result<Vec<Handle>, Error> {
        Ok(self.bounds_in_box_found(pose, size, params)?.objects)
    }

    /// [`Plane::bounds_in_box`], saying whether `max_parts` cut the list.
    pub fn bounds_in_box_found(
        &self,
        pose: Pose,
        size: Vec3,
        params: Option<&QueryParams>,
    ) -> Result<Found, Error> {
        let op = QueryOp::BoundsInBox {
            pose,
            size,
            filter: self.wire_filter(params)?,
        };
        self.objects(op, params.map_or(0, |p| p.max_parts))
    }

    /// Objects whose shape overlaps `object`'s shape (exact test).
    pub fn parts_in_part(
        &self,
        object: &Object,
        params: Option<&QueryParams>,
    ) -> Result<Vec<Handle>, Error> {
        Ok(self.parts_in_part_found(object, params)?.objects)
    }

    /// [`Plane::parts_in_part`], saying whether `max_parts` cut the list.
    pub fn parts_in_part_found(
        &self,
        object: &Object,
        params: Option<&QueryParams>,
    ) -> Result<Found, Error> {
        let op = QueryOp::InPart {
            object: object.handle(),
            filter: self.wire_filter(params)?,
        };
        self.objects(op, params.map_or(0, |p| p.max_parts))
    }
}

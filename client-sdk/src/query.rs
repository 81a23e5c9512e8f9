//! Scene queries on a plane (Roblox's `Raycast`, `Spherecast`, `Blockcast`, `Shapecast`,
//! `GetPartBoundsInRadius`, `GetPartBoundsInBox`, `GetPartsInPart`), each one round trip that
//! also carries the queued writes, so a query sees what this client just did.

use shm_layout::{FilterType, Handle, Hit, PlaneOp, Pose, QueryFilter, QueryOp, Ray, Reply, Vec3};

use crate::{Error, Object, Plane};

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

    fn objects(&self, op: QueryOp) -> Result<Vec<Handle>, Error> {
        match self.query(op)? {
            Reply::Objects(found) => Ok(found),
            other => Err(Error::Protocol(format!("expected objects, got {other:?}"))),
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
        self.objects(QueryOp::BoundsInRadius {
            position,
            radius,
            filter: self.wire_filter(params)?,
        })
    }

    /// Objects whose world bounding box touches the oriented box.
    pub fn bounds_in_box(
        &self,
        pose: Pose,
        size: Vec3,
        params: Option<&QueryParams>,
    ) -> Result<Vec<Handle>, Error> {
        self.objects(QueryOp::BoundsInBox {
            pose,
            size,
            filter: self.wire_filter(params)?,
        })
    }

    /// Objects whose shape overlaps `object`'s shape (exact test).
    pub fn parts_in_part(
        &self,
        object: &Object,
        params: Option<&QueryParams>,
    ) -> Result<Vec<Handle>, Error> {
        self.objects(QueryOp::InPart {
            object: object.handle(),
            filter: self.wire_filter(params)?,
        })
    }
}

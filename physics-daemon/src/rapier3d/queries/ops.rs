//! Scene queries on rapier's query pipeline: rays, swept spheres / boxes / object shapes,
//! and overlap tests, with Roblox's filter (Include / Exclude list, collision group,
//! RespectCanCollide). Queries see the latest tick plus whatever ops added, moved or
//! removed since: such a change first refreshes the broad phase's tree (no time passes).

use std::cell::RefCell;
use std::collections::HashSet;

use rapier3d::parry::query::ShapeCastOptions;
use rapier3d::prelude::*;
use shm_layout::query::page_of;
use shm_layout::{CommandError, FilterType, Handle, Hit, QueryFilter, QueryOp, Reply, Vec3};

use crate::backend::rapier_world::RapierWorld;
use crate::rapier3d::plane::Plane;

/// How many objects containing a ray's or sweep's start are skipped before giving up (a
/// start buried in more than this many overlapping objects reports no hit).
const MAX_STARTS_INSIDE: usize = 16;

/// A query's filter, resolved against the plane once per query.
pub(in crate::rapier3d) struct Resolved<'a> {
    plane: &'a Plane,
    filter_type: FilterType,
    list: HashSet<Handle>,
    /// The query group's mask (which object groups it sees), when filtering by group.
    group_mask: Option<u32>,
    respect_can_collide: bool,
    /// Colliders skipped because the cast started inside them.
    skipped: RefCell<Vec<ColliderHandle>>,
    /// The body whose own shape is being cast or tested.
    own_body: Option<RigidBodyHandle>,
}

impl Resolved<'_> {
    /// Whether the query may see `collider`.
    pub(in crate::rapier3d) fn accepts(&self, collider: ColliderHandle, co: &Collider) -> bool {
        let Some(body) = co.parent() else {
            return false;
        };
        if Some(body) == self.own_body || self.skipped.borrow().contains(&collider) {
            return false;
        }
        let Some(handle) = self.plane.handle_of_collider(collider) else {
            return false;
        };
        let listed = self.list.contains(&handle);
        if listed != (self.filter_type == FilterType::Include) {
            return false;
        }
        let part = self.plane.part(handle);
        if self.respect_can_collide && !part.can_collide {
            return false;
        }
        self.group_mask
            .is_none_or(|mask| mask & (1 << part.collision_group) != 0)
    }
}

impl Plane {
    /// The plane's colliders as a query pipeline that answers through
    /// [`ClippedQueries`](crate::rapier3d::contacts::clipped::ClippedQueries).
    pub(in crate::rapier3d) fn query_pipeline<'a>(
        &'a self,
        filter: rapier3d::prelude::QueryFilter<'a>,
    ) -> rapier3d::prelude::QueryPipeline<'a> {
        crate::rapier3d::contacts::clipped::query_pipeline(&self.world, filter)
    }

    /// Runs one query (checked first). Objects added or moved since the last step are seen.
    pub fn query(&mut self, op: QueryOp) -> Result<Reply, CommandError> {
        let op = op.checked()?;
        self.refresh_scene();
        Ok(match op {
            QueryOp::Raycast { rays, filter } => {
                let f = self.resolve(&filter, None)?;
                Reply::Hits(
                    rays.iter()
                        .map(|r| self.raycast(&f, r.origin, r.direction))
                        .collect(),
                )
            }
            QueryOp::Spherecast {
                origin,
                radius,
                direction,
                filter,
            } => {
                let f = self.resolve(&filter, None)?;
                let start = rapier3d::math::Pose::from_translation(Vector::from(origin));
                let hit = self.sweep(&f, &start, &Ball::new(radius), direction);
                Reply::Hits(vec![hit])
            }
            QueryOp::Blockcast {
                pose,
                size,
                direction,
                filter,
            } => {
                let f = self.resolve(&filter, None)?;
                let shape = Cuboid::new(Vector::from(size) / 2.0);
                let hit = self.sweep(
                    &f,
                    &crate::rapier3d::objects::object::rapier_pose(pose),
                    &shape,
                    direction,
                );
                Reply::Hits(vec![hit])
            }
            QueryOp::Shapecast {
                object,
                direction,
                filter,
            } => {
                let (own, collider) = self.collider_of(object)?;
                let f = self.resolve(&filter, Some(own))?;
                let co = &self.world.colliders[collider];
                let hit = self.sweep(&f, co.position(), co.shape(), direction);
                Reply::Hits(vec![hit])
            }
            QueryOp::Page { query, after_slot } => {
                let (objects, truncated) = page_of(self.overlap(*query)?, Some(after_slot));
                Reply::ObjectPage { objects, truncated }
            }
            // The proximity queries (probes.rs).
            op @ (QueryOp::ProbeGround { .. }
            | QueryOp::ClosestPoint { .. }
            | QueryOp::Clearance { .. }
            | QueryOp::ProbeWall { .. }) => Reply::Probe(self.probe(op)?),
            overlap => match page_of(self.overlap(overlap)?, None) {
                (objects, false) => Reply::Objects(objects),
                (objects, true) => Reply::ObjectPage {
                    objects,
                    truncated: true,
                },
            },
        })
    }

    /// Every object an overlap query finds, ascending slots (the caller pages it).
    fn overlap(&self, op: QueryOp) -> Result<Vec<Handle>, CommandError> {
        Ok(match op {
            QueryOp::BoundsInRadius {
                position,
                radius,
                filter,
            } => {
                let f = self.resolve(&filter, None)?;
                let centre = Vector::from(position);
                let query = Aabb::new(
                    centre - Vector::splat(radius),
                    centre + Vector::splat(radius),
                );
                self.bounds_overlapping(&f, query, |aabb| {
                    // Distance from the centre to the box, squared.
                    let d = (centre.clamp(aabb.mins, aabb.maxs) - centre).length_squared();
                    d <= radius * radius
                })
            }
            QueryOp::BoundsInBox { pose, size, filter } => {
                let f = self.resolve(&filter, None)?;
                let pose = crate::rapier3d::objects::object::rapier_pose(pose);
                let cuboid = Cuboid::new(Vector::from(size) / 2.0);
                let query = cuboid.compute_aabb(&pose);
                self.bounds_overlapping(&f, query, |aabb| {
                    let other = rapier3d::math::Pose::from_translation(aabb.center());
                    rapier3d::parry::query::intersection_test(
                        &pose,
                        &cuboid,
                        &other,
                        &Cuboid::new(aabb.half_extents()),
                    )
                    .map_or(true, |hit| hit.intersecting)
                })
            }
            QueryOp::InPart { object, filter } => {
                let (own, collider) = self.collider_of(object)?;
                let f = self.resolve(&filter, Some(own))?;
                let co = &self.world.colliders[collider];
                let predicate = |c: ColliderHandle, co: &Collider| f.accepts(c, co);
                let pipeline = self.query_pipeline(QueryFilter_::default().predicate(&predicate));
                let mut found: Vec<Handle> = pipeline
                    .intersect_shape(*co.position(), co.shape())
                    .filter_map(|(c, _)| self.handle_of_collider(c))
                    .collect();
                found.sort_by_key(|h| h.slot);
                found.dedup();
                found
            }
            _ => {
                return Err(CommandError::invalid(
                    "only BoundsInRadius, BoundsInBox and InPart list objects",
                ))
            }
        })
    }

    /// Brings the colliders of bodies ops added, moved or reshaped since the last step to
    /// their bodies' poses and puts their boxes into the broad phase's tree, which queries
    /// walk. No time passes and no contact is computed (the step does that as always).
    pub(in crate::rapier3d) fn refresh_scene(&mut self) {
        self.world.refresh_colliders(&mut self.queries.stale);
    }

    pub(in crate::rapier3d) fn resolve(
        &self,
        filter: &QueryFilter,
        own_body: Option<RigidBodyHandle>,
    ) -> Result<Resolved<'_>, CommandError> {
        let group_mask = match filter.collision_group {
            Some(g) if !self.queries.groups.is_registered(g) => {
                return Err(CommandError::invalid_field(
                    "CollisionGroup",
                    format!(
                        "CollisionGroup {g} is not a registered group of plane {}",
                        self.id
                    ),
                ))
            }
            Some(g) => Some(self.queries.groups.mask(g)),
            None => None,
        };
        Ok(Resolved {
            plane: self,
            filter_type: filter.filter_type,
            list: filter.list.iter().copied().collect(),
            group_mask,
            respect_can_collide: filter.respect_can_collide,
            skipped: RefCell::default(),
            own_body,
        })
    }

    /// The body and collider of a live object, or an error naming the handle.
    fn collider_of(
        &self,
        object: Handle,
    ) -> Result<(RigidBodyHandle, ColliderHandle), CommandError> {
        let body = self.body_of(object)?;
        let collider = *self.world.bodies[body]
            .colliders()
            .first()
            .ok_or_else(|| CommandError::invalid(format!("object {object} has no collider")))?;
        Ok((body, collider))
    }

    /// The first object along the ray, skipping objects the origin lies inside.
    fn raycast(&self, f: &Resolved<'_>, origin: Vec3, direction: Vec3) -> Option<Hit> {
        let dir = Vector::from(direction);
        let reach = dir.length();
        if reach == 0.0 {
            return None;
        }
        let ray = rapier3d::parry::query::Ray::new(Vector::from(origin), dir / reach);
        f.skipped.borrow_mut().clear();
        let predicate = |c: ColliderHandle, co: &Collider| f.accepts(c, co);
        let pipeline = self.query_pipeline(QueryFilter_::default().predicate(&predicate));
        for _ in 0..MAX_STARTS_INSIDE {
            let (c, hit) = pipeline.cast_ray_and_get_normal(&ray, reach, true)?;
            if hit.time_of_impact <= 0.0 {
                f.skipped.borrow_mut().push(c);
                continue;
            }
            return Some(Hit {
                object: self.handle_of_collider(c)?,
                position: ray.point_at(hit.time_of_impact).into(),
                normal: hit.normal.into(),
                distance: hit.time_of_impact,
            });
        }
        None
    }

    /// The first object `shape` meets moving from `start` along `direction`, skipping objects
    /// it overlaps at the start (Roblox convention).
    fn sweep(
        &self,
        f: &Resolved<'_>,
        start: &rapier3d::math::Pose,
        shape: &dyn rapier3d::parry::shape::Shape,
        direction: Vec3,
    ) -> Option<Hit> {
        let dir = Vector::from(direction);
        let reach = dir.length();
        if reach == 0.0 {
            return None;
        }
        f.skipped.borrow_mut().clear();
        let predicate = |c: ColliderHandle, co: &Collider| f.accepts(c, co);
        let pipeline = self.query_pipeline(QueryFilter_::default().predicate(&predicate));
        let options = ShapeCastOptions {
            max_time_of_impact: 1.0,
            target_distance: 0.0,
            stop_at_penetration: true,
            compute_impact_geometry_on_penetration: true,
        };
        for _ in 0..MAX_STARTS_INSIDE {
            let (c, hit) = pipeline.cast_shape(start, dir, shape, options)?;
            if hit.time_of_impact <= 0.0 {
                f.skipped.borrow_mut().push(c);
                continue;
            }
            return Some(Hit {
                object: self.handle_of_collider(c)?,
                position: hit.witness1.into(),
                normal: hit.normal1.into(),
                distance: hit.time_of_impact * reach,
            });
        }
        None
    }

    /// Objects whose exact world bounding box passes `touches`, among those whose broad-phase
    /// box meets `query`.
    fn bounds_overlapping(
        &self,
        f: &Resolved<'_>,
        query: Aabb,
        touches: impl Fn(&Aabb) -> bool,
    ) -> Vec<Handle> {
        let predicate = |c: ColliderHandle, co: &Collider| f.accepts(c, co);
        let pipeline = self.query_pipeline(QueryFilter_::default().predicate(&predicate));
        let mut found: Vec<Handle> = pipeline
            .intersect_aabb_conservative(query)
            .filter(|(_, co)| touches(&co.compute_aabb()))
            .filter_map(|(c, _)| self.handle_of_collider(c))
            .collect();
        found.sort_by_key(|h| h.slot);
        found.dedup();
        found
    }
}

/// Rapier's query filter (our `QueryFilter` is the wire type).
type QueryFilter_<'a> = rapier3d::prelude::QueryFilter<'a>;

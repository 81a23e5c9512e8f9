//! What a controller can touch in one tick: the colliders near it, gathered once per tick
//! from the broad phase (one AABB query over the region the tick's move, step, snap and
//! ground probe can reach), and the scene queries of the tick answered over that short list
//! instead of the plane's whole tree.
//!
//! The queries answer exactly as the plane's query pipeline would (the same dispatcher,
//! [`crate::rapier3d::clipped::ClippedQueries`], the same frames: a cast's `witness1` /
//! `normal1` in world space, `witness2` / `normal2` in the cast shape's own frame), so the
//! mover behaves as it did on the whole scene, as long as the region holds everything the
//! tick reaches (each stage asks [`Nearby::ensure`] for the region it reads, which gathers
//! again when it sticks out).

use rapier3d::parry::bounding_volume::{Aabb, BoundingVolume};
use rapier3d::parry::query::{QueryDispatcher, Ray, RayCast, ShapeCastHit, ShapeCastOptions};
use rapier3d::prelude::*;

use crate::rapier3d::clipped::ClippedQueries;

/// A collider near the controller: its handle, the collider, and its AABB now.
#[derive(Clone, Copy)]
pub(super) struct Candidate<'a> {
    pub handle: ColliderHandle,
    pub collider: &'a Collider,
    pub aabb: Aabb,
}

/// What a controller's queries read: the plane's broad phase, bodies and colliders
/// (shared by every controller of a tick, on any thread).
#[derive(Clone, Copy)]
pub(super) struct SceneRefs<'a> {
    pub broad_phase: &'a BroadPhaseBvh,
    pub bodies: &'a RigidBodySet,
    pub colliders: &'a ColliderSet,
}

/// The colliders within a region around a controller (its own body, sensors and colliders
/// its collision group does not collide with left out).
pub(super) struct Nearby<'a> {
    /// Every candidate, in the broad phase's order.
    pub items: Vec<Candidate<'a>>,
    /// The region they were gathered from.
    region: Aabb,
    scene: SceneRefs<'a>,
    own: RigidBodyHandle,
    groups: InteractionGroups,
}

/// The dispatcher of every controller query (see the module docs).
static DISPATCHER: ClippedQueries = ClippedQueries;

impl<'a> Nearby<'a> {
    /// The colliders whose broad-phase AABB meets `region` and that `own` (a controller's
    /// body, of collision groups `groups`) can touch.
    pub fn gather(
        scene: SceneRefs<'a>,
        own: RigidBodyHandle,
        groups: InteractionGroups,
        region: Aabb,
    ) -> Nearby<'a> {
        let mut nearby = Nearby {
            items: Vec::new(),
            region,
            scene,
            own,
            groups,
        };
        nearby.fill();
        nearby
    }

    /// Gathers the candidates of `self.region`.
    fn fill(&mut self) {
        let (own, groups) = (self.own, self.groups);
        let pred = |_: ColliderHandle, co: &Collider| {
            co.parent() != Some(own) && co.collision_groups().test(groups) && !co.is_sensor()
        };
        let filter = QueryFilter::default().predicate(&pred);
        let SceneRefs {
            broad_phase,
            bodies,
            colliders,
        } = self.scene;
        let pipeline = broad_phase.as_query_pipeline(&DISPATCHER, bodies, colliders, filter);
        let handles: Vec<ColliderHandle> = pipeline
            .intersect_aabb_conservative(self.region)
            .map(|(handle, _)| handle)
            .collect();
        self.items.clear();
        self.items.extend(handles.into_iter().filter_map(|handle| {
            let collider = colliders.get(handle)?;
            Some(Candidate {
                handle,
                collider,
                aabb: collider.compute_aabb(),
            })
        }));
    }

    /// Makes sure every query within `need` is answered: gathers again (over both regions,
    /// widened by `slack`) when `need` sticks out of the region gathered (a controller
    /// pushed far out of an overlap, a long fall).
    pub fn ensure(&mut self, need: Aabb, slack: f32) {
        if !self.region.contains(&need) {
            self.region = self.region.merged(&need.loosened(slack));
            self.fill();
        }
    }

    /// The plane's bodies (the colliders' parents).
    pub fn bodies(&self) -> &'a RigidBodySet {
        self.scene.bodies
    }

    /// Whether nothing at all is near.
    pub fn is_empty(&self) -> bool {
        self.items.is_empty()
    }

    /// The first collider `shape` at `pose` hits moving along the unit `dir` (or any
    /// direction of length = speed) within `options.max_time_of_impact`, as
    /// `QueryPipeline::cast_shape` answers it.
    pub fn cast_shape(
        &self,
        pose: &Pose,
        dir: Vector,
        shape: &dyn Shape,
        options: ShapeCastOptions,
    ) -> Option<(ColliderHandle, ShapeCastHit)> {
        // The swept shape's AABB against each candidate's, as a ray against their
        // Minkowski sum (parry's own pruning of a composite cast).
        let own = shape.compute_aabb(pose);
        let margin = own.half_extents() + Vector::splat(options.target_distance);
        let ray = Ray::new(own.center(), dir);
        let mut best: Option<(ColliderHandle, ShapeCastHit)> = None;
        for c in &self.items {
            let reach = best
                .as_ref()
                .map_or(options.max_time_of_impact, |(_, h)| h.time_of_impact);
            let msum = Aabb::new(c.aabb.mins - margin, c.aabb.maxs + margin);
            if msum.cast_local_ray(&ray, reach, true).is_none() {
                continue;
            }
            let co_pose = c.collider.position();
            let Ok(Some(hit)) = DISPATCHER.cast_shapes(
                &co_pose.inv_mul(pose),
                co_pose.rotation.inverse() * dir,
                c.collider.shape(),
                shape,
                options,
            ) else {
                continue;
            };
            if best
                .as_ref()
                .is_none_or(|(_, b)| hit.time_of_impact < b.time_of_impact)
            {
                best = Some((c.handle, hit.transform1_by(co_pose)));
            }
        }
        best
    }

    /// The candidates whose AABB meets `aabb`.
    pub fn within(&self, aabb: Aabb) -> impl Iterator<Item = &Candidate<'a>> + '_ {
        self.items.iter().filter(move |c| c.aabb.intersects(&aabb))
    }

    /// Whether `shape` at `pose` overlaps any candidate.
    pub fn intersects_any(&self, pose: &Pose, shape: &dyn Shape) -> bool {
        self.within(shape.compute_aabb(pose)).any(|c| {
            let pos12 = pose.inv_mul(c.collider.position());
            DISPATCHER
                .intersection_test(&pos12, shape, c.collider.shape())
                .is_ok_and(|hit| hit.intersecting)
        })
    }
}

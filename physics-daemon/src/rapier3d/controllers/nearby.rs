//! What a controller can touch in one tick: the colliders near it, gathered once per tick
//! from the broad phase (one AABB query over the region the tick's move, step, snap and
//! ground probe can reach), and the scene queries of the tick answered over that short list
//! instead of the plane's whole tree.
//!
//! The queries answer exactly as the plane's query pipeline would (the same dispatcher,
//! [`crate::rapier3d::contacts::clipped::ClippedQueries`], the same frames: a cast's `witness1` /
//! `normal1` in world space, `witness2` / `normal2` in the cast shape's own frame), so the
//! mover behaves as it did on the whole scene, as long as the region holds everything the
//! tick reaches (each stage asks [`Nearby::ensure`] for the region it reads, which gathers
//! again when it sticks out).
//!
//! A tick allocates nothing here: the candidate list is a buffer of the thread it runs on,
//! handed back when the tick ends. A box candidate keeps its half extents, so the
//! capsule's contacts with it (most of a tick's work) go straight to the closed form of
//! `contacts::capsule` without asking the shapes what they are.

use std::cell::{Cell, RefCell};

use rapier3d::parry::bounding_volume::{Aabb, BoundingVolume};
use rapier3d::parry::query::{
    Contact, QueryDispatcher, Ray, RayCast, ShapeCastHit, ShapeCastOptions, Unsupported,
};
use rapier3d::parry::shape::Capsule;
use rapier3d::prelude::*;

use crate::rapier3d::contacts::clipped::ClippedQueries;

/// A collider near the controller: its handle, pose, body and AABB now, and its half
/// extents when it is a box.
#[derive(Clone, Copy)]
pub(super) struct Candidate {
    pub handle: ColliderHandle,
    pub pose: Pose,
    pub parent: Option<RigidBodyHandle>,
    pub aabb: Aabb,
    cuboid: Option<Vector>,
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
    pub items: Vec<Candidate>,
    /// The region they were gathered from.
    region: Aabb,
    scene: SceneRefs<'a>,
    own: RigidBodyHandle,
    groups: InteractionGroups,
    /// What the tick's queries covered so far: every query's volume merged (a candidate
    /// whose AABB stays outside it cannot change any answer).
    covered: Cell<Aabb>,
}

/// The dispatcher of every controller query (see the module docs).
static DISPATCHER: ClippedQueries = ClippedQueries;

thread_local! {
    /// The candidate buffer of this thread's ticks (see the module docs).
    static BUFFER: RefCell<Vec<Candidate>> = const { RefCell::new(Vec::new()) };
}

/// The AABB of the controller's `capsule` at `pose`: for an upright pose (turned about Y
/// only, as a controller always is) its segment's ends less and plus the radius, as
/// parry's own AABB has them, without rotating the ends; parry's otherwise.
pub(super) fn capsule_aabb(capsule: &Capsule, pose: &Pose) -> Aabb {
    if pose.rotation.x != 0.0 || pose.rotation.z != 0.0 {
        return capsule.compute_aabb(pose);
    }
    let (a, b) = (
        pose.translation + capsule.segment.a,
        pose.translation + capsule.segment.b,
    );
    let r = Vector::splat(capsule.radius);
    Aabb::new(a.min(b) - r, a.max(b) + r)
}

impl<'a> Nearby<'a> {
    /// The colliders whose broad-phase AABB meets `region` and that `own` (a controller's
    /// body, of collision groups `groups`) can touch.
    pub fn gather(
        scene: SceneRefs<'a>,
        own: RigidBodyHandle,
        groups: InteractionGroups,
        region: Aabb,
    ) -> Nearby<'a> {
        let items = BUFFER.with(|b| std::mem::take(&mut *b.borrow_mut()));
        let mut nearby = Nearby {
            items,
            region,
            scene,
            own,
            groups,
            covered: Cell::new(Aabb::new_invalid()),
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
        self.items.clear();
        self.items
            .extend(
                pipeline
                    .intersect_aabb_conservative(self.region)
                    .map(|(handle, collider)| Candidate {
                        handle,
                        pose: *collider.position(),
                        parent: collider.parent(),
                        aabb: collider.compute_aabb(),
                        cuboid: collider.shape().as_cuboid().map(|c| c.half_extents),
                    }),
            );
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

    /// The shape of candidate `c`.
    pub fn shape(&self, c: &Candidate) -> &'a dyn Shape {
        self.scene.colliders[c.handle].shape()
    }

    /// Merges `aabb` into what the tick's queries covered.
    pub fn cover(&self, aabb: Aabb) {
        self.covered.set(self.covered.get().merged(&aabb));
    }

    /// What the tick's queries covered: the volume of every query asked so far (and what
    /// [`Nearby::cover`] added). A candidate whose AABB stays outside it, before and after
    /// a change, answers no query differently (each query prunes by AABB first).
    pub fn covered(&self) -> Aabb {
        self.covered.get()
    }

    /// Whether nothing at all is near. (With nothing near a tick moves by its whole motion;
    /// with candidates that no query reaches it moves exactly as far, so this answer reads
    /// nothing that [`Nearby::covered`] must hold.)
    pub fn is_empty(&self) -> bool {
        self.items.is_empty()
    }

    /// The contact of `capsule` with candidate `c` placed at `pos12` in the capsule's
    /// frame, as [`crate::rapier3d::contacts::clipped::contact`] answers it.
    pub fn contact(
        &self,
        c: &Candidate,
        pos12: &Pose,
        capsule: &Capsule,
        prediction: f32,
    ) -> Result<Option<Contact>, Unsupported> {
        if let Some(he) = c.cuboid {
            let (a, b) = (capsule.segment.a, capsule.segment.b);
            let radius = capsule.radius;
            if let Some(found) =
                crate::rapier3d::contacts::capsule::capsule_box(pos12, a, b, radius, he, prediction)
            {
                return Ok(found);
            }
        }
        crate::rapier3d::contacts::clipped::contact(pos12, capsule, self.shape(c), prediction)
    }

    /// The first collider `capsule` at `pose` hits moving along the unit `dir` (or any
    /// direction of length = speed) within `options.max_time_of_impact`, as
    /// `QueryPipeline::cast_shape` answers it.
    pub fn cast_shape(
        &self,
        pose: &Pose,
        dir: Vector,
        capsule: &Capsule,
        options: ShapeCastOptions,
    ) -> Option<(ColliderHandle, ShapeCastHit)> {
        // The swept shape's AABB against each candidate's, as a ray against their
        // Minkowski sum (parry's own pruning of a composite cast).
        let own = capsule_aabb(capsule, pose);
        let margin = own.half_extents() + Vector::splat(options.target_distance);
        // The cast's volume: the shape's AABB swept the whole way (a candidate outside it
        // fails the pruning below).
        self.cover(
            own.merged(&own.translated(dir * options.max_time_of_impact))
                .loosened(options.target_distance),
        );
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
            let co_pose = &c.pose;
            let pos12 = co_pose.inv_mul(pose);
            let vel12 = co_pose.rotation.inverse() * dir;
            let found = match c.cuboid {
                // The plane's dispatcher on a box and a capsule (the same contacts, to f32
                // rounding, in the same order) without asking the shapes what they are.
                Some(he) => crate::rapier3d::contacts::clipped::cast_convex_with(
                    &pos12,
                    vel12,
                    self.shape(c),
                    capsule,
                    options,
                    |at, reach| {
                        let (a, b, radius) = (capsule.segment.a, capsule.segment.b, capsule.radius);
                        match crate::rapier3d::contacts::capsule::box_capsule(
                            at, a, b, radius, he, reach,
                        ) {
                            Some(found) => Ok(found),
                            None => crate::rapier3d::contacts::clipped::contact(
                                at,
                                self.shape(c),
                                capsule,
                                reach,
                            ),
                        }
                    },
                ),
                None => DISPATCHER.cast_shapes(&pos12, vel12, self.shape(c), capsule, options),
            };
            let Ok(Some(hit)) = found else {
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
    pub fn within(&self, aabb: Aabb) -> impl Iterator<Item = &Candidate> + '_ {
        self.cover(aabb);
        self.items.iter().filter(move |c| c.aabb.intersects(&aabb))
    }

    /// Whether `capsule` at `pose` overlaps any candidate.
    pub fn intersects_any(&self, pose: &Pose, capsule: &Capsule) -> bool {
        self.within(capsule_aabb(capsule, pose)).any(|c| {
            let pos12 = pose.inv_mul(&c.pose);
            DISPATCHER
                .intersection_test(&pos12, capsule, self.shape(c))
                .is_ok_and(|hit| hit.intersecting)
        })
    }
}

impl Drop for Nearby<'_> {
    /// Hands the candidate buffer back to the thread for its next tick.
    fn drop(&mut self) {
        let mut items = std::mem::take(&mut self.items);
        items.clear();
        BUFFER.with(|b| *b.borrow_mut() = items);
    }
}

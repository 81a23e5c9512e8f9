//! One controller tick: the stages listed in the module doc, in order.
//!
//! Controllers tick in slot order, each committing its move (pushes applied to dynamic
//! bodies, next kinematic pose, flags, events) before the next one reads the scene, so a
//! controller sees those before it where they are going and those after it where they were.
//!
//! On a plane with a pool (Threads > 1) and enough controllers to share, every controller
//! first works out its move on the pool from the scene as the last tick left it, reading
//! the plane only, in tasks of [`PARALLEL_CHUNK`] controllers. Each tick records what its
//! queries covered (the volume of every cast and contact query, its capsule where it starts
//! and ends: [`Nearby::covered`]) and the dynamic bodies in it. A controller got the same
//! move it would get in slot order, and commits it, unless a controller before it in slot
//! order moved with its capsule, where it was or where it went, inside that volume, or
//! pushed a dynamic body it read; those are ticked again in slot order as above. Either
//! way the result is the same, bit for bit. The pairs to compare are the controllers whose
//! covered volumes overlap (a sweep over the volumes sorted along X), and the controllers
//! ticked again (whose moves changed) are compared with every later one.

use std::collections::HashSet;

use rapier3d::parry::bounding_volume::{Aabb, BoundingVolume};
use rayon::prelude::*;

use super::mover::Mover;
use rapier3d::parry::shape::Capsule;

use super::nearby::{capsule_aabb, Nearby, SceneRefs};
use super::*;
use crate::rapier3d::plane::Plane;

/// Fewest controllers handed to the plane's pool (fewer are ticked on the plane's thread).
const PARALLEL_FROM: usize = 8;
/// Fewest controllers ticked as one task of the pool: a task costs a few microseconds to
/// hand over, a controller's tick one or two.
const PARALLEL_CHUNK: usize = 64;

/// The read-only view of a plane a controller's tick works from.
#[derive(Clone, Copy)]
pub(super) struct Scene<'a> {
    pub refs: SceneRefs<'a>,
    /// The plane's gravity (Y), for UsePlaneGravity.
    pub gravity_y: f32,
    /// Whether ticks run side by side and must say what they read that another
    /// controller's commit changes (`Outcome::covered`, `Outcome::dynamic`).
    pub side_by_side: bool,
}

/// Slack added to every covered volume: the colliders' own AABBs (what a commit changes)
/// and the queries' volumes are computed apart and may differ by rounding.
const COVER_SLACK: f32 = 1.0e-3;

/// A controller's tick ready to commit.
struct Outcome {
    t: TickState,
    next: Vector,
    /// The rotation of the next kinematic pose (the controller's yaw at the end of the tick).
    rotation: Rotation,
    pushes: Vec<Push>,
    /// The controller's state before the tick (to tick it again).
    saved: Saved,
    /// What the tick's queries covered, its capsule at the start and the end included
    /// (side by side only; empty otherwise).
    covered: Aabb,
    /// The dynamic bodies the tick read (their velocities: pushes, the platform it rides),
    /// which another controller's push changes (side by side only).
    dynamic: Vec<RigidBodyHandle>,
}

/// Where a committed controller's capsule was and went (its colliders' AABBs), when its
/// pose changed.
type Moved = Option<(Aabb, Aabb)>;

/// What a controller's tick changes in it, kept to tick it again from the start.
#[derive(Clone, Copy)]
struct Saved {
    velocity: Vector,
    yaw: f32,
    on_ground: bool,
    ground: Option<Ground>,
    path_index: usize,
    jump: bool,
}

impl Saved {
    fn of(c: &Controller) -> Saved {
        Saved {
            velocity: c.velocity,
            yaw: c.yaw,
            on_ground: c.on_ground,
            ground: c.ground,
            path_index: c.path_index,
            jump: c.jump,
        }
    }

    fn restore(self, c: &mut Controller) {
        c.velocity = self.velocity;
        c.yaw = self.yaw;
        c.on_ground = self.on_ground;
        c.ground = self.ground;
        c.path_index = self.path_index;
        c.jump = self.jump;
    }
}

/// An impulse for a dynamic body the controller ran into.
pub(super) struct Push {
    pub body: RigidBodyHandle,
    pub impulse: Vector,
    pub point: Vector,
}

impl Plane {
    /// Moves every controller by one tick of `dt` (before the physics step).
    pub(in crate::rapier3d) fn tick_controllers(&mut self, dt: f32) {
        if self.controllers.is_empty() {
            return;
        }
        self.refresh_scene();
        // The map is taken for the tick and its controllers ticked where they are (moving
        // each out and building the map again cost more than some of their ticks).
        let mut controllers = std::mem::take(&mut self.controllers);
        let mut gone = Vec::new();
        let mut work = Vec::with_capacity(controllers.len());
        for (&slot, c) in controllers.iter_mut() {
            let Some(handle) = self.objects.handle_at(slot as usize) else {
                gone.push(slot); // its object is gone
                continue;
            };
            if let Ok(h) = self.body_of(handle) {
                work.push((handle, h, c));
            }
        }
        let pool = (work.len() >= PARALLEL_FROM)
            .then(|| self.world.physics_pipeline.thread_pool())
            .flatten();
        match pool {
            None => {
                for (handle, h, c) in work {
                    let o = self.scene(false).tick(handle, h, c, dt);
                    self.commit_tick(o, c, dt, false);
                }
            }
            Some(pool) => self.tick_side_by_side(&pool, work, dt),
        }
        for slot in gone {
            controllers.remove(&slot);
        }
        self.controllers = controllers;
    }

    /// The ticks of `work` on `pool`, each from the scene as the last tick left it, then
    /// committed in slot order, those that read what an earlier commit changed ticked
    /// again first (see the module docs).
    fn tick_side_by_side(
        &mut self,
        pool: &rayon::ThreadPool,
        work: Vec<(Handle, RigidBodyHandle, &mut Controller)>,
        dt: f32,
    ) {
        let outcomes: Vec<(Outcome, &mut Controller)> = {
            let scene = self.scene(true);
            pool.install(|| {
                work.into_par_iter()
                    .with_min_len(PARALLEL_CHUNK)
                    .map(|(handle, h, c)| (scene.tick(handle, h, c, dt), c))
                    .collect()
            })
        };
        let pairs = overlapping_pairs(&outcomes);
        let mut next_pair = 0;
        // Where the committed controllers went (by position in slot order), those ticked
        // again apart (their moves are not the ones the pairs were found from).
        let mut moved: Vec<Moved> = vec![None; outcomes.len()];
        let mut moved_again: Vec<(Aabb, Aabb)> = Vec::new();
        let mut pushed: HashSet<RigidBodyHandle> = HashSet::new();
        for (j, (o, c)) in outcomes.into_iter().enumerate() {
            let cov = o.covered;
            let inside = |(was, went): &(Aabb, Aabb)| was.intersects(&cov) || went.intersects(&cov);
            let mut again =
                o.dynamic.iter().any(|b| pushed.contains(b)) || moved_again.iter().any(inside);
            while let Some(&(_, earlier)) = pairs.get(next_pair).filter(|p| p.0 as usize == j) {
                again = again || moved[earlier as usize].as_ref().is_some_and(inside);
                next_pair += 1;
            }
            let o = if again {
                let Outcome { t, saved, .. } = o;
                saved.restore(c);
                self.scene(false).tick(t.handle, t.h, c, dt)
            } else {
                o
            };
            pushed.extend(o.pushes.iter().map(|p| p.body));
            let m = self.commit_tick(o, c, dt, true);
            match (again, m) {
                (true, Some(m)) => moved_again.push(m),
                (false, m) => moved[j] = m,
                (true, None) => {}
            }
        }
    }

    /// The read-only view a controller's tick works from; `side_by_side` when the tick must
    /// report what it read that others change.
    fn scene(&self, side_by_side: bool) -> Scene<'_> {
        Scene {
            refs: SceneRefs {
                broad_phase: &self.world.broad_phase,
                bodies: &self.world.bodies,
                colliders: &self.world.colliders,
            },
            gravity_y: self.settings.gravity[1],
            side_by_side,
        }
    }

    /// The end of controller `c`'s tick: its pushes, the next kinematic pose (and the
    /// colliders and broad phase, so queries before the step see it where it is going), the
    /// published flags and the tick's events. Returns, when `track` (ticks side by side),
    /// where its capsule was and went if its pose changed.
    fn commit_tick(&mut self, o: Outcome, c: &mut Controller, dt: f32, track: bool) -> Moved {
        let Outcome {
            t,
            next,
            rotation,
            pushes,
            ..
        } = o;
        // A finished path is cleared here, so a tick can be run again until it commits.
        if c.path_index >= c.path.len() && !c.path.is_empty() {
            c.path.clear();
            c.path_index = 0;
        }
        for p in pushes {
            if let Some(rb) = self.world.bodies.get_mut(p.body) {
                rb.apply_impulse_at_point(p.impulse, p.point, true);
            }
        }
        let (handle, h) = (t.handle, t.h);
        let mut events = t.events;
        let actual = (next - t.start) / dt;
        if c.settings.report_moved && actual.length() > 1e-6 {
            events.push((EVENT_CONTROLLER_MOVED, 0, actual));
        }
        let next_pose = rapier3d::math::Pose::from_parts(next, rotation);
        self.world.bodies[h].set_next_kinematic_position(next_pose);
        let world = &mut self.world;
        let (mut was, mut went, mut changed) = (Aabb::new_invalid(), Aabb::new_invalid(), false);
        for col in world.bodies[h].colliders() {
            if let Some(co) = world.colliders.get_mut(*col) {
                if track && !same_pose(co.position(), &next_pose) {
                    changed = true;
                    was.merge(&co.compute_aabb());
                }
                co.set_position(next_pose);
                let aabb = co.compute_aabb();
                went.merge(&aabb);
                world
                    .broad_phase
                    .set_aabb(&world.integration_parameters, *col, aabb);
            }
        }
        if let Ok(b) = self.objects.get_mut(handle) {
            b.flags = shm_layout::FLAG_CONTROLLER
                | if c.on_ground {
                    shm_layout::FLAG_ON_GROUND
                } else {
                    0
                };
        }
        for (kind, index, velocity) in events {
            self.events.queue(EventRecord {
                kind,
                a_slot: handle.slot,
                a_generation: handle.generation,
                b_slot: index,
                position: next.into(),
                normal: velocity.into(),
                ..EventRecord::default()
            });
        }
        changed.then_some((was, went))
    }
}

/// Whether `a` and `b` are the same pose bit for bit (a query's answer can change with the
/// last bit of either).
pub(super) fn same_pose(a: &rapier3d::math::Pose, b: &rapier3d::math::Pose) -> bool {
    let bits = |p: &rapier3d::math::Pose| {
        let (t, r) = (p.translation, p.rotation);
        [t.x, t.y, t.z, r.x, r.y, r.z, r.w].map(f32::to_bits)
    };
    bits(a) == bits(b)
}

/// The pairs (later, earlier), as positions in slot order, of outcomes whose covered volumes
/// overlap, sorted by the later one: a sweep along X over the volumes sorted by their start.
fn overlapping_pairs(outcomes: &[(Outcome, &mut Controller)]) -> Vec<(u32, u32)> {
    // The volumes side by side, sorted by their start along X (an outcome is large: reading
    // the volumes in place cost a cache miss per comparison).
    let mut boxes: Vec<(Aabb, u32)> = outcomes
        .iter()
        .enumerate()
        .map(|(i, (o, _))| (o.covered, i as u32))
        .collect();
    boxes.sort_unstable_by(|a, b| a.0.mins.x.total_cmp(&b.0.mins.x));
    let mut pairs = Vec::new();
    for (k, (box_a, a)) in boxes.iter().enumerate() {
        for (box_b, b) in &boxes[k + 1..] {
            // NaN or beyond: nothing later in X order starts inside this one.
            if box_b.mins.x > box_a.maxs.x || box_b.mins.x.is_nan() || box_a.maxs.x.is_nan() {
                break;
            }
            if box_a.intersects(box_b) {
                pairs.push((*a.max(b), *a.min(b)));
            }
        }
    }
    pairs.sort_unstable();
    pairs
}

impl<'a> Scene<'a> {
    /// One controller's tick: the stages of the module doc, each a function below.
    fn tick(&self, handle: Handle, h: RigidBodyHandle, c: &mut Controller, dt: f32) -> Outcome {
        let saved = Saved::of(c);
        let mut t = self.begin_tick(c, handle, h);
        let mut motion = self.intended_motion(c, &mut t, dt);
        // The facing is fixed from here until the controller turns (stage 8).
        t.rotation = yaw_rotation(c.yaw);
        // What the tick can reach, gathered once from the broad phase.
        let mut nearby = Nearby::gather(self.refs, h, t.groups, t.reach(c, motion.desired));
        let (mut next, collisions) = self.move_capsule(c, &t, &mut motion, dt, &mut nearby);
        self.settle_on_ground(c, &mut t, &mut next, &mut motion, &mut nearby);
        let pushes = self.clip_velocity(c, &collisions, &mut motion.v, dt);
        c.turn_toward(motion.v, dt);
        c.follow_path(next, &mut t.events);
        c.velocity = motion.v;
        let rotation = yaw_rotation(c.yaw);
        let (covered, dynamic) = if self.side_by_side {
            self.what_it_read(rotation, &saved, &t, next, &nearby)
        } else {
            (Aabb::new_invalid(), Vec::new())
        };
        Outcome {
            t,
            next,
            rotation,
            pushes,
            saved,
            covered,
            dynamic,
        }
    }

    /// What a tick that ends at `next` read that another controller's commit can change:
    /// the volume its queries covered (with its capsule where it started and ends, and some
    /// slack) and the dynamic bodies within it or under it at the start.
    fn what_it_read(
        &self,
        rotation: Rotation,
        saved: &Saved,
        t: &TickState,
        next: Vector,
        nearby: &Nearby<'_>,
    ) -> (Aabb, Vec<RigidBodyHandle>) {
        let at = |p: Vector| rapier3d::math::Pose::from_parts(p, rotation);
        let start = capsule_aabb(&t.shape, &at(t.start));
        let end = capsule_aabb(&t.shape, &at(next));
        let covered = nearby
            .covered()
            .merged(&start)
            .merged(&end)
            .loosened(COVER_SLACK);
        let bodies = self.refs.bodies;
        let is_dynamic = |b: &RigidBodyHandle| bodies.get(*b).is_some_and(|rb| rb.is_dynamic());
        let mut dynamic: Vec<RigidBodyHandle> = nearby
            .items
            .iter()
            .filter(|n| n.aabb.intersects(&covered))
            .filter_map(|n| n.parent)
            .filter(is_dynamic)
            .collect();
        dynamic.extend(saved.ground.map(|g| g.body).filter(is_dynamic));
        (covered, dynamic)
    }

    /// What the stages share: the controller's body, its capsule, its collision groups, its
    /// position at the start of the tick, gravity, and the events the tick produces.
    fn begin_tick(&self, c: &Controller, handle: Handle, h: RigidBodyHandle) -> TickState {
        let s = c.settings;
        let g = if s.use_plane_gravity {
            -self.gravity_y
        } else {
            s.gravity
        };
        let bodies = self.refs.bodies;
        let groups = bodies[h]
            .colliders()
            .first()
            .map(|col| self.refs.colliders[*col].collision_groups())
            .unwrap_or_default();
        TickState {
            handle,
            h,
            // Set once the platform has turned it (see `tick`).
            rotation: Rotation::IDENTITY,
            shape: c.capsule(),
            half_height: s.capsule_half_height + s.capsule_radius,
            start: bodies[h].translation(),
            groups,
            g,
            events: Vec::new(),
        }
    }

    /// Stages 1–3: ride the platform, turn the intent or path into a wish, and run the
    /// movement model (friction, acceleration, air control, jump, gravity). Returns the
    /// velocity and the displacement the tick asks for.
    fn intended_motion(&self, c: &mut Controller, t: &mut TickState, dt: f32) -> Motion {
        let s = c.settings;
        // 1. Ride the platform.
        let foot = t.start - Vector::Y * t.half_height;
        let (carry, platform_velocity, platform_yaw) = self.platform_motion(c, foot, dt);
        c.yaw += platform_yaw;

        // 2. Wish and path.
        let (wish_dir, amount) = c.wish(t.start);
        let wish_speed = s.walk_speed * amount;

        // 3. Velocity: friction and acceleration on the ground, air control in the air.
        let mut v = c.velocity;
        let mut jumped = false;
        if c.on_ground {
            v = apply_friction(v, s.friction, s.walk_speed / 4.0, dt);
            v = accelerate(v, wish_dir, wish_speed, s.acceleration, dt);
        } else {
            v = accelerate(v, wish_dir, wish_speed, s.acceleration * s.air_control, dt);
        }
        let vy_before;
        if c.jump && c.on_ground {
            // Jumping off a platform carries its velocity along.
            v += platform_velocity;
            v.y = s.jump_power + platform_velocity.y.max(0.0);
            vy_before = v.y;
            v.y -= t.g * dt;
            jumped = true;
            c.on_ground = false;
            t.events.push((EVENT_CONTROLLER_JUMPED, 0, Vector::ZERO));
        } else if c.on_ground {
            vy_before = 0.0;
            v.y = 0.0;
        } else {
            vy_before = v.y;
            v.y -= t.g * dt;
        }
        c.jump = false;
        // Horizontal: v·dt; vertical: the mean of the tick's velocities (exact for constant
        // gravity, so the apex is JumpPower² / 2g at any dt).
        let desired = horizontal(v) * dt + Vector::Y * (0.5 * (vy_before + v.y) * dt) + carry;
        Motion {
            v,
            desired,
            carry,
            jumped,
        }
    }

    /// Stages 4–5: out of anything it overlaps, then the move (slide, no climbing past
    /// MaxSlope, snap while grounded) and, when blocked on the ground, the step up. Returns
    /// where it ends and what stopped it.
    fn move_capsule(
        &self,
        c: &Controller,
        t: &TickState,
        m: &mut Motion,
        dt: f32,
        nearby: &mut Nearby<'a>,
    ) -> (Vector, Vec<CharacterCollision>) {
        let s = c.settings;
        // 4. Out of anything it overlaps (spawned inside geometry, a platform moved into it).
        let depenetrated = self.depenetrate(&t.shape, t.start, nearby);
        let position = t.start + depenetrated;
        if depenetrated.y > 0.0 && m.desired.y < 0.0 {
            m.desired.y = 0.0;
        }
        nearby.ensure(t.swept(&c.settings, position, m.desired), 1.0);

        // 5. Move.
        let snap = (c.on_ground && !m.jumped).then_some(s.step_height.max(SKIN * 4.0));
        let mover = Mover {
            offset: SKIN,
            max_slope_climb_angle: s.max_slope.to_radians(),
            min_slope_slide_angle: s.max_slope.to_radians(),
            snap_to_ground: snap,
        };
        let pose = rapier3d::math::Pose::from_parts(position, t.rotation);
        let mut collisions: Vec<CharacterCollision> = Vec::new();
        let moved = mover.move_shape(dt, nearby, &t.shape, &pose, m.desired, |col| {
            collisions.push(col)
        });
        let mut next = position + moved.translation;
        // Blocked while walking on the ground: try the step (lift, move, drop).
        let wanted_h = horizontal(m.desired - m.carry);
        let got_h = horizontal(moved.translation - m.carry);
        if c.on_ground
            && !m.jumped
            && s.step_height > 0.0
            && got_h.length() + 1e-4 < wanted_h.length() * 0.5
        {
            if let Some(stepped) =
                self.step_up(&t.shape, next, t.rotation, wanted_h - got_h, &s, nearby)
            {
                next = stepped;
                // The step's face did not stop it: keep the speed.
                collisions.clear();
            }
        }
        (next, collisions)
    }

    /// Stage 6: the ground probe (what is under the capsule now), OnGround, the platform for
    /// the next tick, GroundY, and Landed.
    fn settle_on_ground(
        &self,
        c: &mut Controller,
        t: &mut TickState,
        next: &mut Vector,
        m: &mut Motion,
        nearby: &mut Nearby<'a>,
    ) {
        let s = c.settings;
        let was_on_ground = c.on_ground;
        let probe = if was_on_ground && !m.jumped {
            s.step_height.max(SKIN * 4.0)
        } else {
            SKIN * 4.0
        };
        let rising = m.v.y > 0.0 && !was_on_ground;
        let ground = if rising {
            None
        } else {
            self.probe_ground(&t.shape, *next, t.rotation, probe, s.max_slope, nearby)
        };
        c.on_ground = false;
        c.ground = None;
        if let Some((body, distance, walkable, face_walkable)) = ground {
            let close = distance <= SKIN * 3.0;
            // Standing on a step's edge counts (the face under it is walkable ground); a
            // steep slope does not, whatever touches it.
            if (walkable && (close || (was_on_ground && !m.jumped))) || (face_walkable && close) {
                // Settle onto it (snap down slopes and steps while grounded).
                if walkable && distance > SKIN {
                    next.y -= distance - SKIN;
                }
                c.on_ground = true;
            }
            if let Some(b) = self.refs.bodies.get(body) {
                c.ground = Some(Ground {
                    body,
                    pose: *b.position(),
                });
            }
        }
        if let Some(floor) = s.ground_y {
            if next.y - t.half_height <= floor + SKIN && m.v.y <= 0.0 {
                next.y = next.y.max(floor + t.half_height);
                c.on_ground = true;
            }
        }
        if c.on_ground {
            m.v.y = 0.0;
            if !was_on_ground {
                t.events.push((EVENT_CONTROLLER_LANDED, 0, Vector::ZERO));
            }
        }
    }

    /// Stage 7: plans the pushes of dynamic bodies it ran into, then clips the velocity
    /// against what stopped it (slide along walls, stop at ceilings); a body pushed with
    /// less than the cap gave way.
    fn clip_velocity(
        &self,
        c: &Controller,
        collisions: &[CharacterCollision],
        v: &mut Vector,
        dt: f32,
    ) -> Vec<Push> {
        let (pushes, gave_way) = self.plan_pushes(collisions, c, dt);
        for col in collisions
            .iter()
            .filter(|col| !gave_way.contains(&col.handle))
        {
            let n = col.hit.normal1;
            let into = v.dot(n);
            if into < 0.0 {
                let floor_like = n.y >= c.settings.max_slope.to_radians().cos();
                if floor_like {
                    v.y = v.y.max(0.0);
                } else {
                    *v -= n * into;
                }
            }
        }
        pushes
    }
}

/// What the stages of one tick share.
struct TickState {
    handle: Handle,
    h: RigidBodyHandle,
    /// The controller's facing while it moves (set again after the platform turns it).
    rotation: Rotation,
    shape: Capsule,
    half_height: f32,
    start: Vector,
    groups: InteractionGroups,
    g: f32,
    /// (kind, index, velocity) of the events the tick produced so far.
    events: Vec<(u32, u32, Vector)>,
}

impl TickState {
    /// The region a tick that starts at `start` and asks for `desired` can read: the capsule
    /// at both ends, widened by what the move's snap, the step (lift, reach, drop) and the
    /// ground probe reach beyond them.
    fn reach(&self, c: &Controller, desired: Vector) -> Aabb {
        self.swept(&c.settings, self.start, desired)
    }

    /// The capsule from `from` to `from + desired`, widened as in [`TickState::reach`].
    fn swept(&self, s: &ControllerSettings, from: Vector, desired: Vector) -> Aabb {
        let pose = rapier3d::math::Pose::from_translation(from);
        let a = capsule_aabb(&self.shape, &pose);
        let b = capsule_aabb(
            &self.shape,
            &(rapier3d::math::Pose::from_translation(desired) * pose),
        );
        let margin = s.step_height.max(SKIN * 4.0) + s.capsule_radius + 0.25;
        a.merged(&b).loosened(margin)
    }
}

/// The movement model's result: the velocity, the displacement asked for (the platform's
/// carry included) and whether it jumped.
struct Motion {
    v: Vector,
    desired: Vector,
    carry: Vector,
    jumped: bool,
}

impl Controller {
    /// Stage 8: turns toward the horizontal velocity (LookWhereMoving) at TurnSpeed; the
    /// yaw is kept in (−π, π], what Rotation.Y reads.
    fn turn_toward(&mut self, v: Vector, dt: f32) {
        let s = self.settings;
        let vh = horizontal(v);
        if s.look_where_moving && vh.length() > TURN_MIN_SPEED {
            let target = yaw_toward(vh);
            self.yaw += angle_diff(self.yaw, target) * (s.turn_speed * dt).min(1.0);
        }
        self.yaw = angle_diff(0.0, self.yaw);
    }

    /// Stage 9: advances the path when `position` is within WaypointThreshold of the
    /// waypoint walked to (WaypointReached, PathFinished).
    fn follow_path(&mut self, position: Vector, events: &mut Vec<(u32, u32, Vector)>) {
        if let Some(target) = self.path.get(self.path_index) {
            let d = horizontal(*target - position).length();
            if d < self.settings.waypoint_threshold {
                self.path_index += 1;
                events.push((EVENT_WAYPOINT_REACHED, self.path_index as u32, Vector::ZERO));
                if self.path_index == self.path.len() {
                    // Cleared when the tick commits.
                    events.push((EVENT_PATH_FINISHED, 0, Vector::ZERO));
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use shm_layout::{ObjectProp, PlaneProp, Pose, Reply, Shape};

    use super::super::super::Plane;
    use super::*;

    /// A small xorshift for reproducible crowds.
    struct Rng(u64);
    impl Rng {
        fn next(&mut self) -> f32 {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 7;
            self.0 ^= self.0 << 17;
            (self.0 >> 40) as f32 / (1u64 << 24) as f32
        }
    }

    /// A crowd on a plane of `threads`: `n` controllers almost touching on a grid, each
    /// walking to a point on the far side of the crowd, among anchored boxes and light
    /// dynamic crates they push. Returns every tick's state hash and the final poses' bits.
    fn crowd(threads: u32, seed: u64, n: usize, ticks: usize) -> (Vec<u64>, Vec<[u32; 3]>) {
        let mut plane =
            Plane::new(1, &[PlaneProp::TickRate(0.0), PlaneProp::Threads(threads)]).unwrap();
        let mut cube = |size: [f32; 3], at: [f32; 3], anchored: bool| {
            plane
                .add_object(
                    &Shape::Cube { size },
                    Pose::at(at),
                    &[ObjectProp::Anchored(anchored)],
                )
                .unwrap();
        };
        cube([200.0, 1.0, 200.0], [0.0, -0.5, 0.0], true);
        let mut rng = Rng(seed);
        for _ in 0..6 {
            cube(
                [2.0; 3],
                [rng.next() * 30.0 - 15.0, 1.0, rng.next() * 30.0 - 15.0],
                true,
            );
        }
        // Light crates the controllers push.
        for _ in 0..8 {
            cube(
                [1.0; 3],
                [rng.next() * 24.0 - 12.0, 0.5, rng.next() * 24.0 - 12.0],
                false,
            );
        }
        let side = (n as f32).sqrt().ceil() as usize;
        let mut handles = Vec::new();
        for i in 0..n {
            let (gx, gz) = ((i % side) as f32, (i / side) as f32);
            let spacing = 2.05 + rng.next() * 0.3;
            let at = [
                (gx - side as f32 / 2.0) * spacing,
                2.6,
                (gz - side as f32 / 2.0) * spacing,
            ];
            let Reply::Object { handle, .. } = plane
                .controller_op(ControllerOp::Create {
                    pose: Pose::at(at),
                    size: [2.0, 5.0, 2.0],
                    controlled: false,
                    props: vec![],
                })
                .unwrap()
            else {
                panic!("no controller handle");
            };
            // Across the crowd: the mirror point, jittered.
            let to = [
                -at[0] + rng.next() * 4.0 - 2.0,
                0.0,
                -at[2] + rng.next() * 4.0 - 2.0,
            ];
            plane
                .controller_op(ControllerOp::SetPath {
                    handle,
                    waypoints: vec![to],
                })
                .unwrap();
            handles.push(handle);
        }
        let mut hashes = Vec::with_capacity(ticks);
        for _ in 0..ticks {
            plane.step(1.0 / 60.0).unwrap();
            hashes.push(plane.state_hash());
        }
        let poses = handles
            .iter()
            .map(|h| plane.body_state(h.slot as usize).position.map(f32::to_bits))
            .collect();
        (hashes, poses)
    }

    #[test]
    fn a_crowd_ticked_side_by_side_matches_slot_order_bit_for_bit() {
        // One core: Threads = 2 is capped to 1 and nothing runs side by side to compare.
        if crate::backend::pools::cores() < 2 {
            eprintln!("one core: no pool, nothing to compare");
            return;
        }
        for seed in [1, 42] {
            let (one, one_poses) = crowd(1, seed, 144, 60);
            let (two, two_poses) = crowd(2, seed, 144, 60);
            if let Some(t) = (0..one.len()).find(|&t| one[t] != two[t]) {
                panic!("seed {seed}: Threads = 2 differs from Threads = 1 at tick {t}");
            }
            assert_eq!(one_poses, two_poses, "seed {seed}");
        }
    }
}

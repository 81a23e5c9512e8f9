//! One controller tick: the stages listed in the module doc, in order.

use super::*;

impl Plane {
    /// Moves every controller by one tick of `dt` (before the physics step).
    pub(in crate::rapier3d) fn tick_controllers(&mut self, dt: f32) {
        if self.controllers.is_empty() {
            return;
        }
        self.refresh_scene();
        let slots: Vec<u32> = self.controllers.keys().copied().collect();
        for slot in slots {
            self.tick_controller(slot, dt);
        }
    }

    /// One controller's tick: the stages of the module doc, each a function below.
    fn tick_controller(&mut self, slot: u32, dt: f32) {
        let Some(handle) = self.bodies.handle_at(slot as usize) else {
            self.controllers.remove(&slot);
            return;
        };
        let Ok(h) = self.body_of(handle) else {
            return;
        };
        let Some(mut c) = self.controllers.remove(&slot) else {
            return;
        };
        let mut t = self.begin_tick(&c, handle, h);
        let mut motion = self.intended_motion(&mut c, &mut t, dt);
        let (mut next, collisions) = self.move_capsule(&c, &t, &mut motion, dt);
        self.settle_on_ground(&mut c, &mut t, &mut next, &mut motion);
        self.clip_velocity(&c, &collisions, &mut motion.v, dt);
        c.turn_toward(motion.v, dt);
        c.follow_path(next, &mut t.events);
        c.velocity = motion.v;
        self.commit_tick(&c, &t, next, dt);
        self.controllers.insert(slot, c);
    }

    /// What the stages share: the controller's body, its capsule, its collision groups, its
    /// position at the start of the tick, gravity, and the events the tick produces.
    fn begin_tick(&self, c: &Controller, handle: Handle, h: RigidBodyHandle) -> TickState {
        let s = c.settings;
        let g = if s.use_plane_gravity {
            -self.settings.gravity[1]
        } else {
            s.gravity
        };
        let groups = self.world.bodies[h]
            .colliders()
            .first()
            .map(|col| self.world.colliders[*col].collision_groups())
            .unwrap_or_default();
        TickState {
            handle,
            h,
            shape: c.shape(),
            half_height: s.capsule_half_height + s.capsule_radius,
            start: self.world.bodies[h].translation(),
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
    ) -> (Vector, Vec<CharacterCollision>) {
        let s = c.settings;
        let (h, groups) = (t.h, t.groups);
        // 4. Out of anything it overlaps (spawned inside geometry, a platform moved into it).
        let depenetrated = self.depenetrate(h, &t.shape, t.start, groups);
        let position = t.start + depenetrated;
        if depenetrated.y > 0.0 && m.desired.y < 0.0 {
            m.desired.y = 0.0;
        }

        // 5. Move.
        let kcc = KinematicCharacterController {
            up: Vector::Y,
            offset: CharacterLength::Absolute(SKIN),
            slide: true,
            // Steps are ours (`step_up`): rapier's autostep nudges only as far as the tick's
            // motion, so a round capsule's bottom stays on the edge and taller steps fail.
            autostep: None,
            max_slope_climb_angle: s.max_slope.to_radians(),
            min_slope_slide_angle: s.max_slope.to_radians(),
            snap_to_ground: (c.on_ground && !m.jumped)
                .then_some(CharacterLength::Absolute(s.step_height.max(SKIN * 4.0))),
            ..KinematicCharacterController::default()
        };
        let pose = rapier3d::math::Pose::from_parts(position, yaw_rotation(c.yaw));
        let mut collisions: Vec<CharacterCollision> = Vec::new();
        let moved = {
            let exclude = |_: ColliderHandle, co: &Collider| {
                co.parent() != Some(h) && co.collision_groups().test(groups) && !co.is_sensor()
            };
            let filter = rapier3d::prelude::QueryFilter::default().predicate(&exclude);
            let pipeline = self.query_pipeline(filter);
            kcc.move_shape(dt, &pipeline, &*t.shape, &pose, m.desired, |col| {
                collisions.push(col)
            })
        };
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
                self.step_up(h, &t.shape, next, c.yaw, wanted_h - got_h, &s, groups)
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
    ) {
        let s = c.settings;
        // Rapier's controller also says whether it is grounded (it sees stair edges as
        // ground, whose normals lean).
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
            self.probe_ground(t.h, &t.shape, *next, c.yaw, probe, s.max_slope, t.groups)
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
            if let Some(b) = self.world.bodies.get(body) {
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

    /// Stage 7: pushes dynamic bodies it ran into, then clips the velocity against what
    /// stopped it (slide along walls, stop at ceilings); a body pushed with less than the
    /// cap gave way.
    fn clip_velocity(
        &mut self,
        c: &Controller,
        collisions: &[CharacterCollision],
        v: &mut Vector,
        dt: f32,
    ) {
        let gave_way = self.push_bodies(collisions, c, dt);
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
    }

    /// The end of the tick: the next kinematic pose (and the colliders and broad phase, so
    /// controllers ticked after this one see it where it is going), the published flags and
    /// the tick's events.
    fn commit_tick(&mut self, c: &Controller, t: &TickState, next: Vector, dt: f32) {
        let (handle, h) = (t.handle, t.h);
        let mut events = t.events.clone();
        let actual = (next - t.start) / dt;
        if c.settings.report_moved && actual.length() > 1e-6 {
            events.push((EVENT_CONTROLLER_MOVED, 0, actual));
        }
        let next_pose = rapier3d::math::Pose::from_parts(next, yaw_rotation(c.yaw));
        self.world.bodies[h].set_next_kinematic_position(next_pose);
        let world = &mut self.world;
        for col in world.bodies[h].colliders() {
            if let Some(co) = world.colliders.get_mut(*col) {
                co.set_position(next_pose);
                let aabb = co.compute_aabb();
                world
                    .broad_phase
                    .set_aabb(&world.integration_parameters, *col, aabb);
            }
        }
        if let Ok(b) = self.bodies.get_mut(handle) {
            b.flags = shm_layout::FLAG_CONTROLLER
                | if c.on_ground {
                    shm_layout::FLAG_ON_GROUND
                } else {
                    0
                };
        }
        for (kind, index, velocity) in events {
            self.pending_events.push(EventRecord {
                kind,
                a_slot: handle.slot,
                a_generation: handle.generation,
                b_slot: index,
                position: next.into(),
                normal: velocity.into(),
                ..EventRecord::default()
            });
        }
        self.dirty.mark(handle.slot);
    }
}

/// What the stages of one tick share.
struct TickState {
    handle: Handle,
    h: RigidBodyHandle,
    shape: SharedShape,
    half_height: f32,
    start: Vector,
    groups: InteractionGroups,
    g: f32,
    /// (kind, index, velocity) of the events the tick produced so far.
    events: Vec<(u32, u32, Vector)>,
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
                    self.path.clear();
                    self.path_index = 0;
                    events.push((EVENT_PATH_FINISHED, 0, Vector::ZERO));
                }
            }
        }
    }
}

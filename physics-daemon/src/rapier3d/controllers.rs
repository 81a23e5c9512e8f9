//! Kinematic character controllers, ticked inside the plane before each physics step.
//!
//! A controller is an object of the plane: a kinematic capsule published like any body. Each
//! tick it
//! 1. rides what it stands on (the displacement of an anchored or kinematic platform since
//!    the last tick, the velocity of a dynamic one),
//! 2. turns its motion intent or path into a wish direction and runs Quake's movement model
//!    (ground friction with a stop speed, `accelerate` toward the wish speed, air control,
//!    gravity integrated exactly so the jump apex is JumpPower² / 2g),
//! 3. pushes itself out of anything it overlaps (depenetration, deepest first),
//! 4. moves with rapier's shape-casting character controller (slide along walls, step up
//!    to StepHeight, no climbing past MaxSlope, snap down slopes and steps while grounded),
//! 5. probes the ground under its capsule (OnGround, the platform for the next tick),
//! 6. clips its velocity against what stopped it, pushes dynamic bodies it ran into with a
//!    force capped at PushStrength, turns toward its velocity and advances its path,
//! 7. and hands rapier its next kinematic pose.
//!
//! A plane without controllers skips all of it.

use std::collections::BTreeMap;

use rapier3d::control::{CharacterCollision, CharacterLength, KinematicCharacterController};
use rapier3d::parry::query::ShapeCastOptions;
use rapier3d::prelude::*;
use shm_layout::controller_op::ControllerInfo;
use shm_layout::{
    CommandError, ControllerOp, ControllerProp, ControllerSettings, EventRecord, Handle, Pose,
    Reply, Shape, Vec3, EVENT_CONTROLLER_JUMPED, EVENT_CONTROLLER_LANDED, EVENT_CONTROLLER_MOVED,
    EVENT_PATH_FINISHED, EVENT_WAYPOINT_REACHED,
};

use super::part::Part;
use super::{Body, Plane};
use crate::backend::counted::{CountedVec, Counter};

/// Gap kept between the capsule and what it touches (units).
const SKIN: f32 = 0.01;
/// Depenetration passes per tick (deepest overlap first).
const DEPENETRATION_PASSES: usize = 4;
/// Below this horizontal speed a controller does not turn toward its velocity.
const TURN_MIN_SPEED: f32 = 0.1;

/// What a controller stands on.
#[derive(Debug, Clone, Copy, serde::Serialize, serde::Deserialize)]
struct Ground {
    body: RigidBodyHandle,
    /// Its pose when the controller last stood on it (for platforms moved by pose writes).
    pose: rapier3d::math::Pose,
}

/// One controller's own state (its body lives in the plane's slot table).
#[derive(Debug, serde::Serialize, serde::Deserialize)]
pub(super) struct Controller {
    pub settings: ControllerSettings,
    velocity: Vector,
    yaw: f32,
    on_ground: bool,
    ground: Option<Ground>,
    move_vector: [f32; 2],
    /// The facing when the motion intent was last set (see [`Controller::wish`]).
    intent_yaw: f32,
    /// Counted in the plane's state bytes (a client's quota).
    path: CountedVec<Vector>,
    /// 0-based index of the waypoint being walked to.
    path_index: usize,
    jump: bool,
}

/// The yaw of a rotation: the angle about +Y that turns the controller's forward, the
/// CFrame's LookVector (its −Z, as on Roblox), to the rotation's LookVector.
fn yaw_of(rotation: [f32; 4]) -> f32 {
    let q = Rotation::from_array(rotation);
    let look = q * Vector::NEG_Z;
    yaw_toward(look)
}

/// The yaw whose LookVector points along the horizontal part of `direction`.
fn yaw_toward(direction: Vector) -> f32 {
    (-direction.x).atan2(-direction.z)
}

fn yaw_rotation(yaw: f32) -> Rotation {
    Rotation::from_axis_angle(Vector::Y, yaw)
}

/// The shortest signed angle from `a` to `b`.
fn angle_diff(a: f32, b: f32) -> f32 {
    let tau = std::f32::consts::TAU;
    (b - a + std::f32::consts::PI).rem_euclid(tau) - std::f32::consts::PI
}

fn horizontal(v: Vector) -> Vector {
    Vector::new(v.x, 0.0, v.z)
}

impl Controller {
    fn new(settings: ControllerSettings, yaw: f32, state_bytes: &Counter) -> Controller {
        Controller {
            settings,
            velocity: Vector::ZERO,
            yaw,
            on_ground: false,
            ground: None,
            move_vector: [0.0; 2],
            intent_yaw: yaw,
            path: CountedVec::new(state_bytes),
            path_index: 0,
            jump: false,
        }
    }

    fn shape(&self) -> SharedShape {
        SharedShape::capsule_y(
            self.settings.capsule_half_height,
            self.settings.capsule_radius,
        )
    }

    /// Full size of the capsule's box, for the object's Size.
    fn size(&self) -> Vec3 {
        let r = self.settings.capsule_radius;
        [
            2.0 * r,
            2.0 * (self.settings.capsule_half_height + r),
            2.0 * r,
        ]
    }

    /// The wish direction (unit or zero) and its intensity in [0, 1], for a controller at
    /// `position`: toward the next waypoint, else the motion intent (+z forward along the
    /// LookVector, +x right) turned by the facing. A controller that turns toward where it
    /// moves (LookWhereMoving) takes the intent in the facing it had when the intent was
    /// given: turning must not turn the intent too, or any intent but straight ahead would
    /// walk it in circles.
    fn wish(&self, position: Vector) -> (Vector, f32) {
        if let Some(target) = self.path.get(self.path_index) {
            return (horizontal(*target - position).normalize_or_zero(), 1.0);
        }
        let [x, z] = self.move_vector;
        let local = Vector::new(x, 0.0, -z);
        let amount = local.length().min(1.0);
        let yaw = if self.settings.look_where_moving {
            self.intent_yaw
        } else {
            self.yaw
        };
        (yaw_rotation(yaw) * local.normalize_or_zero(), amount)
    }
}

/// Quake's PM_Friction on the horizontal velocity: speed drops by
/// friction × max(speed, stop_speed) × dt, never below zero.
fn apply_friction(v: Vector, friction: f32, stop_speed: f32, dt: f32) -> Vector {
    let h = horizontal(v);
    let speed = h.length();
    if speed < 1e-6 {
        return Vector::new(0.0, v.y, 0.0);
    }
    let drop = speed.max(stop_speed) * friction * dt;
    let scale = (speed - drop).max(0.0) / speed;
    Vector::new(h.x * scale, v.y, h.z * scale)
}

/// Quake's PM_Accelerate: raises the speed along `dir` toward `wish_speed` by at most
/// accel × wish_speed × dt, leaving other directions alone.
fn accelerate(v: Vector, dir: Vector, wish_speed: f32, accel: f32, dt: f32) -> Vector {
    let current = v.dot(dir);
    let add = wish_speed - current;
    if add <= 0.0 {
        return v;
    }
    v + dir * (accel * wish_speed * dt).min(add)
}

impl Plane {
    /// Runs one controller op.
    pub fn controller_op(&mut self, op: ControllerOp) -> Result<Reply, CommandError> {
        match op.checked()? {
            ControllerOp::Create {
                pose,
                size,
                controlled,
                props,
            } => {
                let handle = self.create_controller(pose, size, controlled, &props)?;
                Ok(Reply::Object {
                    handle,
                    tick: self.tick,
                })
            }
            ControllerOp::Set { handle, prop } => {
                self.set_controller(handle, prop)?;
                Ok(Reply::Applied { tick: self.tick })
            }
            ControllerOp::Info { handle } => {
                // The wall probe of the info reads the scene as ops left it.
                self.refresh_scene();
                Ok(Reply::Controller(Box::new(self.controller_info(handle)?)))
            }
            ControllerOp::SetPath { handle, waypoints } => {
                let c = self.controller_mut(handle)?;
                c.path
                    .replace(waypoints.into_iter().map(Vector::from).collect());
                c.path_index = 0;
                Ok(Reply::Applied { tick: self.tick })
            }
            ControllerOp::AppendWaypoint { handle, point } => {
                let c = self.controller_mut(handle)?;
                if c.path.len() >= shm_layout::controller_op::MAX_WAYPOINTS {
                    return Err(CommandError::invalid_field(
                        "waypoint",
                        "the path already holds the most waypoints allowed",
                    ));
                }
                if c.path_index >= c.path.len() {
                    c.path.clear();
                    c.path_index = 0;
                }
                c.path.push(Vector::from(point));
                Ok(Reply::Applied { tick: self.tick })
            }
            ControllerOp::StopWalking { handle } => {
                let c = self.controller_mut(handle)?;
                c.path.clear();
                c.path_index = 0;
                c.move_vector = [0.0; 2];
                Ok(Reply::Applied { tick: self.tick })
            }
            ControllerOp::Jump { handle } => {
                let c = self.controller_mut(handle)?;
                let launched = c.on_ground;
                c.jump |= launched;
                Ok(Reply::Flag(launched))
            }
            ControllerOp::Teleport { handle, pose } => {
                let yaw = yaw_of(pose.rotation);
                let c = self.controller_mut(handle)?;
                c.velocity = Vector::ZERO;
                c.path.clear();
                c.path_index = 0;
                c.yaw = yaw;
                c.intent_yaw = yaw;
                c.ground = None;
                self.place_controller(handle, Vector::from(pose.position), yaw)?;
                Ok(Reply::Applied { tick: self.tick })
            }
            ControllerOp::Destroy { handle } => {
                self.controller_mut(handle)?;
                self.destroy_object(handle)?;
                Ok(Reply::Applied { tick: self.tick })
            }
        }
    }

    fn create_controller(
        &mut self,
        pose: Pose,
        size: Vec3,
        controlled: bool,
        props: &[ControllerProp],
    ) -> Result<Handle, CommandError> {
        let mut settings = ControllerSettings::defaults(size, controlled);
        let yaw = yaw_of(pose.rotation);
        let mut controller = Controller::new(settings, yaw, &self.state_bytes);
        let mut state = Vec::new();
        for prop in props {
            if !settings.apply(*prop)? {
                state.push(*prop);
            }
        }
        controller.settings = settings;
        // The object's part is the capsule (mass, Density, groups, queries all see it).
        let mut part = Part::new(&Shape::Capsule {
            size: controller.size(),
        });
        part.is_controller = true;
        let mut collider = ColliderBuilder::new(controller.shape()).build();
        part.configure_collider(&mut collider, &self.groups)?;
        let slot = self
            .bodies
            .next_slot()
            .ok_or_else(|| CommandError::invalid(format!("plane {} is full", self.id)))?;
        let body = RigidBodyBuilder::kinematic_position_based()
            .pose(rapier3d::math::Pose::from_parts(
                Vector::from(pose.position),
                yaw_rotation(yaw),
            ))
            .user_data(slot as u128)
            .build();
        let h = self.world.insert_body(body);
        self.world.insert_collider(collider, Some(h));
        self.quality_counts[part.hit_box_quality as usize] += 1;
        let handle = self.bodies.insert(Body {
            handle: h,
            part: Box::new(part),
            flags: shm_layout::FLAG_CONTROLLER,
        })?;
        self.dirty.mark(handle.slot);
        self.query_stale.push(h);
        self.controllers.insert(handle.slot, controller);
        for prop in state {
            self.set_controller(handle, prop)?;
        }
        Ok(handle)
    }

    fn controller_mut(&mut self, handle: Handle) -> Result<&mut Controller, CommandError> {
        self.body_of(handle)?;
        self.controllers.get_mut(&handle.slot).ok_or_else(|| {
            CommandError::invalid_field(
                "controller",
                format!("object {handle} of plane {} is not a controller", self.id),
            )
        })
    }

    /// Moves a controller's body to `position` facing `yaw` at once (a teleport).
    fn place_controller(
        &mut self,
        handle: Handle,
        position: Vector,
        yaw: f32,
    ) -> Result<(), CommandError> {
        let h = self.body_of(handle)?;
        let pose = rapier3d::math::Pose::from_parts(position, yaw_rotation(yaw));
        let body = &mut self.world.bodies[h];
        body.set_position(pose, true);
        body.set_next_kinematic_position(pose);
        self.dirty.mark(handle.slot);
        self.query_stale.push(h);
        Ok(())
    }

    fn set_controller(&mut self, handle: Handle, prop: ControllerProp) -> Result<(), CommandError> {
        let prop = prop.checked()?;
        let c = self.controller_mut(handle)?;
        let shape_before = (c.settings.capsule_radius, c.settings.capsule_half_height);
        let mut settings = c.settings;
        if settings.apply(prop)? {
            c.settings = settings;
            if shape_before != (settings.capsule_radius, settings.capsule_half_height) {
                let size = c.size();
                let shape = c.shape();
                let h = self.body_of(handle)?;
                self.bodies.get_mut(handle)?.part.size = size;
                for col in self.world.bodies[h].colliders().to_vec() {
                    self.world.colliders[col].set_shape(shape.clone());
                }
                self.query_stale.push(h);
            }
            return Ok(());
        }
        match prop {
            ControllerProp::Position(p) => {
                let yaw = c.yaw;
                c.velocity = Vector::ZERO;
                c.ground = None;
                self.place_controller(handle, Vector::from(p), yaw)?;
            }
            ControllerProp::Velocity(v) => {
                c.velocity = Vector::from(v);
                if v[1] > 0.0 {
                    c.on_ground = false;
                }
            }
            ControllerProp::Rotation(r) => {
                c.yaw = r[1];
                c.intent_yaw = r[1];
                let yaw = c.yaw;
                let h = self.body_of(handle)?;
                let pos = self.world.bodies[h].translation();
                self.place_controller(handle, pos, yaw)?;
            }
            ControllerProp::MoveVector(m) => {
                if m != c.move_vector {
                    c.intent_yaw = c.yaw;
                }
                c.move_vector = m;
            }
            _ => {}
        }
        Ok(())
    }

    fn controller_info(&self, handle: Handle) -> Result<ControllerInfo, CommandError> {
        self.body_of(handle)?;
        let c = self.controllers.get(&handle.slot).ok_or_else(|| {
            CommandError::invalid_field(
                "controller",
                format!("object {handle} is not a controller"),
            )
        })?;
        Ok(ControllerInfo {
            handle,
            settings: c.settings,
            velocity: c.velocity.into(),
            rotation: [0.0, c.yaw, 0.0],
            on_ground: c.on_ground,
            move_vector: c.move_vector,
            path_length: c.path.len() as u32,
            path_index: if c.path_index < c.path.len() {
                c.path_index as u32 + 1
            } else {
                0
            },
            // Probed on request, where the last tick's move left the capsule: a tick pays
            // nothing for it.
            wall_normal: self.controller_wall(handle, c).into(),
        })
    }

    /// Moves every controller by one tick of `dt` (before the physics step).
    pub(super) fn tick_controllers(&mut self, dt: f32) {
        if self.controllers.is_empty() {
            return;
        }
        self.refresh_scene();
        let slots: Vec<u32> = self.controllers.keys().copied().collect();
        for slot in slots {
            self.tick_controller(slot, dt);
        }
    }

    fn tick_controller(&mut self, slot: u32, dt: f32) {
        let Some(handle) = self.bodies.handle_at(slot as usize) else {
            self.controllers.remove(&slot);
            return;
        };
        let Ok(h) = self.body_of(handle) else {
            return;
        };
        let plane_gravity = -self.settings.gravity[1];
        let Some(mut c) = self.controllers.remove(&slot) else {
            return;
        };
        let s = c.settings;
        let g = if s.use_plane_gravity {
            plane_gravity
        } else {
            s.gravity
        };
        let shape = c.shape();
        let half_height = s.capsule_half_height + s.capsule_radius;
        let start = self.world.bodies[h].translation();
        let groups = self.world.bodies[h]
            .colliders()
            .first()
            .map(|col| self.world.colliders[*col].collision_groups())
            .unwrap_or_default();
        let mut events: Vec<(u32, u32, Vector)> = Vec::new();

        // 1. Ride the platform.
        let foot = start - Vector::Y * half_height;
        let (carry, platform_velocity, platform_yaw) = self.platform_motion(&c, foot, dt);
        c.yaw += platform_yaw;

        // 2. Wish and path.
        let (wish_dir, amount) = c.wish(start);
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
            v.y -= g * dt;
            jumped = true;
            c.on_ground = false;
            events.push((EVENT_CONTROLLER_JUMPED, 0, Vector::ZERO));
        } else if c.on_ground {
            vy_before = 0.0;
            v.y = 0.0;
        } else {
            vy_before = v.y;
            v.y -= g * dt;
        }
        c.jump = false;
        // Horizontal: v·dt; vertical: the mean of the tick's velocities (exact for constant
        // gravity, so the apex is JumpPower² / 2g at any dt).
        let mut desired = horizontal(v) * dt + Vector::Y * (0.5 * (vy_before + v.y) * dt) + carry;

        // 4. Out of anything it overlaps (spawned inside geometry, a platform moved into it).
        let depenetrated = self.depenetrate(h, &shape, start, groups);
        let position = start + depenetrated;
        if depenetrated.y > 0.0 && desired.y < 0.0 {
            desired.y = 0.0;
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
            snap_to_ground: (c.on_ground && !jumped)
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
            kcc.move_shape(dt, &pipeline, &*shape, &pose, desired, |col| {
                collisions.push(col)
            })
        };
        let mut next = position + moved.translation;
        // Blocked while walking on the ground: try the step (lift, move, drop).
        let wanted_h = horizontal(desired - carry);
        let got_h = horizontal(moved.translation - carry);
        if c.on_ground
            && !jumped
            && s.step_height > 0.0
            && got_h.length() + 1e-4 < wanted_h.length() * 0.5
        {
            if let Some(stepped) =
                self.step_up(h, &shape, next, c.yaw, wanted_h - got_h, &s, groups)
            {
                next = stepped;
                // The step's face did not stop it: keep the speed.
                collisions.clear();
            }
        }

        // 6. Ground probe: what is under the capsule now. Rapier's controller also says
        // whether it is grounded (it sees stair edges as ground, whose normals lean).
        let was_on_ground = c.on_ground;
        let probe = if was_on_ground && !jumped {
            s.step_height.max(SKIN * 4.0)
        } else {
            SKIN * 4.0
        };
        let rising = v.y > 0.0 && !was_on_ground;
        let ground = if rising {
            None
        } else {
            self.probe_ground(h, &shape, next, c.yaw, probe, s.max_slope, groups)
        };
        c.on_ground = false;
        c.ground = None;
        if let Some((body, distance, walkable, face_walkable)) = ground {
            let close = distance <= SKIN * 3.0;
            // Standing on a step's edge counts (the face under it is walkable ground); a
            // steep slope does not, whatever touches it.
            if (walkable && (close || (was_on_ground && !jumped))) || (face_walkable && close) {
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
            if next.y - half_height <= floor + SKIN && v.y <= 0.0 {
                next.y = next.y.max(floor + half_height);
                c.on_ground = true;
            }
        }
        if c.on_ground {
            v.y = 0.0;
            if !was_on_ground {
                events.push((EVENT_CONTROLLER_LANDED, 0, Vector::ZERO));
            }
        }

        // 7. Push dynamic bodies; clip the velocity against what stopped it (slide along
        // walls, stop at ceilings); a body pushed with less than the cap gave way.
        let gave_way = self.push_bodies(&collisions, &c, dt);
        for col in collisions
            .iter()
            .filter(|col| !gave_way.contains(&col.handle))
        {
            let n = col.hit.normal1;
            let into = v.dot(n);
            if into < 0.0 {
                let floor_like = n.y >= s.max_slope.to_radians().cos();
                if floor_like {
                    v.y = v.y.max(0.0);
                } else {
                    v -= n * into;
                }
            }
        }

        // 8. Facing.
        let vh = horizontal(v);
        if s.look_where_moving && vh.length() > TURN_MIN_SPEED {
            let target = yaw_toward(vh);
            c.yaw += angle_diff(c.yaw, target) * (s.turn_speed * dt).min(1.0);
        }
        // Kept in (−π, π]: what Rotation.Y reads.
        c.yaw = angle_diff(0.0, c.yaw);

        // 9. Path.
        if let Some(target) = c.path.get(c.path_index) {
            let d = horizontal(*target - next).length();
            if d < s.waypoint_threshold {
                c.path_index += 1;
                events.push((EVENT_WAYPOINT_REACHED, c.path_index as u32, Vector::ZERO));
                if c.path_index == c.path.len() {
                    c.path.clear();
                    c.path_index = 0;
                    events.push((EVENT_PATH_FINISHED, 0, Vector::ZERO));
                }
            }
        }
        c.velocity = v;
        let actual = (next - start) / dt;
        if s.report_moved && actual.length() > 1e-6 {
            events.push((EVENT_CONTROLLER_MOVED, 0, actual));
        }
        let next_pose = rapier3d::math::Pose::from_parts(next, yaw_rotation(c.yaw));
        self.world.bodies[h].set_next_kinematic_position(next_pose);
        // Controllers ticked after this one in the same tick see it where it is going.
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
        self.controllers.insert(slot, c);
    }

    /// The platform's motion at `foot` since the last tick: (translation to ride along,
    /// its velocity there, its yaw change).
    fn platform_motion(&self, c: &Controller, foot: Vector, dt: f32) -> (Vector, Vector, f32) {
        let none = (Vector::ZERO, Vector::ZERO, 0.0);
        let Some(ground) = c.ground.filter(|_| c.on_ground) else {
            return none;
        };
        let Some(body) = self.world.bodies.get(ground.body) else {
            return none;
        };
        if body.is_dynamic()
            || (body.is_kinematic() && body.body_type() == RigidBodyType::KinematicVelocityBased)
        {
            let v = body.velocity_at_point(foot);
            return (v * dt, v, body.angvel().y * dt);
        }
        // Anchored or pose-driven: how far its pose moved since we stood on it.
        let now = *body.position();
        let delta = now * ground.pose.inverse();
        let carried = delta.transform_point(foot) - foot;
        let yaw = yaw_of(delta.rotation.to_array());
        (carried, carried / dt, yaw)
    }

    /// Quake's stair step for a capsule blocked at `position` with `remaining` horizontal
    /// motion: lift by StepHeight (as far as the ceiling allows), move forward by the
    /// remaining motion (at least far enough for the capsule's bottom to clear the edge),
    /// drop back down. Accepted when it lands on walkable ground higher than it started and
    /// no higher than StepHeight.
    #[allow(clippy::too_many_arguments)]
    fn step_up(
        &self,
        own: RigidBodyHandle,
        shape: &SharedShape,
        position: Vector,
        yaw: f32,
        remaining: Vector,
        s: &ControllerSettings,
        groups: InteractionGroups,
    ) -> Option<Vector> {
        let dir = remaining.normalize_or_zero();
        if dir == Vector::ZERO {
            return None;
        }
        let pred = |_: ColliderHandle, co: &Collider| {
            co.parent() != Some(own) && co.collision_groups().test(groups) && !co.is_sensor()
        };
        let pipeline =
            self.query_pipeline(rapier3d::prelude::QueryFilter::default().predicate(&pred));
        let rotation = yaw_rotation(yaw);
        let cast = |from: Vector, along: Vector, reach: f32| {
            let options = ShapeCastOptions {
                max_time_of_impact: reach,
                target_distance: SKIN,
                stop_at_penetration: false,
                compute_impact_geometry_on_penetration: true,
            };
            pipeline
                .cast_shape(
                    &rapier3d::math::Pose::from_parts(from, rotation),
                    along,
                    &**shape,
                    options,
                )
                .map(|(_, hit)| hit)
        };
        // Lift.
        let lift =
            cast(position, Vector::Y, s.step_height).map_or(s.step_height, |h| h.time_of_impact);
        if lift < SKIN * 2.0 {
            return None;
        }
        let lifted = position + Vector::Y * lift;
        // Forward: the remaining motion, at least enough to get the capsule's bottom over
        // the tread.
        let reach = remaining.length().max(s.capsule_radius);
        let forward = cast(lifted, dir, reach).map_or(reach, |h| h.time_of_impact);
        if forward < SKIN * 2.0 {
            return None;
        }
        let ahead = lifted + dir * forward;
        // Drop.
        let hit = cast(ahead, -Vector::Y, lift + SKIN * 2.0)?;
        // The contact normal as the capsule feels it (a box reports a face normal at its
        // edges; the capsule's own normal there leans, and says it would stand on an edge).
        let felt = -(rotation * hit.normal2);
        if hit.time_of_impact <= 0.0 || felt.y < s.max_slope.to_radians().cos() - 1e-4 {
            return None; // started inside something, or landed on a slope too steep
        }
        let landed = ahead - Vector::Y * hit.time_of_impact;
        // How high the step is: where the capsule stands on it, above its bottom now.
        let bottom = position.y - (s.capsule_half_height + s.capsule_radius);
        let rise = hit.witness1.y - bottom;
        if landed.y - position.y <= SKIN || rise > s.step_height + SKIN {
            return None;
        }
        // Nothing may overlap the capsule where it lands.
        let pose = rapier3d::math::Pose::from_parts(landed, rotation);
        if pipeline.intersect_shape(pose, &**shape).next().is_some() {
            return None;
        }
        Some(landed)
    }

    /// Pushes the capsule at `position` out of everything it overlaps, deepest first.
    fn depenetrate(
        &self,
        own: RigidBodyHandle,
        shape: &SharedShape,
        position: Vector,
        groups: InteractionGroups,
    ) -> Vector {
        let mut offset = Vector::ZERO;
        for _ in 0..DEPENETRATION_PASSES {
            let pose = rapier3d::math::Pose::from_translation(position + offset);
            let mut deepest: Option<(f32, Vector)> = None;
            let pred = |_: ColliderHandle, co: &Collider| {
                co.parent() != Some(own) && co.collision_groups().test(groups) && !co.is_sensor()
            };
            let pipeline =
                self.query_pipeline(rapier3d::prelude::QueryFilter::default().predicate(&pred));
            for (_, co) in pipeline.intersect_shape(pose, &**shape) {
                // The pose has no rotation: the contact's capsule-local normal is the world's.
                let pos12 = pose.inv_mul(co.position());
                if let Ok(Some(contact)) =
                    super::clipped::contact(&pos12, &**shape, co.shape(), 0.0)
                {
                    if contact.dist < 0.0 && deepest.is_none_or(|(d, _)| contact.dist < d) {
                        deepest = Some((contact.dist, contact.normal1));
                    }
                }
            }
            let Some((dist, normal)) = deepest else {
                break;
            };
            // normal1 points from the capsule toward the obstacle: move the other way.
            offset += normal * (dist - SKIN);
        }
        offset
    }

    /// The ground within `reach` under the capsule at `position`: (its body, the gap to it,
    /// whether the contact normal as the capsule feels it is walkable under `max_slope`,
    /// whether the surface's own normal is).
    #[allow(clippy::too_many_arguments)]
    fn probe_ground(
        &self,
        own: RigidBodyHandle,
        shape: &SharedShape,
        position: Vector,
        yaw: f32,
        reach: f32,
        max_slope: f32,
        groups: InteractionGroups,
    ) -> Option<(RigidBodyHandle, f32, bool, bool)> {
        let pred = |_: ColliderHandle, co: &Collider| {
            co.parent() != Some(own) && co.collision_groups().test(groups) && !co.is_sensor()
        };
        let pipeline =
            self.query_pipeline(rapier3d::prelude::QueryFilter::default().predicate(&pred));
        let pose = rapier3d::math::Pose::from_parts(position, yaw_rotation(yaw));
        let options = ShapeCastOptions {
            max_time_of_impact: reach,
            target_distance: 0.0,
            stop_at_penetration: false,
            compute_impact_geometry_on_penetration: true,
        };
        let (col, hit) = pipeline.cast_shape(&pose, -Vector::Y, &**shape, options)?;
        // The normal as the capsule feels it: on a box's edge it leans (a box reports its
        // face normal there).
        let felt = -(pose.rotation * hit.normal2);
        let limit = max_slope.to_radians().cos() - 1e-4;
        let body = self.world.colliders.get(col)?.parent()?;
        Some((
            body,
            hit.time_of_impact,
            felt.y >= limit,
            hit.normal1.y >= limit,
        ))
    }

    /// Dynamic bodies the move ran into get an impulse along the push, capped at
    /// PushStrength × dt (a crate heavier than that cap can move blocks the controller).
    fn push_bodies(
        &mut self,
        collisions: &[CharacterCollision],
        c: &Controller,
        dt: f32,
    ) -> Vec<ColliderHandle> {
        let cap = c.settings.push_strength * dt;
        let mut gave_way = Vec::new();
        for col in collisions {
            let Some(body) = self
                .world
                .colliders
                .get(col.handle)
                .and_then(|co| co.parent())
            else {
                continue;
            };
            let Some(rb) = self.world.bodies.get_mut(body) else {
                continue;
            };
            if !rb.is_dynamic() {
                continue;
            }
            // Push along the horizontal part of the contact normal, away from the capsule.
            let n = -horizontal(col.hit.normal1).normalize_or_zero();
            let wanted = horizontal(col.translation_remaining).dot(n).max(0.0) / dt;
            let relative = (wanted - rb.linvel().dot(n)).max(0.0);
            let needed = rb.mass() * relative;
            let impulse = needed.min(cap);
            if impulse > 0.0 {
                rb.apply_impulse_at_point(n * impulse, col.hit.witness1, true);
            }
            if needed <= cap {
                gave_way.push(col.handle);
            }
        }
        gave_way
    }
}

impl Plane {
    /// The wall beside controller `c` (object `handle`) where it stands now, or zero.
    fn controller_wall(&self, handle: Handle, c: &Controller) -> Vector {
        let Ok(h) = self.body_of(handle) else {
            return Vector::ZERO;
        };
        let body = &self.world.bodies[h];
        let groups = body
            .colliders()
            .first()
            .map(|col| self.world.colliders[*col].collision_groups())
            .unwrap_or_default();
        self.wall_beside(
            h,
            &c.shape(),
            body.translation(),
            c.yaw,
            c.settings.max_slope,
            groups,
        )
    }

    /// The unit normal of the nearest wall (steeper than `max_slope`, not a ceiling) within
    /// [`WALL_SKIN`] of the capsule at `position`, or zero.
    #[allow(clippy::too_many_arguments)]
    fn wall_beside(
        &self,
        own: RigidBodyHandle,
        shape: &SharedShape,
        position: Vector,
        yaw: f32,
        max_slope: f32,
        groups: InteractionGroups,
    ) -> Vector {
        let pred = |_: ColliderHandle, co: &Collider| {
            co.parent() != Some(own) && co.collision_groups().test(groups) && !co.is_sensor()
        };
        let pipeline =
            self.query_pipeline(rapier3d::prelude::QueryFilter::default().predicate(&pred));
        let pose = rapier3d::math::Pose::from_parts(position, yaw_rotation(yaw));
        let mut best: Option<(f32, Vector)> = None;
        let region = shape.compute_aabb(&pose).loosened(WALL_SKIN);
        for (_, co) in pipeline.intersect_aabb_conservative(region) {
            self.each_piece(co, &**shape, &pose, WALL_SKIN, |piece, piece_pose| {
                let pos12 = pose.inv_mul(&piece_pose);
                let Ok(Some(contact)) = super::clipped::contact(&pos12, &**shape, piece, WALL_SKIN)
                else {
                    return;
                };
                let normal = (piece_pose.rotation * contact.normal2).normalize_or_zero();
                if contact.dist <= WALL_SKIN
                    && super::probes::is_wall(normal, max_slope)
                    && best.is_none_or(|(d, _)| contact.dist < d)
                {
                    best = Some((contact.dist, normal));
                }
            });
        }
        best.map_or(Vector::ZERO, |(_, n)| n)
    }

    /// Adds `dv` to a controller's velocity (an explosion's kick); a kick upward lifts it
    /// off the ground.
    pub(super) fn kick_controller(&mut self, slot: u32, dv: Vector) {
        if let Some(c) = self.controllers.get_mut(&slot) {
            c.velocity += dv;
            if dv.y > 0.0 {
                c.on_ground = false;
            }
        }
    }
}

/// How far from the capsule's side a wall still counts for `OnWall` (units): a few times
/// the gap the mover keeps from what it touches.
const WALL_SKIN: f32 = 5.0 * SKIN;

/// Moves the count of every controller's path to `counter` (controllers restored from a
/// snapshot count in their new plane).
pub(super) fn count_paths_in(controllers: &mut Controllers, counter: &Counter) {
    for c in controllers.values_mut() {
        c.path.count_in(counter);
    }
}

/// The controllers of a plane, by slot.
pub(super) type Controllers = BTreeMap<u32, Controller>;

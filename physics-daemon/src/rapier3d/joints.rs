//! Joints: every [`JointKind`] is one rapier `GenericJoint` built from the joint's
//! [`JointSettings`] (locked, limited, coupled and motorised axes of the joint frame, whose
//! X axis is `Axis`). After each step the plane measures every joint's positional and
//! angular error (the tick header's `max_joint_error`), its constraint force, and breaks
//! the joints whose force exceeded `BreakForce` (an `EVENT_JOINT_BROKE` event).
//!
//! Joint frames: frame A is `AnchorA` on A with X along `Axis`; frame B is `AnchorB` on B
//! with the rotation that makes the two frames coincide in the pose the bodies had when
//! the joint was made, so every angle (hinge angle, limits, motor targets) is measured from
//! the creation pose.

use rapier3d::prelude::*;
use shm_layout::joint_op::MAX_JOINTS;
use shm_layout::joint_op::{AxisMode, JointInfo, JointKind, JointOp, JointProp, JointSettings};
use shm_layout::{CommandError, CommandResult, EventRecord, Handle, Reply, EVENT_JOINT_BROKE};

use crate::backend::SlotTable;

use super::articulations::{self, Articulations};
use super::Plane;

/// Damping of a velocity motor when `Damping` is 0: stiff enough to hold the speed within
/// a few ticks (acceleration-based: the gain per second).
pub(super) const VELOCITY_MOTOR_GAIN: f32 = 1.0e4;
/// Position motor spring when `Stiffness` is 0 (acceleration-based, 1/s²) and its damping.
pub(super) const POSITION_MOTOR_STIFFNESS: f32 = 400.0;
pub(super) const POSITION_MOTOR_DAMPING: f32 = 40.0;

/// One joint of the plane.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub(super) struct Joint {
    kind: JointKind,
    a: Handle,
    b: Option<Handle>,
    body_a: RigidBodyHandle,
    body_b: RigidBodyHandle,
    /// Rotation of B relative to A at creation (`rot_b⁻¹ · rot_a`).
    rel: Rotation,
    /// The rapier joint; None once broken.
    rapier: Option<ImpulseJointHandle>,
    settings: JointSettings,
    error: f32,
    angular_error: f32,
    force: f32,
    position: f32,
    broken: bool,
    /// What A and B were at the last step, and whether the options changed since: either
    /// rebuilds the rapier joint before the next step.
    seen: Option<(EndState, EndState)>,
    dirty: bool,
    /// The multibody joint while the joint is articulated (see `articulations`).
    link: Option<MultibodyJointHandle>,
    /// The companion impulse joint holding an articulated ball joint's limits.
    limit: Option<ImpulseJointHandle>,
}

/// What one end of a joint is to the solver.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
enum EndState {
    /// Dynamic and simulated.
    Dynamic,
    /// Fixed (anchored, the world, a map part).
    Fixed,
    /// Out of the simulation: gone, disabled by rapier's quarantine of non-finite state, or
    /// about to be (a non-finite pose or velocity, which rapier disables at the start of the
    /// step).
    Disabled,
}

impl EndState {
    fn of(body: Option<&RigidBody>) -> EndState {
        let Some(b) = body else {
            return EndState::Disabled;
        };
        let finite = b.position().translation.is_finite()
            && b.position().rotation.is_finite()
            && b.linvel().is_finite()
            && b.angvel().is_finite();
        if !b.is_enabled() || !finite {
            EndState::Disabled
        } else if b.is_dynamic() {
            EndState::Dynamic
        } else {
            EndState::Fixed
        }
    }
}

/// The plane's joints.
#[derive(Clone, serde::Serialize, serde::Deserialize)]
pub(super) struct Joints {
    table: SlotTable<Joint>,
    /// A fixed body without colliders: the "world" end of joints to the world.
    ground: Option<RigidBodyHandle>,
    /// Largest positional error after the last step.
    pub max_error: f32,
    /// The articulated joint trees.
    pub articulations: Articulations,
}

impl Default for Joints {
    fn default() -> Self {
        Joints {
            table: SlotTable::new("joint", MAX_JOINTS),
            ground: None,
            max_error: 0.0,
            articulations: Articulations::default(),
        }
    }
}

impl Joints {
    /// See [`SlotTable::adopt_limits`] (a snapshot's joint table).
    pub fn adopt_limits(&mut self, like: &Joints) -> Result<(), CommandError> {
        self.table.adopt_limits(&like.table)
    }

    /// Live joints (they count as objects for the quotas).
    pub fn live(&self) -> u32 {
        self.table.live()
    }
}

impl Plane {
    /// The articulated ball joints with limits: (link, twist limit, swing limit), a missing
    /// limit as π.
    pub(super) fn limited_ball_links(&self) -> Vec<(MultibodyJointHandle, f32, f32)> {
        (0..self.joints.table.slot_count())
            .filter_map(|i| {
                let j = self.joints.table.at(i)?;
                let link = j.link?;
                articulations::needs_limit_joint(j.kind, &j.settings).then(|| {
                    let pi = std::f32::consts::PI;
                    (
                        link,
                        j.settings.twist_limit.unwrap_or(pi),
                        j.settings.swing_limit.unwrap_or(pi),
                    )
                })
            })
            .collect()
    }

    /// The force each articulated joint carried over the last step, keyed by its child body
    /// (what `articulations::set_armature` sizes a joint's armature for).
    pub(super) fn articulated_loads(&self) -> std::collections::HashMap<RigidBodyHandle, f32> {
        (0..self.joints.table.slot_count())
            .filter_map(|i| {
                let j = self.joints.table.at(i)?;
                let link = j.link?;
                let child = if link.0 == j.body_a.0 {
                    j.body_a
                } else {
                    j.body_b
                };
                Some((child, j.force))
            })
            .collect()
    }

    /// Forgets every joint's articulation (the trees were torn down): companions go, and
    /// each joint is looked at again before the next step.
    pub(super) fn forget_articulated(&mut self) {
        for i in 0..self.joints.table.slot_count() {
            let Some(j) = self.joints.table.at_mut(i) else {
                continue;
            };
            if j.link.is_none() && j.limit.is_none() {
                continue;
            }
            j.link = None;
            j.seen = None;
            if let Some(l) = j.limit.take() {
                self.world.impulse_joints.remove(l, true);
            }
        }
    }
}

const LIN: [JointAxis; 3] = [JointAxis::LinX, JointAxis::LinY, JointAxis::LinZ];
const ANG: [JointAxis; 3] = [JointAxis::AngX, JointAxis::AngY, JointAxis::AngZ];

fn vec(v: [f32; 3]) -> Vector {
    Vector::from(v)
}

/// The rapier joint for `kind` with `s`; `rel` turns frame A into frame B.
fn build(kind: JointKind, s: &JointSettings, rel: Rotation) -> GenericJoint {
    let frame_rot = GenericJoint::complete_ang_frame(vec(s.axis));
    let mut j = GenericJoint::new(JointAxesMask::empty());
    j.set_local_frame1(Pose::from_parts(vec(s.anchor_a), frame_rot));
    j.set_local_frame2(Pose::from_parts(vec(s.anchor_b), rel * frame_rot));
    j.set_contacts_enabled(s.collide_connected);
    let angle_limits = |lo: Option<f32>, hi: Option<f32>| {
        [
            lo.unwrap_or(-shm_layout::joint_op::MAX_ANGLE),
            hi.unwrap_or(shm_layout::joint_op::MAX_ANGLE),
        ]
    };
    let distance_limits =
        |lo: Option<f32>, hi: Option<f32>| [lo.unwrap_or(-f32::MAX), hi.unwrap_or(f32::MAX)];
    let cone = |j: &mut GenericJoint| {
        if let Some(t) = s.twist_limit {
            j.set_limits(JointAxis::AngX, [-t, t]);
        }
        if let Some(w) = s.swing_limit {
            j.set_limits(JointAxis::AngY, [-w, w]);
            j.set_limits(JointAxis::AngZ, [-w, w]);
        }
    };
    let motor = |j: &mut GenericJoint, axis: JointAxis| {
        if let Some(target) = s.motor_target {
            if s.stiffness > 0.0 {
                j.set_motor_model(axis, MotorModel::ForceBased);
                j.set_motor(
                    axis,
                    target,
                    s.motor_speed.unwrap_or(0.0),
                    s.stiffness,
                    s.damping,
                );
            } else {
                j.set_motor(
                    axis,
                    target,
                    s.motor_speed.unwrap_or(0.0),
                    POSITION_MOTOR_STIFFNESS,
                    POSITION_MOTOR_DAMPING,
                );
            }
        } else if let Some(speed) = s.motor_speed {
            let gain = if s.damping > 0.0 {
                s.damping
            } else {
                VELOCITY_MOTOR_GAIN
            };
            j.set_motor_velocity(axis, speed, gain);
        }
        if s.motor_speed.is_some() || s.motor_target.is_some() {
            j.set_motor_max_force(axis, s.motor_max_force);
        }
    };
    match kind {
        JointKind::Ball | JointKind::ConeTwist => {
            j.lock_axes(JointAxesMask::LIN_AXES);
            cone(&mut j);
        }
        JointKind::Fixed => {
            j.lock_axes(JointAxesMask::LIN_AXES | JointAxesMask::ANG_AXES);
        }
        JointKind::Hinge => {
            j.lock_axes(JointAxesMask::LIN_AXES | JointAxesMask::ANG_Y | JointAxesMask::ANG_Z);
            if s.lower_angle.is_some() || s.upper_angle.is_some() {
                j.set_limits(JointAxis::AngX, angle_limits(s.lower_angle, s.upper_angle));
            }
            motor(&mut j, JointAxis::AngX);
        }
        JointKind::Prismatic => {
            j.lock_axes(JointAxesMask::LIN_Y | JointAxesMask::LIN_Z | JointAxesMask::ANG_AXES);
            if s.lower_distance.is_some() || s.upper_distance.is_some() {
                j.set_limits(
                    JointAxis::LinX,
                    distance_limits(s.lower_distance, s.upper_distance),
                );
            }
            motor(&mut j, JointAxis::LinX);
        }
        JointKind::SixDof => {
            let mut locked = JointAxesMask::empty();
            for (i, mode) in s.axes.iter().enumerate() {
                let axis = if i < 3 { LIN[i] } else { ANG[i - 3] };
                match mode {
                    AxisMode::Locked => locked |= axis.into(),
                    AxisMode::Free => {}
                    AxisMode::Limited if i < 3 => {
                        j.set_limits(axis, distance_limits(s.lower_distance, s.upper_distance));
                    }
                    AxisMode::Limited => {
                        j.set_limits(axis, angle_limits(s.lower_angle, s.upper_angle));
                    }
                }
            }
            j.lock_axes(locked);
            super::axis_motors::apply(&mut j, s);
        }
        JointKind::Rope => {
            j.coupled_axes = JointAxesMask::LIN_AXES;
            j.set_limits(
                JointAxis::LinX,
                [0.0, s.upper_distance.unwrap_or(s.rest_length)],
            );
        }
        JointKind::Spring => {
            j.coupled_axes = JointAxesMask::LIN_AXES;
            j.set_motor_model(JointAxis::LinX, MotorModel::ForceBased);
            j.set_motor_position(JointAxis::LinX, s.rest_length, s.stiffness, s.damping);
        }
    }
    j
}

/// The signed angle of a relative rotation about one of its frame's axes (the angle
/// rapier's limits compare), in (-π, π].
fn axis_angle(q: Rotation, i: usize) -> f32 {
    let q = if q.w < 0.0 { -q } else { q };
    let imag = [q.x, q.y, q.z];
    2.0 * imag[i].atan2(q.w)
}

fn overshoot(v: f32, lo: f32, hi: f32) -> f32 {
    (lo - v).max(v - hi).max(0.0)
}

impl Plane {
    /// Routes one joint op.
    pub(super) fn joint_op(&mut self, op: JointOp) -> CommandResult {
        match op.checked()? {
            JointOp::Create { kind, a, b, props } => {
                let handle = self.create_joint(kind, a, b, &props)?;
                Ok(Reply::Joint {
                    handle,
                    tick: self.clock.tick,
                })
            }
            JointOp::Set { joint, prop } => {
                self.set_joint(joint, prop)?;
                Ok(Reply::Applied {
                    tick: self.clock.tick,
                })
            }
            JointOp::Info { joint } => Ok(Reply::JointInfo(Box::new(self.joint_info(joint)?))),
            JointOp::Destroy { joint } => {
                let j = self.joints.table.remove(joint)?;
                self.remove_rapier_joint(&j);
                self.joint_holds(j.a, -1);
                if let Some(b) = j.b {
                    self.joint_holds(b, -1);
                }
                Ok(Reply::Applied {
                    tick: self.clock.tick,
                })
            }
        }
    }

    fn ground(&mut self) -> RigidBodyHandle {
        if let Some(g) = self.joints.ground {
            return g;
        }
        let g = self
            .world
            .insert_body(RigidBodyBuilder::fixed().user_data(u128::MAX).build());
        self.joints.ground = Some(g);
        g
    }

    fn create_joint(
        &mut self,
        kind: JointKind,
        a: Handle,
        b: Option<Handle>,
        props: &[JointProp],
    ) -> Result<Handle, CommandError> {
        let body_a = self.body_of(a)?;
        let body_b = match b {
            Some(b) if b == a => {
                return Err(CommandError::invalid_field(
                    "objB",
                    "a joint needs two different objects (objB is objA)",
                ))
            }
            Some(b) => self.body_of(b)?,
            None => self.ground(),
        };
        let mut settings = JointSettings::default();
        for p in props {
            settings.store(*p);
        }
        settings.check(kind)?;
        let rel =
            self.world.bodies[body_b].rotation().inverse() * *self.world.bodies[body_a].rotation();
        let data = build(kind, &settings, rel);
        let rapier = self.world.insert_impulse_joint(body_a, body_b, data);
        let joint = Joint {
            kind,
            a,
            b,
            body_a,
            body_b,
            rel,
            rapier: Some(rapier),
            settings,
            error: 0.0,
            angular_error: 0.0,
            force: 0.0,
            position: 0.0,
            broken: false,
            seen: None,
            dirty: false,
            link: None,
            limit: None,
        };
        self.joints.articulations.dirty = true;
        match self.joints.table.insert(joint) {
            Ok(h) => {
                self.joint_holds(a, 1);
                if let Some(b) = b {
                    self.joint_holds(b, 1);
                }
                self.measure_joint(h);
                Ok(h)
            }
            Err(e) => {
                self.world.remove_impulse_joint(rapier);
                Err(e)
            }
        }
    }

    fn set_joint(&mut self, handle: Handle, prop: JointProp) -> Result<(), CommandError> {
        let joint = self.joints.table.get(handle)?;
        let mut settings = joint.settings;
        settings.store(prop);
        settings.check(joint.kind)?;
        let structural = articulations::articulable(joint.kind, &joint.settings)
            != articulations::articulable(joint.kind, &settings)
            || articulations::needs_limit_joint(joint.kind, &joint.settings)
                != articulations::needs_limit_joint(joint.kind, &settings);
        let j = self.joints.table.get_mut(handle)?;
        j.settings = settings;
        j.dirty = true;
        let ends = [Some(j.a), j.b];
        self.joints.articulations.dirty |= structural;
        // A joint write wakes both ends, as an object write does: a sleeping door at its
        // limit must feel a new motor or limit (rapier wakes a body's whole island, an
        // articulation's links with it, at the next step).
        for object in ends.into_iter().flatten() {
            self.wake(object)?;
        }
        Ok(())
    }

    fn joint_info(&self, handle: Handle) -> Result<JointInfo, CommandError> {
        let j = self.joints.table.get(handle)?;
        Ok(JointInfo {
            handle,
            kind: j.kind,
            a: j.a,
            b: j.b,
            settings: j.settings,
            error: j.error,
            angular_error: j.angular_error,
            broken: j.broken,
            force: j.force,
            position: j.position,
        })
    }

    fn remove_rapier_joint(&mut self, j: &Joint) {
        if let Some(r) = j.rapier {
            self.world.impulse_joints.remove(r, true);
        }
        if let Some(l) = j.limit {
            self.world.impulse_joints.remove(l, true);
        }
        if j.link.is_some() {
            self.tear_down_articulations();
        }
        self.joints.articulations.dirty = true;
    }

    /// Removes every joint attached to an object that is being destroyed (before its body
    /// goes).
    pub(super) fn remove_joints_of(&mut self, body: RigidBodyHandle) {
        if self.joints.table.live() == 0 {
            return;
        }
        let doomed: Vec<Handle> = (0..self.joints.table.slot_count())
            .filter_map(|i| {
                let j = self.joints.table.at(i)?;
                (j.body_a == body || j.body_b == body)
                    .then(|| self.joints.table.handle_at(i))
                    .flatten()
            })
            .collect();
        for h in doomed {
            if let Ok(j) = self.joints.table.remove(h) {
                self.remove_rapier_joint(&j);
                self.joint_holds(j.a, -1);
                if let Some(b) = j.b {
                    self.joint_holds(b, -1);
                }
            }
        }
    }

    /// Counts a joint more (`1`) or less (`-1`) holding `object`, and refreshes its body's
    /// rotation lock: a part a joint holds is free to rotate (see
    /// `Part::rotation_locked_by_quality`).
    fn joint_holds(&mut self, object: Handle, delta: i32) {
        let Ok(body) = self.bodies.get_mut(object) else {
            return; // gone with its joint
        };
        let h = body.handle;
        body.part.joints = body.part.joints.saturating_add_signed(delta);
        let part = &body.part;
        if let Some(rb) = self.world.bodies.get_mut(h) {
            rb.set_locked_axes(part.locked_axes(), true);
        }
    }

    /// Before a step: a joint whose options changed, or whose bodies changed what they are
    /// to the solver (anchored, released, disabled), is rebuilt by removing and inserting it,
    /// which is what makes rapier refresh its cached joint selection. A joint is parked (no
    /// rapier joint) while it has no dynamic end or while either end is disabled, and comes
    /// back when both ends allow it again.
    ///
    /// Why disabled ends matter: rapier disables a body whose pose or velocity went non-finite
    /// (its quarantine) and takes it out of the active set, but its joint selection still
    /// picks a joint whose dynamic ends are "not sleeping", and stamps such a body with the
    /// world-attached solver id. A joint between two quarantined bodies, or between a
    /// quarantined body and a fixed one, then reaches the solver with both ends
    /// world-attached, and its constraint colouring panics (`unreachable!()` in
    /// `interaction_groups.rs`).
    pub(super) fn joints_before_step(&mut self) {
        if self.joints.table.live() == 0 {
            return;
        }
        // A change of structure (see `articulations`) rebuilds the trees.
        let states = |p: &Plane, j: &Joint| {
            (
                EndState::of(p.world.bodies.get(j.body_a)),
                EndState::of(p.world.bodies.get(j.body_b)),
            )
        };
        let relayout = self.joints.articulations.dirty
            || (0..self.joints.table.slot_count()).any(|i| {
                self.joints
                    .table
                    .at(i)
                    .is_some_and(|j| !j.broken && j.seen != Some(states(self, j)))
            });
        let mut articulated = vec![false; self.joints.table.slot_count()];
        let plans = if relayout {
            self.tear_down_articulations();
            let candidates: Vec<articulations::Candidate> = (0..self.joints.table.slot_count())
                .filter_map(|i| {
                    let j = self.joints.table.at(i)?;
                    let now = states(self, j);
                    let ok = !j.broken
                        && articulations::articulable(j.kind, &j.settings)
                        && now.0 != EndState::Disabled
                        && now.1 != EndState::Disabled
                        && (now.0 == EndState::Dynamic || now.1 == EndState::Dynamic);
                    ok.then_some((
                        i,
                        j.body_a,
                        j.body_b,
                        now.0 == EndState::Dynamic,
                        now.1 == EndState::Dynamic,
                    ))
                })
                .collect();
            let plans = articulations::plan(&candidates);
            for p in &plans {
                for e in &p.edges {
                    articulated[e.0] = true;
                }
            }
            plans
        } else {
            for (i, a) in articulated.iter_mut().enumerate() {
                *a = self.joints.table.at(i).is_some_and(|j| j.link.is_some());
            }
            Vec::new()
        };
        for (i, &art) in articulated.iter().enumerate() {
            let Some(j) = self.joints.table.at(i) else {
                continue;
            };
            if j.broken {
                continue;
            }
            let now = states(self, j);
            if art {
                let old = j.rapier;
                if let Some(r) = old {
                    self.world.impulse_joints.remove(r, true);
                }
                if !relayout && j.dirty {
                    self.update_articulated(i);
                }
                let j = self.joints.table.at_mut(i).expect("live slot");
                j.rapier = None;
                j.seen = Some(now);
                j.dirty = false;
                continue;
            }
            if j.seen == Some(now) && !j.dirty {
                continue;
            }
            let (kind, rel, settings, a, b, old) =
                (j.kind, j.rel, j.settings, j.body_a, j.body_b, j.rapier);
            if let Some(r) = old {
                self.world.impulse_joints.remove(r, true);
            }
            let active = now.0 != EndState::Disabled
                && now.1 != EndState::Disabled
                && (now.0 == EndState::Dynamic || now.1 == EndState::Dynamic);
            let new = active.then(|| {
                self.world
                    .insert_impulse_joint(a, b, build(kind, &settings, rel))
            });
            let j = self.joints.table.at_mut(i).expect("live slot");
            j.rapier = new;
            j.seen = Some(now);
            j.dirty = false;
        }
        for p in plans {
            self.build_planned_tree(p);
        }
        self.joints.articulations.dirty = false;
        self.articulations_before_step();
    }

    /// Builds one planned tree: its multibody joints and the companions of limited ball
    /// joints.
    fn build_planned_tree(&mut self, p: articulations::TreePlan) {
        let edges: Vec<_> = p
            .edges
            .iter()
            .map(|&(slot, parent, child, flip)| {
                let j = self.joints.table.at(slot).expect("planned joint");
                let three = matches!(j.kind, JointKind::Ball | JointKind::ConeTwist);
                let data =
                    articulations::multibody_data(build(j.kind, &j.settings, j.rel), three, flip);
                (data, parent, child)
            })
            .collect();
        let links = self.build_tree(p.root, p.fixed_end, &edges, &p.bodies);
        for (&(slot, ..), link) in p.edges.iter().zip(links) {
            let j = self.joints.table.at(slot).expect("planned joint");
            let limit = articulations::needs_limit_joint(j.kind, &j.settings).then(|| {
                let data = articulations::limit_data(build(j.kind, &j.settings, j.rel));
                (j.body_a, j.body_b, data)
            });
            let limit = limit.map(|(a, b, data)| self.world.insert_impulse_joint(a, b, data));
            // Rapier refused the link (it should not): the joint stays an impulse joint.
            let fallback = link.is_none().then(|| {
                let j = self.joints.table.at(slot).expect("planned joint");
                let data = build(j.kind, &j.settings, j.rel);
                let (a, b) = (j.body_a, j.body_b);
                self.world.insert_impulse_joint(a, b, data)
            });
            let j = self.joints.table.at_mut(slot).expect("planned joint");
            j.link = link;
            j.limit = limit;
            j.rapier = fallback;
        }
    }

    /// An articulated joint's options changed (motor, limits, CollideConnected): its
    /// multibody joint and companion take them in place.
    fn update_articulated(&mut self, i: usize) {
        let j = self.joints.table.at(i).expect("live slot");
        let (Some(link), limit) = (j.link, j.limit) else {
            return;
        };
        let data = build(j.kind, &j.settings, j.rel);
        let three = matches!(j.kind, JointKind::Ball | JointKind::ConeTwist);
        // The link is keyed by its child body: the joint was flipped when A is the child.
        let flip = link.0 == j.body_a.0;
        if let Some((mb, id)) = self.world.multibody_joints.get_mut(link) {
            if let Some(l) = mb.link_mut(id) {
                l.joint.data = articulations::multibody_data(data, three, flip);
            }
            articulations::undamp_springs(mb);
        }
        if let Some(l) = limit {
            if let Some(ij) = self.world.impulse_joints.get_mut(l, true) {
                ij.data = articulations::limit_data(data);
            }
        }
    }

    /// After a step: every joint's error and force, breaking the overloaded ones (one
    /// event each). Runs only when the plane has joints.
    pub(super) fn joints_after_step(&mut self, dt: f32) {
        self.joints.max_error = 0.0;
        let articulated = if self.joints.articulations.is_empty() {
            Default::default()
        } else {
            self.articulations_after_ccd();
            self.articulated_forces(dt)
        };
        self.articulations_after_step();
        if self.joints.table.live() == 0 {
            return;
        }
        // Rapier keeps the impulse of the last substep: force = impulse / substep dt.
        let substep = dt
            / self
                .world
                .integration_parameters
                .num_solver_iterations
                .max(1) as f32;
        for i in 0..self.joints.table.slot_count() {
            let Some(h) = self.joints.table.handle_at(i) else {
                continue;
            };
            let force = {
                let j = self.joints.table.at(i).expect("live slot");
                let child = j.link.map(|l| {
                    if l.0 == j.body_a.0 {
                        j.body_a
                    } else {
                        j.body_b
                    }
                });
                match j.rapier.and_then(|r| self.world.impulse_joints.get(r)) {
                    _ if child.is_some() => child
                        .and_then(|c| articulated.get(&c).copied())
                        .unwrap_or(0.0),
                    Some(rj) => {
                        let imp = &rj.impulses;
                        let mut lin = Vector::new(imp[0], imp[1], imp[2]);
                        for (k, axis) in LIN.iter().enumerate() {
                            if let Some(l) = rj.data.limits(*axis) {
                                lin[k] += l.impulse;
                            }
                            if let Some(m) = rj.data.motor(*axis) {
                                lin[k] += m.impulse;
                            }
                        }
                        lin.length() / substep
                    }
                    None => 0.0,
                }
            };
            self.measure_joint(h);
            let j = self.joints.table.get_mut(h).expect("live handle");
            j.force = force;
            if j.break_check(force) {
                let (rapier, a) = (j.rapier.take(), j.a);
                j.broken = true;
                let anchor = self.world.bodies[j.body_a].position() * vec(j.settings.anchor_a);
                if let Some(r) = rapier {
                    self.world.impulse_joints.remove(r, true);
                }
                self.events.push(EventRecord {
                    kind: EVENT_JOINT_BROKE,
                    a_slot: h.slot,
                    a_generation: h.generation,
                    b_slot: a.slot,
                    b_generation: a.generation,
                    impulse: force,
                    position: anchor.into(),
                    tick: self.clock.tick,
                    seq: self.event_seq,
                    ..EventRecord::default()
                });
                self.event_seq += 1;
            }
            let j = self.joints.table.get(h).expect("live handle");
            if !j.broken {
                self.joints.max_error = self.joints.max_error.max(j.error);
            }
        }
    }

    /// Recomputes one joint's error figures and position from the bodies' poses.
    fn measure_joint(&mut self, h: Handle) {
        let Ok(j) = self.joints.table.get(h) else {
            return;
        };
        let (Some(ba), Some(bb)) = (
            self.world.bodies.get(j.body_a),
            self.world.bodies.get(j.body_b),
        ) else {
            return;
        };
        let s = &j.settings;
        let frame_rot = GenericJoint::complete_ang_frame(vec(s.axis));
        let f1 = ba.position() * Pose::from_parts(vec(s.anchor_a), frame_rot);
        let f2 = bb.position() * Pose::from_parts(vec(s.anchor_b), j.rel * frame_rot);
        let d = f1.rotation.inverse() * (f2.translation - f1.translation);
        let q = f1.rotation.inverse() * f2.rotation;
        let ang = [axis_angle(q, 0), axis_angle(q, 1), axis_angle(q, 2)];
        let any = (-f32::MAX, f32::MAX);
        let lim =
            |lo: Option<f32>, hi: Option<f32>| (lo.unwrap_or(-f32::MAX), hi.unwrap_or(f32::MAX));
        // Per axis: (lin mode, range) and (ang mode, range).
        let (lin_err, ang_err, position) = match j.kind {
            JointKind::Ball | JointKind::ConeTwist => {
                let t = s.twist_limit.unwrap_or(f32::MAX);
                let w = s.swing_limit.unwrap_or(f32::MAX);
                let a = overshoot(ang[0], -t, t)
                    .max(overshoot(ang[1], -w, w))
                    .max(overshoot(ang[2], -w, w));
                (d.length(), a, 0.0)
            }
            JointKind::Fixed => (
                d.length(),
                ang.iter().fold(0.0f32, |m, a| m.max(a.abs())),
                0.0,
            ),
            JointKind::Hinge => {
                let (lo, hi) = lim(s.lower_angle, s.upper_angle);
                let a = ang[1]
                    .abs()
                    .max(ang[2].abs())
                    .max(overshoot(ang[0], lo, hi));
                (d.length(), a, ang[0])
            }
            JointKind::Prismatic => {
                let (lo, hi) = lim(s.lower_distance, s.upper_distance);
                let l = (d.y * d.y + d.z * d.z).sqrt() + overshoot(d.x, lo, hi);
                (l, ang.iter().fold(0.0f32, |m, a| m.max(a.abs())), d.x)
            }
            JointKind::SixDof => {
                let mut l2 = 0.0f32;
                let mut a = 0.0f32;
                for i in 0..6 {
                    let (range, v) = match (i < 3, s.axes[i]) {
                        (_, AxisMode::Free) => (any, 0.0),
                        (_, AxisMode::Locked) => {
                            ((0.0, 0.0), if i < 3 { d[i] } else { ang[i - 3] })
                        }
                        (true, AxisMode::Limited) => {
                            (lim(s.lower_distance, s.upper_distance), d[i])
                        }
                        (false, AxisMode::Limited) => {
                            (lim(s.lower_angle, s.upper_angle), ang[i - 3])
                        }
                    };
                    let o = overshoot(v, range.0, range.1);
                    if i < 3 {
                        l2 += o * o;
                    } else {
                        a = a.max(o);
                    }
                }
                (l2.sqrt(), a, 0.0)
            }
            JointKind::Rope => {
                let len = s.upper_distance.unwrap_or(s.rest_length);
                (overshoot(d.length(), 0.0, len), 0.0, d.length())
            }
            JointKind::Spring => (0.0, 0.0, d.length()),
        };
        let j = self.joints.table.get_mut(h).expect("live handle");
        j.error = lin_err;
        j.angular_error = ang_err;
        j.position = position;
    }
}

impl Joint {
    fn break_check(&self, force: f32) -> bool {
        !self.broken && self.settings.break_force > 0.0 && force > self.settings.break_force
    }
}

#[cfg(test)]
mod tests {
    use shm_layout::{JointOp, JointProp, ObjectProp, PlaneOp, PlaneProp, Pose, Reply, Shape};

    use crate::backend::Backend;
    use crate::rapier3d::Plane;

    fn plane() -> Plane {
        Plane::new(
            1,
            &[
                PlaneProp::TickRate(0.0),
                PlaneProp::LinearDamping(0.0),
                PlaneProp::AngularDamping(0.0),
            ],
        )
        .unwrap()
    }

    fn ball(p: &mut Plane, at: [f32; 3], weight: f32) -> shm_layout::Handle {
        p.add_object(
            &Shape::Sphere { radius: 0.25 },
            Pose::at(at),
            &[ObjectProp::Weight(weight)],
        )
        .unwrap()
    }

    /// A xorshift generator from `seed`: `rnd(n)` is in `0..n` (the random-sequence tests).
    fn xorshift(mut seed: u64) -> impl FnMut(u64) -> u64 {
        move |n| {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            seed % n
        }
    }

    fn joint(p: &mut Plane, op: JointOp) -> shm_layout::Handle {
        match p.apply(PlaneOp::Joint(op)).unwrap() {
            Reply::Joint { handle, .. } => handle,
            r => panic!("{r:?}"),
        }
    }

    #[test]
    fn a_hanging_mass_loads_its_joint_with_its_weight() {
        let mut p = plane();
        let b = ball(&mut p, [0.0, -2.0, 0.0], 2.0);
        let j = joint(
            &mut p,
            JointOp::Create {
                kind: shm_layout::JointKind::Ball,
                a: b,
                b: None,
                props: vec![JointProp::AnchorA([0.0, 2.0, 0.0])],
            },
        );
        for _ in 0..120 {
            p.step(1.0 / 60.0).unwrap();
        }
        let Reply::JointInfo(info) = p.apply(PlaneOp::Joint(JointOp::Info { joint: j })).unwrap()
        else {
            panic!()
        };
        // m·g = 2 × 50 = 100.
        assert!((info.force - 100.0).abs() < 5.0, "force {}", info.force);
        assert!(info.error < 0.01, "error {}", info.error);
    }

    /// Bodies whose state went non-finite are disabled by rapier (its quarantine), yet its
    /// joint selection still hands their joints to the solver with both ends world-attached,
    /// which panics there. The sequence the fuzzer found: forced bodies stepped with the
    /// smallest positive dt (1e-45 s, which overflowed the force drive until it fell back to
    /// setting velocities: see `tiny_steps_leave_forced_bodies_enabled`), then joints made on
    /// them and a normal step. Quarantine is reproduced here as rapier leaves it (bodies
    /// disabled); the joints are parked, no step panics, a joint made afterwards works, and
    /// re-enabled bodies get their joints back.
    #[test]
    fn joints_of_quarantined_bodies_are_parked_instead_of_panicking_the_solver() {
        use shm_layout::JointKind;
        let mut p = Plane::new(
            1,
            &[
                shm_layout::PlaneProp::TickRate(0.0),
                shm_layout::PlaneProp::AngularDamping(3.4382944),
                shm_layout::PlaneProp::SolverIterations(13),
                shm_layout::PlaneProp::RestThreshold(0.8737293),
            ],
        )
        .unwrap();
        let a = p
            .add_object(
                &Shape::Cube {
                    size: [1.0, 1.0, 1.0],
                },
                Pose::at([0.0, 0.0, 0.0]),
                &[],
            )
            .unwrap();
        let b = ball(&mut p, [0.4, 0.0, 0.0], 1.0);
        let c = ball(&mut p, [5.0, 0.0, 0.0], 1.0);
        let parked = |p: &Plane| {
            (0..p.joints.table.slot_count())
                .filter_map(|i| p.joints.table.at(i))
                .filter(|j| j.rapier.is_none() && j.link.is_none())
                .count()
        };
        let step = |p: &mut Plane, i: usize, dt: f32| {
            let stepped = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| p.step(dt)));
            assert!(stepped.is_ok(), "step {i} (dt {dt}) panicked");
        };
        step(&mut p, 0, 1.0 / 60.0);
        let bodies: Vec<_> = [a, b, c]
            .iter()
            .map(|h| p.bodies.get(*h).unwrap().handle)
            .collect();
        for h in &bodies {
            p.world.bodies[*h].set_enabled(false);
        }
        step(&mut p, 0, 1.0 / 60.0);
        // Free balls, more than the quarantined ones, so that rapier's joint selection scans
        // every joint rather than only those next to awake bodies.
        for k in 0..6 {
            ball(&mut p, [20.0 + k as f32, 0.0, 0.0], 1.0);
        }
        // Joints made on the quarantined balls (as the fuzzer did) are parked at once.
        for (kind, x, y) in [
            (JointKind::Hinge, a, Some(b)),
            (JointKind::Ball, c, None),
            (JointKind::Fixed, b, Some(c)),
        ] {
            joint(
                &mut p,
                JointOp::Create {
                    kind,
                    a: x,
                    b: y,
                    props: vec![],
                },
            );
        }
        for i in 1..4 {
            step(&mut p, i, 1.0 / 60.0);
        }
        let quarantined = p
            .world
            .bodies
            .iter()
            .filter(|(_, b)| !b.is_enabled())
            .count();
        assert_eq!(quarantined, 3, "the three balls are quarantined");
        assert_eq!(parked(&p), 3, "their joints are parked");

        // A pendulum made now swings on its 2-unit rod.
        let pendulum = ball(&mut p, [10.0, -2.0, 0.0], 1.0);
        let rod = joint(
            &mut p,
            JointOp::Create {
                kind: JointKind::Ball,
                a: pendulum,
                b: None,
                props: vec![JointProp::AnchorA([0.0, 2.0, 0.0])],
            },
        );
        p.apply(PlaneOp::Object {
            handle: pendulum,
            op: shm_layout::ObjectOp::Set(ObjectProp::Velocity([5.0, 0.0, 0.0])),
        })
        .unwrap();
        for _ in 0..30 {
            p.step(1.0 / 60.0).unwrap();
        }
        let Reply::JointInfo(info) = p
            .apply(PlaneOp::Joint(JointOp::Info { joint: rod }))
            .unwrap()
        else {
            panic!()
        };
        // Off the rod by under 1 % of its length.
        assert!(info.error < 0.02, "pendulum joint error {}", info.error);
        let body = p.joints.table.get(rod).unwrap().body_a;
        let x = p.world.bodies[body].translation().x;
        assert!((x - 10.0).abs() > 0.1, "the pendulum swung: x = {x}");

        // Re-enabled (set_enabled(true) is how rapier lifts a quarantine), the balls get
        // their joints back.
        for h in &bodies {
            p.world.bodies[*h].set_enabled(true);
        }
        step(&mut p, 4, 1.0 / 60.0);
        assert_eq!(parked(&p), 0, "joints restored");
    }

    /// A forced body stepped with the smallest positive dt (its force drive's mass / dt
    /// overflows) keeps a finite state and stays in the simulation instead of being
    /// quarantined by rapier.
    #[test]
    fn tiny_steps_leave_forced_bodies_enabled() {
        let mut p = plane();
        let a = ball(&mut p, [0.0, 0.0, 0.0], 1.0);
        p.apply(PlaneOp::Object {
            handle: a,
            op: shm_layout::ObjectOp::Set(ObjectProp::ConstantForce([0.0, 1.0, 0.0])),
        })
        .unwrap();
        p.step(1.0e-45).unwrap();
        p.step(1.0 / 60.0).unwrap();
        let body = &p.world.bodies[p.bodies.get(a).unwrap().handle];
        assert!(body.is_enabled(), "quarantined by a tiny step");
        assert!(body.translation().is_finite() && body.linvel().is_finite());
        // Gravity (-50) and the force (+1 on weight 1) over the 1/60 s step.
        let vy = body.linvel().y;
        assert!((vy - (-49.0 / 60.0)).abs() < 0.02, "vy {vy}");
    }

    /// Articulated joints with motors and limits stepped with tiny time steps (found by the
    /// fuzzer: an articulated joint with a motor target and limits, a step of 1e-38 s: the
    /// solver's rates (1 / dt) overflowed into NaN motor bounds and panicked it). A step
    /// under `MIN_DYNAMIC_DT` is simulated as that long; no step may panic, every body stays
    /// finite and the plane's clock counts every step.
    #[test]
    fn articulations_with_motors_survive_tiny_steps() {
        use shm_layout::JointKind;
        let motor = [JointProp::MotorTarget(1.5), JointProp::MotorMaxForce(50.0)];
        let cases = [
            (
                JointKind::Prismatic,
                vec![JointProp::LowerDistance(0.5), JointProp::UpperDistance(3.0)],
            ),
            (
                JointKind::Hinge,
                vec![JointProp::LowerAngle(-0.5), JointProp::UpperAngle(0.5)],
            ),
            (JointKind::Ball, vec![JointProp::SwingLimit(1.0)]),
            (
                JointKind::ConeTwist,
                vec![JointProp::SwingLimit(1.0), JointProp::TwistLimit(1.5)],
            ),
        ];
        for (kind, limits) in cases {
            let mut props = limits.clone();
            if matches!(kind, JointKind::Prismatic | JointKind::Hinge) {
                props.extend(motor);
            }
            for tiny in [1e-45f32, 1e-38, 1e-30, 1e-20, 1e-12, 1e-9] {
                let mut p = plane();
                let a = ball(&mut p, [0.0, 0.0, 0.0], 1.0);
                let b = ball(&mut p, [1.0, 0.0, 0.0], 1.0);
                let c = ball(&mut p, [2.0, 0.5, 0.0], 1.0);
                for (x, y) in [(a, b), (b, c)] {
                    joint(
                        &mut p,
                        JointOp::Create {
                            kind,
                            a: x,
                            b: Some(y),
                            props: props.clone(),
                        },
                    );
                }
                let steps = [
                    1.0 / 60.0,
                    tiny,
                    tiny,
                    1.0 / 60.0,
                    tiny,
                    1.0 / 60.0,
                    1.0 / 60.0,
                ];
                for dt in steps {
                    let done =
                        std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| p.step(dt)));
                    assert!(
                        matches!(done, Ok(Ok(true))),
                        "{kind:?}: a step of {dt:e} s (tiny {tiny:e}) panicked or failed"
                    );
                }
                assert_eq!(p.tick(), steps.len() as u64);
                for h in [a, b, c] {
                    let body = &p.world.bodies[p.bodies.get(h).unwrap().handle];
                    assert!(
                        body.translation().is_finite() && body.linvel().is_finite(),
                        "{kind:?}, tiny {tiny:e}: {:?} {:?}",
                        body.translation(),
                        body.linvel()
                    );
                }
            }
        }
    }

    /// Random articulations (every articulable kind, with its limits and motors) on parts
    /// of very different weights, pushed by forces and impulses up to the largest floats,
    /// stepped with steps from 1e-45 s to 0.7 s (what the fuzzer found: a force so large on
    /// a light link that the velocity it asked for overflowed f32; the link's joint
    /// coordinates went NaN within the step and the solver panicked on its motor bounds).
    /// No step may panic.
    #[test]
    fn random_articulations_under_extreme_pushes_never_panic() {
        use shm_layout::{JointKind, ObjectOp};
        let mut rnd = xorshift(0x2545_f491_4f6c_dd1d);
        let huge = [1.0, 50.0, 1e20, f32::MAX];
        for round in 0..150 {
            let mut p = plane();
            let mut objs = Vec::new();
            let mut log = Vec::new();
            for _ in 0..40 {
                let pick = |rnd: &mut dyn FnMut(u64) -> u64| objs[rnd(objs.len() as u64) as usize];
                let op = match rnd(8) {
                    0 | 1 => PlaneOp::AddObject {
                        shape: Shape::Sphere { radius: 0.25 },
                        pose: Pose::at([rnd(4) as f32, rnd(3) as f32 * 0.4, 0.0]),
                        props: vec![ObjectProp::Weight([0.005, 1.0, 100.0][rnd(3) as usize])],
                    },
                    2 | 3 if objs.len() >= 2 => {
                        let (a, b) = (pick(&mut rnd), pick(&mut rnd));
                        let (kind, props) = match rnd(4) {
                            0 => (
                                JointKind::Hinge,
                                vec![
                                    JointProp::LowerAngle(-0.5),
                                    JointProp::UpperAngle(0.5),
                                    JointProp::MotorTarget(1.5),
                                    JointProp::MotorMaxForce(huge[rnd(4) as usize]),
                                ],
                            ),
                            1 => (
                                JointKind::Prismatic,
                                vec![
                                    JointProp::LowerDistance(0.5),
                                    JointProp::UpperDistance(3.0),
                                    JointProp::MotorTarget(1.5),
                                    JointProp::MotorMaxForce(huge[rnd(4) as usize]),
                                ],
                            ),
                            2 => (JointKind::Ball, vec![JointProp::SwingLimit(1.0)]),
                            _ => (
                                JointKind::ConeTwist,
                                vec![JointProp::SwingLimit(1.0), JointProp::TwistLimit(1.5)],
                            ),
                        };
                        PlaneOp::Joint(JointOp::Create {
                            kind,
                            a,
                            b: Some(b),
                            props,
                        })
                    }
                    4 if !objs.is_empty() => {
                        let f = huge[rnd(4) as usize] * [-1.0, 1.0][rnd(2) as usize];
                        PlaneOp::Object {
                            handle: pick(&mut rnd),
                            op: ObjectOp::Set(ObjectProp::ConstantForce([f, 26.4, -f])),
                        }
                    }
                    5 if !objs.is_empty() => {
                        let j = huge[rnd(4) as usize];
                        PlaneOp::Object {
                            handle: pick(&mut rnd),
                            op: ObjectOp::ApplyImpulse([j, -2.9, -13.1]),
                        }
                    }
                    _ => PlaneOp::Step {
                        dt: [1.0 / 60.0, 1e-45, 0.1, 0.7][rnd(4) as usize],
                    },
                };
                log.push(format!("{op:?}"));
                let outcome = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                    if let PlaneOp::Step { dt } = op {
                        p.step(dt).map(|_| Reply::Applied { tick: 0 })
                    } else {
                        p.apply(op)
                    }
                }));
                match outcome {
                    Ok(Ok(Reply::Object { handle, .. })) => objs.push(handle),
                    Ok(_) => {}
                    Err(_) => panic!("round {round} panicked after:\n{}", log.join("\n")),
                }
            }
            // What such pushes leave is not physics any more (a body they make non-finite
            // is quarantined by rapier at its next step); what must hold is that the plane
            // goes on stepping.
            let next =
                std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| p.step(1.0 / 60.0)));
            assert!(
                matches!(next, Ok(Ok(_))),
                "round {round}: the plane does not step on after:\n{}",
                log.join("\n")
            );
        }
    }

    /// Random sequences of joint, anchoring, waking, teleporting, forcing, destroying and
    /// stepping ops on a few objects: no step may panic (rapier's solver must never receive a joint
    /// whose two bodies are both world-attached).
    #[test]
    fn random_joint_sequences_never_panic_the_solver() {
        use shm_layout::{JointKind, ObjectOp};
        let mut rnd = xorshift(0x9e37_79b9_7f4a_7c15);
        let kinds = [
            JointKind::Ball,
            JointKind::Hinge,
            JointKind::ConeTwist,
            JointKind::SixDof,
            JointKind::Fixed,
            JointKind::Prismatic,
            JointKind::Rope,
            JointKind::Spring,
        ];
        for round in 0..300 {
            let mut p = plane();
            let mut objs = Vec::new();
            let mut joints = Vec::new();
            let mut log = Vec::new();
            for _ in 0..60 {
                let op = match rnd(11) {
                    0 => {
                        let props = if rnd(3) == 0 {
                            vec![ObjectProp::Anchored(true)]
                        } else {
                            vec![]
                        };
                        PlaneOp::AddObject {
                            shape: Shape::Sphere { radius: 0.25 },
                            pose: Pose::at([rnd(4) as f32, rnd(3) as f32 * 0.4, 0.0]),
                            props,
                        }
                    }
                    1 | 2 if !objs.is_empty() => {
                        let a = objs[rnd(objs.len() as u64) as usize];
                        let b = (rnd(3) != 0).then(|| objs[rnd(objs.len() as u64) as usize]);
                        let mut props = vec![];
                        if rnd(3) == 0 {
                            props.push(JointProp::BreakForce(rnd(100) as f32));
                        }
                        PlaneOp::Joint(JointOp::Create {
                            kind: kinds[rnd(8) as usize],
                            a,
                            b,
                            props,
                        })
                    }
                    3 if !objs.is_empty() => PlaneOp::Object {
                        handle: objs[rnd(objs.len() as u64) as usize],
                        op: ObjectOp::Set(ObjectProp::Anchored(rnd(2) == 0)),
                    },
                    4 if !objs.is_empty() => PlaneOp::Object {
                        handle: objs[rnd(objs.len() as u64) as usize],
                        op: if rnd(2) == 0 {
                            ObjectOp::Wake
                        } else {
                            ObjectOp::Set(ObjectProp::Pose(Pose::at([0.0, 5.0, 0.0])))
                        },
                    },
                    5 if !objs.is_empty() && rnd(3) == 0 => PlaneOp::Object {
                        handle: objs[rnd(objs.len() as u64) as usize],
                        op: ObjectOp::Destroy,
                    },
                    6 if !joints.is_empty() => {
                        let joint = joints[rnd(joints.len() as u64) as usize];
                        if rnd(3) == 0 {
                            PlaneOp::Joint(JointOp::Destroy { joint })
                        } else {
                            PlaneOp::Joint(JointOp::Set {
                                joint,
                                prop: JointProp::CollideConnected(rnd(2) == 0),
                            })
                        }
                    }
                    8 if !objs.is_empty() && rnd(4) == 0 => {
                        // What rapier's quarantine does to a body gone non-finite.
                        let h = objs[rnd(objs.len() as u64) as usize];
                        if let Ok(b) = p.bodies.get(h) {
                            let on = rnd(3) == 0;
                            p.world.bodies[b.handle].set_enabled(on);
                        }
                        PlaneOp::Info
                    }
                    7 if !objs.is_empty() => PlaneOp::Object {
                        handle: objs[rnd(objs.len() as u64) as usize],
                        op: ObjectOp::Set(ObjectProp::ConstantForce([0.0, 1.0, 0.0])),
                    },
                    // 1e-45 s overflows the force drive of forced bodies: rapier quarantines
                    // (disables) them.
                    _ => PlaneOp::Step {
                        dt: [1.0 / 60.0, 1e-5, 0.1, 1e-45][rnd(4) as usize],
                    },
                };
                log.push(format!("{op:?}"));
                let outcome = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                    if let PlaneOp::Step { dt } = op {
                        // Long idle stretches let bodies fall asleep.
                        for _ in 0..[1, 1, 90][rnd(3) as usize] {
                            p.step(dt).map(|_| Reply::Applied { tick: 0 })?;
                        }
                        Ok(Reply::Applied { tick: 0 })
                    } else {
                        p.apply(op)
                    }
                }));
                match outcome {
                    Ok(Ok(Reply::Object { handle, .. })) => objs.push(handle),
                    Ok(Ok(Reply::Joint { handle, .. })) => joints.push(handle),
                    Ok(_) => {}
                    Err(_) => panic!("round {round} panicked after:\n{}", log.join("\n")),
                }
            }
        }
    }
}

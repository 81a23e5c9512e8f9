//! The joints' side of a step: before it, rebuilding what changed (rapier joints of
//! changed ends, the articulated trees); after it, the error figures, the constraint forces
//! and breaking (`EVENT_JOINT_BROKE`).

use rapier3d::prelude::*;
use shm_layout::joint_op::{AxisMode, JointKind};
use shm_layout::{EventRecord, Handle, EVENT_JOINT_BROKE};

use crate::rapier3d::joints::articulations;
use crate::rapier3d::joints::build::{axis_angle, build, overshoot, vec, LIN};
use crate::rapier3d::joints::table::{EndState, Joint};
use crate::rapier3d::plane::Plane;

impl Plane {
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
    pub(in crate::rapier3d) fn joints_before_step(&mut self) {
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
    pub(in crate::rapier3d::joints) fn build_planned_tree(&mut self, p: articulations::TreePlan) {
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
    pub(in crate::rapier3d::joints) fn update_articulated(&mut self, i: usize) {
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
            articulations::multibody::undamp_springs(mb);
        }
        if let Some(l) = limit {
            if let Some(ij) = self.world.impulse_joints.get_mut(l, true) {
                ij.data = articulations::limit_data(data);
            }
        }
    }

    /// After a step: every joint's error and force, breaking the overloaded ones (one
    /// event each). Runs only when the plane has joints.
    pub(in crate::rapier3d) fn joints_after_step(&mut self, dt: f32) {
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
                self.events.record(EventRecord {
                    kind: EVENT_JOINT_BROKE,
                    a_slot: h.slot,
                    a_generation: h.generation,
                    b_slot: a.slot,
                    b_generation: a.generation,
                    impulse: force,
                    position: anchor.into(),
                    tick: self.clock.tick,
                    ..EventRecord::default()
                });
            }
            let j = self.joints.table.get(h).expect("live handle");
            if !j.broken {
                self.joints.max_error = self.joints.max_error.max(j.error);
            }
        }
    }

    /// Recomputes one joint's error figures and position from the bodies' poses.
    pub(in crate::rapier3d::joints) fn measure_joint(&mut self, h: Handle) {
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

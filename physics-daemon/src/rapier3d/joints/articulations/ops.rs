//! The articulations' side of the plane: building and tearing down the trees, taking in
//! writes to links before a step, and after it holding the joints through CCD hits and the
//! speed caps.

use rapier3d::prelude::*;

use crate::rapier3d::joints::articulations::multibody::*;
use crate::rapier3d::joints::articulations::{Tree, LIMIT_SLOP};
use crate::rapier3d::plane::Plane;

impl Plane {
    /// Removes every articulation (multibody joints and private roots); the joints that
    /// were articulated are rebuilt as the next step decides.
    pub(in crate::rapier3d) fn tear_down_articulations(&mut self) {
        let trees = std::mem::take(&mut self.joints.articulations.trees);
        for t in &trees {
            self.world
                .multibody_joints
                .remove_multibody_articulations(t.root, true);
            if t.fixed_end.is_some() {
                self.world.remove_body(t.root);
            }
        }
        self.joints.articulations.dirty = true;
        self.forget_articulated();
    }

    /// Builds one tree: `root` is the dynamic body at its root, or `fixed_end` (the tree's
    /// fixed end) gets a private root; `edges` are (joint slot, parent body, child body,
    /// flip) in parent-before-child order. Returns each joint's multibody handle.
    pub(in crate::rapier3d) fn build_tree(
        &mut self,
        root: RigidBodyHandle,
        fixed_end: Option<RigidBodyHandle>,
        edges: &[(GenericJoint, RigidBodyHandle, RigidBodyHandle)],
        bodies: &[RigidBodyHandle],
    ) -> Vec<Option<MultibodyJointHandle>> {
        let root = match fixed_end {
            Some(f) => {
                let pose = *self.world.bodies[f].position();
                self.world.insert_body(
                    RigidBodyBuilder::fixed()
                        .pose(pose)
                        .user_data(u128::MAX)
                        .build(),
                )
            }
            None => root,
        };
        let handles: Vec<_> = edges
            .iter()
            .map(|(data, parent, child)| {
                let parent = if Some(*parent) == fixed_end {
                    root
                } else {
                    *parent
                };
                self.world
                    .multibody_joints
                    .insert(parent, *child, *data, true)
            })
            .collect();
        if let Some(link) = self.world.multibody_joints.rigid_body_link(root).copied() {
            if let Some(mb) = self
                .world
                .multibody_joints
                .get_multibody_mut(link.multibody)
            {
                let heaviest = bodies
                    .iter()
                    .filter_map(|b| self.world.bodies.get(*b))
                    .map(|b| b.mass())
                    .fold(0.0f32, f32::max);
                mb.armature_mut().fill(ARMATURE_PER_MASS * heaviest);
                undamp_springs(mb);
                coordinates_from_bodies(mb, &self.world.bodies);
                // Velocities from the bodies' (zero at first).
                let dv: Vec<(Vector, Vector)> = mb
                    .links()
                    .map(|l| {
                        let rb = &self.world.bodies[l.rigid_body_handle()];
                        (rb.linvel(), rb.angvel())
                    })
                    .collect();
                take_velocity_changes(mb, &self.world.bodies, &dv);
                mb.update_rigid_bodies(&mut self.world.bodies, true);
            }
        }
        let links = bodies
            .iter()
            .map(|b| {
                let rb = &self.world.bodies[*b];
                (*b, *rb.position(), rb.linvel(), rb.angvel())
            })
            .collect();
        self.joints.articulations.trees.push(Tree {
            root,
            fixed_end,
            links,
        });
        handles
    }

    /// Before a step: every joint coordinate's armature for this step's substeps (see
    /// [`set_armature`]).
    fn size_armatures(&mut self) {
        let loads = self.articulated_loads();
        let p = &self.world.integration_parameters;
        let dt_sub = p.dt / p.num_solver_iterations.max(1) as f32;
        let g = self.world.gravity.length();
        for t in &self.joints.articulations.trees {
            let heaviest = t
                .links
                .iter()
                .filter_map(|(b, ..)| self.world.bodies.get(*b))
                .map(|b| b.mass())
                .fold(0.0f32, f32::max);
            let Some(link) = self.world.multibody_joints.rigid_body_link(t.root).copied() else {
                continue;
            };
            if let Some(mb) = self
                .world
                .multibody_joints
                .get_multibody_mut(link.multibody)
            {
                set_armature(mb, &self.world.bodies, heaviest, g, dt_sub, &loads);
            }
        }
    }

    /// Before a step: writes to articulated bodies since the last step (poses, velocities)
    /// are taken into their articulations, and private roots follow their fixed ends.
    pub(in crate::rapier3d) fn articulations_before_step(&mut self) {
        if !self.joints.articulations.trees.is_empty() {
            self.size_armatures();
        }
        for t in &self.joints.articulations.trees {
            if let Some(f) = t.fixed_end {
                if let Some(pose) = self.world.bodies.get(f).map(|b| *b.position()) {
                    if let Some(root) = self.world.bodies.get_mut(t.root) {
                        if *root.position() != pose {
                            root.set_position(pose, true);
                        }
                    }
                }
            }
            let bodies = &self.world.bodies;
            let moved = t
                .links
                .iter()
                .any(|(h, pose, ..)| bodies.get(*h).is_some_and(|b| b.position() != pose));
            let pushed = t.links.iter().any(|(h, _, v, w)| {
                bodies
                    .get(*h)
                    .is_some_and(|b| b.linvel() != *v || b.angvel() != *w)
            });
            if !moved && !pushed {
                continue;
            }

            let Some(link) = self.world.multibody_joints.rigid_body_link(t.root).copied() else {
                continue;
            };
            let Some(mb) = self
                .world
                .multibody_joints
                .get_multibody_mut(link.multibody)
            else {
                continue;
            };
            if moved {
                coordinates_from_bodies(mb, &self.world.bodies);
            }
            if pushed {
                let seen: std::collections::HashMap<_, _> =
                    t.links.iter().map(|(h, _, v, w)| (*h, (*v, *w))).collect();
                let dv: Vec<(Vector, Vector)> = mb
                    .links()
                    .map(|l| {
                        let rb = &self.world.bodies[l.rigid_body_handle()];
                        match seen.get(&l.rigid_body_handle()) {
                            Some((v, w)) => (rb.linvel() - *v, rb.angvel() - *w),
                            None => (Vector::ZERO, Vector::ZERO),
                        }
                    })
                    .collect();
                mb.forward_kinematics(&self.world.bodies, true);
                take_velocity_changes(mb, &self.world.bodies, &dv);
                clamp_joint_speeds(mb);
            }
            mb.update_rigid_bodies(&mut self.world.bodies, true);
            for (h, ..) in &t.links {
                if let Some(b) = self.world.bodies.get_mut(*h) {
                    b.wake_up(true);
                }
            }
        }
        // The step starts from here: what it changes is what the joints did (see
        // `articulated_forces`).
        self.articulations_after_step();
    }

    /// The force each articulated joint carried over the last step, keyed by the joint's
    /// child body: the momentum change of the subtree it holds, less gravity's share,
    /// `|Σ mᵢ (Δvᵢ / dt − sᵢ g)|` over that subtree (contacts and forces on the subtree
    /// count in; for a hanging chain it is the weight below the joint).
    pub(in crate::rapier3d) fn articulated_forces(
        &self,
        dt: f32,
    ) -> std::collections::HashMap<RigidBodyHandle, f32> {
        let mut out = std::collections::HashMap::new();
        let g = self.world.gravity;
        for t in &self.joints.articulations.trees {
            let Some(link) = self.world.multibody_joints.rigid_body_link(t.root) else {
                continue;
            };
            let Some(mb) = self.world.multibody_joints.get_multibody(link.multibody) else {
                continue;
            };
            let before: std::collections::HashMap<_, _> =
                t.links.iter().map(|(h, _, v, _)| (*h, *v)).collect();
            let n = mb.num_links();
            let mut net = vec![Vector::ZERO; n];
            for (i, l) in mb.links().enumerate() {
                let h = l.rigid_body_handle();
                let (Some(rb), Some(v0)) = (self.world.bodies.get(h), before.get(&h)) else {
                    continue;
                };
                if rb.is_dynamic() {
                    net[i] = rb.mass() * ((rb.linvel() - *v0) / dt - g * rb.gravity_scale());
                }
            }
            // Links come parents first: children's sums go up in reverse order.
            for i in (0..n).rev() {
                let Some(l) = mb.link(i) else { continue };
                if let Some(p) = l.parent_id() {
                    let f = net[i];
                    net[p] += f;
                    out.insert(l.rigid_body_handle(), f.length());
                }
            }
        }
        out
    }
}

impl Plane {
    /// After a step: a link the step moved off its joints (rapier's CCD puts a fast body back
    /// at its time of impact, a link included) has its articulation's coordinates reset from
    /// the bodies' poses, so the joints hold through the hit instead of for a tick apart; such
    /// a link, or one the plane's speed caps slowed, also hands its velocity back to the
    /// articulation (a 1,000 u/s hit otherwise left the joints moving as the bodies no longer
    /// did, and the next steps diverged).
    pub(in crate::rapier3d) fn articulations_after_ccd(&mut self) {
        for t in &self.joints.articulations.trees {
            let Some(link) = self.world.multibody_joints.rigid_body_link(t.root).copied() else {
                continue;
            };
            let Some(mb) = self
                .world
                .multibody_joints
                .get_multibody_mut(link.multibody)
            else {
                continue;
            };
            let bodies = &self.world.bodies;
            let off = mb.links().any(|l| {
                bodies
                    .get(l.rigid_body_handle())
                    .is_some_and(|b| b.position() != l.local_to_world())
            });
            // The plane's speed caps act on the bodies after rapier moved them.
            let (w_cap, v_cap) = (
                self.settings.max_angular_speed * 0.9999,
                self.settings.max_linear_speed * 0.9999,
            );
            let capped = mb.links().any(|l| {
                bodies
                    .get(l.rigid_body_handle())
                    .is_some_and(|b| b.angvel().length() >= w_cap || b.linvel().length() >= v_cap)
            });
            if off {
                coordinates_from_bodies(mb, bodies);
            }
            if off || capped {
                velocities_from_bodies(mb, bodies);
                mb.update_rigid_bodies(&mut self.world.bodies, true);
            }
        }
        self.articulations_clamp_speeds();
        self.ball_limit_stops();
    }

    /// After a step: every joint's angular speed is held to [`MAX_JOINT_SPEED`] before the
    /// next step integrates it.
    fn articulations_clamp_speeds(&mut self) {
        for t in &self.joints.articulations.trees {
            let Some(link) = self.world.multibody_joints.rigid_body_link(t.root).copied() else {
                continue;
            };
            if let Some(mb) = self
                .world
                .multibody_joints
                .get_multibody_mut(link.multibody)
            {
                clamp_joint_speeds(mb);
            }
        }
    }

    /// After a step: a limited ball joint the step left past its swing or twist limit is put
    /// back on the limit (each angle as `measure_joint` reads it clamped, its children
    /// following) and its relative spin stopped: an inelastic limit stop, on top of the
    /// companion impulse joint that pushes back during the step.
    fn ball_limit_stops(&mut self) {
        let limited = self.limited_ball_links();
        let mut touched = Vec::new();
        for (link, twist, swing) in limited {
            let Some((mb, id)) = self.world.multibody_joints.get_mut(link) else {
                continue;
            };
            let Some(l) = mb.link(id) else { continue };
            let q = l.joint().joint_rot();
            let q = if q.w < 0.0 { -q } else { q };
            let a = [
                2.0 * q.x.atan2(q.w),
                2.0 * q.y.atan2(q.w),
                2.0 * q.z.atan2(q.w),
            ];
            let lim = [twist, swing, swing];
            // Small overshoots are the companion joint's to correct (a limb resting at its
            // limit against the floor would otherwise be put back every tick, and jitter).
            if (0..3).all(|i| a[i].abs() <= lim[i] + LIMIT_SLOP) {
                continue;
            }
            // Each angle clamped: q' = normalize(1, tan(aᵢ/2)) has 2·atan2(q'ᵢ, w') = aᵢ.
            let t: Vec<f32> = (0..3)
                .map(|i| (a[i].clamp(-lim[i], lim[i]) * 0.5).tan())
                .collect();
            let target = Rotation::from_xyzw(t[0], t[1], t[2], 1.0).normalize();
            let d = (target * q.inverse()).to_scaled_axis();
            let at = l.assembly_id();
            let mut disp = vec![0.0f32; mb.ndofs()];
            disp[at..at + 3].copy_from_slice(&[d.x, d.y, d.z]);
            mb.apply_displacements(&disp);
            stop_joint(mb, &self.world.bodies, at);
            touched.push(link);
        }
        for link in touched {
            if let Some((mb, _)) = self.world.multibody_joints.get_mut(link) {
                mb.forward_kinematics(&self.world.bodies, true);
                mb.update_rigid_bodies(&mut self.world.bodies, true);
            }
        }
    }

    /// After a step: what the step left in the articulated bodies (see `Tree::links`).
    pub(in crate::rapier3d) fn articulations_after_step(&mut self) {
        let bodies = &self.world.bodies;
        for t in self.joints.articulations.trees.iter_mut() {
            for (h, pose, v, w) in t.links.iter_mut() {
                if let Some(b) = bodies.get(*h) {
                    (*pose, *v, *w) = (*b.position(), b.linvel(), b.angvel());
                }
            }
        }
    }
}

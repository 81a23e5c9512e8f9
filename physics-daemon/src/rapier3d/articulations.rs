//! Articulations: joints that form a tree are simulated as one reduced-coordinate
//! articulation (rapier's `MultibodyJointSet`, like PhysX articulations), whose links cannot
//! drift apart whatever their mass ratio; the other joints stay rapier impulse joints.
//!
//! Which joints are articulated is decided again whenever the structure changes (a joint
//! made or destroyed, `BreakForce` set, an end anchored, released or quarantined): a joint
//! is articulated when it is a `Ball`, `ConeTwist`, `Hinge`, `Prismatic` or `Fixed` joint,
//! unbreakable (`BreakForce` 0), between two dynamic objects or a dynamic object and a
//! fixed end (the world or an anchored object), and its connected group of joints over
//! dynamic objects has no loop and at most one fixed end. A tree with a fixed end is rooted
//! at a private fixed body (no collider) that follows the fixed end's pose, so that any
//! number of trees can hang from one anchored part without merging. Loops, breakable joints,
//! `SixDof`, `Rope` and `Spring` joints stay impulse joints.
//!
//! Rapier has no angular limits for the three rotations of a ball joint (its coordinates
//! there are integrated angular velocities), so a `Ball` / `ConeTwist` with `SwingLimit` or
//! `TwistLimit` keeps a companion impulse joint that only enforces those limits from the
//! bodies' actual relative rotation.
//!
//! An articulation's state is its joint coordinates and velocities; the bodies' poses and
//! velocities are derived from them. Writes to a link (CFrame, Velocity, impulses, speed
//! caps) are taken in before each step: a moved link resets its joint coordinates from the
//! bodies' poses, and a velocity change is applied as the generalized impulse
//! `Δq̇ = M⁻¹ Σ Jᵢᵀ Mᵢ Δvᵢ` (momentum-consistent; `M` the articulation's mass matrix, `Jᵢ`
//! the link's Jacobian).

use rapier3d::na::{DMatrix, DVector, Matrix3};
use rapier3d::prelude::*;
use rapier3d::utils::AngularInertiaOps;
use shm_layout::joint_op::{JointKind, JointSettings};

use super::Plane;

/// Rotor inertia (rapier's per-coordinate "armature") of every joint coordinate, per unit
/// of the tree's heaviest link mass (units²): the least each coordinate gets (see
/// [`set_armature`] for what a loaded joint gets on top). Without it rapier's articulation
/// integration lets light links whipping under a heavy one gain energy: the 1,000:1 chain
/// of point-like links diverged after 2.9 s at 60 Hz (armature 0.01 still did, 0.1 held
/// for 15 s). It lengthens a unit-mass pendulum of length 2 by 0.001 %.
const ARMATURE_PER_MASS: f32 = 1.0e-4;

/// Rapier damps every free rotation of an articulation by 0.1 N·m·s/rad (its
/// `default_damping`): an undamped hinge spring of k = 50 on a 2 kg ball lost all its
/// energy in 10 s. The coordinates of joints with a spring (a force-based motor with a
/// stiffness) lose that damping; a spring's damping is its `Damping`.
pub(super) fn undamp_springs(mb: &mut Multibody) {
    let spans: Vec<(usize, usize)> = mb
        .links()
        .filter(|l| {
            l.joint()
                .data
                .motors
                .iter()
                .any(|m| m.model == MotorModel::ForceBased && m.stiffness > 0.0)
        })
        .map(|l| (l.assembly_id(), l.joint().ndofs()))
        .collect();
    let damping = mb.damping_mut();
    for (at, n) in spans {
        damping.iter_mut().skip(at).take(n).for_each(|d| *d = 0.0);
    }
}

/// Sets each joint coordinate's armature for a step of substeps `dt_sub` under gravity `g`.
///
/// Rapier integrates an articulation semi-implicitly (symplectic Euler per substep): the
/// inertia is implicit, but the forces the links pass along are explicit in the joint
/// coordinates. A link pulled by a tension `T` at a lever `ℓ` from its joint is a spring of
/// stiffness `T·ℓ` on its joint's rotation, stable only while `ω·dt_sub < 2`, `ω² = T·ℓ / I`
/// (`I` the rotation's inertia). A light link holding a heavy one breaks that: the
/// 20-link chain with a 1,000× end released from horizontal at 60 Hz carries
/// `T ≈ 3·m·g ≈ 1.5·10⁵` on links of `I ≈ 0.4`, `ω·dt_sub ≈ 2.5`; its energy grew
/// 10⁸-fold within a second after the first swing and its positions went NaN. Each
/// coordinate gets the armature that makes `ω·dt_sub ≤ √2` (a factor 2 on `ω²` below the
/// limit): `a = ½·T·ℓ·dt_sub² − I`, with `T` the larger of `3·g·M` (`M` the mass the joint
/// holds: the tension of a pendulum swinging from horizontal) and the force it carried
/// the step before (`loads`, keyed by the child body), `ℓ` the child link's farthest load
/// point (its centre of mass, its children's joints) from the joint, `I` the child's own
/// inertia about the joint (its least principal one plus `m·r²`), and at least
/// `ARMATURE_PER_MASS · heaviest`. Unloaded and evenly loaded chains get (almost) only
/// that least armature; what the step pays is one pass over the links.
fn set_armature(
    mb: &mut Multibody,
    bodies: &RigidBodySet,
    heaviest: f32,
    g: f32,
    dt_sub: f32,
    loads: &std::collections::HashMap<RigidBodyHandle, f32>,
) {
    let n = mb.num_links();
    let mut held = vec![0.0f32; n];
    let mut lever = vec![0.0f32; n];
    let mut own = vec![0.0f32; n];
    let anchor = |l: &MultibodyLink| l.joint().data.local_frame2.translation;
    for (i, l) in mb.links().enumerate() {
        let Some(rb) = bodies.get(l.rigid_body_handle()).filter(|b| b.is_dynamic()) else {
            continue;
        };
        let mp = rb.mass_properties().local_mprops;
        let r = (mp.local_com - anchor(l)).length();
        held[i] = rb.mass();
        lever[i] = r;
        own[i] = mp.principal_inertia().min_element() + rb.mass() * r * r;
    }
    // Children after their parents: the mass each joint holds, and each link's lever to its
    // children's joints.
    let links: Vec<(Option<usize>, Vector)> = mb
        .links()
        .map(|l| (l.parent_id(), l.joint().data.local_frame1.translation))
        .collect();
    for i in (0..n).rev() {
        if let Some(p) = links[i].0 {
            held[p] += held[i];
            let parent_anchor = mb.link(p).map(anchor).unwrap_or(Vector::ZERO);
            lever[p] = lever[p].max((links[i].1 - parent_anchor).length());
        }
    }
    let least = ARMATURE_PER_MASS * heaviest;
    let spans: Vec<(usize, usize, f32)> = mb
        .links()
        .enumerate()
        .filter(|(_, l)| !l.is_root())
        .map(|(i, l)| {
            let tension =
                (3.0 * g * held[i]).max(loads.get(&l.rigid_body_handle()).copied().unwrap_or(0.0));
            let need = 0.5 * tension * lever[i] * dt_sub * dt_sub - own[i];
            let a = if need.is_finite() {
                need.max(least)
            } else {
                least
            };
            (l.assembly_id(), l.joint().ndofs(), a)
        })
        .collect();
    let armature = mb.armature_mut();
    for (at, n, a) in spans {
        armature.iter_mut().skip(at).take(n).for_each(|x| *x = a);
    }
}

/// The fastest a joint of an articulation turns (rad/s, relative to its parent), as PhysX's
/// articulations' default `maxJointVelocity` (100): rapier integrates a joint's rotation
/// explicitly, and a 1,000 u/s hit that spun a ragdoll's limbs at ~800 rad/s (13 rad a
/// tick) made the next steps diverge to 10⁸ u/s and NaN.
pub(super) const MAX_JOINT_SPEED: f32 = 100.0;

/// Scales down each joint's angular velocity that exceeds [`MAX_JOINT_SPEED`], the free
/// root's spin included.
fn clamp_joint_speeds(mb: &mut Multibody) {
    let blocks: Vec<(usize, usize)> = mb
        .links()
        .map(|l| {
            let locked = l.joint().data.locked_axes.bits();
            let lin = (0..3).filter(|i| locked & (1 << i) == 0).count();
            let ang = (3..6).filter(|i| locked & (1 << i) == 0).count();
            (l.assembly_id() + lin, ang)
        })
        .collect();
    let mut v = mb.generalized_velocity_mut();
    for (at, n) in blocks {
        let norm = (at..at + n).map(|k| v[k] * v[k]).sum::<f32>().sqrt();
        if norm > MAX_JOINT_SPEED {
            let k = MAX_JOINT_SPEED / norm;
            for i in at..at + n {
                v[i] *= k;
            }
        }
    }
}

/// Makes `mb`'s joint velocities match its bodies' velocities (in the momentum sense, see
/// `take_velocity_changes`), its Jacobians taken at the bodies' current poses.
fn velocities_from_bodies(mb: &mut Multibody, bodies: &RigidBodySet) {
    mb.forward_kinematics(bodies, true);
    let qd = mb.generalized_velocity().clone_owned();
    let dv: Vec<(Vector, Vector)> = mb
        .links()
        .enumerate()
        .map(|(i, l)| {
            let Some(rb) = bodies.get(l.rigid_body_handle()).filter(|b| b.is_dynamic()) else {
                return (Vector::ZERO, Vector::ZERO);
            };
            let v = mb.body_jacobian(i) * &qd;
            (
                rb.linvel() - Vector::new(v[0], v[1], v[2]),
                rb.angvel() - Vector::new(v[3], v[4], v[5]),
            )
        })
        .collect();
    take_velocity_changes(mb, bodies, &dv);
}

/// Overshoot of a ball joint's limit (rad) left to its companion impulse joint before the
/// inelastic stop puts the joint back on its limit.
const LIMIT_SLOP: f32 = 0.05;

/// One articulated tree.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
struct Tree {
    /// The body at the root of the rapier multibody (a private fixed root, or a dynamic one).
    root: RigidBodyHandle,
    /// The fixed end the private root follows (None: the root is a dynamic body of the tree).
    fixed_end: Option<RigidBodyHandle>,
    /// Every dynamic body of the tree with its pose and velocities as the last step (or the
    /// build) left them: a difference before the next step is a write to take in.
    links: Vec<(RigidBodyHandle, Pose, Vector, Vector)>,
}

/// The plane's articulated trees.
#[derive(Debug, Clone, Default, serde::Serialize, serde::Deserialize)]
pub(super) struct Articulations {
    /// The structure changed: the trees are rebuilt before the next step.
    pub dirty: bool,
    trees: Vec<Tree>,
}

/// Whether a joint of `kind` with `s` can be articulated (given suitable ends).
pub(super) fn articulable(kind: JointKind, s: &JointSettings) -> bool {
    s.break_force == 0.0
        && matches!(
            kind,
            JointKind::Ball
                | JointKind::ConeTwist
                | JointKind::Hinge
                | JointKind::Prismatic
                | JointKind::Fixed
        )
}

/// Whether a joint of `kind` with `s` needs a companion impulse joint for its limits.
pub(super) fn needs_limit_joint(kind: JointKind, s: &JointSettings) -> bool {
    matches!(kind, JointKind::Ball | JointKind::ConeTwist)
        && (s.twist_limit.is_some() || s.swing_limit.is_some())
}

/// The multibody form of `j`: three-rotation joints lose their angular limits (the
/// companion holds them); `flip` swaps its bodies (parent = body 1 in rapier), which
/// negates the coordinate of its one free axis (hinge angle, slide), its limits and motor.
pub(super) fn multibody_data(
    mut j: GenericJoint,
    three_rotations: bool,
    flip: bool,
) -> GenericJoint {
    if three_rotations {
        j.limit_axes = JointAxesMask::empty();
    }
    if flip {
        std::mem::swap(&mut j.local_frame1, &mut j.local_frame2);
        for l in j.limits.iter_mut() {
            (l.min, l.max) = (-l.max, -l.min);
        }
        for m in j.motors.iter_mut() {
            m.target_pos = -m.target_pos;
            m.target_vel = -m.target_vel;
        }
    }
    j
}

/// The companion of a limited ball joint: the same joint with no locked axis.
pub(super) fn limit_data(mut j: GenericJoint) -> GenericJoint {
    j.locked_axes = JointAxesMask::empty();
    j
}

/// Signed angle of `q` about its frame axis `i`, in (-π, π].
fn axis_angle(q: Rotation, i: usize) -> f32 {
    let q = if q.w < 0.0 { -q } else { q };
    2.0 * [q.x, q.y, q.z][i].atan2(q.w)
}

/// Sets the joint coordinates of every link of `mb` so that the links sit where their
/// bodies are now (locked axes snap), then runs its forward kinematics.
fn coordinates_from_bodies(mb: &mut Multibody, bodies: &RigidBodySet) {
    let mut disp = vec![0.0f32; mb.ndofs()];
    for link in mb.links() {
        let Some(parent) = link.parent_id() else {
            continue;
        };
        let parent_rb = mb.link(parent).expect("parent link").rigid_body_handle();
        let joint = link.joint();
        let data = &joint.data;
        let f1 = *bodies[parent_rb].position() * data.local_frame1;
        let f2 = *bodies[link.rigid_body_handle()].position() * data.local_frame2;
        let rel = f1.inverse() * f2;
        let coords = joint.coords();
        let locked = data.locked_axes.bits();
        let mut k = link.assembly_id();
        for (i, c) in coords.iter().take(3).enumerate() {
            if locked & (1 << i) == 0 {
                disp[k] = rel.translation[i] - c;
                k += 1;
            }
        }
        let free_ang: Vec<usize> = (0..3).filter(|i| locked & (1 << (3 + i)) == 0).collect();
        match free_ang.len() {
            1 => {
                let i = free_ang[0];
                disp[k] = axis_angle(rel.rotation, i) - coords[3 + i];
            }
            3 => {
                let d = (rel.rotation * joint.joint_rot().inverse()).to_scaled_axis();
                disp[k..k + 3].copy_from_slice(&[d.x, d.y, d.z]);
            }
            _ => {}
        }
    }
    mb.apply_displacements(&disp);
    mb.forward_kinematics(bodies, true);
}

/// `mb`'s joint-space mass matrix `Σ Jᵢᵀ Mᵢ Jᵢ` over its dynamic links.
fn mass_matrix(mb: &Multibody, bodies: &RigidBodySet) -> DMatrix<f32> {
    let n = mb.ndofs();
    let mut m = DMatrix::<f32>::zeros(n, n);
    for (i, link) in mb.links().enumerate() {
        let rb = &bodies[link.rigid_body_handle()];
        if !rb.is_dynamic() {
            continue;
        }
        let j = mb.body_jacobian(i);
        let inertia = rb
            .mass_properties()
            .effective_angular_inertia()
            .into_matrix();
        let inertia = Matrix3::from_column_slice(&inertia.to_cols_array());
        let (jl, ja) = (j.rows(0, 3), j.rows(3, 3));
        m += jl.transpose() * jl * rb.mass() + ja.transpose() * inertia * ja;
    }
    m
}

/// Stops the relative motion of the joint coordinates `at..at + 3` of `mb` with the
/// smallest generalized impulse (`Δq̇ = −M⁻¹Sᵀ(SM⁻¹Sᵀ)⁻¹Sq̇`, S selecting them): the rest of
/// the tree keeps its momentum and no energy is added.
fn stop_joint(mb: &mut Multibody, bodies: &RigidBodySet, at: usize) {
    let n = mb.ndofs();
    if at + 3 > n {
        return;
    }
    let Some(minv) = mass_matrix(mb, bodies).cholesky().map(|c| c.inverse()) else {
        return;
    };
    let qd = mb.generalized_velocity().clone_owned();
    let a = minv.view((at, at), (3, 3)).into_owned();
    let Some(ainv) = a.try_inverse() else { return };
    let lambda = ainv * qd.rows(at, 3);
    let dq = -(minv.columns(at, 3) * lambda);
    if dq.iter().all(|x| x.is_finite()) {
        let mut v = mb.generalized_velocity_mut();
        v += dq;
    }
}

/// Adds to `mb`'s generalized velocities the generalized impulse of the velocity changes
/// `dv` (per link: linear, angular), `Δq̇ = M⁻¹ Σ Jᵢᵀ Mᵢ Δvᵢ`.
fn take_velocity_changes(mb: &mut Multibody, bodies: &RigidBodySet, dv: &[(Vector, Vector)]) {
    let n = mb.ndofs();
    if n == 0 {
        return;
    }
    let mut m = DMatrix::<f32>::zeros(n, n);
    let mut p = DVector::<f32>::zeros(n);
    for (i, link) in mb.links().enumerate() {
        let rb = &bodies[link.rigid_body_handle()];
        if !rb.is_dynamic() {
            continue;
        }
        let j = mb.body_jacobian(i);
        let mass = rb.mass();
        let inertia = rb
            .mass_properties()
            .effective_angular_inertia()
            .into_matrix();
        let inertia = Matrix3::from_column_slice(&inertia.to_cols_array());
        let jl = j.rows(0, 3);
        let ja = j.rows(3, 3);
        m += jl.transpose() * jl * mass + ja.transpose() * inertia * ja;
        let (dl, da) = dv[i];
        let lin = rapier3d::na::Vector3::new(dl.x, dl.y, dl.z) * mass;
        let ang = inertia * rapier3d::na::Vector3::new(da.x, da.y, da.z);
        p += jl.transpose() * lin + ja.transpose() * ang;
    }
    if let Some(ch) = m.cholesky() {
        let dq = ch.solve(&p);
        if dq.iter().all(|x| x.is_finite()) {
            let mut v = mb.generalized_velocity_mut();
            v += dq;
        }
    }
}

impl Plane {
    /// Removes every articulation (multibody joints and private roots); the joints that
    /// were articulated are rebuilt as the next step decides.
    pub(super) fn tear_down_articulations(&mut self) {
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
    pub(super) fn build_tree(
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
    pub(super) fn articulations_before_step(&mut self) {
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
    pub(super) fn articulated_forces(
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

/// Whether every body the articulations name exists (a snapshot's, before it is taken).
pub(super) fn hold_together(
    a: &Articulations,
    bodies: &RigidBodySet,
    multibodies: &MultibodyJointSet,
) -> bool {
    let trees = a.trees.iter().all(|t| {
        bodies.get(t.root).is_some()
            && t.fixed_end.is_none_or(|f| bodies.get(f).is_some())
            && t.links.iter().all(|(h, ..)| bodies.get(*h).is_some())
    });
    trees
        && multibodies.multibodies().all(|mb| {
            mb.links()
                .all(|l| bodies.get(l.rigid_body_handle()).is_some())
        })
}

impl Articulations {
    /// Whether the plane has no articulated tree.
    pub fn is_empty(&self) -> bool {
        self.trees.is_empty()
    }
}

impl Plane {
    /// After a step: a link the step moved off its joints (rapier's CCD puts a fast body back
    /// at its time of impact, a link included) has its articulation's coordinates reset from
    /// the bodies' poses, so the joints hold through the hit instead of for a tick apart; such
    /// a link, or one the plane's speed caps slowed, also hands its velocity back to the
    /// articulation (a 1,000 u/s hit otherwise left the joints moving as the bodies no longer
    /// did, and the next steps diverged).
    pub(super) fn articulations_after_ccd(&mut self) {
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
    pub(super) fn articulations_after_step(&mut self) {
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

/// A joint that could be articulated: (joint slot, body A, body B, A dynamic, B dynamic).
pub(super) type Candidate = (usize, RigidBodyHandle, RigidBodyHandle, bool, bool);

/// One tree to build.
pub(super) struct TreePlan {
    /// Its dynamic root (when it has no fixed end).
    pub root: RigidBodyHandle,
    /// Its one fixed end (a private root will follow it).
    pub fixed_end: Option<RigidBodyHandle>,
    /// (joint slot, parent body, child body, flip) with every parent before its children;
    /// `flip`: the parent is the joint's body B.
    pub edges: Vec<(usize, RigidBodyHandle, RigidBodyHandle, bool)>,
    /// Its dynamic bodies.
    pub bodies: Vec<RigidBodyHandle>,
}

/// The trees among `candidates`: groups of joints connected through dynamic bodies with no
/// loop and at most one fixed end. Deterministic (candidate order).
pub(super) fn plan(candidates: &[Candidate]) -> Vec<TreePlan> {
    use std::collections::HashMap;
    let mut index: HashMap<RigidBodyHandle, usize> = HashMap::new();
    let mut order: Vec<RigidBodyHandle> = Vec::new();
    let mut node = |h: RigidBodyHandle, order: &mut Vec<RigidBodyHandle>| {
        *index.entry(h).or_insert_with(|| {
            order.push(h);
            order.len() - 1
        })
    };
    // Node ids of each candidate's dynamic ends.
    let ends: Vec<(Option<usize>, Option<usize>)> = candidates
        .iter()
        .map(|&(_, a, b, da, db)| {
            (
                da.then(|| node(a, &mut order)),
                db.then(|| node(b, &mut order)),
            )
        })
        .collect();
    let mut parent: Vec<usize> = (0..order.len()).collect();
    fn find(p: &mut [usize], mut x: usize) -> usize {
        while p[x] != x {
            p[x] = p[p[x]];
            x = p[x];
        }
        x
    }
    for e in &ends {
        if let (Some(a), Some(b)) = *e {
            let (ra, rb) = (find(&mut parent, a), find(&mut parent, b));
            if ra != rb {
                parent[ra.max(rb)] = ra.min(rb);
            }
        }
    }
    let n = order.len();
    let (mut nodes, mut edges, mut fixed) = (vec![0usize; n], vec![0usize; n], vec![0usize; n]);
    for i in 0..n {
        let r = find(&mut parent, i);
        nodes[r] += 1;
    }
    let comp: Vec<usize> = ends
        .iter()
        .map(|e| {
            let x = e.0.or(e.1).expect("a candidate has a dynamic end");
            find(&mut parent, x)
        })
        .collect();
    for (e, &c) in ends.iter().zip(&comp) {
        match e {
            (Some(_), Some(_)) => edges[c] += 1,
            _ => fixed[c] += 1,
        }
    }
    let is_tree = |c: usize| edges[c] + 1 == nodes[c] && fixed[c] <= 1;
    // Adjacency of tree components: node -> (candidate index, other node or None = fixed).
    let mut adj: Vec<Vec<(usize, Option<usize>)>> = vec![Vec::new(); n];
    for (k, e) in ends.iter().enumerate() {
        if !is_tree(comp[k]) {
            continue;
        }
        match *e {
            (Some(a), Some(b)) => {
                adj[a].push((k, Some(b)));
                adj[b].push((k, Some(a)));
            }
            (Some(a), None) | (None, Some(a)) => adj[a].push((k, None)),
            (None, None) => {}
        }
    }
    let mut plans = Vec::new();
    let mut done = vec![false; n];
    for (k, &c) in comp.iter().enumerate() {
        if done[c] || !is_tree(c) {
            continue;
        }
        done[c] = true;
        // Start: the dynamic end of the fixed edge, else body B of the first joint.
        let fixed_edge = (0..ends.len())
            .find(|&i| comp[i] == c && matches!(ends[i], (Some(_), None) | (None, Some(_))));
        let (start, fixed_end, mut out) = match fixed_edge {
            Some(i) => {
                let (slot, a, b, da, _) = candidates[i];
                let (dyn_node, fixed_body, child) = if da {
                    (ends[i].0.unwrap(), b, a)
                } else {
                    (ends[i].1.unwrap(), a, b)
                };
                // The fixed end is the parent: flip when it is body B.
                (
                    dyn_node,
                    Some(fixed_body),
                    vec![(slot, fixed_body, child, da)],
                )
            }
            None => (ends[k].1.expect("dynamic B"), None, Vec::new()),
        };
        let mut used = vec![false; ends.len()];
        if let Some(i) = fixed_edge {
            used[i] = true;
        }
        let mut queue = std::collections::VecDeque::from([start]);
        let mut bodies = vec![order[start]];
        let mut visited = vec![false; n];
        visited[start] = true;
        while let Some(p) = queue.pop_front() {
            for &(ci, other) in &adj[p] {
                let Some(o) = other else { continue };
                if visited[o] || used[ci] {
                    continue;
                }
                visited[o] = true;
                used[ci] = true;
                let (slot, a, _, _, _) = candidates[ci];
                let (pb, cb) = (order[p], order[o]);
                out.push((slot, pb, cb, pb != a));
                bodies.push(cb);
                queue.push_back(o);
            }
        }
        plans.push(TreePlan {
            root: order[start],
            fixed_end,
            edges: out,
            bodies,
        });
    }
    plans
}

#[cfg(test)]
mod tests {
    use shm_layout::{JointKind, JointOp, JointProp, ObjectOp, ObjectProp, PlaneOp, PlaneProp};
    use shm_layout::{Pose, Reply, Shape};

    use crate::backend::Backend;
    use crate::rapier3d::Plane;

    #[test]
    fn a_pushed_pendulum_bob_takes_the_push_once() {
        let mut p = Plane::new(
            1,
            &[
                PlaneProp::TickRate(0.0),
                PlaneProp::LinearDamping(0.0),
                PlaneProp::AngularDamping(0.0),
            ],
        )
        .unwrap();
        let bob = p
            .add_object(
                &Shape::Sphere { radius: 0.1 },
                Pose::at([0.0, 18.0, 0.0]),
                &[ObjectProp::Weight(1.0)],
            )
            .unwrap();
        let Reply::Joint { .. } = p
            .apply(PlaneOp::Joint(JointOp::Create {
                kind: JointKind::Ball,
                a: bob,
                b: None,
                props: vec![
                    JointProp::AnchorA([0.0, 2.0, 0.0]),
                    JointProp::AnchorB([0.0, 20.0, 0.0]),
                ],
            }))
            .unwrap()
        else {
            panic!()
        };
        for _ in 0..5 {
            p.step(1.0 / 60.0).unwrap();
        }
        p.apply(PlaneOp::Object {
            handle: bob,
            op: ObjectOp::Set(ObjectProp::Velocity([5.0, 0.0, 0.0])),
        })
        .unwrap();
        let h = p.bodies.get(bob).unwrap().handle;
        for i in 0..6 {
            p.step(1.0 / 240.0).unwrap();
            let b = &p.world.bodies[h];
            assert!(b.linvel().is_finite(), "step {i}");
        }
        let v = p.world.bodies[h].linvel().length();
        assert!((v - 5.0).abs() < 0.2, "speed {v}");
    }

    /// A 1,000:1 chain of point-like links swinging for 15 s: rapier's articulation stays
    /// finite (it diverged at 2.9 s without the armature) and every gap stays below 0.01.
    #[test]
    fn a_heavy_ended_chain_publishes_finite_states() {
        let mut p = Plane::new(
            1,
            &[
                PlaneProp::TickRate(0.0),
                PlaneProp::LinearDamping(0.0),
                PlaneProp::AngularDamping(0.0),
            ],
        )
        .unwrap();
        let mut prev = None;
        for i in 0..20 {
            let w = if i == 19 { 1000.0 } else { 1.0 };
            let link = p
                .add_object(
                    &Shape::Sphere { radius: 0.2 },
                    Pose::at([i as f32 * 0.5 + 0.5, 20.0, 0.0]),
                    &[ObjectProp::Weight(w)],
                )
                .unwrap();
            let anchor_b = if prev.is_some() {
                [0.5, 0.0, 0.0]
            } else {
                [0.5, 20.0, 0.0]
            };
            p.apply(PlaneOp::Joint(JointOp::Create {
                kind: JointKind::Ball,
                a: link,
                b: prev,
                props: vec![JointProp::AnchorA([0.0; 3]), JointProp::AnchorB(anchor_b)],
            }))
            .unwrap();
            prev = Some(link);
        }
        for t in 0..900 {
            p.step(1.0 / 60.0).unwrap();
            for i in 0..p.bodies.slot_count() {
                let s = p.body_state(i);
                assert!(s.is_finite(), "tick {t} slot {i}: {s:?}");
            }
            assert!(
                p.joints.max_error < 0.01,
                "tick {t}: error {}",
                p.joints.max_error
            );
        }
    }

    /// A velocity written to one link of a free (unanchored) articulation moves the pair's
    /// centre of mass with the written momentum, in its direction: two unit balls in zero
    /// gravity, one pushed at 4 along +Z, move their centre at 2 along +Z.
    #[test]
    fn a_push_on_a_free_articulation_keeps_its_momentum() {
        let mut p = Plane::new(
            1,
            &[
                PlaneProp::TickRate(0.0),
                PlaneProp::Gravity([0.0; 3]),
                PlaneProp::LinearDamping(0.0),
                PlaneProp::AngularDamping(0.0),
            ],
        )
        .unwrap();
        let a = p
            .add_object(
                &Shape::Sphere { radius: 0.1 },
                Pose::at([0.0, 5.0, 0.0]),
                &[],
            )
            .unwrap();
        let b = p
            .add_object(
                &Shape::Sphere { radius: 0.1 },
                Pose::at([1.0, 5.0, 0.0]),
                &[],
            )
            .unwrap();
        p.apply(PlaneOp::Joint(JointOp::Create {
            kind: JointKind::Ball,
            a,
            b: Some(b),
            props: vec![
                JointProp::AnchorA([0.5, 0.0, 0.0]),
                JointProp::AnchorB([-0.5, 0.0, 0.0]),
            ],
        }))
        .unwrap();
        p.step(1.0 / 60.0).unwrap();
        p.apply(PlaneOp::Object {
            handle: a,
            op: ObjectOp::Set(ObjectProp::Velocity([0.0, 0.0, 4.0])),
        })
        .unwrap();
        for _ in 0..30 {
            p.step(1.0 / 60.0).unwrap();
        }
        let (ha, hb) = (
            p.bodies.get(a).unwrap().handle,
            p.bodies.get(b).unwrap().handle,
        );
        let v = (p.world.bodies[ha].linvel() + p.world.bodies[hb].linvel()) * 0.5;
        assert!(
            (v.z - 2.0).abs() < 0.02 && v.x.abs() < 0.02 && v.y.abs() < 0.02,
            "{v:?}"
        );
    }
}

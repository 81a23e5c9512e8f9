//! Arithmetic on one rapier multibody (an articulated tree): armatures, speed clamps, joint
//! coordinates and velocities read back from the bodies, the mass matrix, inelastic stops
//! and generalized impulses.

use rapier3d::na::{DMatrix, DVector, Matrix3};
use rapier3d::prelude::*;
use rapier3d::utils::AngularInertiaOps;

/// Rotor inertia (rapier's per-coordinate "armature") of every joint coordinate, per unit
/// of the tree's heaviest link mass (units²): the least each coordinate gets (see
/// [`set_armature`] for what a loaded joint gets on top). Without it rapier's articulation
/// integration lets light links whipping under a heavy one gain energy: the 1,000:1 chain
/// of point-like links diverged after 2.9 s at 60 Hz (armature 0.01 still did, 0.1 held
/// for 15 s). It lengthens a unit-mass pendulum of length 2 by 0.001 %.
pub(in crate::rapier3d::joints) const ARMATURE_PER_MASS: f32 = 1.0e-4;

/// Rapier damps every free rotation of an articulation by 0.1 N·m·s/rad (its
/// `default_damping`): an undamped hinge spring of k = 50 on a 2 kg ball lost all its
/// energy in 10 s. The coordinates of joints with a spring (a force-based motor with a
/// stiffness) lose that damping; a spring's damping is its `Damping`.
pub(crate) fn undamp_springs(mb: &mut Multibody) {
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
pub(in crate::rapier3d::joints) fn set_armature(
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
pub(crate) const MAX_JOINT_SPEED: f32 = 100.0;

/// Scales down each joint's angular velocity that exceeds [`MAX_JOINT_SPEED`], the free
/// root's spin included.
pub(in crate::rapier3d::joints) fn clamp_joint_speeds(mb: &mut Multibody) {
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
pub(in crate::rapier3d::joints) fn velocities_from_bodies(
    mb: &mut Multibody,
    bodies: &RigidBodySet,
) {
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

/// Signed angle of `q` about its frame axis `i`, in (-π, π].
pub(in crate::rapier3d::joints) fn axis_angle(q: Rotation, i: usize) -> f32 {
    let q = if q.w < 0.0 { -q } else { q };
    2.0 * [q.x, q.y, q.z][i].atan2(q.w)
}

/// Sets the joint coordinates of every link of `mb` so that the links sit where their
/// bodies are now (locked axes snap), then runs its forward kinematics.
pub(in crate::rapier3d::joints) fn coordinates_from_bodies(
    mb: &mut Multibody,
    bodies: &RigidBodySet,
) {
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
pub(in crate::rapier3d::joints) fn mass_matrix(
    mb: &Multibody,
    bodies: &RigidBodySet,
) -> DMatrix<f32> {
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
pub(in crate::rapier3d::joints) fn stop_joint(
    mb: &mut Multibody,
    bodies: &RigidBodySet,
    at: usize,
) {
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
pub(in crate::rapier3d::joints) fn take_velocity_changes(
    mb: &mut Multibody,
    bodies: &RigidBodySet,
    dv: &[(Vector, Vector)],
) {
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

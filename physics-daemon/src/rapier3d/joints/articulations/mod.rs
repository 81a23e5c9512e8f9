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

use rapier3d::prelude::*;
use shm_layout::joint_op::{JointKind, JointSettings};

pub(in crate::rapier3d::joints) mod multibody;
mod ops;
#[cfg(test)]
mod tests;

/// Overshoot of a ball joint's limit (rad) left to its companion impulse joint before the
/// inelastic stop puts the joint back on its limit.
pub(in crate::rapier3d::joints) const LIMIT_SLOP: f32 = 0.05;

/// One articulated tree.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub(in crate::rapier3d::joints) struct Tree {
    /// The body at the root of the rapier multibody (a private fixed root, or a dynamic one).
    pub(in crate::rapier3d::joints) root: RigidBodyHandle,
    /// The fixed end the private root follows (None: the root is a dynamic body of the tree).
    pub(in crate::rapier3d::joints) fixed_end: Option<RigidBodyHandle>,
    /// Every dynamic body of the tree with its pose and velocities as the last step (or the
    /// build) left them: a difference before the next step is a write to take in.
    pub(in crate::rapier3d::joints) links: Vec<(RigidBodyHandle, Pose, Vector, Vector)>,
}

/// The plane's articulated trees.
#[derive(Debug, Clone, Default, serde::Serialize, serde::Deserialize)]
pub(crate) struct Articulations {
    /// The structure changed: the trees are rebuilt before the next step.
    pub dirty: bool,
    pub(in crate::rapier3d::joints) trees: Vec<Tree>,
}

/// Whether a joint of `kind` with `s` can be articulated (given suitable ends).
pub(crate) fn articulable(kind: JointKind, s: &JointSettings) -> bool {
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
pub(crate) fn needs_limit_joint(kind: JointKind, s: &JointSettings) -> bool {
    matches!(kind, JointKind::Ball | JointKind::ConeTwist)
        && (s.twist_limit.is_some() || s.swing_limit.is_some())
}

/// The multibody form of `j`: three-rotation joints lose their angular limits (the
/// companion holds them); `flip` swaps its bodies (parent = body 1 in rapier), which
/// negates the coordinate of its one free axis (hinge angle, slide), its limits and motor.
pub(crate) fn multibody_data(
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
pub(crate) fn limit_data(mut j: GenericJoint) -> GenericJoint {
    j.locked_axes = JointAxesMask::empty();
    j
}

/// Whether every body the articulations name exists (a snapshot's, before it is taken).
pub(crate) fn hold_together(
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

/// A joint that could be articulated: (joint slot, body A, body B, A dynamic, B dynamic).
pub(crate) type Candidate = (usize, RigidBodyHandle, RigidBodyHandle, bool, bool);

/// One tree to build.
pub(crate) struct TreePlan {
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
pub(crate) fn plan(candidates: &[Candidate]) -> Vec<TreePlan> {
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

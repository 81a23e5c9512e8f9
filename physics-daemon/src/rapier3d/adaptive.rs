//! Adaptive solving (`AdaptiveSolving`, on by default): the islands that need more substeps
//! get them, the others pay nothing.
//!
//! The plane's solver runs `SolverIterations` substeps (see `solver`): enough for contacts
//! between bodies of similar mass under a modest load. Two things defeat it, and both are
//! found in the contacts after each step:
//!
//! - **Load.** The lower contacts of a tall stack carry many bodies' weight and sink deeper
//!   than the solver can recover in one tick (a base-100 pyramid crept 0.76 in 2 s). A pair
//!   deeper than [`TRIGGER_DEPTH`] gives both its bodies [`LOAD_EXTRA`] more substeps; the
//!   pyramid then holds within 0.01.
//! - **Mass ratio.** A heavy body on a light one: the light body sets the contact's effective
//!   mass, so the soft contact (a spring of rapier's natural frequency) lets the heavy one
//!   sink by ratio · g / ω² (1,000:1 sank 0.73). A touching pair of dynamic bodies whose
//!   masses differ [`RATIO`] times or more gets [`RATIO_EXTRA`] more substeps, and while any
//!   such pair exists the plane's contacts follow the faster substep rate in stiffness (as
//!   `solver` does for a plane-wide SolverIterations of 32, the setting that held 1,000:1).
//!
//! Rapier runs each connected group of awake bodies (contacts and joints) at the largest
//! request inside it (`additional_solver_iterations`), so only the islands holding such a
//! pair pay. A plane with an articulation does not adapt: rapier would run every awake body
//! at the largest request (it does not split multibody scenes into groups), and an
//! articulated ragdoll hit at 1,000 units/s went non-finite with extra substeps. A boost stays while its pair is
//! deeper than [`RELEASE_DEPTH`] or keeps its mass ratio, and ends otherwise: every pass
//! reads the contacts of that tick, and a pass runs when some contact is deeper than
//! [`RELEASE_DEPTH`] and every 32nd tick (so boosts of pairs that came apart end).
//!
//! The decision reads only the contacts, each body's current boost and the plane's tick, all
//! part of a snapshot: a restored plane boosts exactly as the original would.

use rapier3d::prelude::*;

/// Depth (units at HitBoxQuality 1, scaled with the plane's allowed error) past which a
/// contact asks for more substeps: six times rapier's allowed error.
const TRIGGER_DEPTH: f32 = 0.03;
/// Depth under which a boosted pair lets its boost go (unless its mass ratio keeps it).
const RELEASE_DEPTH: f32 = 0.01;
/// The allowed error the depths above are written for (HitBoxQuality 1).
const BASE_ALLOWED_ERROR: f32 = 0.005;
/// Mass ratio from which a touching pair is boosted whatever its depth (and its light body
/// made to carry the heavy one): 1,000:1 needs the boost; at 100 alternating columns of
/// four between 30:1 and 100:1 sank 0.06 to 0.14, at 30 they sink at most 0.09.
const RATIO: f32 = 30.0;
/// Extra substeps for a deep pair: 16 in all at the defaults (a base-100 pyramid holds).
const LOAD_EXTRA: usize = 12;
/// Extra substeps for a pair of a high mass ratio: 32 in all at the defaults, 1,920 substeps
/// a second (a 1,000:1 column of four holds).
pub(super) const RATIO_EXTRA: usize = 28;
/// A pass runs at least every this many ticks.
const PASS_EVERY: u64 = 32;
/// A contact whose normal is within ~45° of gravity is a support (one body rests on the
/// other) for the dominance pass.
const SUPPORT_COS: f32 = 0.7;
/// Highest dominance level the pass gives (rapier's groups are i8).
const MAX_LEVEL: i32 = 100;

/// A support edge: (lower body, upper body, whether the upper is the heavy one of a
/// high-ratio pair), bodies as raw handle parts.
type Support = ((u32, u32), (u32, u32), bool);

/// The adaptive pass's state (see the module doc).
#[derive(Debug, Clone, Default, serde::Serialize, serde::Deserialize)]
pub(super) struct Adaptive {
    /// Bodies the last pass gave extra substeps.
    boosted: u32,
    /// Whether the last pass found a pair of a high mass ratio.
    stiffened: bool,
}

impl Adaptive {
    /// After a step: boosts the bodies of the pairs that need more substeps and lets the
    /// others' boosts go (see the module doc).
    /// `on`: the plane's AdaptiveSolving; `awake`: bodies awake after the step; the step's
    /// deepest penetration and tick.
    pub(super) fn adapt(
        &mut self,
        world: &mut PhysicsWorld,
        on: bool,
        awake: usize,
        (max_penetration, tick): (f32, u64),
    ) {
        let articulated = world.multibody_joints.iter().next().is_some();
        if !on || articulated {
            if self.boosted > 0 || self.stiffened {
                self.unboost_all(&mut world.bodies);
            }
            return;
        }
        // Nothing awake, nothing to decide: a sleeping pair keeps what it had (it costs
        // nothing asleep) and is looked at again once something wakes. A settled pile pays
        // no pass at all (the periodic pass over every pair cost it 12 % of its step).
        if awake == 0 {
            return;
        }
        let scale =
            world.integration_parameters.normalized_allowed_linear_error / BASE_ALLOWED_ERROR;
        let (trigger, release) = (TRIGGER_DEPTH * scale, RELEASE_DEPTH * scale);
        if max_penetration <= release && !tick.is_multiple_of(PASS_EVERY) {
            return;
        }
        let bodies = &world.bodies;
        // (body, extra substeps) for the bodies some pair asks for; bodies to let go.
        let (mut wanted, mut unwanted) = (Vec::new(), Vec::new());
        let mut stiffened = false;
        // Support edges (lower body, upper body, whether the upper is the heavy one of a
        // high-ratio pair) for the dominance pass below.
        let down = world.gravity.normalize_or_zero();
        let mut supports = Vec::new();
        // Dynamic bodies resting on anchored geometry: only such a light body carries a heavy
        // one as a floor would. Higher in a column the extra substeps hold the pair (a light
        // box given the heavy one's weight to nobody above the floor let a 1,000:1 box on a
        // column of four sink through it).
        let mut grounded = std::collections::BTreeSet::new();
        for pair in world.narrow_phase.contact_pairs() {
            let Some((manifold, contact)) = pair.find_deepest_contact() else {
                continue;
            };
            let (Some(h1), Some(h2)) = (manifold.data.rigid_body1, manifold.data.rigid_body2)
            else {
                continue;
            };
            let (Some(b1), Some(b2)) = (bodies.get(h1), bodies.get(h2)) else {
                continue;
            };
            let depth = -contact.dist;
            let boosted =
                b1.additional_solver_iterations() > 0 || b2.additional_solver_iterations() > 0;
            let heavy = b1.is_dynamic() && b2.is_dynamic() && {
                let (m1, m2) = (b1.mass(), b2.mass());
                m1.max(m2) >= RATIO * m1.min(m2)
            };
            if b1.is_dynamic() != b2.is_dynamic() {
                // The manifold's normal points from body 1 toward body 2.
                let along = manifold.data.normal.dot(down);
                let on_top = if b1.is_dynamic() {
                    along > SUPPORT_COS
                } else {
                    along < -SUPPORT_COS
                };
                if on_top {
                    let h = if b1.is_dynamic() { h1 } else { h2 };
                    grounded.insert(h.into_raw_parts());
                }
            }
            if b1.is_dynamic() && b2.is_dynamic() {
                // The manifold's normal points from body 1 toward body 2.
                let along = manifold.data.normal.dot(down);
                let (lower, upper) = if along > SUPPORT_COS {
                    ((h2, b2), (h1, b1))
                } else if along < -SUPPORT_COS {
                    ((h1, b1), (h2, b2))
                } else {
                    ((h1, b1), (h1, b1))
                };
                if lower.0 != upper.0 {
                    let step = heavy && upper.1.mass() > lower.1.mass();
                    supports.push((lower.0.into_raw_parts(), upper.0.into_raw_parts(), step));
                }
            }
            let extra = if heavy {
                stiffened = true;
                RATIO_EXTRA
            } else if depth > trigger || (boosted && depth > release) {
                LOAD_EXTRA
            } else {
                0
            };
            for (h, b) in [(h1, b1), (h2, b2)] {
                if !b.is_dynamic() {
                    continue;
                }
                if extra > 0 {
                    wanted.push((h.into_raw_parts(), extra));
                } else if b.additional_solver_iterations() > 0 {
                    unwanted.push(h.into_raw_parts());
                }
            }
        }
        let was_stiffened = self.stiffened;
        self.stiffened = stiffened;
        if stiffened || was_stiffened {
            for s in supports.iter_mut() {
                s.2 &= grounded.contains(&s.0);
            }
            set_dominance(&mut world.bodies, &supports);
        }
        // Each body takes the largest request of its pairs.
        wanted.sort_unstable_by(|a, b| a.0.cmp(&b.0).then(b.1.cmp(&a.1)));
        wanted.dedup_by_key(|w| w.0);
        self.boosted = wanted.len() as u32;
        let bodies = &mut world.bodies;
        for raw in unwanted {
            if wanted.binary_search_by(|w| w.0.cmp(&raw)).is_err() {
                set_extra(bodies, raw, 0);
            }
        }
        for (raw, extra) in wanted {
            set_extra(bodies, raw, extra);
        }
    }

    /// Every body back to the plane's own substeps (AdaptiveSolving turned off, or an
    /// articulation made).
    fn unboost_all(&mut self, bodies: &mut RigidBodySet) {
        let boosted: Vec<RigidBodyHandle> = bodies
            .iter()
            .filter(|(_, b)| b.additional_solver_iterations() > 0)
            .map(|(h, _)| h)
            .collect();
        for h in boosted {
            set_extra(bodies, h.into_raw_parts(), 0);
        }
        if self.stiffened {
            set_dominance(bodies, &[]);
        }
        (self.boosted, self.stiffened) = (0, false);
    }

    /// Whether the last pass found a pair of a high mass ratio.
    pub(super) fn stiffened(&self) -> bool {
        self.stiffened
    }
}

/// Sets a body's extra substeps, touching it only when that changes something.
fn set_extra(bodies: &mut RigidBodySet, raw: (u32, u32), extra: usize) {
    let h = RigidBodyHandle::from_raw_parts(raw.0, raw.1);
    if bodies
        .get(h)
        .is_some_and(|b| b.additional_solver_iterations() != extra)
    {
        if let Some(b) = bodies.get_mut(h) {
            b.set_additional_solver_iterations(extra);
        }
    }
}

/// Shock propagation for high mass ratios: a light body carrying a heavy one acts, for that
/// contact, as immovable (rapier's dominance groups), and so does everything under it.
///
/// Substeps alone do not hold a heavy body on a light one: the solver's iterations move the
/// heavy body by the light one's share of momentum each (≈ 2·m/M), so its fall is never
/// stopped at the velocity level and the position correction that pushes it back out stays
/// in its velocity: a 1,000:1 box bounced between 1.29 and 1.80 forever (rest 1.5) with 32
/// substeps and stiffened contacts. With the light body dominant the heavy one rests on it
/// as on a floor. `supports` lists (lower, upper, heavy step) edges: each lower body gets a
/// level at least its upper body's, plus one across a heavy-on-light edge; every other
/// dynamic body goes back to level 0. What it gives up: for that contact the heavy body
/// cannot push the light one (it is on something anyway), and a light body pushed sideways
/// drags the heavy one without feeling its inertia.
fn set_dominance(bodies: &mut RigidBodySet, supports: &[Support]) {
    let mut level: std::collections::BTreeMap<(u32, u32), i32> = Default::default();
    if supports.iter().any(|s| s.2) {
        // Relax the "lower ≥ upper + step" constraints; a column settles in its height in
        // rounds, and any cycle (bodies side by side) is cut off by the cap.
        for _ in 0..32 {
            let mut changed = false;
            for &(lower, upper, step) in supports {
                let need = (level.get(&upper).copied().unwrap_or(0) + step as i32).min(MAX_LEVEL);
                let have = level.entry(lower).or_insert(0);
                if *have < need {
                    *have = need;
                    changed = true;
                }
            }
            if !changed {
                break;
            }
        }
    }
    let stale: Vec<RigidBodyHandle> = bodies
        .iter()
        .filter(|(h, b)| b.dominance_group() != 0 && !level.contains_key(&h.into_raw_parts()))
        .map(|(h, _)| h)
        .collect();
    for h in stale {
        if let Some(b) = bodies.get_mut(h) {
            b.set_dominance_group(0);
        }
    }
    for (raw, l) in level {
        let h = RigidBodyHandle::from_raw_parts(raw.0, raw.1);
        if let Some(b) = bodies
            .get_mut(h)
            .filter(|b| b.dominance_group() as i32 != l)
        {
            b.set_dominance_group(l as i8);
        }
    }
}

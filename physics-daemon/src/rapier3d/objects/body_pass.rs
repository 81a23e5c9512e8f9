//! The per-body pass before every step, over the bodies the step will move (rapier's awake
//! set, then the ones changed by ops since the last step): the force pass (`forces`), the
//! MaxAngularSpeed cap (`limits`) and contact prediction (`solver`), one read of each body.
//!
//! What the pass does to a body depends on that body alone, so it is worked out first, on
//! the plane's pool when the plane has one (Threads > 1) and the pass is large, and then
//! written in one sweep on the calling thread, in list order (rapier hands out bodies for
//! writing one at a time, recording each). The sweep also clears the force the previous
//! pass left in rapier's accumulator; bodies that pass forced and this one does not list
//! (asleep since, removed, anchored) are cleared after it. With or without a pool the same
//! numbers are written in the same order: Threads only changes which thread does the
//! arithmetic, never the result (`tests` checks it bit for bit).
//!
//! The after-step passes on the pool are [`Scratch::cap_angular_speeds`] (finding bodies over
//! MaxAngularSpeed, capped with `limits`) and the contact figures (`contacts::figures`, run
//! beside the state hash).

use std::sync::Arc;

use rapier3d::prelude::*;
use rayon::prelude::*;

use crate::backend::SlotTable;
use crate::rapier3d::objects::forces::{drive, Env, Push};
use crate::rapier3d::objects::limits::capped;
use crate::rapier3d::objects::object::Object;

/// Items (bodies, contact pairs) below which a pass runs on the calling thread: handing
/// work to the pool and back costs more than a few thousand bodies' worth of it.
pub(crate) const PARALLEL_FROM: usize = 2_048;
/// Fewest items one pool task takes.
pub(crate) const MIN_TASK: usize = 256;

/// Buffers the passes reuse from step to step.
#[derive(Debug, Default)]
pub(crate) struct Scratch {
    /// Bodies a pass visits.
    pub handles: Vec<RigidBodyHandle>,
    /// Rapier's awake set, copied for the pool.
    pub active: Vec<RigidBodyHandle>,
    /// What the pass does to each of `handles`.
    updates: Vec<Update>,
    /// Bodies the last pass left a force on (reset by the next one). Snapshot state (the
    /// plane's `plane_state!` names it): the next pass clears the force of those it does
    /// not list, which a restored plane must do as the original would.
    pub(in crate::rapier3d) previous: Vec<RigidBodyHandle>,
    /// Bodies the pass running now leaves a force on.
    forced: Vec<RigidBodyHandle>,
    /// Bodies the pass running now has written.
    listed: HandleSet,
}

/// A set of body handles by arena index, for the pass's membership tests (no hashing).
#[derive(Debug, Default)]
struct HandleSet {
    bits: Vec<u64>,
}

impl HandleSet {
    fn index(h: RigidBodyHandle) -> (usize, u64) {
        let i = h.into_raw_parts().0 as usize;
        (i / 64, 1 << (i % 64))
    }

    fn insert(&mut self, h: RigidBodyHandle) {
        let (word, bit) = Self::index(h);
        if word >= self.bits.len() {
            self.bits.resize(word + 1, 0);
        }
        self.bits[word] |= bit;
    }

    fn contains(&self, h: RigidBodyHandle) -> bool {
        let (word, bit) = Self::index(h);
        self.bits.get(word).is_some_and(|w| w & bit != 0)
    }

    /// Empties the set, which holds at most `members`.
    fn clear(&mut self, members: &[RigidBodyHandle]) {
        if members.len() * 8 > self.bits.len() {
            self.bits.fill(0);
        } else {
            for h in members {
                let (word, _) = Self::index(*h);
                if let Some(w) = self.bits.get_mut(word) {
                    *w = 0;
                }
            }
        }
    }
}

/// What the pass before the step changes on one body (None: leave as is).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
struct Update {
    angvel: Option<Vector>,
    /// Set directly, waking the body (the force pass's fallback for a non-finite force).
    linvel: Option<Vector>,
    /// Added to rapier's force accumulator for this step.
    force: Option<Vector>,
    soft_ccd: Option<f32>,
}

/// Plane-wide inputs of the pass.
pub(crate) struct Inputs {
    /// None when the force pass has nothing to do.
    pub forces: Option<Env>,
    pub max_angular_speed: f32,
    pub prediction: Prediction,
}

/// `world`'s pool (the plane's, Threads > 1) when it has one and `items` are worth handing
/// to it.
pub(crate) fn pool_for(world: &PhysicsWorld, items: usize) -> Option<Arc<rayon::ThreadPool>> {
    if items < PARALLEL_FROM {
        return None;
    }
    world.physics_pipeline.thread_pool()
}

impl Scratch {
    /// Before a step (after the solver is tuned): forces, angular speed caps and contact
    /// prediction for every body the step will move: rapier's awake set, then the bodies
    /// of `slots` changed by ops since the last step.
    pub(crate) fn prepare_bodies(
        &mut self,
        world: &mut PhysicsWorld,
        slots: &SlotTable<Object>,
        inputs: &Inputs,
    ) {
        let mut handles = std::mem::take(&mut self.handles);
        handles.clear();
        handles.extend(world.islands.active_bodies());
        // Bodies changed by ops since the last step, awake or not yet listed as awake: a
        // body can be listed twice (or more), and gets one update.
        let dirty = slots.since_step();
        handles.extend(
            dirty
                .iter()
                .filter_map(|s| slots.at(*s as usize).map(|b| b.handle)),
        );
        match pool_for(world, handles.len()) {
            Some(pool) => {
                let mut updates = std::mem::take(&mut self.updates);
                let bodies = &world.bodies;
                pool.install(|| {
                    handles
                        .par_iter()
                        .with_min_len(MIN_TASK)
                        .map(|h| update(bodies, slots, *h, inputs))
                        .collect_into_vec(&mut updates)
                });
                for (h, u) in handles.iter().zip(&updates) {
                    self.write(&mut world.bodies, *h, u);
                }
                self.updates = updates;
            }
            None => {
                for h in &handles {
                    let u = update(&world.bodies, slots, *h, inputs);
                    self.write(&mut world.bodies, *h, &u);
                }
            }
        }
        // Bodies the previous pass left a force on and this one did not list (asleep,
        // removed, anchored): their force stays in rapier's accumulator until reset.
        for h in self.previous.drain(..) {
            if !self.listed.contains(h) {
                if let Some(body) = world.bodies.get_mut(h) {
                    body.reset_forces(false);
                }
            }
        }
        std::mem::swap(&mut self.previous, &mut self.forced);
        self.listed.clear(&handles);
        self.handles = handles;
    }

    /// Writes one body's update. Every listed body is taken for writing, changed or not (the
    /// step treats them as touched); one the list repeats is written once.
    fn write(&mut self, bodies: &mut RigidBodySet, h: RigidBodyHandle, u: &Update) {
        let Some(body) = bodies.get_mut(h) else {
            return; // removed since it was marked
        };
        if self.listed.contains(h) {
            return; // listed twice: awake and changed by an op
        }
        self.listed.insert(h);
        // The previous pass's force goes (rapier keeps forces until reset).
        body.reset_forces(false);
        if let Some(w) = u.angvel {
            body.set_angvel(w, false);
        }
        if let Some(v) = u.linvel {
            body.set_linvel(v, true);
        }
        if let Some(f) = u.force {
            body.add_force(f, false);
            self.forced.push(h);
        }
        if let Some(reach) = u.soft_ccd {
            body.set_soft_ccd_prediction(reach);
        }
    }

    /// After a step: caps the angular speed of the awake bodies at `max` (sleeping ones are
    /// at rest). Finding the few bodies over the cap reads every awake body: on the plane's
    /// pool when it has one and many bodies are awake.
    pub(crate) fn cap_angular_speeds(&mut self, world: &mut PhysicsWorld, max: f32) {
        let over = |b: &RigidBody| b.is_dynamic() && b.angvel().length() > max;
        let mut handles = std::mem::take(&mut self.handles);
        handles.clear();
        match pool_for(world, world.islands.num_active_bodies()) {
            Some(pool) => {
                let bodies = &world.bodies;
                let active = &mut self.active;
                active.clear();
                active.extend(world.islands.active_bodies());
                pool.install(|| {
                    handles.par_extend(
                        active
                            .par_iter()
                            .with_min_len(MIN_TASK)
                            .filter(|h| bodies.get(**h).is_some_and(over)),
                    )
                });
            }
            None => {
                let bodies = &world.bodies;
                handles.extend(
                    world
                        .islands
                        .active_bodies()
                        .filter(|h| bodies.get(*h).is_some_and(over)),
                );
            }
        }
        for h in &handles {
            if let Some(body) = world.bodies.get_mut(*h) {
                body.set_angvel(capped(body.angvel(), max), false);
            }
        }
        self.handles = handles;
    }
}

/// What the pass before the step does to body `h` (reads only).
fn update(
    bodies: &RigidBodySet,
    slots: &SlotTable<Object>,
    h: RigidBodyHandle,
    inputs: &Inputs,
) -> Update {
    let Some(body) = bodies.get(h).filter(|b| b.is_dynamic()) else {
        return Update::default();
    };
    let mut u = Update::default();
    let w0 = body.angvel();
    let mut w = w0;
    let mut v = body.linvel();
    let part = slots.at(body.user_data as usize).map(|b| &b.part);
    if let (Some(env), Some(part)) = (&inputs.forces, part) {
        let push;
        (w, push) = drive(body, part, env);
        match push {
            Push::None => {}
            Push::Force(f) => u.force = Some(f),
            Push::Velocity(set) => {
                u.linvel = Some(set);
                v = set;
            }
        }
    }
    let w = capped(w, inputs.max_angular_speed);
    if w != w0 {
        u.angvel = Some(w);
    }
    let reach = inputs.prediction.reach(v);
    if body.soft_ccd_prediction() != reach {
        u.soft_ccd = Some(reach);
    }
    u
}

/// How far ahead soft CCD predicts contacts: 2 units, 120 units/s at 60 Hz. A body that moves
/// farther in a step is swept by rapier's CCD against moving bodies too, whatever its
/// HitBoxQuality (the vendored rapier's pair rule, vendor/rapier3d-0.36.1/PATCHED.md).
const SOFT_CCD_REACH: f32 = 2.0;

/// Soft CCD for the bodies a step moves by more than half the prediction distance
/// (gravity's share included), none for the others.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Prediction {
    threshold: f32,
    g_dt: f32,
    dt: f32,
}

impl Prediction {
    /// What decides each body's contact prediction in a step of `dt` (read after the solver
    /// is tuned).
    pub(crate) fn new(world: &PhysicsWorld, dt: f32) -> Prediction {
        let p = &world.integration_parameters;
        Prediction {
            threshold: 0.5 * p.prediction_distance(),
            g_dt: world.gravity.length() * dt,
            dt,
        }
    }

    /// The soft-CCD reach a dynamic body moving at `linvel` gets for the step.
    pub(crate) fn reach(&self, linvel: Vector) -> f32 {
        // Gravity's share of the tick counts, except for a body standing exactly still
        // (one that just landed): it keeps the plain prediction, whose contact rapier's
        // soft-CCD pair test would drop (its contact events would stop and start again).
        let speed = linvel.length();
        let travel = if speed > 0.0 {
            (speed + self.g_dt) * self.dt
        } else {
            0.0
        };
        if travel > self.threshold {
            SOFT_CCD_REACH
        } else {
            0.0
        }
    }
}

#[cfg(test)]
mod tests {
    use shm_layout::{
        Handle, ObjectOp, ObjectProp, Pin, PlaneOp, PlaneProp, Pose, RotateTo, Shape,
    };

    use super::PARALLEL_FROM;
    use crate::backend::Backend;
    use crate::rapier3d::Plane;

    const CUBES: usize = 2_500;

    fn set(p: &mut Plane, h: Handle, prop: ObjectProp) {
        p.apply(PlaneOp::Object {
            handle: h,
            op: ObjectOp::Set(prop),
        })
        .unwrap();
    }

    /// Every tick's (state hash, max penetration bits, contact pairs) of a pile of cubes
    /// driven by ops of every kind the pass handles.
    fn run(threads: u32) -> (Vec<(u64, u32, u32)>, usize) {
        let mut p = Plane::new(
            1,
            &[
                PlaneProp::TickRate(0.0),
                PlaneProp::Threads(threads),
                PlaneProp::MaxAngularSpeed(3.0),
            ],
        )
        .unwrap();
        let cube = Shape::Cube {
            size: [1.0, 1.0, 1.0],
        };
        p.add_object(
            &Shape::Cube {
                size: [80.0, 1.0, 80.0],
            },
            Pose::at([30.0, -0.5, 30.0]),
            &[ObjectProp::Anchored(true)],
        )
        .unwrap();
        let cubes: Vec<Handle> = (0..CUBES)
            .map(|i| {
                let (column, layer) = (i / 5, i % 5);
                let at = [
                    (column % 23) as f32 * 1.25,
                    0.5 + layer as f32,
                    (column / 23) as f32 * 1.25,
                ];
                p.add_object(&cube, Pose::at(at), &[]).unwrap()
            })
            .collect();
        let mut ticks = Vec::new();
        let mut most_awake = 0;
        for t in 0..60 {
            if t % 7 == 3 {
                for k in 0..20 {
                    let h = cubes[(k * 131 + t) % CUBES];
                    set(&mut p, h, ObjectProp::Velocity([1.0, 4.0, -2.0]));
                }
            }
            match t {
                5 => {
                    for k in 0..50 {
                        set(
                            &mut p,
                            cubes[k * 37],
                            ObjectProp::ConstantForce([0.0, 60.0, 3.0]),
                        );
                    }
                }
                9 => set(
                    &mut p,
                    cubes[100],
                    ObjectProp::RotateTo(Some(RotateTo {
                        target: [0.0, 0.383, 0.0, 0.924],
                        strength: 20.0,
                    })),
                ),
                11 => set(
                    &mut p,
                    cubes[200],
                    ObjectProp::Pin(Some(Pin {
                        force: 500.0,
                        relative: [0.5, 0.5, 0.0],
                        target: Pose::at([3.0, 12.0, 3.0]),
                    })),
                ),
                13 => set(
                    &mut p,
                    cubes[301],
                    ObjectProp::AngularVelocity([0.0, 40.0, 0.0]),
                ),
                20 => {
                    p.set(PlaneProp::Drag(0.3)).unwrap();
                }
                25 => {
                    p.apply(PlaneOp::Object {
                        handle: cubes[400],
                        op: ObjectOp::Destroy,
                    })
                    .unwrap();
                }
                30 => {
                    let ball = Shape::Sphere { radius: 0.5 };
                    let down = [ObjectProp::Velocity([0.0, -30.0, 0.0])];
                    p.add_object(&ball, Pose::at([5.0, 20.0, 5.0]), &down)
                        .unwrap();
                }
                _ => {}
            }
            p.step(1.0 / 60.0).unwrap();
            let h = p.header();
            ticks.push((h.state_hash, h.max_penetration.to_bits(), h.contact_pairs));
            most_awake = most_awake.max(p.awake_count());
        }
        if threads > 1 {
            assert!(p.pool_for(PARALLEL_FROM).is_some(), "the plane has a pool");
        }
        (ticks, most_awake)
    }

    /// The passes a plane's pool runs (the pass before the step, the speed caps after it,
    /// the contact figures beside the state hash) give every tick bit for bit what the
    /// calling thread alone gives.
    #[test]
    fn threads_2_passes_match_threads_1_to_the_bit() {
        let (one, awake) = run(1);
        let (two, _) = run(2);
        assert!(
            awake >= PARALLEL_FROM,
            "{awake} bodies awake: the pool passes never ran"
        );
        assert!(one.windows(2).any(|w| w[0].0 != w[1].0), "the pile moves");
        assert!(
            one.iter().any(|t| t.2 as usize >= PARALLEL_FROM),
            "contact pairs"
        );
        for (tick, (a, b)) in one.iter().zip(&two).enumerate() {
            assert_eq!(a, b, "tick {tick}: Threads = 1 {a:x?}, Threads = 2 {b:x?}");
        }
    }
}

//! The rapier3d backend: one 3D plane is a rapier world, the slot table that gives bodies
//! stable handles, and the plane options. No I/O here: the server hands it ops and the
//! publisher writes what it reports.
//!
//! - `backend`: the [`Backend`](crate::backend::Backend) implementation (op routing).
//! - `objects`, `properties`, `part`: objects, their properties and their rapier mapping.
//! - `forces`, `solver`, `contacts`: the per-tick force pass, solver tuning, contacts.
//! - `body_pass`: the per-body pass before each step (forces, speed caps, contact
//!   prediction), and when a pass runs on the plane's pool (Threads > 1, large planes).
//! - `queries`, `collision_groups`: scene queries and the plane's collision-group table.
//! - `controllers`: kinematic character controllers, ticked before each step.
//! - `limits`: MaxLinearSpeed and MaxAngularSpeed.
//! - `joints`: joints, their error figures and breaking; `maps`: triangle-mesh maps.
//! - `thin`: thin colliders, whose contacts are recomputed every step.

mod backend;
mod body_pass;
mod clipped;
mod collision_groups;
mod contacts;
mod controllers;
mod explode;
mod forces;
mod held {
    //! Held objects: see `crate::backend::held`.
    crate::backend::held::held_bodies!(rapier3d);
}
mod adaptive;
mod articulations;
mod axis_motors;
mod capsule_contact;
#[cfg(test)]
mod ccd_tests;
mod contact_points;
#[cfg(test)]
mod joint_edge_tests;
mod joints;
mod limits;
mod map_store;
mod maps;
mod objects;
mod offload;
mod part;
mod pose_mirror;
mod probes;
mod properties;
mod publish;
mod queries;
mod rollback;
mod snapshot;
mod solver;
#[cfg(test)]
mod stack_tests;
mod thin;
#[cfg(test)]
mod unstepped;

use std::sync::mpsc;

use std::time::Instant;

use rapier3d::prelude::*;
use shm_layout::validate::MAX_HIT_BOX_QUALITY;
use shm_layout::{
    BodyState, CollisionGroups, CommandError, EventRecord, PlaneId, PlaneInfo, PlaneKind,
    PlaneProp, PlaneSettings, StateHasher, TickHeader,
};

use crate::backend::{HeaderFigures, SlotTable};
use part::Part;

pub use objects::MAX_SLOTS;
pub use offload::{no_other_engine, DeferHook, SimpleBody, SimplePose};
pub use snapshot::GpuSaved;

/// One object: its rapier body and what the API says about it.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
struct Body {
    handle: RigidBodyHandle,
    /// Boxed: the slot table stays small, so the publisher's pass over every slot reads one
    /// short entry per body (the part's settings are read only where they matter).
    part: Box<Part>,
    /// `FLAG_*` bits the plane adds to the published state (controllers).
    flags: u32,
}

/// One rapier3d plane.
pub struct Plane {
    /// The plane's id (stamped into its tick headers).
    pub id: PlaneId,
    settings: PlaneSettings,
    world: PhysicsWorld,
    bodies: SlotTable<Body>,
    /// Objects per HitBoxQuality value: the plane-wide solver scales with the maximum.
    quality_counts: [u32; MAX_HIT_BOX_QUALITY as usize + 1],
    /// Objects with a drive of their own (ImpulseDirection, ConstantForce, RotateTo, SetPin).
    driven: u32,
    /// Mesh vertices of all parts (for quotas).
    mesh_vertices: u64,
    /// Buffers of the per-body passes.
    pass: body_pass::Scratch,
    /// Objects a step must leave where it found them (see `held`).
    held: Vec<held::HeldBody>,
    /// The tick clock and the last step's figures (see `backend::clock`).
    clock: crate::backend::Clock,
    /// Bodies the last adaptive pass gave extra substeps (see `adaptive`).
    boosted: u32,
    /// Whether the last adaptive pass found a pair of a high mass ratio (see `adaptive`).
    stiffened: bool,
    /// Objects asking for contact events; the event collector runs only when > 0.
    reporting: u32,
    collision_tx: mpsc::Sender<CollisionEvent>,
    collision_rx: mpsc::Receiver<CollisionEvent>,
    force_tx: mpsc::Sender<ContactForceEvent>,
    tear_tx: mpsc::Sender<SoftBodyTearEvent>,
    events: Vec<EventRecord>,
    /// Running number of the next event (EventRecord::seq).
    event_seq: u64,
    /// Colliders removed since the last step with the object they belonged to, so their
    /// contact-stopped events still name it.
    removed: Vec<(ColliderHandle, shm_layout::Handle)>,
    /// Character controllers by slot; ticked before each step (none: nothing to do).
    controllers: controllers::Controllers,
    /// Events produced before the step (controllers), published with the step's events.
    pending_events: Vec<EventRecord>,
    /// The collision-group table objects' CollisionGroup indexes into.
    groups: CollisionGroups,
    /// Bodies an op added, moved or reshaped since the last step: a query first brings their
    /// colliders' poses and broad-phase boxes up to date, so it sees the change.
    query_stale: crate::backend::Marks<RigidBodyHandle>,
    /// Joints (see `joints`).
    joints: joints::Joints,
    /// Map pieces uploaded since the last build (see `maps`).
    map_pending: maps::PendingMap,
    /// [`StateHasher`] over every slot as the last step left it (the tick header's).
    state_hash: u64,
    /// Bytes of controller paths (counted against the owner's quota).
    state_bytes: crate::backend::counted::Counter,
    /// States of the last ticks while RollbackTicks > 0 (see `rollback`).
    rollback: rollback::Ring,
    /// Every slot's state as the last step left it, for the publisher (see `pose_mirror`).
    mirror: pose_mirror::PoseMirror,
}

impl Plane {
    /// A plane with default options, then `props` applied in order (`DeferGpu = true` is
    /// refused: see [`Plane::new_with`]).
    pub fn new(id: PlaneId, props: &[PlaneProp]) -> Result<Plane, CommandError> {
        Plane::new_with(id, props, &mut no_other_engine)
    }

    /// A plane with default options.
    fn empty(id: PlaneId) -> Plane {
        let settings = PlaneSettings::default();
        let mut world = PhysicsWorld::new();
        world.gravity = Vector::from(settings.gravity);
        let (collision_tx, collision_rx) = mpsc::channel();
        let (force_tx, _) = mpsc::channel();
        let (tear_tx, _) = mpsc::channel();
        Plane {
            id,
            settings,
            world,
            bodies: SlotTable::tracked("object", MAX_SLOTS),
            quality_counts: [0; MAX_HIT_BOX_QUALITY as usize + 1],
            driven: 0,
            mesh_vertices: 0,
            pass: body_pass::Scratch::default(),
            held: Vec::new(),
            clock: Default::default(),
            boosted: 0,
            stiffened: false,
            reporting: 0,
            collision_tx,
            collision_rx,
            force_tx,
            tear_tx,
            events: Vec::new(),
            event_seq: 0,
            removed: Vec::new(),
            groups: CollisionGroups::default(),
            controllers: Default::default(),
            pending_events: Vec::new(),
            query_stale: Default::default(),
            joints: joints::Joints::default(),
            map_pending: maps::PendingMap::default(),
            state_hash: 0,
            state_bytes: Default::default(),
            rollback: Default::default(),
            mirror: Default::default(),
        }
    }

    /// Applies one option (`DeferGpu = true` is refused: see [`Plane::set_with`]).
    pub fn set(&mut self, prop: PlaneProp) -> Result<(), CommandError> {
        self.apply_prop(prop, false, &mut no_other_engine)
    }

    /// Applies one option; `creating` allows the construction-only ones; `defer` takes
    /// `DeferGpu`.
    fn apply_prop(
        &mut self,
        prop: PlaneProp,
        creating: bool,
        defer: &mut DeferHook<'_>,
    ) -> Result<(), CommandError> {
        let before = self.settings;
        let prop = self.settings.apply(prop, creating)?;
        if let PlaneProp::DeferGpu(on) = prop {
            if let Err(mut e) = defer(self, on) {
                self.settings = before;
                e.message = match creating {
                    true => format!("{}; no plane was created", e.message),
                    false => format!("{}; plane {} stays on the CPU", e.message, self.id),
                };
                return Err(e);
            }
        }
        // Mapping onto rapier: options read at step time need nothing here.
        match prop {
            PlaneProp::Gravity(g) => self.world.gravity = Vector::from(g),
            PlaneProp::Threads(n) => self.set_threads(n)?,
            PlaneProp::NeverSleep(on) => self.set_never_sleep(on),
            _ => {}
        }
        // Forces changed: resting bodies must feel them (sleeping ones would ignore them).
        if prop.changes_forces() {
            self.world.wake_up_all(true);
        }
        self.bodies.mark_all();
        Ok(())
    }

    fn set_never_sleep(&mut self, on: bool) {
        let template = if on {
            RigidBodyActivation::cannot_sleep()
        } else {
            RigidBodyActivation::active()
        };
        for (_, body) in self.world.bodies.iter_mut() {
            let activation = body.activation_mut();
            activation.normalized_linear_threshold = template.normalized_linear_threshold;
            activation.angular_threshold = template.angular_threshold;
            body.wake_up(true);
        }
    }

    fn set_threads(&mut self, n: u32) -> Result<(), CommandError> {
        // Capped by the machine's cores; the plane reads back what it uses. Only a plane
        // that asks for parallelism pays for a pool, shared with the planes of its size.
        let used = crate::backend::pools::capped(n);
        self.settings.threads = used;
        let pool =
            if used > 1 {
                Some(crate::backend::pools::shared(used).map_err(|e| {
                    CommandError::new(shm_layout::ErrorKind::Internal, e.to_string())
                })?)
            } else {
                None
            };
        self.world.physics_pipeline.set_thread_pool(pool);
        Ok(())
    }

    /// Automatic ticks per second (0 = manual).
    pub fn tick_rate(&self) -> f32 {
        self.settings.tick_rate
    }

    /// Whether the plane advances.
    pub fn enabled(&self) -> bool {
        self.settings.enabled
    }

    /// Ticks stepped so far.
    pub fn tick(&self) -> u64 {
        self.clock.tick
    }

    /// Every option and figure of the plane.
    pub fn info(&self) -> PlaneInfo {
        PlaneInfo {
            id: self.id,
            kind: PlaneKind::Rapier3d,
            settings: self.settings,
            tick: self.clock.tick,
            object_count: self.bodies.live(),
            effective_solver_iterations: self.solver_settings(self.nominal_dt()).iterations as u32,
            max_hit_box_quality: self.max_quality(),
        }
    }

    /// Advances by `dt`. Returns false (and does nothing) when the plane is disabled.
    pub fn step(&mut self, dt: f32) -> Result<bool, CommandError> {
        // The last tick is kept before this one changes anything.
        if !self.begin_step(dt)? {
            return Ok(false);
        }
        let started = Instant::now();
        // Whether this step can change any published state: bodies awake, or ops since the
        // last step. A settled plane keeps its hash without rehashing every slot.
        let moving = self.clock.tick == 0
            || self.world.islands.num_active_bodies() > 0
            || !self.bodies.since_step().is_empty();
        // The clock advances by the step as asked; the simulation takes at least a
        // nanosecond (see `MIN_DYNAMIC_DT`).
        let asked = dt;
        let dt = crate::backend::engine_dt(dt);
        self.world.integration_parameters.dt = dt;
        self.tune_solver(dt);
        self.tick_controllers(dt);
        self.prepare_bodies(dt);
        self.joints_before_step();
        let hooks = contacts::RestThreshold {
            threshold: self.settings.rest_threshold,
            gravity: self.world.gravity,
        };
        self.held_before_step();
        // Planes of a shared pool take turns in rapier's step (see `pools::turn`).
        let pool = self.world.physics_pipeline.thread_pool();
        let turn = pool.as_deref().map(|pool| {
            crate::backend::pools::turn(pool)
                .lock()
                .unwrap_or_else(std::sync::PoisonError::into_inner)
        });
        // Contacts of objects removed since the last step still end with an event.
        if self.reporting > 0 || !self.removed.is_empty() {
            let collector = ChannelEventCollector::new(
                self.collision_tx.clone(),
                self.force_tx.clone(),
                self.tear_tx.clone(),
            );
            self.world.step_with_events(&hooks, &collector);
        } else {
            self.world.step_with_events(&hooks, &());
        }
        drop(turn);
        self.held_after_step();
        self.query_stale.clear();
        self.limit_speeds_after_step();
        self.bodies.stepped();
        self.clock.advance(asked);
        self.collect_events();
        self.joints_after_step(dt);
        self.removed.clear();
        let rehash = moving || self.awake_count() > 0;
        let mut mirror = std::mem::take(&mut self.mirror);
        if rehash {
            self.list_moved(&mut mirror.moved);
        }
        let (figures, hash) = self.figures_and_hash(rehash, &mut mirror);
        self.mirror = mirror;
        (self.clock.max_penetration, self.clock.contact_pairs) = figures;
        if let Some(hash) = hash {
            self.state_hash = hash;
        }
        self.adapt_solving();
        self.clock.timed(started);
        // Kept for Rewind off the tick's path (see `rollback`).
        self.rollback.note_step();
        Ok(true)
    }

    /// Events of the last step (contact started / stopped).
    pub fn events(&self) -> &[EventRecord] {
        &self.events
    }

    /// The header of the newest tick.
    pub fn header(&self) -> TickHeader {
        self.clock.header(
            self.id,
            HeaderFigures {
                slot_count: self.bodies.slot_count() as u32,
                body_count: self.bodies.live(),
                max_joint_error: self.joints.max_error,
                event_count: self.event_seq,
                state_hash: self.state_hash,
            },
        )
    }

    /// After a step: the contact figures of the tick header and, when `rehash`, the state
    /// hash. The hash is one sequential chain over every slot; on the plane's pool it runs
    /// beside the contact figures (themselves split over the pool), not after them.
    fn figures_and_hash(
        &self,
        rehash: bool,
        mirror: &mut pose_mirror::PoseMirror,
    ) -> ((f32, u32), Option<u64>) {
        let (slots, bodies, narrow_phase) =
            (&self.bodies, &self.world.bodies, &self.world.narrow_phase);
        let marks = slots.marks_made();
        let hash = move || rehash.then(move || mirror.rehash(slots, bodies, marks));
        let pairs = narrow_phase.contact_graph().raw_graph().raw_edges().len();
        let work = pairs + if rehash { slots.slot_count() } else { 0 };
        match self.pool_for(work) {
            Some(pool) => pool.install(|| {
                let split = pairs >= body_pass::PARALLEL_FROM;
                rayon::join(|| contacts::contact_figures(narrow_phase, split), hash)
            }),
            None => (contacts::contact_figures(narrow_phase, false), hash()),
        }
    }

    /// The slots this step can have changed without an op marking them, for the pose
    /// mirror's rehash: the bodies awake before the step (the body pass's list) and after
    /// it (a body outside both has not moved), and the controllers (their published flags
    /// change in the controllers' tick).
    fn list_moved(&self, moved: &mut Vec<u32>) {
        moved.clear();
        let bodies = &self.world.bodies;
        moved.extend(
            self.pass
                .handles
                .iter()
                .filter_map(|h| bodies.get(*h))
                .map(|b| b.user_data as u32),
        );
        moved.extend(self.awake_slots().map(|s| s as u32));
        moved.extend(self.controllers.keys().copied());
    }

    /// [`StateHasher`] over every slot's state now, in slot order. The tick header carries
    /// it as the last step left it (0 before the first step): right after a step any
    /// reader recomputes it from the sample's bodies; ops applied since show in the next
    /// tick's.
    pub fn state_hash(&self) -> u64 {
        let mut h = StateHasher::new();
        for i in 0..self.slot_count() {
            h.add(&self.body_state(i));
        }
        h.finish()
    }

    /// Length of the published body array.
    pub fn slot_count(&self) -> usize {
        self.bodies.slot_count()
    }

    /// Slots of the bodies rapier simulates now (awake dynamic and kinematic ones). A body
    /// outside this set has not moved since the step that put it to sleep.
    pub fn awake_slots(&self) -> impl Iterator<Item = usize> + '_ {
        // Every body carries its slot in user_data (set in add_object).
        self.world
            .active_bodies()
            .map(|(_, body)| body.user_data as usize)
    }

    /// Number of bodies in [`Plane::awake_slots`].
    pub fn awake_count(&self) -> usize {
        self.world.islands.num_active_bodies()
    }

    /// The published state of slot `i` (dead slots carry only their generation).
    pub fn body_state(&self, i: usize) -> BodyState {
        publish::body_state(&self.bodies, &self.world.bodies, i)
    }
}

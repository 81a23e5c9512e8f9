//! One 3D plane: a rapier world, the slot table that gives bodies stable handles, and the
//! plane options. No I/O here: the server feeds it commands and publishes what it reports.

mod objects;

use std::sync::mpsc;
use std::sync::Arc;
use std::time::Instant;

use rapier3d::prelude::*;
use shm_layout::{
    BodyState, CommandError, EventRecord, PlaneId, PlaneInfo, PlaneProp, TickHeader,
    EVENT_CONTACT_STARTED, EVENT_CONTACT_STOPPED, FLAG_ALIVE, FLAG_ANCHORED, FLAG_SLEEPING,
    LAYOUT_VERSION,
};

use crate::validate;

pub const MAX_THREADS: u32 = 64;
pub const MAX_TICK_RATE: f32 = 10_000.0;
/// Largest accepted step: longer steps are almost certainly a unit mistake.
pub const MAX_DT: f32 = 1.0;

/// One entry of the slot table. The generation grows every time the slot is reused.
#[derive(Debug, Clone, Copy, Default)]
struct Slot {
    generation: u32,
    body: Option<RigidBodyHandle>,
}

pub struct Plane {
    pub id: PlaneId,
    /// Client that created the plane; the plane is released when that client goes away.
    pub owner: u128,
    world: PhysicsWorld,
    slots: Vec<Slot>,
    free_slots: Vec<u32>,
    live: u32,
    threads: u32,
    tick_rate: f32,
    enabled: bool,
    tick: u64,
    sim_time: f64,
    last_step_us: f32,
    last_dt: f32,
    max_penetration: f32,
    contact_pairs: u32,
    /// Objects asking for contact events; the event collector runs only when > 0.
    reporting: u32,
    collision_tx: mpsc::Sender<CollisionEvent>,
    collision_rx: mpsc::Receiver<CollisionEvent>,
    force_tx: mpsc::Sender<ContactForceEvent>,
    tear_tx: mpsc::Sender<SoftBodyTearEvent>,
    events: Vec<EventRecord>,
}

impl Plane {
    /// A plane with default options, then `props` applied in order.
    pub fn new(id: PlaneId, owner: u128, props: &[PlaneProp]) -> Result<Plane, CommandError> {
        let mut world = PhysicsWorld::new();
        world.gravity = Vector::new(0.0, -50.0, 0.0);
        let (collision_tx, collision_rx) = mpsc::channel();
        let (force_tx, _) = mpsc::channel();
        let (tear_tx, _) = mpsc::channel();
        let mut plane = Plane {
            id,
            owner,
            world,
            slots: Vec::new(),
            free_slots: Vec::new(),
            live: 0,
            threads: 1,
            tick_rate: 60.0,
            enabled: true,
            tick: 0,
            sim_time: 0.0,
            last_step_us: 0.0,
            last_dt: 0.0,
            max_penetration: 0.0,
            contact_pairs: 0,
            reporting: 0,
            collision_tx,
            collision_rx,
            force_tx,
            tear_tx,
            events: Vec::new(),
        };
        for prop in props {
            plane.apply_prop(*prop, true)?;
        }
        Ok(plane)
    }

    /// Applies one option; `creating` allows the construction-only ones.
    pub fn set(&mut self, prop: PlaneProp) -> Result<(), CommandError> {
        self.apply_prop(prop, false)
    }

    fn apply_prop(&mut self, prop: PlaneProp, creating: bool) -> Result<(), CommandError> {
        match prop {
            PlaneProp::Gravity(g) => {
                self.world.gravity = Vector::from(validate::finite3("Gravity", g)?);
                // Sleeping bodies would ignore the new gravity until touched.
                self.world.wake_up_all(true);
            }
            PlaneProp::Threads(n) => {
                if !creating {
                    return Err(CommandError::invalid(format!(
                        "Threads is read-only after creation (tried to set {n})"
                    )));
                }
                if !(1..=MAX_THREADS).contains(&n) {
                    return Err(CommandError::invalid(format!(
                        "Threads must be within [1, {MAX_THREADS}], got {n}"
                    )));
                }
                self.set_threads(n)?;
            }
            PlaneProp::TickRate(hz) => {
                self.tick_rate = validate::in_range("TickRate", hz, 0.0, MAX_TICK_RATE)?;
            }
            PlaneProp::Enabled(on) => self.enabled = on,
        }
        Ok(())
    }

    fn set_threads(&mut self, n: u32) -> Result<(), CommandError> {
        // Only a plane that asks for parallelism pays for a pool of its own.
        let pool = if n > 1 {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(n as usize)
                .thread_name(move |i| format!("plane-worker-{i}"))
                .build()
                .map_err(|e| CommandError::new(shm_layout::ErrorKind::Internal, e.to_string()))?;
            Some(Arc::new(pool))
        } else {
            None
        };
        self.world.physics_pipeline.set_thread_pool(pool);
        self.threads = n;
        Ok(())
    }

    pub fn tick_rate(&self) -> f32 {
        self.tick_rate
    }

    pub fn enabled(&self) -> bool {
        self.enabled
    }

    pub fn tick(&self) -> u64 {
        self.tick
    }

    pub fn info(&self) -> PlaneInfo {
        PlaneInfo {
            id: self.id,
            gravity: self.world.gravity.into(),
            threads: self.threads,
            tick_rate: self.tick_rate,
            enabled: self.enabled,
            tick: self.tick,
            object_count: self.live,
        }
    }

    /// Advances by `dt`. Returns false (and does nothing) when the plane is disabled.
    pub fn step(&mut self, dt: f32) -> Result<bool, CommandError> {
        let dt = validate::positive("dt", dt)?;
        if dt > MAX_DT {
            return Err(CommandError::invalid(format!(
                "dt must be at most {MAX_DT} s, got {dt}"
            )));
        }
        if !self.enabled {
            return Ok(false);
        }
        let started = Instant::now();
        self.world.integration_parameters.dt = dt;
        if self.reporting > 0 {
            let collector = ChannelEventCollector::new(
                self.collision_tx.clone(),
                self.force_tx.clone(),
                self.tear_tx.clone(),
            );
            self.world.step_with_events(&(), &collector);
        } else {
            self.world.step();
        }
        self.tick += 1;
        self.sim_time += dt as f64;
        self.last_dt = dt;
        (self.max_penetration, self.contact_pairs) = self.contact_figures();
        self.collect_events();
        self.last_step_us = started.elapsed().as_secs_f32() * 1e6;
        Ok(true)
    }

    /// Deepest penetration and number of touching pairs, for the tick header.
    fn contact_figures(&self) -> (f32, u32) {
        let mut deepest = 0.0f32;
        let mut pairs = 0;
        for (_, contact) in self
            .world
            .narrow_phase
            .contact_pairs()
            .filter_map(|p| p.find_deepest_contact())
        {
            deepest = deepest.max(-contact.dist);
            pairs += 1;
        }
        (deepest, pairs)
    }

    fn collect_events(&mut self) {
        self.events.clear();
        while let Ok(event) = self.collision_rx.try_recv() {
            let kind = if event.started() {
                EVENT_CONTACT_STARTED
            } else {
                EVENT_CONTACT_STOPPED
            };
            let (Some(a), Some(b)) = (
                self.handle_of_collider(event.collider1()),
                self.handle_of_collider(event.collider2()),
            ) else {
                continue; // one side was removed in the same step
            };
            self.events.push(EventRecord {
                kind,
                a_slot: a.slot,
                a_generation: a.generation,
                b_slot: b.slot,
                b_generation: b.generation,
                _reserved: 0,
                tick: self.tick,
            });
        }
    }

    /// Events of the last step (contact started / stopped).
    pub fn events(&self) -> &[EventRecord] {
        &self.events
    }

    pub fn header(&self) -> TickHeader {
        TickHeader {
            layout_version: LAYOUT_VERSION,
            plane_id: self.id,
            tick: self.tick,
            sim_time: self.sim_time,
            tick_end_ns: 0,
            step_time_us: self.last_step_us,
            dt: self.last_dt,
            slot_count: self.slots.len() as u32,
            body_count: self.live,
            max_penetration: self.max_penetration,
            max_joint_error: 0.0,
            contact_pairs: self.contact_pairs,
            _reserved: 0,
        }
    }

    pub fn slot_count(&self) -> usize {
        self.slots.len()
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
        let slot = self.slots[i];
        let Some(body) = slot.body.and_then(|h| self.world.bodies.get(h)) else {
            return BodyState {
                generation: slot.generation,
                ..BodyState::default()
            };
        };
        let pose = body.position();
        let mut flags = FLAG_ALIVE;
        if body.is_sleeping() {
            flags |= FLAG_SLEEPING;
        }
        if body.is_fixed() {
            flags |= FLAG_ANCHORED;
        }
        BodyState {
            position: pose.translation.into(),
            flags,
            rotation: pose.rotation.into(),
            linear_velocity: body.linvel().into(),
            generation: slot.generation,
            angular_velocity: body.angvel().into(),
            _reserved: 0,
        }
    }
}

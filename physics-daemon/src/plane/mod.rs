//! One 3D plane: a rapier world, the slot table that gives bodies stable handles, and the
//! plane options. No I/O here: the server feeds it commands and publishes what it reports.

mod contacts;
mod forces;
mod objects;
mod part;
mod properties;
mod solver;

use std::sync::mpsc;
use std::sync::Arc;
use std::time::Instant;

use rapier3d::prelude::*;
use shm_layout::validate::{self, MAX_DT, MAX_HIT_BOX_QUALITY};
use shm_layout::{
    BodyState, CommandError, EventRecord, PlaneId, PlaneInfo, PlaneProp, TickHeader, Vec3,
    FLAG_ALIVE, FLAG_ANCHORED, FLAG_SLEEPING, LAYOUT_VERSION,
};

use part::Part;

/// One entry of the slot table. The generation grows every time the slot is reused.
#[derive(Debug, Default)]
struct Slot {
    generation: u32,
    body: Option<RigidBodyHandle>,
    part: Option<Part>,
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
    linear_damping: f32,
    angular_damping: f32,
    drag: f32,
    buoyancy: f32,
    constant_force: Vec3,
    rest_threshold: f32,
    solver_iterations: u32,
    loop_solver: bool,
    never_sleep: bool,
    /// Objects per HitBoxQuality value: the plane-wide solver scales with the maximum.
    quality_counts: [u32; MAX_HIT_BOX_QUALITY as usize + 1],
    /// Objects with a drive of their own (ImpulseDirection, ConstantForce, RotateTo, SetPin).
    driven: u32,
    /// Bodies changed by commands since the last step: the force pass sees them even
    /// before rapier's island manager lists them as awake.
    touched: Vec<RigidBodyHandle>,
    /// Bodies the last force pass left a force on (reset at the next pass).
    forced: Vec<RigidBodyHandle>,
    scratch: Vec<RigidBodyHandle>,
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
            linear_damping: 0.10,
            angular_damping: 0.30,
            drag: 0.0,
            buoyancy: 0.0,
            constant_force: [0.0; 3],
            rest_threshold: 0.5,
            solver_iterations: 4,
            loop_solver: false,
            never_sleep: false,
            quality_counts: [0; MAX_HIT_BOX_QUALITY as usize + 1],
            driven: 0,
            touched: Vec::new(),
            forced: Vec::new(),
            scratch: Vec::new(),
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
        let prop = prop.checked()?;
        match prop {
            PlaneProp::Gravity(g) => self.world.gravity = Vector::from(g),
            PlaneProp::Threads(n) => {
                if !creating {
                    return Err(CommandError::invalid(format!(
                        "Threads is read-only after creation (tried to set {n})"
                    )));
                }
                self.set_threads(n)?;
            }
            PlaneProp::TickRate(hz) => self.tick_rate = hz,
            PlaneProp::Enabled(on) => self.enabled = on,
            PlaneProp::LinearDamping(k) => self.linear_damping = k,
            PlaneProp::AngularDamping(k) => self.angular_damping = k,
            PlaneProp::Drag(k) => self.drag = k,
            PlaneProp::Buoyancy(b) => self.buoyancy = b,
            PlaneProp::ConstantForce(f) => self.constant_force = f,
            PlaneProp::RestThreshold(v) => self.rest_threshold = v,
            PlaneProp::SolverIterations(n) => self.solver_iterations = n,
            PlaneProp::LoopSolver(on) => self.loop_solver = on,
            PlaneProp::NeverSleep(on) => self.set_never_sleep(on),
        }
        // Forces changed: resting bodies must feel them (sleeping ones would ignore them).
        if matches!(
            prop,
            PlaneProp::Gravity(_) | PlaneProp::Buoyancy(_) | PlaneProp::ConstantForce(_)
        ) {
            self.world.wake_up_all(true);
        }
        Ok(())
    }

    fn set_never_sleep(&mut self, on: bool) {
        self.never_sleep = on;
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
            linear_damping: self.linear_damping,
            angular_damping: self.angular_damping,
            drag: self.drag,
            buoyancy: self.buoyancy,
            constant_force: self.constant_force,
            rest_threshold: self.rest_threshold,
            solver_iterations: self.solver_iterations,
            loop_solver: self.loop_solver,
            never_sleep: self.never_sleep,
            effective_solver_iterations: self.solver_settings().iterations as u32,
            max_hit_box_quality: self.max_quality(),
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
        self.tune_solver();
        self.apply_forces(dt);
        let hooks = contacts::RestThreshold(self.rest_threshold);
        if self.reporting > 0 {
            let collector = ChannelEventCollector::new(
                self.collision_tx.clone(),
                self.force_tx.clone(),
                self.tear_tx.clone(),
            );
            self.world.step_with_events(&hooks, &collector);
        } else {
            self.world.step_with_events(&hooks, &());
        }
        self.tick += 1;
        self.sim_time += dt as f64;
        self.last_dt = dt;
        (self.max_penetration, self.contact_pairs) = self.contact_figures();
        self.collect_events();
        self.last_step_us = started.elapsed().as_secs_f32() * 1e6;
        Ok(true)
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
        let slot = &self.slots[i];
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

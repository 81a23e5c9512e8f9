//! The GUI plane itself ([`Plane`]): its fields, creation and options, the step, and what
//! it publishes (tick header, body states). Ops, the force pass, controllers, queries,
//! snapshots and rollback are methods of it in files of their own.

use std::time::Instant;

use rapier2d::prelude::*;
use shm_layout::gui_op::GuiPlaneInfo;
use shm_layout::settings::gui_plane::GUI_TIME_UNTIL_SLEEP;
use shm_layout::settings::{GuiPlaneProp, GuiPlaneSettings};
use shm_layout::{
    BodyState, CommandError, EventRecord, PlaneId, PlaneInfo, PlaneKind, PlaneProp, PlaneSettings,
    StateHasher, TickHeader, FLAG_ALIVE, FLAG_ANCHORED, FLAG_SLEEPING,
};

use super::hooks;
use super::object::{HeldBody, Object, LENGTH_UNIT, MAX_SLOTS, WALLS_SLOT};
use super::state::State;
use crate::backend::rollback::Ring;
use crate::backend::{held, HeaderFigures, SlotTable};

/// One GUI plane.
pub struct Plane {
    /// The plane's id (stamped into its tick headers).
    pub id: PlaneId,
    pub(super) settings: GuiPlaneSettings,
    pub(super) world: PhysicsWorld,
    pub(super) bodies: SlotTable<Object>,
    /// Slots of bodies with a controller, in creation order.
    pub(super) controlled: Vec<u32>,
    /// Bodies with a force or a pending impulse of their own.
    pub(super) driven: u32,
    /// An op moved, added or reshaped a body since the last step (queries refresh first).
    pub(super) query_stale: crate::backend::Marks<RigidBodyHandle>,
    /// Bodies a step must leave where it found them (see `held`).
    pub(super) held: Vec<HeldBody>,
    /// The tick clock and the last step's figures (see `backend::clock`).
    pub(super) clock: crate::backend::Clock,
    pub(super) events: Vec<EventRecord>,
    pub(super) event_seq: u64,
    /// Bytes of controller paths and kept ticks (counted against the owner's quota).
    pub(super) state_bytes: crate::backend::counted::Counter,
    /// Its `Name`, unique in the domain (creation only; not part of its state).
    pub(super) name: shm_layout::PlaneName,
    /// Written to the daemon's state directory (creation only; not part of its state).
    pub(super) persistent: bool,
    /// `RollbackTicks`: ticks kept for `Rewind`.
    pub(super) rollback_ticks: u32,
    /// The kept ticks (see `rollback`).
    pub(super) rollback: Ring<State>,
}

impl Plane {
    /// A GUI plane with default options, then `props` applied in order. It accepts the GUI
    /// options (`PlaneProp::Gui`) and the options of every plane (`TickRate`, `Enabled`,
    /// `Shared`).
    pub fn new(id: PlaneId, props: &[PlaneProp]) -> Result<Plane, CommandError> {
        let settings = GuiPlaneSettings::default();
        let mut world = PhysicsWorld::new();
        world.gravity = Vector::from(settings.gravity);
        world.integration_parameters.length_unit = LENGTH_UNIT;
        let mut plane = Plane {
            id,
            settings,
            world,
            bodies: SlotTable::tracked("object", MAX_SLOTS),
            controlled: Vec::new(),
            driven: 0,
            query_stale: Default::default(),
            held: Vec::new(),
            clock: Default::default(),
            events: Vec::new(),
            event_seq: 0,
            state_bytes: Default::default(),
            name: shm_layout::PlaneName::NONE,
            persistent: false,
            rollback_ticks: 0,
            rollback: Default::default(),
        };
        for prop in props {
            plane.apply_prop(*prop, true)?;
        }
        if let Some((min, max)) = plane.settings.bounds {
            plane.build_walls(min, max);
        }
        Ok(plane)
    }

    /// Applies one option after creation.
    pub fn set(&mut self, prop: PlaneProp) -> Result<(), CommandError> {
        self.apply_prop(prop, false)
    }

    pub(super) fn apply_prop(
        &mut self,
        prop: PlaneProp,
        creating: bool,
    ) -> Result<(), CommandError> {
        match prop.checked()? {
            PlaneProp::TickRate(hz) => self.settings.tick_rate = hz,
            PlaneProp::Enabled(on) => self.settings.enabled = on,
            PlaneProp::Shared(on) if creating => self.settings.shared = on,
            PlaneProp::Shared(on) => {
                return Err(CommandError::invalid_field(
                    "Shared",
                    format!("Shared is read-only after creation (tried to set {on})"),
                ))
            }
            PlaneProp::Name(n) if creating => self.name = n,
            PlaneProp::Persistent(on) if creating => self.persistent = on,
            prop @ (PlaneProp::Name(_) | PlaneProp::Persistent(_)) => {
                return Err(CommandError::invalid_field(
                    prop.name(),
                    format!("{} can only be given at creation", prop.name()),
                ))
            }
            PlaneProp::RollbackTicks(k) => {
                self.rollback_ticks = k;
                if k == 0 {
                    self.rollback.clear();
                }
            }
            PlaneProp::Gui(g) => {
                let g = self.settings.apply(g, creating)?;
                match g {
                    GuiPlaneProp::Gravity(v) => self.world.gravity = Vector::from(v),
                    GuiPlaneProp::RestThreshold(_) | GuiPlaneProp::NeverSleep(_) => {
                        self.refresh_activation()
                    }
                    _ => {}
                }
                if g.changes_forces() {
                    self.world.wake_up_all(true);
                }
            }
            other => {
                return Err(CommandError::invalid_field(
                    other.name(),
                    format!(
                        "{} is an option of 3D planes; a GUI plane takes Gravity, \
                         LinearDamping, AngularDamping, Drag, ConstantForce, RestThreshold, \
                         SolverIterations, NeverSleep, BoundsMin/BoundsMax, TickRate, Enabled, \
                         Shared, Name, Persistent and RollbackTicks",
                        other.name()
                    ),
                ))
            }
        }
        self.bodies.mark_all();
        Ok(())
    }

    /// The sleep rule of the reference: a body whose speed stays below RestThreshold for
    /// 0.5 s sleeps; RestThreshold 0 or NeverSleep keeps bodies awake. Rapier measures the
    /// pose drift per step against `2 · threshold · dt`, hence the halving.
    pub(super) fn activation(&self) -> RigidBodyActivation {
        if self.settings.never_sleep || self.settings.rest_threshold <= 0.0 {
            return RigidBodyActivation::cannot_sleep();
        }
        let mut a = RigidBodyActivation::active();
        a.normalized_linear_threshold = self.settings.rest_threshold / (2.0 * LENGTH_UNIT);
        a.time_until_sleep = GUI_TIME_UNTIL_SLEEP;
        a
    }

    fn refresh_activation(&mut self) {
        let template = self.activation();
        for (_, body) in self.world.bodies.iter_mut() {
            let a = body.activation_mut();
            a.normalized_linear_threshold = template.normalized_linear_threshold;
            a.angular_threshold = template.angular_threshold;
            a.time_until_sleep = template.time_until_sleep;
            body.wake_up(true);
        }
    }

    /// Automatic ticks per second (0 = manual).
    pub fn tick_rate(&self) -> f32 {
        self.settings.tick_rate
    }

    /// Whether the plane advances.
    pub fn enabled(&self) -> bool {
        self.settings.enabled
    }

    /// Every GUI option and count.
    pub fn gui_info(&self) -> GuiPlaneInfo {
        GuiPlaneInfo {
            id: self.id,
            settings: self.settings,
            tick: self.clock.tick,
            object_count: self.bodies.live(),
            controller_count: self.controlled.len() as u32,
        }
    }

    /// The plane as every kind describes itself (`PlaneOp::Info`): the options planes share
    /// are filled in (Gravity as (x, y, 0)); the others are the 3D defaults. `GuiOp::Info`
    /// has every GUI option.
    pub fn info(&self) -> PlaneInfo {
        let s = &self.settings;
        PlaneInfo {
            id: self.id,
            kind: PlaneKind::Gui2d,
            settings: PlaneSettings {
                gravity: [s.gravity[0], s.gravity[1], 0.0],
                tick_rate: s.tick_rate,
                enabled: s.enabled,
                shared: s.shared,
                linear_damping: s.linear_damping,
                angular_damping: s.angular_damping,
                drag: s.drag,
                constant_force: [s.constant_force[0], s.constant_force[1], 0.0],
                rest_threshold: s.rest_threshold,
                solver_iterations: s.solver_iterations,
                never_sleep: s.never_sleep,
                name: self.name,
                persistent: self.persistent,
                rollback_ticks: self.rollback_ticks,
                ..PlaneSettings::default()
            },
            tick: self.clock.tick,
            object_count: self.bodies.live(),
            effective_solver_iterations: s.solver_iterations,
            max_hit_box_quality: 1,
        }
    }

    /// Advances by `dt`. Returns false (and does nothing) when the plane is disabled.
    pub fn step(&mut self, dt: f32) -> Result<bool, CommandError> {
        let dt = crate::backend::check_dt(dt)?;
        if !self.settings.enabled {
            return Ok(false);
        }
        let started = Instant::now();
        self.events.clear();
        // The clock advances by the step as asked; the simulation takes at least a
        // nanosecond (see `MIN_DYNAMIC_DT`).
        let asked = dt;
        let dt = crate::backend::engine_dt(dt);
        self.world.integration_parameters.dt = dt;
        self.world.integration_parameters.num_solver_iterations =
            self.settings.solver_iterations as usize;
        self.drive_controllers(dt);
        self.apply_forces(dt);
        held::before_step(&mut self.held, &self.world);
        self.world.step_with_events(&hooks::Hooks, &());
        held::after_step(&self.held, &mut self.world);
        self.query_stale.clear();
        self.bodies.stepped();
        self.clock.advance(asked);
        self.after_step_controllers();
        (self.clock.max_penetration, self.clock.contact_pairs) = self.contact_figures();
        self.clock.timed(started);
        self.keep_for_rollback();
        Ok(true)
    }

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

    /// Controller signals of the last step, in order.
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
                max_joint_error: 0.0,
                event_count: self.event_seq,
                state_hash: self.state_hash(),
            },
        )
    }

    /// [`StateHasher`] over every slot's published state, in slot order (what the tick
    /// header carries: any reader can recompute it from the sample's bodies).
    pub fn state_hash(&self) -> u64 {
        StateHasher::of_slots(self.slot_count(), |i| self.body_state(i))
    }

    /// Length of the published body array.
    pub fn slot_count(&self) -> usize {
        self.bodies.slot_count()
    }

    /// Slots of the bodies rapier simulates now.
    pub fn awake_slots(&self) -> impl Iterator<Item = usize> + '_ {
        self.world
            .active_bodies()
            .map(|(_, body)| body.user_data as usize)
            .filter(|slot| *slot != WALLS_SLOT)
    }

    /// Number of awake bodies.
    pub fn awake_count(&self) -> usize {
        self.world.islands.num_active_bodies()
    }

    /// The published state of slot `i` (dead slots carry only their generation).
    pub fn body_state(&self, i: usize) -> BodyState {
        let generation = self.bodies.generation(i);
        let Some(body) = self
            .bodies
            .at(i)
            .and_then(|b| self.world.bodies.get(b.handle))
        else {
            return BodyState {
                generation,
                ..BodyState::default()
            };
        };
        let mut flags = FLAG_ALIVE;
        if body.is_sleeping() {
            flags |= FLAG_SLEEPING;
        }
        if body.is_fixed() {
            flags |= FLAG_ANCHORED;
        }
        let p = body.translation();
        let half = body.rotation().angle() * 0.5;
        let v = body.linvel();
        BodyState {
            position: [p.x, p.y, 0.0],
            flags,
            rotation: [0.0, 0.0, half.sin(), half.cos()],
            linear_velocity: [v.x, v.y, 0.0],
            generation,
            angular_velocity: [0.0, 0.0, body.angvel()],
            _reserved: 0,
        }
    }

    /// Appends one event (running number assigned here).
    pub(super) fn push_event(&mut self, mut record: EventRecord) {
        record.tick = self.clock.tick;
        record.seq = self.event_seq;
        self.event_seq += 1;
        self.events.push(record);
    }
}

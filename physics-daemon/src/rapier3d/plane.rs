//! The 3D plane: the rapier world, the plane's options and clock, and the parts it owns
//! (objects, joints, controllers, contact events, history). [`Plane::step`] calls them in
//! one visible order. The ops that reach the parts are `impl Plane` blocks in the parts'
//! folders (`objects/ops.rs`, `joints/ops.rs`, ...), which nothing here imports.

use std::time::Instant;

use rapier3d::prelude::*;
use shm_layout::{
    BodyState, CommandError, EventRecord, PlaneId, PlaneInfo, PlaneKind, PlaneSettings,
    StateHasher, TickHeader,
};

use crate::backend::held::{self, HeldIn};
use crate::backend::rapier_world::RapierWorld;
use crate::backend::rollback::Duplicate;
use crate::backend::{HeaderFigures, SlotTable};
use crate::rapier3d::adaptive::Adaptive;
use crate::rapier3d::contacts::figures::contact_figures;
use crate::rapier3d::contacts::hooks::RestThreshold;
use crate::rapier3d::contacts::log::{Events, Kept as EventsKept};
use crate::rapier3d::controllers::Controllers;
use crate::rapier3d::history::pose_mirror::PoseMirror;
use crate::rapier3d::history::{publish, History};
use crate::rapier3d::joints::table::Joints;
use crate::rapier3d::objects::body_pass;
use crate::rapier3d::objects::object::{body_state, Object};
use crate::rapier3d::objects::tally::Kept as TallyKept;
use crate::rapier3d::objects::Objects;
use crate::rapier3d::queries::Queries;

/// One rapier3d plane.
pub struct Plane {
    /// The plane's id (stamped into its tick headers).
    pub id: PlaneId,
    pub(super) settings: PlaneSettings,
    pub(super) world: PhysicsWorld,
    /// The objects: the slot table, the tallies over their parts, the body pass's buffers
    /// and the pending map (see `objects`).
    pub(super) objects: Objects,
    /// Objects a step must leave where it found them (see `held`).
    held: Vec<HeldIn<PhysicsWorld>>,
    /// The tick clock and the last step's figures (see `backend::clock`).
    pub(super) clock: crate::backend::Clock,
    /// The adaptive pass's boosted bodies and stiffened contacts (see `adaptive`).
    pub(super) adaptive: Adaptive,
    /// The events of the last step and what contact events need across steps.
    pub(super) events: Events,
    /// Character controllers by slot; ticked before each step (none: nothing to do).
    pub(super) controllers: Controllers,
    /// The collision-group table and the bodies queries must bring up to date (see
    /// `queries`).
    pub(super) queries: Queries,
    /// Joints (see `joints`).
    pub(super) joints: Joints,
    /// Bytes of controller paths (counted against the owner's quota).
    pub(super) state_bytes: crate::backend::counted::Counter,
    /// The state hash and pose mirror of the last step, the ticks kept for Rewind (see
    /// `history`).
    pub(super) history: History<State>,
}

impl Plane {
    /// A plane with default options.
    pub(super) fn empty(id: PlaneId) -> Plane {
        let settings = PlaneSettings::default();
        let mut world = PhysicsWorld::new();
        world.gravity = Vector::from(settings.gravity);
        Plane {
            id,
            settings,
            world,
            objects: Objects::default(),
            held: Vec::new(),
            clock: Default::default(),
            adaptive: Adaptive::default(),
            events: Events::default(),
            controllers: Default::default(),
            queries: Queries::default(),
            joints: Joints::default(),
            state_bytes: Default::default(),
            history: History::default(),
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
            object_count: self.objects.live(),
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
            || !self.objects.since_step().is_empty();
        // The clock advances by the step as asked; the simulation takes at least a
        // nanosecond (see `MIN_DYNAMIC_DT`).
        let asked = dt;
        let dt = crate::backend::engine_dt(dt);
        self.world.integration_parameters.dt = dt;
        self.tune_solver(dt);
        self.tick_controllers(dt);
        self.prepare_bodies(dt);
        self.joints_before_step();
        let hooks = RestThreshold {
            threshold: self.settings.rest_threshold,
            gravity: self.world.gravity,
        };
        held::before_step(&mut self.held, &self.world);
        // Planes of a shared pool take turns in rapier's step (see `pools::turn`).
        let pool = self.world.physics_pipeline.thread_pool();
        let turn = pool.as_deref().map(|pool| {
            crate::backend::pools::turn(pool)
                .lock()
                .unwrap_or_else(std::sync::PoisonError::into_inner)
        });
        // Contacts of objects removed since the last step still end with an event.
        if self.events.listening() {
            let collector = self.events.collector();
            self.world.step_with_events(&hooks, &collector);
        } else {
            self.world.step_with_events(&hooks, &());
        }
        drop(turn);
        held::after_step(&self.held, &mut self.world);
        self.queries.step_done();
        self.limit_speeds_after_step();
        self.objects.stepped();
        self.clock.advance(asked);
        self.collect_events();
        self.joints_after_step(dt);
        self.events.step_done();
        let rehash = moving || self.awake_count() > 0;
        let mut mirror = std::mem::take(self.history.mirror_mut());
        if rehash {
            self.list_moved(&mut mirror.moved);
        }
        let (figures, hash) = self.figures_and_hash(rehash, &mut mirror);
        *self.history.mirror_mut() = mirror;
        (self.clock.max_penetration, self.clock.contact_pairs) = figures;
        self.adapt_solving();
        self.clock.timed(started);
        // The new hash; the tick is kept for Rewind off the tick's path (see `history`).
        self.history.stepped(hash);
        Ok(true)
    }

    /// Events of the last step (contact started / stopped).
    pub fn events(&self) -> &[EventRecord] {
        self.events.records()
    }

    /// The header of the newest tick.
    pub fn header(&self) -> TickHeader {
        self.clock.header(
            self.id,
            HeaderFigures {
                slot_count: self.objects.slot_count() as u32,
                body_count: self.objects.live(),
                max_joint_error: self.joints.max_error,
                event_count: self.events.count(),
                state_hash: self.history.hash(),
            },
        )
    }

    /// After a step: the contact figures of the tick header and, when `rehash`, the state
    /// hash. The hash is one sequential chain over every slot; on the plane's pool it runs
    /// beside the contact figures (themselves split over the pool), not after them.
    fn figures_and_hash(&self, rehash: bool, mirror: &mut PoseMirror) -> ((f32, u32), Option<u64>) {
        let (slots, bodies, narrow_phase) = (
            self.objects.table(),
            &self.world.bodies,
            &self.world.narrow_phase,
        );
        let marks = slots.marks_made();
        let hash = move || rehash.then(move || mirror.rehash(slots, bodies, marks));
        let pairs = narrow_phase.contact_graph().raw_graph().raw_edges().len();
        let work = pairs + if rehash { slots.slot_count() } else { 0 };
        match self.pool_for(work) {
            Some(pool) => pool.install(|| {
                let split = pairs >= body_pass::PARALLEL_FROM;
                rayon::join(|| contact_figures(narrow_phase, split), hash)
            }),
            None => (contact_figures(narrow_phase, false), hash()),
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
            self.objects
                .passed()
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
        StateHasher::of_slots(self.slot_count(), |i| self.body_state(i))
    }

    /// Length of the published body array.
    pub fn slot_count(&self) -> usize {
        self.objects.slot_count()
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

    /// Holds (`on`) or releases the rapier body `h` (see `held`).
    pub(super) fn set_held(&mut self, h: RigidBodyHandle, on: bool) {
        held::hold(&mut self.held, h, on);
    }

    /// The published state of slot `i` (dead slots carry only their generation).
    pub fn body_state(&self, i: usize) -> BodyState {
        body_state(self.objects.table(), &self.world.bodies, i)
    }

    /// [`crate::backend::Backend::write_states`] of this plane.
    pub(super) fn write_sample(
        &self,
        out: &mut [std::mem::MaybeUninit<BodyState>],
        filter: crate::backend::SlotFilter<'_>,
    ) {
        publish::write_sample(
            self.history.mirror(),
            self.objects.table(),
            &self.world,
            out,
            filter,
        );
    }
}

/// The plane's state, field list written once: `StateRef` borrows it to encode, `State`
/// owns it decoded, `clone_state` copies it (Rewind). The engine's world comes first; the
/// other fields are the plane's own and `Clone`, each `field: type = where the plane
/// holds it`.
macro_rules! plane_state {
    (world, $($vis:vis $field:ident: $ty:ty = $($place:ident).+,)*) => {
        #[derive(serde::Serialize)]
        pub(super) struct StateRef<'a> {
            world: &'a PhysicsWorld,
            $($field: &'a $ty,)*
        }

        #[derive(serde::Deserialize)]
        pub(super) struct State {
            pub(super) world: PhysicsWorld,
            $($vis $field: $ty,)*
        }

        impl Plane {
            /// The state as an owned copy (what Rewind keeps): the engine's sets cloned, its
            /// per-step workspaces fresh.
            pub(super) fn clone_state(&self) -> State {
                State { world: self.world.copy(), $($field: self.$($place).+.clone(),)* }
            }

            pub(super) fn state_ref(&self) -> StateRef<'_> {
                StateRef { world: &self.world, $($field: &self.$($place).+,)* }
            }

            pub(super) fn take_state(&mut self, state: State) {
                self.world = state.world;
                $(self.$($place).+ = state.$field;)*
            }
        }

        impl Duplicate for State {
            /// Another copy of a kept state (a second rewind to the same tick).
            fn duplicate(&self) -> State {
                State { world: self.world.copy(), $($field: self.$field.clone(),)* }
            }
        }

        impl State {
            /// The copy borrowed to encode (`Plane::snapshot_later`).
            pub(super) fn as_ref(&self) -> StateRef<'_> {
                StateRef { world: &self.world, $($field: &self.$field,)* }
            }
        }
    };
}

plane_state! {
    world,
    pub(super) settings: PlaneSettings = settings,
    pub(super) bodies: SlotTable<Object> = objects.bodies,
    pub(super) tally: TallyKept = objects.tally.kept,
    forced: Vec<RigidBodyHandle> = objects.pass.previous,
    held: Vec<HeldIn<PhysicsWorld>> = held,
    pub(super) clock: crate::backend::Clock = clock,
    adaptive: Adaptive = adaptive,
    events: EventsKept = events.kept,
    pub(super) controllers: Controllers = controllers,
    queries: Queries = queries,
    pub(super) joints: Joints = joints,
    pub(super) state_hash: u64 = history.state_hash,
}

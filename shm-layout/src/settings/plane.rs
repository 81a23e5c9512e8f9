//! Plane options: one row each in the plane settings table (wire variant, name, default,
//! range, stored field, flags).

use serde::{Deserialize, Serialize};

use super::gui_plane::GuiPlaneProp;
use super::row::Range;
use crate::error::CommandError;
use crate::geometry::Vec3;
use crate::plane_kind::PlaneKind;
use crate::plane_name::PlaneName;
use crate::validate::{MAX_SOLVER_ITERATIONS, MAX_THREADS, MAX_TICK_RATE, MIN_TICK_RATE};

super::table::settings_table! {
    /// A plane option. One row each: wire variant (row order is wire order: new rows go
    /// last), API name, default, range, stored field and flags (see [`super::table`]).
    /// Options flagged `creation_only` are rejected by a later `Set`.
    #[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
    pub enum PlaneProp;
    /// Every option of a plane, as set. [`Default`] holds the documented defaults.
    #[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
    pub struct PlaneSettings;
    rows {
        /// Acceleration applied to every non-anchored object (units/s²). Default (0, -50, 0).
        Gravity(Vec3) "Gravity" = [0.0, -50.0, 0.0], field: gravity, flags: [changes_forces, lua];
        /// Worker threads; a rayon pool is built only when > 1. Creation only. Default 1.
        Threads(u32) "Threads" = 1, range: Range::Within(1.0, MAX_THREADS as f64),
            field: threads, flags: [creation_only, lua];
        /// Ticks per second of wall time; 0 = manual (only `Step` advances the plane).
        /// Default 60.
        TickRate(f32) "TickRate" = 60.0, range: Range::Within(0.0, MAX_TICK_RATE as f64),
            check: check_tick_rate, field: tick_rate, flags: [lua];
        /// When false the plane does not advance. Default true.
        Enabled(bool) "Enabled" = true, field: enabled, flags: [lua];
        /// Per-second linear damping: each tick `v *= max(0, 1 - k·dt)`. Default 0.10.
        LinearDamping(f32) "LinearDamping" = 0.10, range: Range::NonNegative,
            field: linear_damping, flags: [lua];
        /// The same for angular velocity. Default 0.30.
        AngularDamping(f32) "AngularDamping" = 0.30, range: Range::NonNegative,
            field: angular_damping, flags: [lua];
        /// Quadratic drag coefficient: `F = -Drag·|v|·v`. Default 0.
        Drag(f32) "Drag" = 0.0, range: Range::NonNegative, field: drag, flags: [lua];
        /// Upward acceleration on every dynamic body. Default 0.
        Buoyancy(f32) "Buoyancy" = 0.0, field: buoyancy, flags: [changes_forces, lua];
        /// World-space force on every dynamic body (heavier bodies accelerate less).
        ConstantForce(Vec3) "ConstantForce" = [0.0; 3], field: constant_force,
            flags: [changes_forces, lua];
        /// Normal approach speed below which a contact does not bounce. Default 0.5.
        RestThreshold(f32) "RestThreshold" = 0.5, range: Range::NonNegative,
            field: rest_threshold, flags: [lua];
        /// Solver iterations per tick, clamped to [1, 64]. Default 4.
        SolverIterations(u32) "SolverIterations" = 4,
            range: Range::Clamped(1.0, MAX_SOLVER_ITERATIONS as f64), field: solver_iterations,
            flags: [derived, lua];
        /// Pins the solver at 64 iterations.
        LoopSolver(bool) "LoopSolver" = false, field: loop_solver, flags: [derived, lua];
        /// Keeps every body awake.
        NeverSleep(bool) "NeverSleep" = false, field: never_sleep, flags: [lua];
        /// Other clients may change the plane (set options, add and change objects, step it);
        /// without it they may only read. Only the owner may destroy it. Creation only.
        Shared(bool) "Shared" = false, field: shared, flags: [creation_only, lua];
        /// Largest linear speed of a body (units/s), enforced by the solver after every substep.
        /// Default [`DEFAULT_MAX_LINEAR_SPEED`]. Positive and finite.
        MaxLinearSpeed(f32) "MaxLinearSpeed" = DEFAULT_MAX_LINEAR_SPEED, range: Range::Positive,
            field: max_linear_speed, flags: [lua];
        /// Largest angular speed of a body (rad/s), enforced before and after every step.
        /// Default [`DEFAULT_MAX_ANGULAR_SPEED`]. Positive and finite.
        MaxAngularSpeed(f32) "MaxAngularSpeed" = DEFAULT_MAX_ANGULAR_SPEED,
            range: Range::Positive, field: max_angular_speed, flags: [lua];
        /// Runs the plane on the GPU (wgpu compute: spheres and axis-aligned boxes, single-point
        /// contacts, a spatial-hash broadphase) instead of rapier on the CPU. Default false. Safe
        /// to flip at run time: poses and velocities carry over.
        DeferGpu(bool) "DeferGpu" = false, field: defer_gpu, flags: [lua];
        /// An option of a GUI plane (`PhysicsService.NewGUI`); 3D planes refuse it.
        Gui(GuiPlaneProp) "Gui" = GuiPlaneProp::NeverSleep(false), check: GuiPlaneProp::checked;
        /// Most objects other clients (processes) may have added to a `Shared` plane at once;
        /// what they add counts against their own quotas. Only the owner sets it. Default
        /// [`NO_SHARED_OBJECT_LIMIT`]: no cap beyond the adders' quotas; 0: others add nothing.
        SharedObjectLimit(u32) "SharedObjectLimit" = NO_SHARED_OBJECT_LIMIT,
            field: shared_object_limit, flags: [lua];
        /// Ticks the plane keeps for `Rewind` (its state after each of its last K ticks,
        /// counted in the owner's state bytes). Default 0: nothing kept, nothing paid.
        RollbackTicks(u32) "RollbackTicks" = 0,
            range: Range::Within(0.0, MAX_ROLLBACK_TICKS as f64), field: rollback_ticks,
            flags: [lua];
        /// The plane's name: unique within the domain, so any process of the same user can
        /// `Open` it (see [`crate::plane_name`]). Creation only. Default: none.
        Name(PlaneName) "Name" = PlaneName::NONE, field: name, flags: [creation_only];
        /// Written to the daemon's `--state-dir` (every `--snapshot-every` seconds, on
        /// `Save` and at shutdown), kept when its owner leaves, and restored by the next
        /// daemon of the domain. Needs a `Name`. Creation only. Default false.
        Persistent(bool) "Persistent" = false, field: persistent, flags: [creation_only, lua];
        /// Islands whose contacts need it (a tall stack's deep contacts, a pair of bodies
        /// whose masses differ 100 times or more) get extra substeps after each step; the
        /// others pay nothing. Default true.
        AdaptiveSolving(bool) "AdaptiveSolving" = true, field: adaptive_solving, flags: [lua];
    }
    options: {
        /// Options of a new plane: the backend, then one field per plane option (`None`
        /// keeps the daemon's default). Either a struct literal
        /// (`PlaneOptions { tick_rate: Some(0.0), ..Default::default() }`) or a builder over
        /// [`PlaneProp`] (`PlaneOptions::manual().with(PlaneProp::Drag(0.1))`).
        #[derive(Debug, Clone, Default)]
        pub struct PlaneOptions {
            /// Which backend simulates the plane (default: rapier3d).
            pub kind: Option<PlaneKind>,
        }
    }
}

impl PlaneOptions {
    /// A manual plane: it advances only on `Step`. What tests and replays use.
    pub fn manual() -> Self {
        PlaneOptions {
            tick_rate: Some(0.0),
            ..Default::default()
        }
    }
}

/// Most ticks a plane keeps for `Rewind`.
pub const MAX_ROLLBACK_TICKS: u32 = 64;

/// A tick period must be representable: tiny positive rates are refused.
fn check_tick_rate(hz: f32) -> Result<f32, CommandError> {
    if hz != 0.0 && hz < MIN_TICK_RATE {
        return Err(CommandError::invalid_field(
            "TickRate",
            format!(
                "TickRate must be 0 (manual) or within [{MIN_TICK_RATE}, {MAX_TICK_RATE}], got {hz}"
            ),
        ));
    }
    Ok(hz)
}

/// Default `SharedObjectLimit`: no cap beyond the adders' own quotas.
pub const NO_SHARED_OBJECT_LIMIT: u32 = u32::MAX;

/// Default `MaxLinearSpeed`: 10,000 units/s. With units like Roblox studs (≈ 0.28 m) that is
/// about 2.8 km/s, above any projectile a game fires (a rifle bullet is ≈ 3,200 units/s) and
/// 200 s of free fall under the default gravity, while a runaway force still ends at a finite
/// speed instead of overflowing. Rapier's own default (400) would clip bullets and fast
/// vehicles.
pub const DEFAULT_MAX_LINEAR_SPEED: f32 = 10_000.0;

/// Default `MaxAngularSpeed`: 1,000 rad/s (about 9,500 rpm), above a car wheel of radius 0.5
/// at 300 units/s (600 rad/s) and a spinning propeller, while a runaway torque still ends at
/// a finite spin. Rapier's own cap (a quarter turn per tick, 47 rad/s at 60 Hz) would stop
/// wheels of ordinary vehicles.
pub const DEFAULT_MAX_ANGULAR_SPEED: f32 = 1_000.0;

impl PlaneSettings {
    /// Checks `prop` and stores it. `creating` allows the creation-only options. Returns the
    /// option as stored (clamped where documented).
    pub fn apply(&mut self, prop: PlaneProp, creating: bool) -> Result<PlaneProp, CommandError> {
        let prop = prop.checked()?;
        if prop.creation_only() && !creating {
            return Err(CommandError::invalid_field(
                prop.name(),
                format!(
                    "{} is read-only after creation (tried to set {})",
                    prop.name(),
                    prop.value_text()
                ),
            ));
        }
        if let PlaneProp::Gui(g) = prop {
            return Err(CommandError::invalid_field(
                g.name(),
                format!(
                    "{} {g:?} is an option of GUI planes, not of 3D planes",
                    g.name()
                ),
            ));
        }
        self.store(&prop);
        Ok(prop)
    }
}

impl PlaneProp {
    /// The option's name in the API (`"TickRate"`; a GUI option's own name).
    pub fn name(&self) -> &'static str {
        match self {
            PlaneProp::Gui(g) => g.name(),
            other => other.row().name,
        }
    }

    /// Options that only `CreatePlane` may set.
    pub fn creation_only(&self) -> bool {
        self.row().creation_only
    }

    /// Whether creation options `props` share the plane with other clients.
    pub fn shared_in(props: &[PlaneProp]) -> bool {
        props.contains(&PlaneProp::Shared(true))
    }

    /// Options that change the forces on resting bodies (which must then wake up).
    pub fn changes_forces(&self) -> bool {
        self.row().changes_forces
    }
}

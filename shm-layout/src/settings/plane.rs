//! Plane options: the wire variant, the defaults and the checks of each.

use serde::{Deserialize, Serialize};

use crate::validate::{finite, finite3, in_range, non_negative, positive};
use crate::validate::{MAX_SOLVER_ITERATIONS, MAX_THREADS, MAX_TICK_RATE, MIN_TICK_RATE};
use crate::{CommandError, Vec3};

/// A plane option. Options marked "creation only" are rejected by a later `Set`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum PlaneProp {
    /// Acceleration applied to every non-anchored object (units/s²).
    Gravity(Vec3),
    /// Worker threads; a rayon pool is built only when > 1. Creation only.
    Threads(u32),
    /// Ticks per second of wall time; 0 = manual (only `Step` advances the plane).
    TickRate(f32),
    /// When false the plane does not advance.
    Enabled(bool),
    /// Per-second linear damping: each tick `v *= max(0, 1 - k·dt)`. Default 0.10.
    LinearDamping(f32),
    /// The same for angular velocity. Default 0.30.
    AngularDamping(f32),
    /// Quadratic drag coefficient: `F = -Drag·|v|·v`. Default 0.
    Drag(f32),
    /// Upward acceleration on every dynamic body. Default 0.
    Buoyancy(f32),
    /// World-space force on every dynamic body (heavier bodies accelerate less).
    ConstantForce(Vec3),
    /// Normal approach speed below which a contact does not bounce. Default 0.5.
    RestThreshold(f32),
    /// Solver iterations per tick, clamped to [1, 64]. Default 4.
    SolverIterations(u32),
    /// Pins the solver at 64 iterations.
    LoopSolver(bool),
    /// Keeps every body awake.
    NeverSleep(bool),
    /// Other clients may change the plane (set options, add and change objects, step it);
    /// without it they may only read. Only the owner may destroy it. Creation only.
    Shared(bool),
    /// Largest linear speed of a body (units/s), enforced by the solver after every substep.
    /// Default [`DEFAULT_MAX_LINEAR_SPEED`]. Positive and finite.
    MaxLinearSpeed(f32),
    /// Largest angular speed of a body (rad/s), enforced before and after every step.
    /// Default [`DEFAULT_MAX_ANGULAR_SPEED`]. Positive and finite.
    MaxAngularSpeed(f32),
    /// Runs the plane on the GPU (wgpu compute: spheres and axis-aligned boxes, single-point
    /// contacts, a spatial-hash broadphase) instead of rapier on the CPU. Default false. Safe
    /// to flip at run time: poses and velocities carry over.
    DeferGpu(bool),
    /// An option of a GUI plane (`PhysicsService.NewGUI`); 3D planes refuse it.
    Gui(super::gui_plane::GuiPlaneProp),
    /// Most objects other clients (processes) may have added to a `Shared` plane at once;
    /// what they add counts against their own quotas. Only the owner sets it. Default
    /// [`NO_SHARED_OBJECT_LIMIT`]: no cap beyond the adders' quotas; 0: others add nothing.
    SharedObjectLimit(u32),
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

/// Every option of a plane, as set. [`Default`] holds the documented defaults.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PlaneSettings {
    /// `Gravity`, default (0, -50, 0).
    pub gravity: Vec3,
    /// `Threads`, default 1 (creation only).
    pub threads: u32,
    /// `TickRate`, default 60 Hz; 0 = manual.
    pub tick_rate: f32,
    /// `Enabled`, default true.
    pub enabled: bool,
    /// `LinearDamping`, default 0.10.
    pub linear_damping: f32,
    /// `AngularDamping`, default 0.30.
    pub angular_damping: f32,
    /// `Drag`, default 0.
    pub drag: f32,
    /// `Buoyancy`, default 0.
    pub buoyancy: f32,
    /// `ConstantForce`, default 0.
    pub constant_force: Vec3,
    /// `RestThreshold`, default 0.5.
    pub rest_threshold: f32,
    /// `SolverIterations` as set (clamped to [1, 64]), default 4.
    pub solver_iterations: u32,
    /// `LoopSolver`, default false.
    pub loop_solver: bool,
    /// `NeverSleep`, default false.
    pub never_sleep: bool,
    /// `Shared`, default false (creation only).
    pub shared: bool,
    /// `MaxLinearSpeed`, default [`DEFAULT_MAX_LINEAR_SPEED`] (10,000 units/s).
    pub max_linear_speed: f32,
    /// `MaxAngularSpeed`, default [`DEFAULT_MAX_ANGULAR_SPEED`] (1,000 rad/s).
    pub max_angular_speed: f32,
    /// `DeferGpu`, default false (the CPU, rapier).
    pub defer_gpu: bool,
    /// `SharedObjectLimit`, default [`NO_SHARED_OBJECT_LIMIT`].
    pub shared_object_limit: u32,
}

impl Default for PlaneSettings {
    fn default() -> Self {
        PlaneSettings {
            gravity: [0.0, -50.0, 0.0],
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
            shared: false,
            max_linear_speed: DEFAULT_MAX_LINEAR_SPEED,
            max_angular_speed: DEFAULT_MAX_ANGULAR_SPEED,
            defer_gpu: false,
            shared_object_limit: NO_SHARED_OBJECT_LIMIT,
        }
    }
}

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
        match prop {
            PlaneProp::Gravity(g) => self.gravity = g,
            PlaneProp::Threads(n) => self.threads = n,
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
            PlaneProp::NeverSleep(on) => self.never_sleep = on,
            PlaneProp::Shared(on) => self.shared = on,
            PlaneProp::MaxLinearSpeed(v) => self.max_linear_speed = v,
            PlaneProp::MaxAngularSpeed(w) => self.max_angular_speed = w,
            PlaneProp::DeferGpu(on) => self.defer_gpu = on,
            PlaneProp::SharedObjectLimit(n) => self.shared_object_limit = n,
            PlaneProp::Gui(g) => {
                return Err(CommandError::invalid_field(
                    g.name(),
                    format!(
                        "{} {g:?} is an option of GUI planes, not of 3D planes",
                        g.name()
                    ),
                ))
            }
        }
        Ok(prop)
    }
}

impl PlaneProp {
    /// The option's name in the API (`"TickRate"`).
    pub fn name(&self) -> &'static str {
        match self {
            PlaneProp::Gravity(_) => "Gravity",
            PlaneProp::Threads(_) => "Threads",
            PlaneProp::TickRate(_) => "TickRate",
            PlaneProp::Enabled(_) => "Enabled",
            PlaneProp::LinearDamping(_) => "LinearDamping",
            PlaneProp::AngularDamping(_) => "AngularDamping",
            PlaneProp::Drag(_) => "Drag",
            PlaneProp::Buoyancy(_) => "Buoyancy",
            PlaneProp::ConstantForce(_) => "ConstantForce",
            PlaneProp::RestThreshold(_) => "RestThreshold",
            PlaneProp::SolverIterations(_) => "SolverIterations",
            PlaneProp::LoopSolver(_) => "LoopSolver",
            PlaneProp::NeverSleep(_) => "NeverSleep",
            PlaneProp::Shared(_) => "Shared",
            PlaneProp::MaxLinearSpeed(_) => "MaxLinearSpeed",
            PlaneProp::MaxAngularSpeed(_) => "MaxAngularSpeed",
            PlaneProp::DeferGpu(_) => "DeferGpu",
            PlaneProp::Gui(g) => g.name(),
            PlaneProp::SharedObjectLimit(_) => "SharedObjectLimit",
        }
    }

    /// Options that only `CreatePlane` may set.
    pub fn creation_only(&self) -> bool {
        matches!(self, PlaneProp::Threads(_) | PlaneProp::Shared(_))
    }

    /// Whether creation options `props` share the plane with other clients.
    pub fn shared_in(props: &[PlaneProp]) -> bool {
        props.contains(&PlaneProp::Shared(true))
    }

    /// Options that change the forces on resting bodies (which must then wake up).
    pub fn changes_forces(&self) -> bool {
        matches!(
            self,
            PlaneProp::Gravity(_) | PlaneProp::Buoyancy(_) | PlaneProp::ConstantForce(_)
        )
    }

    fn value_text(&self) -> String {
        match *self {
            PlaneProp::Gravity(v) | PlaneProp::ConstantForce(v) => format!("{v:?}"),
            PlaneProp::Threads(n) | PlaneProp::SolverIterations(n) => n.to_string(),
            PlaneProp::TickRate(x)
            | PlaneProp::LinearDamping(x)
            | PlaneProp::AngularDamping(x)
            | PlaneProp::Drag(x)
            | PlaneProp::Buoyancy(x)
            | PlaneProp::RestThreshold(x)
            | PlaneProp::MaxLinearSpeed(x)
            | PlaneProp::MaxAngularSpeed(x) => x.to_string(),
            PlaneProp::Enabled(b)
            | PlaneProp::LoopSolver(b)
            | PlaneProp::NeverSleep(b)
            | PlaneProp::Shared(b)
            | PlaneProp::DeferGpu(b) => b.to_string(),
            PlaneProp::Gui(g) => format!("{g:?}"),
            PlaneProp::SharedObjectLimit(n) => n.to_string(),
        }
    }

    /// The option as the daemon applies it, or an error naming it and the value.
    pub fn checked(self) -> Result<PlaneProp, CommandError> {
        use PlaneProp::*;
        Ok(match self {
            Gravity(g) => Gravity(finite3("Gravity", g)?),
            Threads(n) if !(1..=MAX_THREADS).contains(&n) => {
                return Err(CommandError::invalid_field(
                    "Threads",
                    format!("Threads must be within [1, {MAX_THREADS}], got {n}"),
                ))
            }
            TickRate(hz) => {
                let hz = in_range("TickRate", hz, 0.0, MAX_TICK_RATE)?;
                // A tick period must be representable: tiny positive rates are refused.
                if hz != 0.0 && hz < MIN_TICK_RATE {
                    return Err(CommandError::invalid_field(
                        "TickRate",
                        format!(
                            "TickRate must be 0 (manual) or within [{MIN_TICK_RATE}, \
                             {MAX_TICK_RATE}], got {hz}"
                        ),
                    ));
                }
                TickRate(hz)
            }
            LinearDamping(k) => LinearDamping(non_negative("LinearDamping", k)?),
            AngularDamping(k) => AngularDamping(non_negative("AngularDamping", k)?),
            Drag(k) => Drag(non_negative("Drag", k)?),
            Buoyancy(b) => Buoyancy(finite("Buoyancy", b)?),
            ConstantForce(f) => ConstantForce(finite3("ConstantForce", f)?),
            RestThreshold(v) => RestThreshold(non_negative("RestThreshold", v)?),
            SolverIterations(n) => SolverIterations(n.clamp(1, MAX_SOLVER_ITERATIONS)),
            MaxLinearSpeed(v) => MaxLinearSpeed(positive("MaxLinearSpeed", v)?),
            MaxAngularSpeed(w) => MaxAngularSpeed(positive("MaxAngularSpeed", w)?),
            Gui(g) => Gui(g.checked()?),
            other => other,
        })
    }
}

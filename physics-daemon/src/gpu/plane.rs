//! [`GpuPlane`]: the 3D plane kind when the daemon has the GPU path, a wrapper around the
//! rapier3d plane behind the same backend seam. While `DeferGpu` is off it hands everything
//! to the rapier plane; while it is on, its [`GpuWorld`] steps the bodies instead of rapier.
//! The rapier world stays the store of everything but motion: objects are added, changed and
//! removed through it as on the CPU path, and each change is handed to the GPU world (its
//! slot re-uploaded); the GPU world owns poses and velocities, which are written back into
//! rapier bodies when an op needs them (the op's own body, every body before a query) and
//! when the plane flips back. The rapier plane keeps the tick clock, dirty marks and
//! snapshots (its `offload` surface); it does not know the GPU exists.
//!
//! Not on the GPU path (an error names the op and says to set DeferGpu = false): joints,
//! character controllers, triangle-mesh maps, RotateTo and SetPin. Queries run on the CPU
//! against the last GPU tick's poses. Contact events are not produced, bodies do not sleep,
//! CCD and HitBoxQuality do not apply.

use std::time::Instant;

use shm_layout::{
    BodyState, CommandError, CommandResult, ErrorKind, EventRecord, ObjectOp, ObjectProp, PlaneId,
    PlaneKind, PlaneOp, PlaneProp, Reply, StateHasher, TickHeader,
};

use super::broadphase::PairMode;
use super::context::context;
use super::world::{GpuWorld, StepEnv};
use crate::backend::{Backend, SlotFilter, SnapshotJob, Usage};
use crate::rapier3d::{self, GpuSaved};

fn unsupported(what: &str) -> CommandError {
    CommandError::new(
        ErrorKind::InvalidValue,
        format!(
            "{what} is not supported on the GPU path (DeferGpu = true); set DeferGpu = false first"
        ),
    )
}

/// A 3D plane that can run on the GPU: the rapier3d plane and, while `DeferGpu` is on, the
/// GPU world that steps its bodies. Reads through `Deref` go to the rapier plane (what does
/// not depend on where bodies move); everything that does is a method of its own here.
pub struct GpuPlane {
    plane: rapier3d::Plane,
    /// The GPU world while `DeferGpu` is on.
    gpu: Option<GpuWorld>,
}

impl std::ops::Deref for GpuPlane {
    type Target = rapier3d::Plane;

    fn deref(&self) -> &rapier3d::Plane {
        &self.plane
    }
}

impl std::ops::DerefMut for GpuPlane {
    fn deref_mut(&mut self) -> &mut rapier3d::Plane {
        &mut self.plane
    }
}

/// Moves `plane`'s motion onto the GPU (`on`) or back to rapier, carrying every body's pose
/// and velocity (the plane's [`rapier3d::DeferHook`]). Nothing changes on error.
fn flip(
    gpu: &mut Option<GpuWorld>,
    plane: &mut rapier3d::Plane,
    on: bool,
) -> Result<(), CommandError> {
    match (on, gpu.is_some()) {
        (true, false) => {
            if let Some(what) = plane.simple_refusal() {
                return Err(CommandError::invalid_field(
                    "DeferGpu",
                    format!(
                        "DeferGpu = true refused: plane {} has {what}, which the GPU path does \
                         not simulate",
                        plane.id
                    ),
                ));
            }
            let ctx = context().map_err(|e| {
                CommandError::invalid_field("DeferGpu", format!("DeferGpu = true failed: {e}"))
            })?;
            let mut world = GpuWorld::new(ctx);
            for slot in 0..plane.slot_count() {
                world.set_body(slot, plane.simple_body(slot));
            }
            *gpu = Some(world);
        }
        (false, true) => {
            pull_all(gpu, plane);
            *gpu = None;
            plane.wake_all();
        }
        _ => {}
    }
    Ok(())
}

/// Writes the GPU world's pose and velocities of `slot` into its rapier body.
fn pull(gpu: &Option<GpuWorld>, plane: &mut rapier3d::Plane, slot: usize) {
    if let Some(p) = gpu.as_ref().and_then(|g| g.pose(slot)) {
        plane.set_simple_pose(slot, p);
    }
}

fn pull_all(gpu: &Option<GpuWorld>, plane: &mut rapier3d::Plane) {
    for slot in 0..plane.slot_count() {
        pull(gpu, plane, slot);
    }
}

/// The GPU world a snapshot's GPU bodies make (`None` for a CPU snapshot). A snapshot of a
/// DeferGpu plane restores only where a GPU adapter is (the same adapter for bit for bit).
fn from_saved(saved: Option<GpuSaved>, defer_gpu: bool) -> Result<Option<GpuWorld>, CommandError> {
    let refused = |what: &str| {
        CommandError::new(ErrorKind::InvalidValue, format!("snapshot refused: {what}"))
    };
    let Some(saved) = saved else {
        return match defer_gpu {
            true => Err(refused("its DeferGpu plane holds no GPU bodies")),
            false => Ok(None),
        };
    };
    if !defer_gpu {
        return Err(refused("it holds GPU bodies for a plane not on the GPU"));
    }
    let ctx = context().map_err(|e| {
        CommandError::invalid_field(
            "DeferGpu",
            format!("the snapshot is of a DeferGpu plane and this daemon cannot run it: {e}"),
        )
    })?;
    let mode = match saved.brute_force {
        true => PairMode::BruteForce,
        false => PairMode::Hash,
    };
    GpuWorld::load(
        ctx,
        &saved.states,
        &saved.params,
        mode,
        (saved.max_penetration, saved.contact_pairs),
    )
    .map(Some)
    .map_err(|e| refused(&e))
}

impl GpuPlane {
    /// A plane with default options, then `props` applied in order (`DeferGpu = true` puts
    /// it on the GPU).
    pub fn new(id: PlaneId, props: &[PlaneProp]) -> Result<GpuPlane, CommandError> {
        let mut gpu = None;
        let plane =
            rapier3d::Plane::new_with(id, props, &mut |plane, on| flip(&mut gpu, plane, on))?;
        Ok(GpuPlane { plane, gpu })
    }

    /// Applies one option (`DeferGpu` moves the plane onto the GPU or back).
    pub fn set(&mut self, prop: PlaneProp) -> Result<(), CommandError> {
        let gpu = &mut self.gpu;
        self.plane
            .set_with(prop, &mut |plane, on| flip(gpu, plane, on))
    }

    /// Whether the plane runs on the GPU now.
    pub fn on_gpu(&self) -> bool {
        self.gpu.is_some()
    }

    /// Name of the GPU adapter the plane runs on, when it does.
    pub fn gpu_adapter(&self) -> Option<&str> {
        self.gpu.as_ref().map(|g| g.adapter())
    }

    /// Every overlapping pair of live collidable objects now, as `(slot, slot)` with the
    /// smaller slot first, found on the GPU through the spatial hash or by testing every
    /// pair. For tests and benchmarks; `None` unless the plane is on the GPU.
    pub fn gpu_pairs(&mut self, mode: PairMode) -> Option<Result<Vec<(u32, u32)>, String>> {
        self.gpu.as_mut().map(|g| g.pairs(mode))
    }

    /// Turns per-stage timing of GPU ticks on or off (for the benchmark; each stage is then
    /// submitted and waited for on its own). No effect off the GPU.
    pub fn set_gpu_stage_timing(&mut self, on: bool) {
        if let Some(g) = &mut self.gpu {
            g.set_stage_timing(on);
        }
    }

    /// With stage timing on, the wall time (s) of each stage of the last GPU tick
    /// ([`GpuWorld::stage_times`]); `None` off the GPU.
    pub fn gpu_stage_times(&self) -> Option<Vec<(&'static str, f64)>> {
        self.gpu.as_ref().map(|g| g.stage_times().to_vec())
    }

    /// Chooses how the GPU solver finds pairs (for the benchmark's brute-force runs).
    pub fn set_gpu_pair_mode(&mut self, mode: PairMode) {
        if let Some(g) = &mut self.gpu {
            g.set_pair_mode(mode);
        }
    }

    /// Advances by `dt` (on the GPU while DeferGpu is on). Returns false (and does nothing)
    /// when the plane is disabled.
    pub fn step(&mut self, dt: f32) -> Result<bool, CommandError> {
        if self.gpu.is_none() {
            return self.plane.step(dt);
        }
        if !self.plane.begin_step(dt)? {
            return Ok(false);
        }
        let started = Instant::now();
        let s = self.plane.settings();
        let env = StepEnv {
            dt,
            substeps: if s.loop_solver {
                64
            } else {
                s.solver_iterations.max(1)
            },
            gravity: s.gravity,
            constant_force: s.constant_force,
            buoyancy: s.buoyancy,
            linear_damping: s.linear_damping,
            angular_damping: s.angular_damping,
            drag: s.drag,
            max_linear_speed: s.max_linear_speed,
            max_angular_speed: s.max_angular_speed,
            rest_threshold: s.rest_threshold,
        };
        let id = self.plane.id;
        let gpu = self.gpu.as_mut().expect("on the GPU");
        gpu.step(&env).map_err(|e| {
            CommandError::new(ErrorKind::Internal, format!("GPU step of plane {id}: {e}"))
        })?;
        let figures = (gpu.max_penetration, gpu.contact_pairs);
        // Nothing sleeps on the GPU path: every step can move every body.
        let hash = self.state_hash();
        self.plane.simple_step_done(dt, figures, hash, started);
        Ok(true)
    }

    /// The published state of slot `i` (dead slots carry only their generation).
    pub fn body_state(&self, i: usize) -> BodyState {
        match &self.gpu {
            // The GPU path's poses live in its read-back, not in rapier's bodies.
            Some(gpu) => self.plane.state_with_pose(i, gpu.pose(i)),
            None => self.plane.body_state(i),
        }
    }

    /// [`StateHasher`] over every slot's state now, in slot order (see
    /// [`rapier3d::Plane::state_hash`]).
    pub fn state_hash(&self) -> u64 {
        if self.gpu.is_none() {
            return self.plane.state_hash();
        }
        StateHasher::of_slots(self.plane.slot_count(), |i| self.body_state(i))
    }

    /// Number of slots that may move in the next step (every slot on the GPU).
    pub fn awake_count(&self) -> usize {
        match self.gpu {
            Some(_) => self.plane.slot_count(),
            None => self.plane.awake_count(),
        }
    }

    /// A DeferGpu plane's GPU bodies (`None` on the CPU path).
    fn gpu_saved(&self) -> Option<GpuSaved> {
        let gpu = self.gpu.as_ref()?;
        let (states, params, mode) = gpu.save();
        Some(GpuSaved {
            states,
            params,
            brute_force: mode == PairMode::BruteForce,
            max_penetration: gpu.max_penetration,
            contact_pairs: gpu.contact_pairs,
        })
    }

    /// The plane's whole state as snapshot bytes, its GPU world included.
    pub fn snapshot(&self) -> Result<Vec<u8>, CommandError> {
        self.plane.snapshot_with(self.gpu_saved())
    }

    /// Becomes exactly the state of `bytes`, on the GPU when the snapshot's plane was.
    /// Nothing changes when the snapshot is refused.
    pub fn restore(&mut self, bytes: &[u8], overrides: &[PlaneProp]) -> Result<(), CommandError> {
        self.gpu = self.plane.restore_with(bytes, overrides, from_saved)?;
        Ok(())
    }

    /// Hands slot `slot` (as rapier now holds it) to the GPU world.
    fn push(&mut self, slot: usize) {
        let body = self.plane.simple_body(slot);
        if let Some(gpu) = &mut self.gpu {
            gpu.set_body(slot, body);
        }
    }

    fn push_all(&mut self) {
        for slot in 0..self.plane.slot_count() {
            self.push(slot);
        }
    }

    fn on_cpu(&mut self, op: PlaneOp) -> CommandResult {
        Backend::apply(&mut self.plane, op)
    }

    /// An op on a GPU plane: what the GPU path supports goes through the rapier world (the
    /// bodies it touches pulled from the GPU first and pushed back after), the rest is
    /// refused.
    fn apply_on_gpu(&mut self, op: PlaneOp) -> CommandResult {
        match op {
            PlaneOp::Controller(_) => Err(unsupported("a character controller op")),
            PlaneOp::Joint(_) => Err(unsupported("a joint op")),
            PlaneOp::Map(_) => Err(unsupported("a triangle-mesh map op")),
            PlaneOp::Query(_) => {
                pull_all(&self.gpu, &mut self.plane);
                self.on_cpu(op)
            }
            PlaneOp::CollisionGroups(_) => {
                let reply = self.on_cpu(op);
                self.push_all();
                reply
            }
            PlaneOp::Explode(_) => {
                pull_all(&self.gpu, &mut self.plane);
                let reply = self.on_cpu(op);
                self.push_all();
                reply
            }
            PlaneOp::AddObject { ref props, .. } => {
                for p in props {
                    check_gpu_prop(p)?;
                }
                let reply = self.on_cpu(op)?;
                if let Reply::Object { handle, .. } = reply {
                    self.push(handle.slot as usize);
                }
                Ok(reply)
            }
            PlaneOp::Object {
                handle,
                op: ref object_op,
            } => {
                if let ObjectOp::Set(p) = object_op {
                    check_gpu_prop(p)?;
                }
                let slot = handle.slot as usize;
                let live = self.plane.is_live(handle);
                if live {
                    pull(&self.gpu, &mut self.plane, slot);
                }
                let reply = self.on_cpu(op);
                if live {
                    self.push(slot);
                }
                reply
            }
            _ => self.on_cpu(op),
        }
    }
}

impl Backend for GpuPlane {
    fn kind(&self) -> PlaneKind {
        PlaneKind::Rapier3d
    }

    fn snapshot_later(&self) -> Option<Result<SnapshotJob, CommandError>> {
        Some(self.plane.snapshot_later_with(self.gpu_saved()))
    }

    fn idle_work(&mut self) -> Result<(), CommandError> {
        self.plane.idle_work()
    }

    fn has_idle_work(&self) -> bool {
        self.plane.has_idle_work()
    }

    fn apply(&mut self, op: PlaneOp) -> CommandResult {
        // The last tick is kept for Rewind before an op changes anything (see
        // `rapier3d::history`).
        self.plane.idle_work()?;
        match op {
            PlaneOp::Set(prop) => self.set(prop).map(|_| Reply::Done),
            PlaneOp::Snapshot => self.snapshot().map(Reply::Snapshot),
            PlaneOp::Restore { bytes, overrides } => {
                self.restore(&bytes, &overrides)?;
                Ok(Reply::Applied {
                    tick: self.plane.tick(),
                })
            }
            op if self.gpu.is_some() => self.apply_on_gpu(op),
            op => self.on_cpu(op),
        }
    }

    fn step(&mut self, dt: f32) -> Result<bool, CommandError> {
        GpuPlane::step(self, dt)
    }

    fn tick_rate(&self) -> f32 {
        self.plane.tick_rate()
    }

    fn enabled(&self) -> bool {
        self.plane.enabled()
    }

    fn tick(&self) -> u64 {
        self.plane.tick()
    }

    fn header(&self) -> TickHeader {
        self.plane.header()
    }

    fn slot_count(&self) -> usize {
        self.plane.slot_count()
    }

    fn awake_count(&self) -> usize {
        GpuPlane::awake_count(self)
    }

    fn for_each_awake(&self, f: &mut dyn FnMut(usize)) {
        match self.gpu {
            // Nothing sleeps on the GPU path.
            Some(_) => (0..self.plane.slot_count()).for_each(f),
            None => Backend::for_each_awake(&self.plane, f),
        }
    }

    fn drain_dirty(&mut self, into: &mut Vec<u32>) -> bool {
        self.plane.drain_dirty(into)
    }

    fn body_state(&self, i: usize) -> BodyState {
        GpuPlane::body_state(self, i)
    }

    fn write_states(&self, out: &mut [std::mem::MaybeUninit<BodyState>], filter: SlotFilter<'_>) {
        if self.gpu.is_none() {
            return self.plane.write_states(out, filter);
        }
        for (i, dst) in out.iter_mut().enumerate() {
            if filter.wants(i) {
                dst.write(self.body_state(i));
            }
        }
    }

    fn events(&self) -> &[EventRecord] {
        self.plane.events()
    }

    fn usage(&self) -> Usage {
        self.plane.usage()
    }
}

/// Object properties the GPU path cannot honour: rows flagged `cpu_only` in the object
/// settings table, set to anything but their default.
fn check_gpu_prop(p: &ObjectProp) -> Result<(), CommandError> {
    if p.row().cpu_only && !p.is_default() {
        return Err(unsupported(p.name()));
    }
    Ok(())
}

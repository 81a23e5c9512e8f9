//! One plane's GPU world: per-slot parameters and states mirrored on the CPU, the device
//! buffers (two state buffers the substeps ping-pong between), uploads of what changed, the
//! step (one submission per tick: forces, then per substep the broadphase and the solve)
//! and the readback of the states the tick publishes.

use std::num::NonZeroU64;
use std::sync::Arc;
use std::time::Instant;

use bytemuck::{Pod, Zeroable};

use super::broadphase::{grid, scan_levels, table_size, PairMode, SCAN_BLOCK};
use super::context::Context;

const WG: u32 = 128;

const F_ALIVE: u32 = 1;
const F_DYNAMIC: u32 = 2;
const F_COLLIDE: u32 = 4;
const F_SPHERE: u32 = 8;
const F_LARGE: u32 = 16;
const F_LOCK_X: u32 = 32;

/// A body's state as the shaders hold it (`pos.w`: deepest contact of the last substep;
/// `vel.w`: its contact count).
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
struct State {
    pos: [f32; 4],
    rot: [f32; 4],
    vel: [f32; 4],
    ang: [f32; 4],
}

/// A body's parameters as the shaders hold them (see `step.wgsl`'s `Param`).
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
struct Param {
    half: [f32; 4],
    accel: [f32; 4],
    mat: [f32; 4],
    bits: [u32; 4],
}

/// The uniform block (`step.wgsl`'s `Env`).
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, Pod, Zeroable)]
struct Env {
    gravity_h: [f32; 4],
    force: [f32; 4],
    damp: [f32; 4],
    limits: [f32; 4],
    counts: [u32; 4],
    mode: [u32; 4],
}

/// One body handed to the GPU world (the plane's own description of a simple body).
pub use crate::rapier3d::SimpleBody as GpuBody;

/// Plane-wide inputs of one tick.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepEnv {
    /// Tick length (s).
    pub dt: f32,
    /// Substeps (broadphase + solve each).
    pub substeps: u32,
    /// Gravity.
    pub gravity: [f32; 3],
    /// The plane's ConstantForce.
    pub constant_force: [f32; 3],
    /// Buoyancy (upward acceleration).
    pub buoyancy: f32,
    /// LinearDamping.
    pub linear_damping: f32,
    /// AngularDamping.
    pub angular_damping: f32,
    /// Drag.
    pub drag: f32,
    /// MaxLinearSpeed.
    pub max_linear_speed: f32,
    /// MaxAngularSpeed.
    pub max_angular_speed: f32,
    /// RestThreshold.
    pub rest_threshold: f32,
}

/// What one slot reads back (handed to the plane as it is).
pub use crate::rapier3d::SimplePose as GpuPose;

struct Buffers {
    capacity: usize,
    table: u32,
    lists_len: usize,
    env: wgpu::Buffer,
    params: wgpu::Buffer,
    /// Per-body velocity change of the tick's forces (bound in `bind`, never read here).
    _dv: wgpu::Buffer,
    state: [wgpu::Buffer; 2],
    atoms: wgpu::Buffer,
    index: wgpu::Buffer,
    lists: wgpu::Buffer,
    readback: wgpu::Buffer,
    /// `bind[k]` reads `state[k]` and writes `state[1 - k]`.
    bind: [wgpu::BindGroup; 2],
    /// Per scan level: its bind group and length.
    scan: Vec<(wgpu::BindGroup, u32)>,
    _scan_buffers: Vec<wgpu::Buffer>,
}

/// One plane's bodies on the GPU.
pub struct GpuWorld {
    ctx: Arc<Context>,
    states: Vec<State>,
    params: Vec<Param>,
    dirty: Vec<u32>,
    all_dirty: bool,
    buffers: Option<Buffers>,
    /// Which state buffer holds the current states.
    current: usize,
    cell: f32,
    large: Vec<u32>,
    mode: PairMode,
    /// Deepest contact of the last substep of the last tick.
    pub max_penetration: f32,
    /// Touching pairs in the last substep of the last tick.
    pub contact_pairs: u32,
    clock: StageClock,
}

/// Wall time of each stage of a tick, when on: the step then submits and waits after every
/// stage (slower than one submission, but each stage's share shows; CPU wall time works on
/// adapters without timestamp queries, such as lavapipe).
#[derive(Default)]
struct StageClock {
    on: bool,
    last: Option<Instant>,
    /// Seconds per stage, summed over the substeps of the last tick, in first-seen order.
    times: Vec<(&'static str, f64)>,
}

impl StageClock {
    fn start(&mut self) {
        self.times.clear();
        self.last = self.on.then(Instant::now);
    }

    /// Charges the time since the last mark to `stage`.
    fn mark(&mut self, stage: &'static str) {
        let Some(last) = self.last else {
            return;
        };
        let now = Instant::now();
        let secs = (now - last).as_secs_f64();
        match self.times.iter_mut().find(|t| t.0 == stage) {
            Some(t) => t.1 += secs,
            None => self.times.push((stage, secs)),
        }
        self.last = Some(now);
    }

    /// When on: submits what `encoder` holds, waits for it, charges the time to `stage`
    /// and leaves a fresh encoder.
    fn cut(
        &mut self,
        ctx: &Context,
        encoder: &mut wgpu::CommandEncoder,
        stage: &'static str,
    ) -> Result<(), String> {
        if !self.on {
            return Ok(());
        }
        let done = std::mem::replace(
            encoder,
            ctx.device.create_command_encoder(&Default::default()),
        );
        ctx.queue.submit([done.finish()]);
        ctx.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| format!("the GPU ({}) failed: {e}", ctx.adapter))?;
        self.mark(stage);
        Ok(())
    }
}

fn usage_storage() -> wgpu::BufferUsages {
    wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::COPY_SRC
}

impl GpuWorld {
    /// An empty world on the shared context.
    pub fn new(ctx: Arc<Context>) -> GpuWorld {
        GpuWorld {
            ctx,
            states: Vec::new(),
            params: Vec::new(),
            dirty: Vec::new(),
            all_dirty: true,
            buffers: None,
            current: 0,
            cell: 1.0,
            large: Vec::new(),
            mode: PairMode::Hash,
            max_penetration: 0.0,
            contact_pairs: 0,
            clock: StageClock::default(),
        }
    }

    /// Turns per-stage timing of the step on or off (see [`GpuWorld::stage_times`]).
    pub fn set_stage_timing(&mut self, on: bool) {
        self.clock.on = on;
    }

    /// With stage timing on, the wall time (s) of each stage of the last step, summed over
    /// its substeps: `upload`, `forces`, `count` (clearing the buckets and counting),
    /// `scan`, `scatter`, `solve`, `readback` (copy, map and copy out) and `figures` (the
    /// CPU pass over the read-back states). Empty when off.
    pub fn stage_times(&self) -> &[(&'static str, f64)] {
        &self.clock.times
    }

    /// The adapter this world runs on.
    pub fn adapter(&self) -> &str {
        &self.ctx.adapter
    }

    /// Chooses how the solver finds candidate pairs (the spatial hash by default).
    pub fn set_pair_mode(&mut self, mode: PairMode) {
        self.mode = mode;
    }

    /// Sets slot `slot` (growing the slot range as needed); `None` removes the body.
    pub fn set_body(&mut self, slot: usize, body: Option<GpuBody>) {
        if slot >= self.states.len() {
            self.states.resize(slot + 1, State::default());
            self.params.resize(slot + 1, Param::default());
            self.all_dirty = true;
        }
        let (state, param) = match body {
            None => (State::default(), Param::default()),
            Some(b) => {
                let mut flags = F_ALIVE;
                if b.inverse_mass > 0.0 {
                    flags |= F_DYNAMIC;
                }
                if b.collide {
                    flags |= F_COLLIDE;
                }
                if b.sphere.is_some() {
                    flags |= F_SPHERE;
                }
                for (i, locked) in b.locks.iter().enumerate() {
                    if *locked {
                        flags |= F_LOCK_X << i;
                    }
                }
                let r = b.sphere.unwrap_or(0.0);
                let [vx, vy, vz] = b.velocity;
                let [wx, wy, wz] = if b.sphere.is_some() {
                    b.angular_velocity
                } else {
                    [0.0; 3]
                };
                let [x, y, z] = b.position;
                let [hx, hy, hz] = b.half_extents;
                let [ax, ay, az] = b.acceleration;
                (
                    State {
                        pos: [x, y, z, 0.0],
                        rot: b.rotation,
                        vel: [vx, vy, vz, 0.0],
                        ang: [wx, wy, wz, 0.0],
                    },
                    Param {
                        half: [hx, hy, hz, r],
                        accel: [ax, ay, az, b.inverse_mass],
                        mat: [
                            b.bounciness,
                            b.friction,
                            if r > 0.0 { 2.5 / r } else { 0.0 },
                            0.0,
                        ],
                        bits: [flags, b.group_bit, b.group_mask, 0],
                    },
                )
            }
        };
        self.states[slot] = state;
        self.params[slot] = param;
        self.dirty.push(slot as u32);
    }

    /// The state of `slot` after the last step (or as set).
    pub fn pose(&self, slot: usize) -> Option<GpuPose> {
        let s = self.states.get(slot)?;
        if self.params[slot].bits[0] & F_ALIVE == 0 {
            return None;
        }
        Some(GpuPose {
            position: [s.pos[0], s.pos[1], s.pos[2]],
            rotation: s.rot,
            velocity: [s.vel[0], s.vel[1], s.vel[2]],
            angular_velocity: [s.ang[0], s.ang[1], s.ang[2]],
        })
    }

    /// Slots the world holds.
    pub fn slot_count(&self) -> usize {
        self.states.len()
    }

    /// Everything a later step reads, as bytes: each slot's state (64 bytes) and parameters
    /// (64 bytes) as the shaders hold them, and the pair mode (a snapshot of a DeferGpu
    /// plane; the grid is derived from the parameters at the next upload).
    pub fn save(&self) -> (Vec<u8>, Vec<u8>, PairMode) {
        (
            bytemuck::cast_slice(&self.states).to_vec(),
            bytemuck::cast_slice(&self.params).to_vec(),
            self.mode,
        )
    }

    /// A world holding what [`GpuWorld::save`] gave (uploaded whole at its first step), with
    /// the last tick's contact figures.
    pub fn load(
        ctx: Arc<Context>,
        states: &[u8],
        params: &[u8],
        mode: PairMode,
        figures: (f32, u32),
    ) -> Result<GpuWorld, String> {
        let size = std::mem::size_of::<State>();
        if !states.len().is_multiple_of(size) || states.len() != params.len() {
            return Err(format!(
                "GPU bodies of {} and {} bytes (64 bytes a slot each, as many of both)",
                states.len(),
                params.len()
            ));
        }
        let mut world = GpuWorld::new(ctx);
        world.states = bytemuck::pod_collect_to_vec(states);
        world.params = bytemuck::pod_collect_to_vec(params);
        world.mode = mode;
        (world.max_penetration, world.contact_pairs) = figures;
        Ok(world)
    }

    fn extents(&self) -> impl Iterator<Item = (u32, f32, bool)> + Clone + '_ {
        self.params.iter().enumerate().filter_map(|(i, p)| {
            let f = p.bits[0];
            (f & F_ALIVE != 0 && f & F_COLLIDE != 0).then(|| {
                let extent = 2.0 * p.half[0].max(p.half[1]).max(p.half[2]);
                (i as u32, extent, f & F_DYNAMIC != 0)
            })
        })
    }

    /// Brings the device buffers up to date with the slots set since the last upload.
    fn flush(&mut self, lists_len: usize) -> Result<(), String> {
        let n = self.states.len();
        let changed = self.all_dirty || !self.dirty.is_empty();
        let mut params_all = false;
        if changed {
            let (cell, large) = grid(self.extents());
            if cell != self.cell || large != self.large {
                params_all = true;
                self.cell = cell;
                self.large = large;
                let is_large: std::collections::HashSet<u32> = self.large.iter().copied().collect();
                for (i, p) in self.params.iter_mut().enumerate() {
                    if is_large.contains(&(i as u32)) {
                        p.bits[0] |= F_LARGE;
                    } else {
                        p.bits[0] &= !F_LARGE;
                    }
                }
            } else {
                for &slot in &self.dirty {
                    let p = &mut self.params[slot as usize];
                    if self.large.contains(&slot) {
                        p.bits[0] |= F_LARGE;
                    } else {
                        p.bits[0] &= !F_LARGE;
                    }
                }
            }
        }
        let lists_len = lists_len.max(n + 4);
        let fits = self
            .buffers
            .as_ref()
            .is_some_and(|b| b.capacity >= n && b.lists_len >= lists_len);
        if !fits {
            let capacity = n.next_power_of_two().max(1024);
            self.buffers = Some(self.allocate(capacity, lists_len.max(capacity + 4))?);
            self.current = 0;
            self.all_dirty = true;
        }
        let b = self.buffers.as_ref().expect("allocated");
        let queue = &self.ctx.queue;
        let state = &b.state[self.current];
        if self.all_dirty || self.dirty.len() > n / 16 {
            queue.write_buffer(&b.params, 0, bytemuck::cast_slice(&self.params));
            queue.write_buffer(state, 0, bytemuck::cast_slice(&self.states));
            params_all = false;
        } else {
            for &slot in &self.dirty {
                let i = slot as usize;
                queue.write_buffer(
                    &b.params,
                    (i * 64) as u64,
                    bytemuck::bytes_of(&self.params[i]),
                );
                queue.write_buffer(state, (i * 64) as u64, bytemuck::bytes_of(&self.states[i]));
            }
        }
        if params_all {
            queue.write_buffer(&b.params, 0, bytemuck::cast_slice(&self.params));
        }
        if changed && !self.large.is_empty() {
            queue.write_buffer(&b.lists, 0, bytemuck::cast_slice(&self.large));
        }
        self.dirty.clear();
        self.all_dirty = false;
        Ok(())
    }

    fn allocate(&self, capacity: usize, lists_len: usize) -> Result<Buffers, String> {
        let device = &self.ctx.device;
        let table = table_size(capacity);
        let state_bytes = (capacity * 64) as u64;
        let lists_bytes = (lists_len * 4) as u64;
        let biggest = state_bytes.max(lists_bytes);
        if biggest > self.ctx.max_binding {
            return Err(format!(
                "{capacity} bodies need a {biggest}-byte buffer; the GPU adapter {} binds at \
                 most {} bytes",
                self.ctx.adapter, self.ctx.max_binding
            ));
        }
        let buffer = |label: &str, size: u64, usage: wgpu::BufferUsages| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: size.max(16),
                usage,
                mapped_at_creation: false,
            })
        };
        let env = buffer(
            "env",
            std::mem::size_of::<Env>() as u64,
            wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        );
        let params = buffer("params", state_bytes, usage_storage());
        let dv = buffer("dv", (capacity * 16) as u64, usage_storage());
        let state = [
            buffer("state-a", state_bytes, usage_storage()),
            buffer("state-b", state_bytes, usage_storage()),
        ];
        let atoms = buffer("atoms", (2 * table as u64 + 4) * 4, usage_storage());
        let index = buffer(
            "index",
            (table as u64 + 4 * capacity as u64) * 4,
            usage_storage(),
        );
        let lists = buffer("lists", lists_bytes, usage_storage());
        let readback = buffer(
            "readback",
            state_bytes,
            wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        );
        fn whole(binding: u32, buffer: &wgpu::Buffer) -> wgpu::BindGroupEntry<'_> {
            wgpu::BindGroupEntry {
                binding,
                resource: buffer.as_entire_binding(),
            }
        }
        let bind = |k: usize| {
            device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("step"),
                layout: &self.ctx.step_layout,
                entries: &[
                    whole(0, &env),
                    whole(1, &params),
                    whole(2, &dv),
                    whole(3, &state[k]),
                    whole(4, &state[1 - k]),
                    whole(5, &atoms),
                    whole(6, &index),
                    whole(7, &lists),
                ],
            })
        };
        let bind = [bind(0), bind(1)];
        let levels = scan_levels(table);
        let mut scan_buffers = Vec::new();
        let mut scan = Vec::new();
        // sums[k] holds the block totals of level k.
        let sums: Vec<wgpu::Buffer> = levels
            .iter()
            .map(|len| {
                buffer(
                    "scan-sums",
                    (len.div_ceil(SCAN_BLOCK) as u64) * 4,
                    usage_storage(),
                )
            })
            .collect();
        for (k, len) in levels.iter().enumerate() {
            let uniform = buffer(
                "scan-len",
                16,
                wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            );
            self.ctx
                .queue
                .write_buffer(&uniform, 0, bytemuck::bytes_of(&[*len, 0, 0, 0]));
            let data = if k == 0 {
                wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                    buffer: &index,
                    offset: 0,
                    size: NonZeroU64::new(table as u64 * 4),
                })
            } else {
                sums[k - 1].as_entire_binding()
            };
            let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("scan"),
                layout: &self.ctx.scan_layout,
                entries: &[
                    wgpu::BindGroupEntry {
                        binding: 0,
                        resource: data,
                    },
                    whole(1, &sums[k]),
                    whole(2, &uniform),
                ],
            });
            scan.push((group, *len));
            scan_buffers.push(uniform);
        }
        scan_buffers.extend(sums);
        Ok(Buffers {
            capacity,
            table,
            lists_len,
            env,
            params,
            _dv: dv,
            state,
            atoms,
            index,
            lists,
            readback,
            bind,
            scan,
            _scan_buffers: scan_buffers,
        })
    }

    fn env(&self, step: &StepEnv, mode: PairMode, pair_capacity: u32) -> Env {
        let b = self.buffers.as_ref().expect("allocated");
        let k = step.substeps.max(1);
        let h = step.dt / k as f32;
        let [gx, gy, gz] = step.gravity;
        let [fx, fy, fz] = step.constant_force;
        let angular_keep = (1.0 - step.angular_damping * step.dt).max(0.0);
        Env {
            gravity_h: [gx * h, gy * h, gz * h, h],
            force: [fx, fy, fz, step.buoyancy],
            damp: [
                (1.0 - step.linear_damping * step.dt).max(0.0),
                angular_keep.powf(1.0 / k as f32),
                step.drag,
                step.dt,
            ],
            limits: [
                step.max_linear_speed,
                step.max_angular_speed,
                step.rest_threshold,
                self.cell,
            ],
            counts: [
                self.states.len() as u32,
                b.table,
                self.large.len() as u32,
                k,
            ],
            mode: [(mode == PairMode::BruteForce) as u32, pair_capacity, 0, 0],
        }
    }

    /// Encodes the hash grid build over the current states.
    fn encode_grid(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        clock: &mut StageClock,
    ) -> Result<(), String> {
        let b = self.buffers.as_ref().expect("allocated");
        let ctx = &self.ctx;
        let groups = (self.states.len() as u32).div_ceil(WG);
        let t = b.table as u64 * 4;
        encoder.clear_buffer(&b.atoms, 0, Some(t));
        {
            let mut pass = encoder.begin_compute_pass(&Default::default());
            pass.set_bind_group(0, &b.bind[self.current], &[]);
            pass.set_pipeline(&ctx.count);
            pass.dispatch_workgroups(groups, 1, 1);
        }
        clock.cut(ctx, encoder, "count")?;
        encoder.copy_buffer_to_buffer(&b.atoms, 0, &b.index, 0, Some(t));
        {
            let mut pass = encoder.begin_compute_pass(&Default::default());
            pass.set_pipeline(&ctx.scan_blocks);
            for (group, len) in &b.scan {
                pass.set_bind_group(0, group, &[]);
                pass.dispatch_workgroups(len.div_ceil(SCAN_BLOCK), 1, 1);
            }
            pass.set_pipeline(&ctx.add_sums);
            for (group, len) in b.scan.iter().rev().skip(1) {
                pass.set_bind_group(0, group, &[]);
                pass.dispatch_workgroups(len.div_ceil(SCAN_BLOCK), 1, 1);
            }
        }
        encoder.copy_buffer_to_buffer(&b.index, 0, &b.atoms, t, Some(t));
        clock.cut(ctx, encoder, "scan")?;
        {
            let mut pass = encoder.begin_compute_pass(&Default::default());
            pass.set_bind_group(0, &b.bind[self.current], &[]);
            pass.set_pipeline(&ctx.scatter);
            pass.dispatch_workgroups(groups, 1, 1);
        }
        clock.cut(ctx, encoder, "scatter")
    }

    /// Advances every body by `step.dt` in `step.substeps` substeps, then reads the states
    /// back.
    pub fn step(&mut self, step: &StepEnv) -> Result<(), String> {
        let mut clock = std::mem::take(&mut self.clock);
        clock.start();
        let stepped = self.step_with(step, &mut clock);
        self.clock = clock;
        stepped
    }

    fn step_with(&mut self, step: &StepEnv, clock: &mut StageClock) -> Result<(), String> {
        self.flush(0)?;
        let n = self.states.len();
        if n == 0 {
            return Ok(());
        }
        let env = self.env(step, self.mode, 0);
        let ctx = self.ctx.clone();
        let b = self.buffers.as_ref().expect("allocated");
        ctx.queue.write_buffer(&b.env, 0, bytemuck::bytes_of(&env));
        let groups = (n as u32).div_ceil(WG);
        let mut encoder = ctx
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("gpu-step"),
            });
        // An empty submission runs the writes flush and the env queued.
        clock.cut(&ctx, &mut encoder, "upload")?;
        {
            let mut pass = encoder.begin_compute_pass(&Default::default());
            pass.set_bind_group(0, &b.bind[self.current], &[]);
            pass.set_pipeline(&ctx.forces);
            pass.dispatch_workgroups(groups, 1, 1);
        }
        clock.cut(&ctx, &mut encoder, "forces")?;
        for _ in 0..env.counts[3] {
            if self.mode == PairMode::Hash {
                self.encode_grid(&mut encoder, clock)?;
            }
            let b = self.buffers.as_ref().expect("allocated");
            {
                let mut pass = encoder.begin_compute_pass(&Default::default());
                pass.set_bind_group(0, &b.bind[self.current], &[]);
                pass.set_pipeline(&ctx.solve);
                pass.dispatch_workgroups(groups, 1, 1);
            }
            clock.cut(&ctx, &mut encoder, "solve")?;
            self.current = 1 - self.current;
        }
        let b = self.buffers.as_ref().expect("allocated");
        let bytes = (n * 64) as u64;
        encoder.copy_buffer_to_buffer(&b.state[self.current], 0, &b.readback, 0, Some(bytes));
        ctx.queue.submit([encoder.finish()]);
        read_back(
            &ctx,
            &b.readback,
            bytes,
            bytemuck::cast_slice_mut(&mut self.states),
        )?;
        clock.mark("readback");
        let (mut deepest, mut touching) = (0.0f32, 0.0f32);
        for s in &self.states {
            deepest = deepest.max(s.pos[3]);
            touching += s.vel[3];
        }
        self.max_penetration = deepest;
        self.contact_pairs = (touching / 2.0).round() as u32;
        clock.mark("figures");
        Ok(())
    }

    /// Every pair of live collidable bodies whose shapes overlap now, `(a, b)` with `a < b`,
    /// sorted, found through the spatial hash or by testing every pair. For tests and the
    /// benchmark; the step never reads pairs back.
    pub fn pairs(&mut self, mode: PairMode) -> Result<Vec<(u32, u32)>, String> {
        let n = self.states.len();
        let capacity = (64 * n + 1024) as u32;
        self.flush(self.large.len().max(n) + 4 + 2 * capacity as usize)?;
        if n == 0 {
            return Ok(Vec::new());
        }
        let ctx = self.ctx.clone();
        let env = self.env(
            &StepEnv {
                dt: 1.0,
                substeps: 1,
                gravity: [0.0; 3],
                constant_force: [0.0; 3],
                buoyancy: 0.0,
                linear_damping: 0.0,
                angular_damping: 0.0,
                drag: 0.0,
                max_linear_speed: 1.0,
                max_angular_speed: 1.0,
                rest_threshold: 0.0,
            },
            mode,
            capacity,
        );
        let b = self.buffers.as_ref().expect("allocated");
        ctx.queue.write_buffer(&b.env, 0, bytemuck::bytes_of(&env));
        let mut encoder = ctx.device.create_command_encoder(&Default::default());
        encoder.clear_buffer(&b.atoms, 0, None);
        if mode == PairMode::Hash {
            self.encode_grid(&mut encoder, &mut StageClock::default())?;
        }
        {
            let mut pass = encoder.begin_compute_pass(&Default::default());
            pass.set_bind_group(0, &b.bind[self.current], &[]);
            pass.set_pipeline(&ctx.pairs);
            pass.dispatch_workgroups((n as u32).div_ceil(WG), 1, 1);
        }
        let large = self.large.len() as u64 * 4;
        let pair_bytes = capacity as u64 * 8;
        let out = ctx.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("pairs-readback"),
            size: 16 + pair_bytes,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        encoder.copy_buffer_to_buffer(&b.atoms, 2 * b.table as u64 * 4, &out, 0, Some(16));
        encoder.copy_buffer_to_buffer(&b.lists, large, &out, 16, Some(pair_bytes));
        ctx.queue.submit([encoder.finish()]);
        let mut raw = vec![0u32; 4 + 2 * capacity as usize];
        read_back(
            &ctx,
            &out,
            16 + pair_bytes,
            bytemuck::cast_slice_mut(&mut raw),
        )?;
        let found = raw[0];
        if found > capacity {
            return Err(format!(
                "{found} overlapping pairs exceed the pair list's {capacity}"
            ));
        }
        let mut pairs: Vec<(u32, u32)> = raw[4..4 + 2 * found as usize]
            .chunks_exact(2)
            .map(|p| (p[0], p[1]))
            .collect();
        pairs.sort_unstable();
        Ok(pairs)
    }
}

/// Maps `buffer`'s first `bytes` bytes after the queued work is done and copies them out.
fn read_back(
    ctx: &Context,
    buffer: &wgpu::Buffer,
    bytes: u64,
    into: &mut [u8],
) -> Result<(), String> {
    let slice = buffer.slice(0..bytes);
    let (tx, rx) = std::sync::mpsc::channel();
    slice.map_async(wgpu::MapMode::Read, move |r| {
        let _ = tx.send(r);
    });
    ctx.device
        .poll(wgpu::PollType::wait_indefinitely())
        .map_err(|e| format!("the GPU ({}) failed: {e}", ctx.adapter))?;
    rx.recv()
        .map_err(|_| "the GPU readback was dropped".to_string())?
        .map_err(|e| format!("the GPU readback failed: {e}"))?;
    {
        let view = slice
            .get_mapped_range()
            .map_err(|e| format!("the GPU readback failed: {e}"))?;
        into[..bytes as usize].copy_from_slice(&view);
    }
    buffer.unmap();
    Ok(())
}

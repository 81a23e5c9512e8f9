//! `DeferGpu`: the plane's bodies stepped by the GPU world ([`crate::gpu::GpuWorld`]) instead
//! of rapier. The rapier world stays the store of everything but motion: objects are added,
//! changed and removed through it as on the CPU path, and each change is handed to the GPU
//! world (its slot re-uploaded); the GPU world owns poses and velocities, which are written
//! back into rapier bodies when an op needs them (the op's own body, every body before a
//! query) and when the plane flips back.
//!
//! Not on the GPU path (an error names the op and says to set DeferGpu = false): joints,
//! character controllers, triangle-mesh maps, RotateTo and SetPin. Queries run on the CPU
//! against the last GPU tick's poses. Contact events are not produced, bodies do not sleep,
//! CCD and HitBoxQuality do not apply.

use rapier3d::prelude::*;
use shm_layout::{
    CommandError, CommandResult, ErrorKind, ObjectOp, ObjectProp, PlaneOp, ShapeKind, Vec3,
};

use super::Plane;
use crate::gpu::{self, GpuBody, GpuWorld, PairMode, StepEnv};

fn unsupported(what: &str) -> CommandError {
    CommandError::new(
        ErrorKind::InvalidValue,
        format!(
            "{what} is not supported on the GPU path (DeferGpu = true); set DeferGpu = false first"
        ),
    )
}

impl Plane {
    /// Whether the plane runs on the GPU now.
    pub fn on_gpu(&self) -> bool {
        self.gpu.is_some()
    }

    /// Name of the GPU adapter the plane runs on, when it does.
    pub fn gpu_adapter(&self) -> Option<&str> {
        self.gpu.as_ref().map(|g| g.adapter())
    }

    /// Moves the plane onto the GPU (`on`) or back to rapier, carrying every body's pose and
    /// velocity. The plane is unchanged on error.
    pub(super) fn set_defer_gpu(&mut self, on: bool) -> Result<(), CommandError> {
        match (on, self.gpu.is_some()) {
            (true, false) => {
                self.check_gpu_ready()?;
                let ctx = gpu::context().map_err(|e| {
                    CommandError::invalid_field("DeferGpu", format!("DeferGpu = true failed: {e}"))
                })?;
                let mut world = GpuWorld::new(ctx);
                for slot in 0..self.bodies.slot_count() {
                    world.set_body(slot, self.gpu_body(slot));
                }
                self.gpu = Some(world);
            }
            (false, true) => {
                self.pull_all();
                self.gpu = None;
                self.world.wake_up_all(true);
            }
            _ => {}
        }
        self.dirty.mark_all();
        Ok(())
    }

    fn check_gpu_ready(&self) -> Result<(), CommandError> {
        let refuse = |what: String| {
            Err(CommandError::invalid_field(
                "DeferGpu",
                format!("DeferGpu = true refused: plane {} has {what}, which the GPU path does not simulate", self.id),
            ))
        };
        if self.joints.live() > 0 {
            return refuse(format!("{} joints", self.joints.live()));
        }
        if !self.controllers.is_empty() {
            return refuse(format!("{} character controllers", self.controllers.len()));
        }
        for slot in 0..self.bodies.slot_count() {
            let Some(body) = self.bodies.at(slot) else {
                continue;
            };
            let part = &body.part;
            if part.map.is_some() {
                return refuse(format!("a triangle-mesh map (slot {slot})"));
            }
            // Stored rows flagged `cpu_only` in the object settings table, off their default.
            let mut rows = ObjectProp::ROWS.iter().enumerate();
            if let Some((_, row)) =
                rows.find(|(i, row)| row.cpu_only && !part.settings.is_default_at(*i))
            {
                return refuse(format!("an object with {} (slot {slot})", row.name));
            }
        }
        Ok(())
    }

    /// Slot `slot` as the GPU world takes it (`None`: no live object there).
    fn gpu_body(&self, slot: usize) -> Option<GpuBody> {
        let b = self.bodies.at(slot)?;
        let body = self.world.bodies.get(b.handle)?;
        let part = &b.part;
        let pose = body.position();
        let [x, y, z] = part.size;
        let sphere = (part.shape == ShapeKind::Sphere).then(|| x.min(y).min(z) / 2.0);
        let half_extents: Vec3 = match sphere {
            Some(r) => [r; 3],
            None => {
                // The world box around the rotated Size box: |R| · half.
                let r = pose.rotation;
                let world = (r * Vector::X).abs() * (x / 2.0)
                    + (r * Vector::Y).abs() * (y / 2.0)
                    + (r * Vector::Z).abs() * (z / 2.0);
                world.into()
            }
        };
        let inverse_mass = if body.is_dynamic() && body.mass() > 0.0 {
            1.0 / body.mass()
        } else {
            0.0
        };
        let acceleration =
            Vector::from(part.impulse_direction) + Vector::from(part.constant_force) * inverse_mass;
        Some(GpuBody {
            position: pose.translation.into(),
            rotation: pose.rotation.into(),
            velocity: body.linvel().into(),
            angular_velocity: body.angvel().into(),
            half_extents,
            sphere,
            inverse_mass,
            acceleration: acceleration.into(),
            bounciness: part.bounciness,
            friction: part.friction,
            collide: part.can_collide,
            locks: [part.locks[0], part.locks[1], part.locks[2]],
            group_bit: 1u32 << part.collision_group,
            group_mask: self.groups.mask(part.collision_group),
        })
    }

    /// Writes the GPU world's pose and velocities of `slot` into its rapier body.
    fn pull(&mut self, slot: usize) {
        let Some(gpu) = &self.gpu else {
            return;
        };
        let (Some(p), Some(b)) = (gpu.pose(slot), self.bodies.at(slot)) else {
            return;
        };
        let h = b.handle;
        let Some(body) = self.world.bodies.get_mut(h) else {
            return;
        };
        body.set_position(
            rapier3d::math::Pose::from_parts(
                Vector::from(p.position),
                Rotation::from_array(p.rotation).normalize(),
            ),
            false,
        );
        if body.is_dynamic() {
            body.set_linvel(Vector::from(p.velocity), false);
            body.set_angvel(Vector::from(p.angular_velocity), false);
        }
        self.query_stale.push(h);
    }

    fn pull_all(&mut self) {
        for slot in 0..self.bodies.slot_count() {
            self.pull(slot);
        }
    }

    /// Hands slot `slot` (as rapier now holds it) to the GPU world.
    fn push(&mut self, slot: usize) {
        let body = self.gpu_body(slot);
        if let Some(gpu) = &mut self.gpu {
            gpu.set_body(slot, body);
        }
    }

    fn push_all(&mut self) {
        for slot in 0..self.bodies.slot_count() {
            self.push(slot);
        }
    }

    /// An op on a GPU plane: what the GPU path supports goes through the rapier world (the
    /// bodies it touches pulled from the GPU first and pushed back after), the rest is
    /// refused.
    pub(super) fn apply_on_gpu(&mut self, op: PlaneOp) -> CommandResult {
        match op {
            PlaneOp::Controller(_) => Err(unsupported("a character controller op")),
            PlaneOp::Joint(_) => Err(unsupported("a joint op")),
            PlaneOp::Map(_) => Err(unsupported("a triangle-mesh map op")),
            PlaneOp::Query(_) => {
                self.pull_all();
                self.apply_on_cpu(op)
            }
            PlaneOp::CollisionGroups(_) => {
                let reply = self.apply_on_cpu(op);
                self.push_all();
                reply
            }
            PlaneOp::Explode(_) => {
                self.pull_all();
                let reply = self.apply_on_cpu(op);
                self.push_all();
                reply
            }
            PlaneOp::AddObject { ref props, .. } => {
                for p in props {
                    check_gpu_prop(p)?;
                }
                let reply = self.apply_on_cpu(op)?;
                if let shm_layout::Reply::Object { handle, .. } = reply {
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
                let live = self.bodies.get(handle).is_ok();
                if live {
                    self.pull(slot);
                }
                let reply = self.apply_on_cpu(op);
                if live {
                    self.push(slot);
                }
                reply
            }
            _ => self.apply_on_cpu(op),
        }
    }

    /// One tick on the GPU (the plane's step calls it while DeferGpu is on).
    pub(super) fn step_on_gpu(&mut self, dt: f32) -> Result<(), CommandError> {
        let s = &self.settings;
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
        let gpu = self.gpu.as_mut().expect("on the GPU");
        gpu.step(&env).map_err(|e| {
            CommandError::new(
                ErrorKind::Internal,
                format!("GPU step of plane {}: {e}", self.id),
            )
        })?;
        self.max_penetration = gpu.max_penetration;
        self.contact_pairs = gpu.contact_pairs;
        self.events.clear();
        self.removed.clear();
        Ok(())
    }

    /// Every overlapping pair of live collidable objects now, as `(slot, slot)` with the
    /// smaller slot first, found on the GPU through the spatial hash or by testing every
    /// pair. For tests and benchmarks; `None` unless the plane is on the GPU.
    pub fn gpu_pairs(&mut self, mode: PairMode) -> Option<Result<Vec<(u32, u32)>, String>> {
        self.gpu.as_mut().map(|g| g.pairs(mode))
    }

    /// Chooses how the GPU solver finds pairs (for the benchmark's brute-force runs).
    pub fn set_gpu_pair_mode(&mut self, mode: PairMode) {
        if let Some(g) = &mut self.gpu {
            g.set_pair_mode(mode);
        }
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

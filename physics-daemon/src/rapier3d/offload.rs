//! What an engine outside rapier needs to step this plane's bodies in rapier's place: the
//! GPU path (`crate::gpu::GpuPlane`, a wrapper around this plane behind the same backend
//! seam) uses it while `DeferGpu` is on. The plane stays the store of everything but motion;
//! the other engine reads each slot as a [`SimpleBody`], hands poses back as [`SimplePose`]s
//! and reports its steps here, so the tick header, dirty marks and snapshots stay this
//! plane's. Nothing here names the GPU: the plane does not know which engine steps it.

use std::time::Instant;

use rapier3d::prelude::*;
use shm_layout::{
    BodyState, CommandError, Handle, ObjectProp, PlaneProp, PlaneSettings, ShapeKind, Vec3,
    FLAG_ALIVE, FLAG_ANCHORED,
};

use super::plane::Plane;

/// One body as a simplified stepper takes it (a sphere or a world-aligned box).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SimpleBody {
    /// Centre.
    pub position: [f32; 3],
    /// Orientation `[x, y, z, w]` (kept as it is for non-spheres).
    pub rotation: [f32; 4],
    /// Linear velocity.
    pub velocity: [f32; 3],
    /// Angular velocity (spheres only turn; others read back zero).
    pub angular_velocity: [f32; 3],
    /// Half extents of its world-aligned box (the rotated Size box's bounds).
    pub half_extents: [f32; 3],
    /// `Some(radius)`: a sphere.
    pub sphere: Option<f32>,
    /// 1 / mass; 0 for anchored bodies.
    pub inverse_mass: f32,
    /// Its own acceleration (ImpulseDirection + ConstantForce / mass).
    pub acceleration: [f32; 3],
    /// Restitution (a pair uses the higher).
    pub bounciness: f32,
    /// Friction (a pair uses the geometric mean).
    pub friction: f32,
    /// CanCollide.
    pub collide: bool,
    /// Translation locks X, Y, Z.
    pub locks: [bool; 3],
    /// Its collision group's bit.
    pub group_bit: u32,
    /// The groups it collides with.
    pub group_mask: u32,
}

/// What the other engine gives back for one slot.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SimplePose {
    /// Centre.
    pub position: [f32; 3],
    /// Orientation.
    pub rotation: [f32; 4],
    /// Linear velocity.
    pub velocity: [f32; 3],
    /// Angular velocity.
    pub angular_velocity: [f32; 3],
}

/// What the plane does when `DeferGpu` changes: given the plane and the new value, it moves
/// the plane's motion to the other engine or back, or refuses (the plane keeps its settings).
pub type DeferHook<'a> = dyn FnMut(&mut Plane, bool) -> Result<(), CommandError> + 'a;

/// The [`DeferHook`] of a plane with no other engine: `DeferGpu = true` is refused.
pub fn no_other_engine(_: &mut Plane, on: bool) -> Result<(), CommandError> {
    if on {
        return Err(CommandError::invalid_field(
            "DeferGpu",
            "DeferGpu = true failed: this daemon was built without the GPU path (cargo \
             feature \"gpu\")",
        ));
    }
    Ok(())
}

impl Plane {
    /// A plane with default options, then `props` applied in order; `defer` takes `DeferGpu`.
    pub fn new_with(
        id: shm_layout::PlaneId,
        props: &[PlaneProp],
        defer: &mut DeferHook<'_>,
    ) -> Result<Plane, CommandError> {
        let mut plane = Plane::empty(id);
        for prop in props {
            plane.apply_prop(*prop, true, defer)?;
        }
        Ok(plane)
    }

    /// Applies one option; `defer` takes `DeferGpu`.
    pub fn set_with(
        &mut self,
        prop: PlaneProp,
        defer: &mut DeferHook<'_>,
    ) -> Result<(), CommandError> {
        self.apply_prop(prop, false, defer)
    }

    /// The plane's options.
    pub fn settings(&self) -> &PlaneSettings {
        &self.settings
    }

    /// Why this plane's motion cannot be stepped by a simplified engine now (joints,
    /// controllers, maps, objects with a `cpu_only` property off its default), as a sentence
    /// naming what it has; `None`: it can.
    pub fn simple_refusal(&self) -> Option<String> {
        if self.joints.live() > 0 {
            return Some(format!("{} joints", self.joints.live()));
        }
        if !self.controllers.is_empty() {
            return Some(format!("{} character controllers", self.controllers.len()));
        }
        for slot in 0..self.objects.slot_count() {
            let Some(body) = self.objects.at(slot) else {
                continue;
            };
            let part = &body.part;
            if part.map.is_some() {
                return Some(format!("a triangle-mesh map (slot {slot})"));
            }
            // Stored rows flagged `cpu_only` in the object settings table, off their default.
            let mut rows = ObjectProp::ROWS.iter().enumerate();
            if let Some((_, row)) =
                rows.find(|(i, row)| row.cpu_only && !part.settings.is_default_at(*i))
            {
                return Some(format!("an object with {} (slot {slot})", row.name));
            }
        }
        None
    }

    /// Slot `slot` as a simplified engine takes it (`None`: no live object there).
    pub fn simple_body(&self, slot: usize) -> Option<SimpleBody> {
        let b = self.objects.at(slot)?;
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
        Some(SimpleBody {
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
            group_mask: self.queries.groups().mask(part.collision_group),
        })
    }

    /// Writes `p` (pose and velocities from the other engine) into slot `slot`'s rapier
    /// body, so ops and queries see it.
    pub fn set_simple_pose(&mut self, slot: usize, p: SimplePose) {
        let Some(b) = self.objects.at(slot) else {
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
        self.queries.mark_stale(h);
        self.history.forget_poses();
    }

    /// Whether `handle` names a live object.
    pub fn is_live(&self, handle: Handle) -> bool {
        self.objects.get(handle).is_ok()
    }

    /// Wakes every body (motion handed back to rapier).
    pub fn wake_all(&mut self) {
        self.world.wake_up_all(true);
        self.history.forget_poses();
    }

    /// What every step does first: the last tick kept for Rewind, `dt` checked. Returns
    /// false when the plane is disabled (the step then does nothing).
    pub fn begin_step(&mut self, dt: f32) -> Result<bool, CommandError> {
        self.finish_keep()?;
        crate::backend::check_dt(dt)?;
        Ok(self.settings.enabled)
    }

    /// Records a step of `dt` another engine took (begun with [`Plane::begin_step`] at
    /// `started`): its contact figures, the state hash of what it left, the tick clock.
    /// Nothing sleeps there: every slot may have moved.
    pub fn simple_step_done(
        &mut self,
        dt: f32,
        (max_penetration, contact_pairs): (f32, u32),
        state_hash: u64,
        started: Instant,
    ) {
        self.clock.max_penetration = max_penetration;
        self.clock.contact_pairs = contact_pairs;
        self.events.clear_step();
        self.objects.stepped();
        self.clock.advance(dt);
        self.history.stepped_elsewhere(state_hash);
        self.clock.timed(started);
    }

    /// The published state of slot `i` with its pose from the other engine (`pose`: what
    /// that engine holds for the slot; `None` or a dead slot: only the generation).
    pub fn state_with_pose(&self, i: usize, pose: Option<SimplePose>) -> BodyState {
        let generation = self.objects.generation(i);
        let Some((p, b)) = pose.zip(self.objects.at(i)) else {
            return BodyState {
                generation,
                ..BodyState::default()
            };
        };
        let mut flags = FLAG_ALIVE | b.flags;
        if self
            .world
            .bodies
            .get(b.handle)
            .is_some_and(|r| r.is_fixed())
        {
            flags |= FLAG_ANCHORED;
        }
        BodyState {
            position: p.position,
            flags,
            rotation: p.rotation,
            linear_velocity: p.velocity,
            generation,
            angular_velocity: p.angular_velocity,
            _reserved: 0,
        }
    }
}

//! Objects of a plane: creation, properties, removal, all addressed by generation-checked
//! handles.

use rapier3d::prelude::*;
use shm_layout::{CommandError, ErrorKind, Handle, ObjectProp, Pose, Shape};

use super::{Plane, Slot};
use crate::validate;

/// Slots per plane; bounds memory a misbehaving client can make the daemon allocate.
pub const MAX_SLOTS: usize = 1 << 20;
/// Smallest mass a dynamic body may have: a zero-mass body neither falls nor takes impulses.
const MIN_MASS: f32 = 1e-4;

fn rapier_pose(p: Pose) -> rapier3d::math::Pose {
    rapier3d::math::Pose::from_parts(Vector::from(p.position), Rotation::from_array(p.rotation))
}

fn collider_for(shape: Shape) -> Result<ColliderBuilder, CommandError> {
    Ok(match shape {
        Shape::Cube { size } => {
            for (axis, v) in ["x", "y", "z"].iter().zip(size) {
                validate::positive(&format!("Size.{axis}"), v)?;
            }
            ColliderBuilder::cuboid(size[0] / 2.0, size[1] / 2.0, size[2] / 2.0)
        }
        Shape::Sphere { radius } => ColliderBuilder::ball(validate::positive("radius", radius)?),
    })
}

impl Plane {
    pub fn add_object(
        &mut self,
        shape: Shape,
        pose: Pose,
        props: &[ObjectProp],
    ) -> Result<Handle, CommandError> {
        let pose = validate::pose("CFrame", pose)?;
        let collider = collider_for(shape)?;
        // Check every property before touching the world so a bad one adds nothing.
        for prop in props {
            validate_prop(*prop)?;
        }
        let slot = match self.free_slots.pop() {
            Some(s) => s,
            None if self.slots.len() < MAX_SLOTS => {
                self.slots.push(Slot::default());
                (self.slots.len() - 1) as u32
            }
            None => {
                return Err(CommandError::new(
                    ErrorKind::Internal,
                    format!("plane {} is full ({MAX_SLOTS} objects)", self.id),
                ))
            }
        };
        let body = RigidBodyBuilder::dynamic()
            .pose(rapier_pose(pose))
            .user_data(slot as u128);
        let body = self.world.insert_body(body);
        let collider = self.world.insert_collider(collider.build(), Some(body));
        ensure_min_mass(&mut self.world.bodies[body], collider);
        let entry = &mut self.slots[slot as usize];
        entry.generation = entry.generation.wrapping_add(1).max(1);
        entry.body = Some(body);
        self.live += 1;
        let handle = Handle {
            slot,
            generation: entry.generation,
        };
        for prop in props {
            self.set_object(handle, *prop)?;
        }
        Ok(handle)
    }

    /// The rapier body behind a handle, or a clear error for unknown and stale handles.
    fn body_of(&self, handle: Handle) -> Result<RigidBodyHandle, CommandError> {
        let slot = self.slots.get(handle.slot as usize).ok_or_else(|| {
            CommandError::new(
                ErrorKind::StaleHandle,
                format!("object {handle:?} does not exist in plane {}", self.id),
            )
        })?;
        match slot.body {
            Some(body) if slot.generation == handle.generation => Ok(body),
            _ => Err(CommandError::new(
                ErrorKind::StaleHandle,
                format!(
                    "object {handle:?} is stale: slot {} now holds generation {} ({})",
                    handle.slot,
                    slot.generation,
                    if slot.body.is_some() {
                        "alive"
                    } else {
                        "empty"
                    }
                ),
            )),
        }
    }

    pub(super) fn handle_of_collider(&self, collider: ColliderHandle) -> Option<Handle> {
        let body = self.world.colliders.get(collider)?.parent()?;
        let slot = self.world.bodies.get(body)?.user_data as u32;
        let generation = self.slots.get(slot as usize)?.generation;
        Some(Handle { slot, generation })
    }

    pub fn set_object(&mut self, handle: Handle, prop: ObjectProp) -> Result<(), CommandError> {
        validate_prop(prop)?;
        let h = self.body_of(handle)?;
        let body = &mut self.world.bodies[h];
        match prop {
            ObjectProp::Pose(p) => {
                body.set_position(rapier_pose(validate::pose("CFrame", p)?), true)
            }
            ObjectProp::Velocity(v) => body.set_linvel(Vector::from(v), true),
            ObjectProp::AngularVelocity(w) => body.set_angvel(Vector::from(w), true),
            ObjectProp::Anchored(on) => {
                let kind = if on {
                    RigidBodyType::Fixed
                } else {
                    RigidBodyType::Dynamic
                };
                body.set_body_type(kind, true);
                body.set_linvel(Vector::ZERO, true);
                body.set_angvel(Vector::ZERO, true);
            }
            ObjectProp::ReportContacts(on) => {
                let colliders = body.colliders().to_vec();
                let mut changed = false;
                for c in colliders {
                    let collider = &mut self.world.colliders[c];
                    let was = collider
                        .active_events()
                        .contains(ActiveEvents::COLLISION_EVENTS);
                    changed |= was != on;
                    collider.set_active_events(if on {
                        ActiveEvents::COLLISION_EVENTS
                    } else {
                        ActiveEvents::empty()
                    });
                }
                if changed {
                    if on {
                        self.reporting += 1;
                    } else {
                        self.reporting -= 1;
                    }
                }
            }
        }
        Ok(())
    }

    pub fn apply_impulse(&mut self, handle: Handle, impulse: [f32; 3]) -> Result<(), CommandError> {
        let impulse = validate::finite3("impulse", impulse)?;
        let h = self.body_of(handle)?;
        self.world.bodies[h].apply_impulse(Vector::from(impulse), true);
        Ok(())
    }

    pub fn destroy_object(&mut self, handle: Handle) -> Result<(), CommandError> {
        let h = self.body_of(handle)?;
        // Turn contact reporting off first so the plane's reporting count stays exact.
        self.set_object(handle, ObjectProp::ReportContacts(false))?;
        self.world.remove_body(h);
        self.slots[handle.slot as usize].body = None;
        self.free_slots.push(handle.slot);
        self.live -= 1;
        Ok(())
    }
}

fn validate_prop(prop: ObjectProp) -> Result<(), CommandError> {
    match prop {
        ObjectProp::Pose(p) => validate::pose("CFrame", p).map(|_| ()),
        ObjectProp::Velocity(v) => validate::finite3("Velocity", v).map(|_| ()),
        ObjectProp::AngularVelocity(w) => validate::finite3("AngularVelocity", w).map(|_| ()),
        ObjectProp::Anchored(_) | ObjectProp::ReportContacts(_) => Ok(()),
    }
}

fn ensure_min_mass(body: &mut RigidBody, _collider: ColliderHandle) {
    if body.mass() < MIN_MASS {
        body.set_additional_mass(MIN_MASS, true);
    }
}

//! Objects of a plane: creation, properties, removal, all addressed by generation-checked
//! handles.

use rapier3d::prelude::*;
use shm_layout::{CommandError, ErrorKind, Handle, ObjectInfo, ObjectProp, Pose, Shape, Vec3};

use super::part::Part;
use super::{Plane, Slot};

/// Slots per plane; bounds memory a misbehaving client can make the daemon allocate.
pub const MAX_SLOTS: usize = 1 << 20;

pub(super) fn rapier_pose(p: Pose) -> rapier3d::math::Pose {
    rapier3d::math::Pose::from_parts(Vector::from(p.position), Rotation::from_array(p.rotation))
}

impl Plane {
    pub fn add_object(
        &mut self,
        shape: &Shape,
        pose: Pose,
        props: &[ObjectProp],
    ) -> Result<Handle, CommandError> {
        let pose = shm_layout::validate::pose("CFrame", pose)?;
        shape.check()?;
        // Check every property before touching the world so a bad one adds nothing.
        let props = props
            .iter()
            .map(|p| p.checked())
            .collect::<Result<Vec<_>, _>>()?;
        let part = Part::new(shape);
        let mut collider = ColliderBuilder::new(part.collider_shape()?).build();
        part.configure_collider(&mut collider)?;
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
        let mut body = RigidBodyBuilder::dynamic()
            .pose(rapier_pose(pose))
            .user_data(slot as u128)
            .build();
        if self.never_sleep {
            *body.activation_mut() = RigidBodyActivation::cannot_sleep();
        }
        let body = self.world.insert_body(body);
        self.world.insert_collider(collider, Some(body));
        part.configure_body(&mut self.world.bodies[body], &self.world.colliders);
        self.quality_counts[part.quality as usize] += 1;
        let entry = &mut self.slots[slot as usize];
        entry.generation = entry.generation.wrapping_add(1).max(1);
        entry.body = Some(body);
        entry.part = Some(part);
        self.live += 1;
        self.touched.push(body);
        let handle = Handle {
            slot,
            generation: entry.generation,
        };
        for prop in props {
            self.set_object(handle, prop)?;
        }
        Ok(handle)
    }

    /// The rapier body behind a handle, or a clear error for unknown and stale handles.
    pub(super) fn body_of(&self, handle: Handle) -> Result<RigidBodyHandle, CommandError> {
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

    pub fn apply_impulse(&mut self, handle: Handle, impulse: Vec3) -> Result<(), CommandError> {
        let impulse = shm_layout::validate::finite3("impulse", impulse)?;
        let h = self.body_of(handle)?;
        // Rapier divides by the mass in effect and skips locked axes; fixed bodies absorb it.
        self.world.bodies[h].apply_impulse(Vector::from(impulse), true);
        self.touched.push(h);
        Ok(())
    }

    pub fn destroy_object(&mut self, handle: Handle) -> Result<(), CommandError> {
        let h = self.body_of(handle)?;
        let part = self.slots[handle.slot as usize]
            .part
            .take()
            .expect("live slot has a part");
        if part.report_contacts {
            self.reporting -= 1;
        }
        self.quality_counts[part.quality as usize] -= 1;
        if part.is_driven() {
            self.driven -= 1;
        }
        self.world.remove_body(h);
        self.slots[handle.slot as usize].body = None;
        self.free_slots.push(handle.slot);
        self.live -= 1;
        Ok(())
    }

    pub fn object_info(&self, handle: Handle) -> Result<ObjectInfo, CommandError> {
        let h = self.body_of(handle)?;
        let body = &self.world.bodies[h];
        let part = self.part(handle);
        let volume = body.colliders().first().map_or(1.0, |c| {
            self.world.colliders[*c].shape().mass_properties(1.0).mass()
        });
        let mass = part.mass(volume);
        Ok(ObjectInfo {
            handle,
            shape: part.shape,
            size: part.size,
            anchored: body.is_fixed(),
            weight: part.weight,
            density: mass / volume,
            mass,
            bounciness: part.bounciness,
            friction: part.friction,
            can_collide: part.can_collide,
            hit_box_quality: part.quality,
            center_of_mass: part.center_of_mass,
            impulse_direction: part.impulse_direction,
            constant_force: part.constant_force,
            locks: part.locks,
            rotation_locked_by_quality: part.rotation_locked_by_quality(),
            ccd: body.is_ccd_enabled(),
            rotate_to: part.rotate_to,
            pin: part.pin,
        })
    }

    /// Sets CenterOfMass to the mesh's vertex centroid (mesh parts only) and returns the
    /// centre of mass in effect.
    pub fn recalculate_center_of_mass(&mut self, handle: Handle) -> Result<Vec3, CommandError> {
        self.body_of(handle)?;
        match self.part(handle).mesh_centroid() {
            Some(c) => {
                self.set_object(handle, ObjectProp::CenterOfMass(c))?;
                Ok(c)
            }
            None => Ok(self.part(handle).center_of_mass),
        }
    }

    pub(super) fn part(&self, handle: Handle) -> &Part {
        self.slots[handle.slot as usize]
            .part
            .as_ref()
            .expect("live slot has a part")
    }
}

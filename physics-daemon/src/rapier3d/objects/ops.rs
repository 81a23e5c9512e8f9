//! Objects of a plane: creation, removal and reading back, all addressed by
//! generation-checked handles from the plane's [`SlotTable`](crate::backend::SlotTable).

use rapier3d::prelude::*;
use shm_layout::{CommandError, ErrorKind, Handle, ObjectInfo, ObjectProp, Pose, Shape, Vec3};

use crate::rapier3d::objects::object::{rapier_pose, Object, MAX_SLOTS};
use crate::rapier3d::objects::part::Part;
use crate::rapier3d::plane::Plane;

impl Plane {
    /// Adds an object of `shape` at `pose`, then applies `props` in order. Every value is
    /// checked before the world changes, so a bad one adds nothing.
    pub fn add_object(
        &mut self,
        shape: &Shape,
        pose: Pose,
        props: &[ObjectProp],
    ) -> Result<Handle, CommandError> {
        let pose = shm_layout::validate::pose("CFrame", pose)?;
        shape.check()?;
        let props = props
            .iter()
            .map(|p| p.checked())
            .collect::<Result<Vec<_>, _>>()?;
        let part = Part::new(shape);
        let mut collider = ColliderBuilder::new(part.collider_shape()?).build();
        part.configure_collider(&mut collider, self.queries.groups())?;
        let slot = self.objects.next_slot().ok_or_else(|| {
            CommandError::new(
                ErrorKind::Internal,
                format!("plane {} is full ({MAX_SLOTS} objects)", self.id),
            )
        })?;
        let mut body = RigidBodyBuilder::dynamic()
            .pose(rapier_pose(pose))
            .user_data(slot as u128)
            .build();
        if self.settings.never_sleep {
            *body.activation_mut() = RigidBodyActivation::cannot_sleep();
        }
        let h = self.world.insert_body(body);
        self.world.insert_collider(collider, Some(h));
        part.configure_body(&mut self.world.bodies[h], &self.world.colliders);
        self.objects
            .tally
            .add(part.hit_box_quality, shape.mesh_vertices() as u64);
        let handle = self.objects.insert(Object {
            handle: h,
            part: Box::new(part),
            flags: 0,
        })?;
        debug_assert_eq!(handle.slot, slot);
        self.queries.mark_stale(h);
        for prop in props {
            self.set_object(handle, prop)?;
        }
        Ok(handle)
    }

    /// The rapier body behind a handle, or a clear error for unknown and stale handles.
    pub(in crate::rapier3d) fn body_of(
        &self,
        handle: Handle,
    ) -> Result<RigidBodyHandle, CommandError> {
        self.objects
            .get(handle)
            .map(|b| b.handle)
            .map_err(|e| self.in_plane(e))
    }

    /// The rapier body behind a handle the caller is about to change: the slot is marked
    /// changed (the publisher rewrites it; the next force pass sees it even before rapier
    /// lists it as awake). Errors as [`Plane::body_of`].
    pub(in crate::rapier3d) fn changing(
        &mut self,
        handle: Handle,
    ) -> Result<RigidBodyHandle, CommandError> {
        match self.objects.get_mut(handle) {
            Ok(b) => Ok(b.handle),
            Err(e) => Err(self.in_plane(e)),
        }
    }

    /// Adds "in plane N" to a slot-table error.
    fn in_plane(&self, mut e: CommandError) -> CommandError {
        e.message = format!("{} (plane {})", e.message, self.id);
        e
    }

    pub(in crate::rapier3d) fn handle_of_collider(
        &self,
        collider: ColliderHandle,
    ) -> Option<Handle> {
        let Some(c) = self.world.colliders.get(collider) else {
            return self.events.removed_owner(collider);
        };
        let slot = self.world.bodies.get(c.parent()?)?.user_data as usize;
        self.objects.handle_at(slot)
    }

    /// Velocity-space impulse: `Δv = impulse / mass`; anchored bodies absorb it. Returns
    /// the linear velocity right after it.
    pub fn apply_impulse(&mut self, handle: Handle, impulse: Vec3) -> Result<Vec3, CommandError> {
        let impulse = shm_layout::validate::finite3("impulse", impulse)?;
        let h = self.changing(handle)?;
        // Rapier divides by the mass in effect and skips locked axes; fixed bodies absorb it.
        let body = &mut self.world.bodies[h];
        body.apply_impulse(Vector::from(impulse), true);
        let v = body.linvel();
        Ok([v.x, v.y, v.z])
    }

    /// Wakes the object up (rapier wakes what rests on it at the next step).
    pub fn wake(&mut self, handle: Handle) -> Result<(), CommandError> {
        let h = self.changing(handle)?;
        self.world.bodies[h].wake_up(true);
        Ok(())
    }

    /// Removes the object; its handle becomes stale.
    pub fn destroy_object(&mut self, handle: Handle) -> Result<(), CommandError> {
        let Object {
            handle: h, part, ..
        } = self.objects.remove(handle).map_err(|e| self.in_plane(e))?;
        self.controllers.remove(&handle.slot);
        if part.report_contacts {
            self.events.count_reporting(false);
        }
        self.objects.tally_mut().remove(
            part.hit_box_quality,
            part.mesh_vertex_count() as u64,
            part.is_driven(),
        );
        // Its contact-stopped events come at the next step, after the slot is gone.
        for c in self.world.bodies[h].colliders() {
            self.events.collider_removed(*c, handle);
        }
        self.remove_joints_of(h);
        self.world.remove_body(h);
        Ok(())
    }

    /// Every property of the object.
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
            settings: part.settings,
            size: part.size,
            anchored: body.is_fixed(),
            sleeping: body.is_sleeping(),
            density: mass / volume,
            mass,
            rotation_locked_by_quality: part.rotation_locked_by_quality(),
            ccd: body.is_ccd_enabled(),
        })
    }

    /// Sets CenterOfMass to the mesh's vertex centroid or the wedge's centroid (other
    /// shapes are unchanged) and returns the centre of mass in effect.
    pub fn recalculate_center_of_mass(&mut self, handle: Handle) -> Result<Vec3, CommandError> {
        self.body_of(handle)?;
        match self.part(handle).centroid() {
            Some(c) => {
                self.set_object(handle, ObjectProp::CenterOfMass(c))?;
                Ok(c)
            }
            None => Ok(self.part(handle).center_of_mass),
        }
    }

    /// The part of a live handle (checked by the caller).
    pub(in crate::rapier3d) fn part(&self, handle: Handle) -> &Part {
        &self.objects.get(handle).expect("checked handle").part
    }
}

//! Setting one object property: the checked value (shm-layout's settings) mapped onto the
//! rapier body, collider and the part.

use rapier3d::prelude::*;
use shm_layout::{CommandError, Handle, ObjectProp};

use super::objects::rapier_pose;
use super::Plane;

impl Plane {
    /// Sets one property of an object (checked first; errors name the property and value).
    pub fn set_object(&mut self, handle: Handle, prop: ObjectProp) -> Result<(), CommandError> {
        let prop = prop.checked()?;
        if let ObjectProp::CollisionGroup(g) = prop {
            if !self.groups.is_registered(g) {
                return Err(CommandError::invalid_field(
                    "CollisionGroup",
                    format!(
                        "CollisionGroup {g} is not a registered group of plane {}",
                        self.id
                    ),
                ));
            }
        }
        let h = self.body_of(handle)?;
        if self.part(handle).map.is_some() {
            super::maps::check_map_prop(&prop)?;
        }
        let part = &mut self.bodies.get_mut(handle)?.part;
        let was_driven = part.is_driven();
        let was_reporting = part.report_contacts;
        let old_quality = part.hit_box_quality;
        // Stored settings first; then which rapier state the change touches.
        let stored = part.settings.store(&prop);
        let (mut collider_changed, mut body_changed, mut shape_changed) = (false, false, false);
        let body = &mut self.world.bodies[h];
        match prop {
            ObjectProp::Pose(p) => body.set_position(rapier_pose(p), true),
            ObjectProp::Velocity(v) => {
                body.set_linvel(masked(Vector::from(v), &part.locks[..3]), true)
            }
            ObjectProp::AngularVelocity(w) => {
                body.set_angvel(masked(Vector::from(w), &part.locks[3..]), true)
            }
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
            ObjectProp::Size(size) => {
                part.resize(size)?;
                shape_changed = true;
            }
            ObjectProp::ReportContacts(_) => {
                collider_changed = was_reporting != part.report_contacts
            }
            ObjectProp::Weight(_)
            | ObjectProp::Density(_)
            | ObjectProp::Bounciness(_)
            | ObjectProp::Friction(_)
            | ObjectProp::CanCollide(_)
            | ObjectProp::CollisionGroup(_) => collider_changed = true,
            ObjectProp::HitBoxQuality(_) | ObjectProp::CenterOfMass(_) => {
                collider_changed = true;
                body_changed = true;
            }
            ObjectProp::FieldRestraint(_) => body_changed = true,
            ObjectProp::Held(_) => {}
            ObjectProp::GravityScale(k) => body.set_gravity_scale(k, true),
            // Read by the force pass every tick.
            ObjectProp::ImpulseDirection(_)
            | ObjectProp::ConstantForce(_)
            | ObjectProp::RotateTo(_)
            | ObjectProp::Pin(_) => {}
        }
        debug_assert_eq!(
            stored,
            !prop.is_published() && !matches!(prop, ObjectProp::Size(_) | ObjectProp::Held(_))
        );
        if let ObjectProp::Held(on) = prop {
            self.hold(h, on);
        }
        let part = &self.bodies.get(handle)?.part;
        if shape_changed {
            // Rapier recycles the contacts of pairs whose poses did not move, even when a
            // shape changed: a fresh collider gets fresh contacts.
            for c in self.world.bodies[h].colliders().to_vec() {
                self.world.remove_collider(c);
                self.removed.push((c, handle));
            }
            let mut collider = ColliderBuilder::new(part.collider_shape()?).build();
            part.configure_collider(&mut collider, &self.groups)?;
            self.world.insert_collider(collider, Some(h));
            body_changed = true;
        } else if collider_changed {
            for c in self.world.bodies[h].colliders().to_vec() {
                part.configure_collider(&mut self.world.colliders[c], &self.groups)?;
            }
            body_changed = true;
        }
        if body_changed {
            part.configure_body(&mut self.world.bodies[h], &self.world.colliders);
        }
        if part.hit_box_quality != old_quality {
            self.quality_counts[old_quality as usize] -= 1;
            self.quality_counts[part.hit_box_quality as usize] += 1;
        }
        match (was_driven, part.is_driven()) {
            (false, true) => self.driven += 1,
            (true, false) => self.driven -= 1,
            _ => {}
        }
        match (was_reporting, part.report_contacts) {
            (false, true) => self.reporting += 1,
            (true, false) => self.reporting -= 1,
            _ => {}
        }
        self.query_stale.push(h);
        // Any change may need the body awake and seen by the next force pass.
        self.world.bodies[h].wake_up(true);
        self.dirty.mark(handle.slot);
        Ok(())
    }
}

/// `v` with the components of locked axes zeroed.
fn masked(mut v: Vector, locks: &[bool]) -> Vector {
    for (i, locked) in locks.iter().enumerate() {
        if *locked {
            v[i] = 0.0;
        }
    }
    v
}

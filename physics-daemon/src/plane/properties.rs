//! Setting one object property: validation, then the rapier body, collider and the part.

use rapier3d::prelude::*;
use shm_layout::{CommandError, Handle, ObjectProp};

use super::objects::rapier_pose;
use super::Plane;

impl Plane {
    pub fn set_object(&mut self, handle: Handle, prop: ObjectProp) -> Result<(), CommandError> {
        let prop = prop.checked()?;
        let h = self.body_of(handle)?;
        let slot = handle.slot as usize;
        let part = self.slots[slot]
            .part
            .as_mut()
            .expect("live slot has a part");
        let was_driven = part.is_driven();
        let old_quality = part.quality;
        // Which rapier state the change touches.
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
            ObjectProp::ReportContacts(on) => {
                if part.report_contacts != on {
                    part.report_contacts = on;
                    collider_changed = true;
                    if on {
                        self.reporting += 1;
                    } else {
                        self.reporting -= 1;
                    }
                }
            }
            ObjectProp::Weight(w) => {
                part.weight = w;
                collider_changed = true;
            }
            ObjectProp::Density(d) => {
                part.density = d;
                collider_changed = true;
            }
            ObjectProp::Bounciness(e) => {
                part.bounciness = e;
                collider_changed = true;
            }
            ObjectProp::Friction(mu) => {
                part.friction = mu;
                collider_changed = true;
            }
            ObjectProp::CanCollide(on) => {
                part.can_collide = on;
                collider_changed = true;
            }
            ObjectProp::HitBoxQuality(q) => {
                part.quality = q;
                collider_changed = true;
                body_changed = true;
            }
            ObjectProp::Size(size) => {
                let old = part.size;
                part.size = size;
                if let Err(e) = part.collider_shape() {
                    part.size = old;
                    return Err(e);
                }
                shape_changed = true;
            }
            ObjectProp::CenterOfMass(c) => {
                part.center_of_mass = c;
                collider_changed = true;
                body_changed = true;
            }
            ObjectProp::ImpulseDirection(a) => part.impulse_direction = a,
            ObjectProp::ConstantForce(f) => part.constant_force = f,
            ObjectProp::FieldRestraint(r) => {
                for (lock, flag) in part.locks.iter_mut().zip(r.flags()) {
                    if let Some(on) = flag {
                        *lock = on;
                    }
                }
                body_changed = true;
            }
            ObjectProp::RotateTo(r) => part.rotate_to = r,
            ObjectProp::Pin(p) => part.pin = p,
        }
        let part = self.slots[slot]
            .part
            .as_ref()
            .expect("live slot has a part");
        if shape_changed {
            // Rapier recycles the contacts of pairs whose poses did not move, even when a
            // shape changed: a fresh collider gets fresh contacts.
            for c in self.world.bodies[h].colliders().to_vec() {
                self.world.remove_collider(c);
            }
            let mut collider = ColliderBuilder::new(part.collider_shape()?).build();
            part.configure_collider(&mut collider)?;
            self.world.insert_collider(collider, Some(h));
            body_changed = true;
        } else if collider_changed {
            for c in self.world.bodies[h].colliders().to_vec() {
                part.configure_collider(&mut self.world.colliders[c])?;
            }
            body_changed = true;
        }
        if body_changed {
            part.configure_body(&mut self.world.bodies[h], &self.world.colliders);
        }
        if part.quality != old_quality {
            self.quality_counts[old_quality as usize] -= 1;
            self.quality_counts[part.quality as usize] += 1;
        }
        match (was_driven, part.is_driven()) {
            (false, true) => self.driven += 1,
            (true, false) => self.driven -= 1,
            _ => {}
        }
        // Any change may need the body awake and seen by the next force pass.
        self.world.bodies[h].wake_up(true);
        self.touched.push(h);
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

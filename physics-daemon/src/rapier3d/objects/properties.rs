//! Setting one object property: the checked value (shm-layout's settings) mapped onto the
//! rapier body, collider and the part.

use rapier3d::prelude::*;
use shm_layout::{CommandError, Handle, ObjectProp};

use crate::rapier3d::objects::object::rapier_pose;
use crate::rapier3d::plane::Plane;

impl Plane {
    /// Sets one property of an object (checked first; errors name the property and value):
    /// the stored settings, then the rapier state the change touches, then the plane's
    /// per-part counts.
    pub fn set_object(&mut self, handle: Handle, prop: ObjectProp) -> Result<(), CommandError> {
        let prop = prop.checked()?;
        self.check_object_prop(handle, &prop)?;
        let h = self.changing(handle)?;
        let before = Counted::of(&self.objects.get(handle)?.part);
        let touched = self.apply_to_body(handle, h, prop)?;
        if let ObjectProp::Held(on) = prop {
            self.set_held(h, on);
        }
        self.reconfigure(handle, h, touched)?;
        self.recount(before, Counted::of(&self.objects.get(handle)?.part));
        self.queries.mark_stale(h);
        // Any change may need the body awake and seen by the next force pass.
        self.world.bodies[h].wake_up(true);
        Ok(())
    }

    /// What the plane refuses beyond the value's own check: unregistered collision groups,
    /// and properties a triangle map cannot take.
    fn check_object_prop(&self, handle: Handle, prop: &ObjectProp) -> Result<(), CommandError> {
        if let ObjectProp::CollisionGroup(g) = *prop {
            if !self.queries.groups().is_registered(g) {
                return Err(CommandError::invalid_field(
                    "CollisionGroup",
                    format!(
                        "CollisionGroup {g} is not a registered group of plane {}",
                        self.id
                    ),
                ));
            }
        }
        if self.objects.get(handle)?.part.map.is_some() {
            crate::rapier3d::objects::maps::check_map_prop(prop)?;
        }
        Ok(())
    }

    /// Stores the property in the part and applies what maps directly onto the rapier body;
    /// returns what must be rebuilt from the part's settings.
    fn apply_to_body(
        &mut self,
        handle: Handle,
        h: RigidBodyHandle,
        prop: ObjectProp,
    ) -> Result<Touched, CommandError> {
        let part = &mut self.objects.get_mut(handle)?.part;
        let was_reporting = part.report_contacts;
        let stored = part.settings.store(&prop);
        debug_assert_eq!(
            stored,
            !prop.is_published() && !matches!(prop, ObjectProp::Size(_) | ObjectProp::Held(_))
        );
        let mut touched = Touched::default();
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
                touched.shape = true;
            }
            ObjectProp::ReportContacts(_) => {
                touched.collider = was_reporting != part.report_contacts
            }
            ObjectProp::Weight(_)
            | ObjectProp::Density(_)
            | ObjectProp::Bounciness(_)
            | ObjectProp::Friction(_)
            | ObjectProp::CanCollide(_)
            | ObjectProp::CollisionGroup(_) => touched.collider = true,
            ObjectProp::HitBoxQuality(_) | ObjectProp::CenterOfMass(_) => {
                touched.collider = true;
                touched.body = true;
            }
            ObjectProp::FieldRestraint(_) => touched.body = true,
            ObjectProp::Held(_) => {}
            ObjectProp::GravityScale(k) => body.set_gravity_scale(k, true),
            // Read by the force pass every tick.
            ObjectProp::ImpulseDirection(_)
            | ObjectProp::ConstantForce(_)
            | ObjectProp::RotateTo(_)
            | ObjectProp::Pin(_) => {}
        }
        Ok(touched)
    }

    /// Rebuilds the collider (a new one when the shape changed) and the body's mass and
    /// locks from the part's settings, as far as `touched` says.
    fn reconfigure(
        &mut self,
        handle: Handle,
        h: RigidBodyHandle,
        touched: Touched,
    ) -> Result<(), CommandError> {
        let part = &self.objects.get(handle)?.part;
        let mut body_changed = touched.body;
        if touched.shape {
            // Rapier recycles the contacts of pairs whose poses did not move, even when a
            // shape changed: a fresh collider gets fresh contacts.
            for c in self.world.bodies[h].colliders().to_vec() {
                self.world.remove_collider(c);
                self.events.collider_removed(c, handle);
            }
            let mut collider = ColliderBuilder::new(part.collider_shape()?).build();
            part.configure_collider(&mut collider, self.queries.groups())?;
            self.world.insert_collider(collider, Some(h));
            body_changed = true;
        } else if touched.collider {
            for c in self.world.bodies[h].colliders().to_vec() {
                part.configure_collider(&mut self.world.colliders[c], self.queries.groups())?;
            }
            body_changed = true;
        }
        if body_changed {
            part.configure_body(&mut self.world.bodies[h], &self.world.colliders);
        }
        Ok(())
    }

    /// Keeps the plane's per-part counts (objects per quality, driven, reporting) in step
    /// with one part's change.
    fn recount(&mut self, before: Counted, after: Counted) {
        self.objects
            .tally_mut()
            .requalify(before.quality, after.quality);
        match (before.driven, after.driven) {
            (false, true) => self.objects.tally_mut().count_driven(true),
            (true, false) => self.objects.tally_mut().count_driven(false),
            _ => {}
        }
        match (before.reporting, after.reporting) {
            (false, true) => self.events.count_reporting(true),
            (true, false) => self.events.count_reporting(false),
            _ => {}
        }
    }
}

/// What a property change leaves to rebuild from the part's settings.
#[derive(Default, Clone, Copy)]
struct Touched {
    /// The collider's material, groups, flags or mass.
    collider: bool,
    /// The body's mass properties and locks.
    body: bool,
    /// The shape: a fresh collider.
    shape: bool,
}

/// What the plane counts about a part.
#[derive(Clone, Copy)]
struct Counted {
    quality: u32,
    driven: bool,
    reporting: bool,
}

impl Counted {
    fn of(part: &crate::rapier3d::objects::part::Part) -> Counted {
        Counted {
            quality: part.hit_box_quality,
            driven: part.is_driven(),
            reporting: part.report_contacts,
        }
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

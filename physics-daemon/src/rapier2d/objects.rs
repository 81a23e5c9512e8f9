//! Bodies for GUI primitives: creation from shape, size and position, every property's
//! mapping onto rapier2d, reading back, and the bounds walls. Addressed by
//! generation-checked handles from the plane's [`SlotTable`](crate::backend::SlotTable).

use rapier2d::prelude::*;
use shm_layout::gui_op::GuiObjectInfo;
use shm_layout::settings::gui_plane::finite2;
use shm_layout::settings::{GuiObjectProp, GuiObjectSettings, GuiShape, Vec2};
use shm_layout::{CommandError, ErrorKind, Handle};

use super::hooks::{layer, CONTROLLED, WALL};
use super::object::{unlocked, Object, MAX_SLOTS, WALLS_SLOT};
use super::plane::Plane;
use crate::backend::held;

/// Thickness of each bounds wall (px): thick enough that nothing tunnels through.
const WALL_THICKNESS: f32 = 10_000.0;

/// The collision shape of a primitive of `shape` filling a `size` box centred on its origin
/// (+Y down: a triangle's apex is at the top).
fn collider_shape(shape: GuiShape, size: Vec2) -> SharedShape {
    let (hx, hy) = (size[0] * 0.5, size[1] * 0.5);
    match shape {
        GuiShape::Square | GuiShape::Image | GuiShape::Text => SharedShape::cuboid(hx, hy),
        GuiShape::Circle => SharedShape::ball(hx.min(hy)),
        // Counter-clockwise, as parry's triangle normals expect.
        GuiShape::Triangle => SharedShape::triangle(
            Vector::new(0.0, -hy),
            Vector::new(hx, hy),
            Vector::new(-hx, hy),
        ),
    }
}

impl Plane {
    /// Adds a body for a primitive; every value is checked before the world changes.
    pub fn add_object(
        &mut self,
        shape: GuiShape,
        size: Vec2,
        position: Vec2,
        props: &[GuiObjectProp],
    ) -> Result<Handle, CommandError> {
        let size = match GuiObjectProp::Size(size).checked()? {
            GuiObjectProp::Size(s) => s,
            _ => unreachable!("Size checks to Size"),
        };
        let position = finite2("Position", position)?;
        let props = props
            .iter()
            .map(|p| p.checked())
            .collect::<Result<Vec<_>, _>>()?;
        let slot = self.bodies.next_slot().ok_or_else(|| {
            CommandError::new(
                ErrorKind::Internal,
                format!("plane {} is full ({MAX_SLOTS} objects)", self.id),
            )
        })?;
        let settings = GuiObjectSettings {
            size,
            ..GuiObjectSettings::default()
        };
        let mut body = RigidBodyBuilder::dynamic()
            .translation(Vector::from(position))
            .user_data(slot as u128)
            .build();
        *body.activation_mut() = self.activation();
        let collider = ColliderBuilder::new(collider_shape(shape, size))
            .friction(settings.friction)
            .friction_combine_rule(CoefficientCombineRule::GeometricMean)
            .restitution(settings.bounciness)
            .restitution_combine_rule(CoefficientCombineRule::Max)
            .mass(settings.mass)
            .user_data(layer(settings.z_index))
            .active_hooks(ActiveHooks::FILTER_CONTACT_PAIRS)
            .build();
        let h = self.world.insert_body(body);
        let c = self.world.insert_collider(collider, Some(h));
        let handle = self.bodies.insert(Object {
            handle: h,
            collider: c,
            shape,
            settings,
            controller: None,
        })?;
        self.query_stale.push(h);
        for prop in props {
            self.set_object(handle, prop)?;
        }
        Ok(handle)
    }

    /// The body of a live handle, or a clear error for unknown and stale handles.
    pub(super) fn body(&self, handle: Handle) -> Result<&Object, CommandError> {
        self.bodies.get(handle).map_err(|mut e| {
            e.message = format!("{} (GUI plane {})", e.message, self.id);
            e
        })
    }

    /// The body of `handle`, which the caller is about to change: its slot is marked
    /// changed. Errors as [`Plane::body`].
    fn changing(&mut self, handle: Handle) -> Result<&mut Object, CommandError> {
        let id = self.id;
        self.bodies.get_mut(handle).map_err(|mut e| {
            e.message = format!("{} (GUI plane {id})", e.message);
            e
        })
    }

    /// Sets one property.
    pub fn set_object(&mut self, handle: Handle, prop: GuiObjectProp) -> Result<(), CommandError> {
        let (h, c) = {
            let b = self.body(handle)?;
            (b.handle, b.collider)
        };
        let was_driven = self.body(handle)?.is_driven();
        let prop = self
            .bodies
            .get_mut(handle)
            .expect("checked handle")
            .settings
            .apply(prop)?;
        let settings = self.body(handle)?.settings;
        let shape = self.body(handle)?.shape;
        let rb = &mut self.world.bodies[h];
        use GuiObjectProp::*;
        match prop {
            Position(p) => {
                rb.set_translation(Vector::from(p), true);
                self.query_stale.push(h);
            }
            Velocity(v) => rb.set_linvel(unlocked(&settings, Vector::from(v)), true),
            Rotation(deg) => {
                rb.set_rotation(rapier2d::math::Rotation::new(deg.to_radians()), true);
                self.query_stale.push(h);
            }
            AngularVelocity(w) if !settings.locked_rotation => rb.set_angvel(w.to_radians(), true),
            AngularVelocity(_) => {}
            ImpulseDirection(_) | ConstantForce(_) => rb.wake_up(true),
            Anchored(on) => {
                if on {
                    rb.set_linvel(Vector::ZERO, false);
                    rb.set_angvel(0.0, false);
                    rb.set_body_type(RigidBodyType::Fixed, true);
                } else {
                    rb.set_body_type(RigidBodyType::Dynamic, true);
                }
            }
            GravityScale(g) => rb.set_gravity_scale(g, true),
            LockedX(_) | LockedY(_) | LockedRotation(_) => {
                let mut axes = LockedAxes::empty();
                if settings.locked_x {
                    axes |= LockedAxes::TRANSLATION_LOCKED_X;
                }
                if settings.locked_y {
                    axes |= LockedAxes::TRANSLATION_LOCKED_Y;
                }
                if settings.locked_rotation {
                    axes |= LockedAxes::ROTATION_LOCKED;
                }
                rb.set_locked_axes(axes, true);
                // A lock zeroes that component of the velocity at once, as the reference does.
                let v = unlocked(&settings, rb.linvel());
                rb.set_linvel(v, true);
                if settings.locked_rotation {
                    rb.set_angvel(0.0, true);
                }
            }
            Held(on) => held::hold(&mut self.held, h, on),
            Mass(m) => {
                self.world.colliders[c].set_mass(m);
                self.refresh_mass(h);
            }
            Bounciness(e) => self.world.colliders[c].set_restitution(e),
            Friction(mu) => self.world.colliders[c].set_friction(mu),
            CanCollide(on) => {
                let groups = if on {
                    InteractionGroups::all()
                } else {
                    InteractionGroups::none()
                };
                self.world.colliders[c].set_collision_groups(groups);
                rb.wake_up(true);
            }
            ZIndex(z) => {
                let co = &mut self.world.colliders[c];
                co.user_data = layer(z) | (co.user_data & CONTROLLED);
                rb.wake_up(true);
            }
            Size(s) => {
                let co = &mut self.world.colliders[c];
                co.set_shape(collider_shape(shape, s));
                co.set_mass(settings.mass);
                self.refresh_mass(h);
                self.query_stale.push(h);
            }
        }
        let driven = self.body(handle)?.is_driven();
        match (was_driven, driven) {
            (false, true) => self.driven += 1,
            (true, false) => self.driven -= 1,
            _ => {}
        }
        Ok(())
    }

    /// Gives body `h` the mass of its collider now (rapier would at the next step), so an
    /// impulse, a jump or drag in the same batch divides by the new Mass; and wakes it.
    fn refresh_mass(&mut self, h: RigidBodyHandle) {
        let rb = &mut self.world.bodies[h];
        rb.recompute_mass_properties_from_colliders(&self.world.colliders);
        rb.wake_up(true);
    }

    /// `Δv = impulse / Mass` now (anchored bodies absorb it; locked axes are skipped).
    /// Returns the linear velocity right after it.
    pub fn apply_impulse(&mut self, handle: Handle, impulse: Vec2) -> Result<Vec2, CommandError> {
        let impulse = finite2("impulse", impulse)?;
        let b = self.changing(handle)?;
        let (h, settings) = (b.handle, b.settings);
        let rb = &mut self.world.bodies[h];
        if rb.is_dynamic() {
            let v = rb.linvel() + Vector::from(impulse) / rb.mass();
            rb.set_linvel(unlocked(&settings, v), true);
        }
        let v = rb.linvel();
        Ok([v.x, v.y])
    }

    /// Wakes the body.
    pub fn wake(&mut self, handle: Handle) -> Result<(), CommandError> {
        let h = self.changing(handle)?.handle;
        self.world.bodies[h].wake_up(true);
        Ok(())
    }

    /// Removes the body and its controller; the handle becomes stale.
    pub fn destroy_object(&mut self, handle: Handle) -> Result<(), CommandError> {
        self.body(handle)?;
        let body = self.bodies.remove(handle).expect("checked handle");
        if body.is_driven() {
            self.driven -= 1;
        }
        if body.controller.is_some() {
            self.controlled.retain(|s| *s != handle.slot);
        }
        self.world.remove_body(body.handle);
        Ok(())
    }

    /// Every property of the object.
    pub fn object_info(&self, handle: Handle) -> Result<GuiObjectInfo, CommandError> {
        let b = self.body(handle)?;
        let rb = &self.world.bodies[b.handle];
        let p = rb.translation();
        let v = rb.linvel();
        Ok(GuiObjectInfo {
            handle,
            shape: b.shape,
            settings: b.settings,
            position: [p.x, p.y],
            velocity: [v.x, v.y],
            rotation: rb.rotation().angle().to_degrees(),
            angular_velocity: rb.angvel().to_degrees(),
            sleeping: rb.is_sleeping(),
            controlled: b.controller.is_some(),
        })
    }

    /// Four fixed walls around `min`..`max` (the bounds): they meet every layer, and a body
    /// bounces off them with its own Bounciness and slides with its own Friction.
    pub(super) fn build_walls(&mut self, min: Vec2, max: Vec2) {
        let t = WALL_THICKNESS * 0.5;
        let (w, h) = (max[0] - min[0], max[1] - min[1]);
        let (cx, cy) = ((min[0] + max[0]) * 0.5, (min[1] + max[1]) * 0.5);
        let body = self.world.insert_body(
            RigidBodyBuilder::fixed()
                .user_data(WALLS_SLOT as u128)
                .build(),
        );
        let walls = [
            (Vector::new(min[0] - t, cy), t, h * 0.5 + 2.0 * t),
            (Vector::new(max[0] + t, cy), t, h * 0.5 + 2.0 * t),
            (Vector::new(cx, min[1] - t), w * 0.5 + 2.0 * t, t),
            (Vector::new(cx, max[1] + t), w * 0.5 + 2.0 * t, t),
        ];
        for (at, hx, hy) in walls {
            let wall = ColliderBuilder::cuboid(hx, hy)
                .translation(at)
                .friction(0.0)
                .friction_combine_rule(CoefficientCombineRule::Min)
                .restitution(0.0)
                .restitution_combine_rule(CoefficientCombineRule::Max)
                .user_data(WALL)
                .active_hooks(
                    ActiveHooks::FILTER_CONTACT_PAIRS | ActiveHooks::MODIFY_SOLVER_CONTACTS,
                )
                .build();
            self.world.insert_collider(wall, Some(body));
        }
    }
}

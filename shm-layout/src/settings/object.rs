//! Object properties: the wire variant, the defaults and the checks of each.

use serde::{Deserialize, Serialize};

use crate::collision_groups::MAX_COLLISION_GROUPS;
use crate::validate::{
    bounded3, clamped, finite3, in_range, non_negative, pose, positive, rotation, size,
    MAX_HIT_BOX_QUALITY, MAX_SIZE, MIN_MASS,
};
use crate::{CommandError, Pose, Vec3};

/// `FieldRestraint`: which axes an object may move along / rotate around. `None` leaves a
/// flag as it is.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Restraint {
    /// LockX.
    pub lock_x: Option<bool>,
    /// LockY.
    pub lock_y: Option<bool>,
    /// LockZ.
    pub lock_z: Option<bool>,
    /// LockRotX.
    pub lock_rot_x: Option<bool>,
    /// LockRotY.
    pub lock_rot_y: Option<bool>,
    /// LockRotZ.
    pub lock_rot_z: Option<bool>,
}

impl Restraint {
    /// The flags in the order LockX, LockY, LockZ, LockRotX, LockRotY, LockRotZ.
    pub fn flags(&self) -> [Option<bool>; 6] {
        [
            self.lock_x,
            self.lock_y,
            self.lock_z,
            self.lock_rot_x,
            self.lock_rot_y,
            self.lock_rot_z,
        ]
    }
}

/// `RotateTo`: a proportional controller driving the angular velocity toward `target`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct RotateTo {
    /// Target orientation, unit quaternion `[x, y, z, w]`.
    pub target: [f32; 4],
    /// Gain (1/s): the orientation error decays as `exp(-strength·t)`.
    pub strength: f32,
}

/// `SetPin`: pulls the body-local point `relative` toward `target.position` and turns the
/// body toward `target.rotation`, with a force capped at `force`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Pin {
    /// Largest force the pin applies.
    pub force: f32,
    /// Body-local point that is pulled.
    pub relative: Vec3,
    /// Where the point is pulled to, and the orientation the body turns toward.
    pub target: Pose,
}

/// An object property.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum ObjectProp {
    /// Teleports the object.
    Pose(Pose),
    /// Linear velocity.
    Velocity(Vec3),
    /// Angular velocity (rad/s).
    AngularVelocity(Vec3),
    /// Anchored objects do not move; setting it zeroes both velocities.
    Anchored(bool),
    /// Report contact started / stopped events for this object.
    ReportContacts(bool),
    /// Mass used when `Density` is 0 (impulses divide by it; free fall ignores it). Default 1.
    Weight(f32),
    /// When > 0, mass = Density × volume (wins over Weight). 0 returns to Weight.
    Density(f32),
    /// Restitution, clamped to [0, 1]; a pair uses the higher value. Default 0.
    Bounciness(f32),
    /// Coulomb friction in [0, 1]; a pair uses `sqrt(a·b)`. Default 0.5.
    Friction(f32),
    /// When false the object passes through everything.
    CanCollide(bool),
    /// Fidelity dial, clamped to [1, 32]. Default 1.
    HitBoxQuality(u32),
    /// Full size of the object's box (a sphere takes the smallest half-extent as radius; a
    /// mesh is scaled to it).
    Size(Vec3),
    /// Body-local centre of mass; non-zero switches to the real inertia of the shape.
    CenterOfMass(Vec3),
    /// Persistent acceleration applied every tick.
    ImpulseDirection(Vec3),
    /// Persistent world-space force applied every tick.
    ConstantForce(Vec3),
    /// Locks axes of motion; unspecified flags are kept.
    FieldRestraint(Restraint),
    /// `None` stops the controller (angular velocity is left as it is).
    RotateTo(Option<RotateTo>),
    /// `None` releases the pin.
    Pin(Option<Pin>),
    /// The object's collision group: an index into the plane's collision-group table.
    CollisionGroup(u8),
    /// Held: steps leave the object where it is (pose and velocities as before the step)
    /// until `Held(false)`, or for at most [`MAX_HELD_TICKS`] ticks. The SDK adds objects
    /// held on planes that tick by themselves and releases them with its next flush, so
    /// properties written right after an add apply before the object's first step.
    Held(bool),
}

/// Ticks a held object waits at most for its release (about half a second at 60 Hz).
pub const MAX_HELD_TICKS: u32 = 30;

/// The stored (not per-tick) properties of an object. [`Default`] holds the documented
/// defaults. Pose, velocities, Anchored and Size live in the engine's body and shape.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ObjectSettings {
    /// `ReportContacts`, default false.
    pub report_contacts: bool,
    /// `Weight`, default 1.
    pub weight: f32,
    /// `Density`, default 0 (mass from Weight).
    pub density: f32,
    /// `Bounciness`, default 0.
    pub bounciness: f32,
    /// `Friction`, default 0.5.
    pub friction: f32,
    /// `CanCollide`, default true.
    pub can_collide: bool,
    /// `HitBoxQuality`, default 1.
    pub hit_box_quality: u32,
    /// `CenterOfMass`, default 0 (the shape's centre).
    pub center_of_mass: Vec3,
    /// `ImpulseDirection`, default 0.
    pub impulse_direction: Vec3,
    /// `ConstantForce`, default 0.
    pub constant_force: Vec3,
    /// LockX, LockY, LockZ, LockRotX, LockRotY, LockRotZ, default all false.
    pub locks: [bool; 6],
    /// `RotateTo`, default none.
    pub rotate_to: Option<RotateTo>,
    /// `SetPin`, default none.
    pub pin: Option<Pin>,
    /// `CollisionGroup` index, default 0 ("Default").
    pub collision_group: u8,
}

impl Default for ObjectSettings {
    fn default() -> Self {
        ObjectSettings {
            report_contacts: false,
            weight: 1.0,
            density: 0.0,
            bounciness: 0.0,
            friction: 0.5,
            can_collide: true,
            hit_box_quality: 1,
            center_of_mass: [0.0; 3],
            impulse_direction: [0.0; 3],
            constant_force: [0.0; 3],
            locks: [false; 6],
            rotate_to: None,
            pin: None,
            collision_group: 0,
        }
    }
}

impl ObjectSettings {
    /// Stores a checked stored property. Returns false for the properties that live in the
    /// engine instead (Pose, velocities, Anchored, Size), leaving the settings unchanged.
    pub fn store(&mut self, prop: &ObjectProp) -> bool {
        match *prop {
            ObjectProp::ReportContacts(on) => self.report_contacts = on,
            ObjectProp::Weight(w) => self.weight = w,
            ObjectProp::Density(d) => self.density = d,
            ObjectProp::Bounciness(e) => self.bounciness = e,
            ObjectProp::Friction(mu) => self.friction = mu,
            ObjectProp::CanCollide(on) => self.can_collide = on,
            ObjectProp::HitBoxQuality(q) => self.hit_box_quality = q,
            ObjectProp::CenterOfMass(c) => self.center_of_mass = c,
            ObjectProp::ImpulseDirection(a) => self.impulse_direction = a,
            ObjectProp::ConstantForce(f) => self.constant_force = f,
            ObjectProp::FieldRestraint(r) => {
                for (lock, flag) in self.locks.iter_mut().zip(r.flags()) {
                    if let Some(on) = flag {
                        *lock = on;
                    }
                }
            }
            ObjectProp::RotateTo(r) => self.rotate_to = r,
            ObjectProp::Pin(p) => self.pin = p,
            ObjectProp::CollisionGroup(g) => self.collision_group = g,
            ObjectProp::Pose(_)
            | ObjectProp::Velocity(_)
            | ObjectProp::AngularVelocity(_)
            | ObjectProp::Anchored(_)
            | ObjectProp::Size(_)
            | ObjectProp::Held(_) => return false,
        }
        true
    }

    /// Whether the force pass has anything to do for this object itself.
    pub fn is_driven(&self) -> bool {
        self.impulse_direction != [0.0; 3]
            || self.constant_force != [0.0; 3]
            || self.rotate_to.is_some()
            || self.pin.is_some()
    }
}

impl ObjectProp {
    /// Whether the property changes what a published body state shows (pose, velocities,
    /// the anchored flag): what a client's read-your-writes overlay must cover.
    pub fn is_published(&self) -> bool {
        matches!(
            self,
            ObjectProp::Pose(_)
                | ObjectProp::Velocity(_)
                | ObjectProp::AngularVelocity(_)
                | ObjectProp::Anchored(_)
        )
    }

    /// The property as the daemon applies it, or an error naming it and the value.
    pub fn checked(self) -> Result<ObjectProp, CommandError> {
        use ObjectProp::*;
        Ok(match self {
            Pose(p) => Pose(pose("CFrame", p)?),
            Velocity(v) => Velocity(finite3("Velocity", v)?),
            AngularVelocity(w) => AngularVelocity(finite3("AngularVelocity", w)?),
            Weight(w) => {
                let w = positive("Weight", w)?;
                if w < MIN_MASS {
                    return Err(CommandError::invalid_field(
                        "Weight",
                        format!("Weight must be at least {MIN_MASS}, got {w}"),
                    ));
                }
                Weight(w)
            }
            Density(d) => Density(non_negative("Density", d)?),
            Bounciness(e) => Bounciness(clamped("Bounciness", e, 0.0, 1.0)?),
            Friction(mu) => Friction(in_range("Friction", mu, 0.0, 1.0)?),
            HitBoxQuality(q) => HitBoxQuality(q.clamp(1, MAX_HIT_BOX_QUALITY)),
            CollisionGroup(g) if g as usize >= MAX_COLLISION_GROUPS => {
                return Err(CommandError::invalid_field(
                    "CollisionGroup",
                    format!(
                        "CollisionGroup must be a group index below {MAX_COLLISION_GROUPS}, \
                         got {g}"
                    ),
                ))
            }
            Size(v) => Size(size("Size", v)?),
            CenterOfMass(c) => CenterOfMass(bounded3("CenterOfMass", c, MAX_SIZE)?),
            ImpulseDirection(a) => ImpulseDirection(finite3("ImpulseDirection", a)?),
            ConstantForce(f) => ConstantForce(finite3("ConstantForce", f)?),
            RotateTo(Some(r)) => RotateTo(Some(self::RotateTo {
                target: rotation("RotateTo.target", r.target)?,
                strength: non_negative("RotateTo.strength", r.strength)?,
            })),
            Pin(Some(p)) => Pin(Some(self::Pin {
                force: non_negative("SetPin.force", p.force)?,
                relative: bounded3("SetPin.relative", p.relative, MAX_SIZE)?,
                target: pose("SetPin.target", p.target)?,
            })),
            other => other,
        })
    }
}

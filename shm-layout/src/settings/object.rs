//! Object properties: one row each in the object settings table (wire variant, name,
//! default, range, stored field, flags), plus the structured values some of them carry.

use serde::{Deserialize, Serialize};

use super::row::{structured_value, Range};
use crate::collision_groups::MAX_COLLISION_GROUPS;
use crate::error::CommandError;
use crate::geometry::{Pose, Vec3};
use crate::validate::{
    bounded3, non_negative, pose, rotation, MAX_HIT_BOX_QUALITY, MAX_SIZE, MIN_MASS,
};

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
    /// Every flag `None`: keeps all locks as they are (the default).
    pub const KEEP: Restraint = Restraint {
        lock_x: None,
        lock_y: None,
        lock_z: None,
        lock_rot_x: None,
        lock_rot_y: None,
        lock_rot_z: None,
    };

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

// Structured payloads: their rows check them with a `check:` function.
structured_value!(Restraint, Option<RotateTo>, Option<Pin>);

super::table::settings_table! {
    /// An object property. One row each: wire variant (row order is wire order: new rows go
    /// last), API name, default, range, stored field and flags (see [`super::table`]).
    #[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
    pub enum ObjectProp;
    /// The stored (not per-tick) properties of an object. [`Default`] holds the documented
    /// defaults. Pose, velocities, Anchored and Size live in the engine's body and shape.
    #[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
    pub struct ObjectSettings;
    rows {
        /// Teleports the object.
        Pose(Pose) "CFrame" = Pose::IDENTITY, flags: [published, on_maps];
        /// Linear velocity.
        Velocity(Vec3) "Velocity" = [0.0; 3], flags: [published];
        /// Angular velocity (rad/s).
        AngularVelocity(Vec3) "AngularVelocity" = [0.0; 3], flags: [published];
        /// Anchored objects do not move; setting it zeroes both velocities.
        Anchored(bool) "Anchored" = false, flags: [published, derived];
        /// Report contact started / stopped events for this object.
        ReportContacts(bool) "ReportContacts" = false, field: report_contacts, flags: [on_maps];
        /// Mass used when `Density` is 0 (impulses divide by it; free fall ignores it). Default 1;
        /// at least `validate::MIN_MASS`.
        Weight(f32) "Weight" = 1.0, range: Range::AtLeast(MIN_MASS as f64), field: weight,
            flags: [derived, lua];
        /// When > 0, mass = Density × volume (wins over Weight). 0 returns to Weight.
        /// (Lua reads the density in effect, `ObjectInfo::density`: a row of its own.)
        Density(f32) "Density" = 0.0, range: Range::NonNegative, field: density,
            flags: [derived];
        /// Restitution, clamped to [0, 1]; a pair uses the higher value. Default 0.
        Bounciness(f32) "Bounciness" = 0.0, range: Range::Clamped(0.0, 1.0), field: bounciness,
            flags: [lua, on_maps];
        /// Coulomb friction in [0, 1]; a pair uses `sqrt(a·b)`. Default 0.5.
        Friction(f32) "Friction" = 0.5, range: Range::Within(0.0, 1.0), field: friction,
            flags: [lua, on_maps];
        /// When false the object passes through everything.
        CanCollide(bool) "CanCollide" = true, field: can_collide, flags: [lua, on_maps];
        /// Fidelity dial, clamped to [1, 32]. Default 1.
        HitBoxQuality(u32) "HitBoxQuality" = 1,
            range: Range::Clamped(1.0, MAX_HIT_BOX_QUALITY as f64), field: hit_box_quality,
            flags: [derived, lua];
        /// Full size of the object's box (a sphere takes the smallest half-extent as radius; a
        /// mesh is scaled to it).
        Size(Vec3) "Size" = [1.0; 3], range: Range::Extent, flags: [derived];
        /// Body-local centre of mass; non-zero switches to the real inertia of the shape.
        CenterOfMass(Vec3) "CenterOfMass" = [0.0; 3], range: Range::Bounded(MAX_SIZE as f64),
            field: center_of_mass, flags: [derived, lua];
        /// Persistent acceleration applied every tick.
        ImpulseDirection(Vec3) "ImpulseDirection" = [0.0; 3], field: impulse_direction,
            flags: [lua];
        /// Persistent world-space force applied every tick.
        ConstantForce(Vec3) "ConstantForce" = [0.0; 3], field: constant_force, flags: [lua];
        /// Locks axes of motion; unspecified flags are kept.
        FieldRestraint(Restraint) "FieldRestraint" = Restraint::KEEP,
            field: locks via store_locks => [bool; 6] = [false; 6];
        /// `None` stops the controller (angular velocity is left as it is).
        RotateTo(Option<RotateTo>) "RotateTo" = None, check: check_rotate_to, field: rotate_to,
            flags: [cpu_only];
        /// `None` releases the pin.
        Pin(Option<Pin>) "SetPin" = None, check: check_pin, field: pin, flags: [cpu_only];
        /// The object's collision group: an index into the plane's collision-group table.
        CollisionGroup(u8) "CollisionGroup" = 0, check: check_collision_group,
            field: collision_group, flags: [on_maps];
        /// Held: steps leave the object where it is (pose and velocities as before the step)
        /// until `Held(false)`, or for at most [`MAX_HELD_TICKS`] ticks. The SDK adds objects
        /// held on planes that tick by themselves and releases them with its next flush, so
        /// properties written right after an add apply before the object's first step.
        Held(bool) "Held" = false, flags: [on_maps];
        /// Multiplies the plane's Gravity for this object: 0 floats, -1 falls up. Default 1.
        GravityScale(f32) "GravityScale" = 1.0, field: gravity_scale, flags: [lua, cpu_only];
    }
}

impl ObjectProp {
    /// Whether a map (a static triangle mesh) takes this value: a row flagged `on_maps`, or
    /// `Anchored(true)` (a map is anchored and stays so).
    pub fn changes_on_map(&self) -> bool {
        self.row().on_maps || matches!(self, ObjectProp::Anchored(true))
    }

    /// The properties a map lets change, in the API's words ("CFrame, ... and Held"), for the
    /// errors that refuse the others.
    pub fn map_changeable() -> String {
        let names: Vec<&str> = ObjectProp::ROWS
            .iter()
            .filter(|r| r.on_maps)
            .map(|r| r.name)
            .collect();
        match names.split_last() {
            Some((last, rest)) if !rest.is_empty() => format!("{} and {last}", rest.join(", ")),
            _ => names.concat(),
        }
    }
}

/// `FieldRestraint` into the six lock flags: flags left `None` keep their value.
fn store_locks(locks: &mut [bool; 6], r: Restraint) {
    for (lock, flag) in locks.iter_mut().zip(r.flags()) {
        if let Some(on) = flag {
            *lock = on;
        }
    }
}

fn check_rotate_to(r: Option<RotateTo>) -> Result<Option<RotateTo>, CommandError> {
    let Some(r) = r else { return Ok(None) };
    Ok(Some(RotateTo {
        target: rotation("RotateTo.target", r.target)?,
        strength: non_negative("RotateTo.strength", r.strength)?,
    }))
}

fn check_pin(p: Option<Pin>) -> Result<Option<Pin>, CommandError> {
    let Some(p) = p else { return Ok(None) };
    Ok(Some(Pin {
        force: non_negative("SetPin.force", p.force)?,
        relative: bounded3("SetPin.relative", p.relative, MAX_SIZE)?,
        target: pose("SetPin.target", p.target)?,
    }))
}

fn check_collision_group(g: u8) -> Result<u8, CommandError> {
    if g as usize >= MAX_COLLISION_GROUPS {
        return Err(CommandError::invalid_field(
            "CollisionGroup",
            format!("CollisionGroup must be a group index below {MAX_COLLISION_GROUPS}, got {g}"),
        ));
    }
    Ok(g)
}

/// Ticks a held object waits at most for its release (about half a second at 60 Hz).
pub const MAX_HELD_TICKS: u32 = 30;

impl ObjectSettings {
    /// Whether the force pass has anything to do for this object itself.
    pub fn is_driven(&self) -> bool {
        self.impulse_direction != [0.0; 3]
            || self.constant_force != [0.0; 3]
            || self.rotate_to.is_some()
            || self.pin.is_some()
    }
}

impl ObjectProp {
    /// The property's name in the API (`"CFrame"`, `"SetPin"`).
    pub fn name(&self) -> &'static str {
        self.row().name
    }

    /// Whether the property changes what a published body state shows (pose, velocities,
    /// the anchored flag): what a client's read-your-writes overlay must cover.
    pub fn is_published(&self) -> bool {
        self.row().published
    }
}

//! GUI object properties (`PhysicsGuiObject`): the shapes of GUI primitives, the wire
//! variant of each property, its default and its check. Pixels, degrees and seconds, +Y down.

use serde::{Deserialize, Serialize};

use super::gui_plane::{finite2, Vec2};
use crate::validate::{clamped, extent, finite, in_range, positive, MIN_MASS};
use crate::CommandError;

/// The shape of a GUI primitive. Every shape fills its `Size` box centred on `Position`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum GuiShape {
    /// `GUI.Basic.Square`: a box of its Size.
    #[default]
    Square,
    /// `GUI.Basic.Circle`: a disc of diameter min(Size.X, Size.Y).
    Circle,
    /// `GUI.Basic.Triangle`: apex at the top centre, base along the bottom edge of its box.
    Triangle,
    /// `GUI.Basic.Image`: a box of its Size.
    Image,
    /// `GUI.Basic.Text`: a box of its Size.
    Text,
}

impl GuiShape {
    /// Every shape, in the order the API lists them.
    pub const ALL: [GuiShape; 5] = [
        GuiShape::Square,
        GuiShape::Circle,
        GuiShape::Triangle,
        GuiShape::Image,
        GuiShape::Text,
    ];

    /// The shape's name in the API (`"Square"`).
    pub fn name(&self) -> &'static str {
        match self {
            GuiShape::Square => "Square",
            GuiShape::Circle => "Circle",
            GuiShape::Triangle => "Triangle",
            GuiShape::Image => "Image",
            GuiShape::Text => "Text",
        }
    }
}

/// A property of a GUI object.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum GuiObjectProp {
    /// Centre of the body (px); writing teleports and wakes it.
    Position(Vec2),
    /// Linear velocity (px/s); wakes the body.
    Velocity(Vec2),
    /// Rotation in degrees (clockwise on screen, +Y down).
    Rotation(f32),
    /// Angular velocity in degrees per second.
    AngularVelocity(f32),
    /// One-shot impulse applied at the next tick, then cleared (`Δv = J / Mass`).
    ImpulseDirection(Vec2),
    /// Per-body force re-applied every tick.
    ConstantForce(Vec2),
    /// Mass, default 1; at least 0.0001 (smaller positive values are raised to it).
    Mass(f32),
    /// Coefficient of restitution, clamped to [0, 1]; a pair uses the higher, walls the
    /// body's own. Default 0.
    Bounciness(f32),
    /// Friction in [0, 4]; a pair uses the geometric mean. Default 0.3.
    Friction(f32),
    /// Anchored bodies do not move (others collide with them); setting true zeroes velocity.
    Anchored(bool),
    /// When false the body passes through others and rays (it still integrates).
    CanCollide(bool),
    /// Multiplier on the plane's Gravity. Default 1.
    GravityScale(f32),
    /// Zeroes the X velocity every tick.
    LockedX(bool),
    /// Zeroes the Y velocity every tick.
    LockedY(bool),
    /// Freezes rotation.
    LockedRotation(bool),
    /// The collision layer: bodies collide only with bodies of the same ZIndex.
    ZIndex(i32),
    /// Size of the primitive's box (px), each side within [0.001, 100,000].
    Size(Vec2),
    /// Held: steps leave the body where it is until `Held(false)`, or for at most
    /// [`crate::settings::object::MAX_HELD_TICKS`] ticks (see `ObjectProp::Held`).
    Held(bool),
}

/// The stored properties of a GUI object (the ones not read from the engine).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct GuiObjectSettings {
    /// `Mass`, default 1.
    pub mass: f32,
    /// `Bounciness`, default 0.
    pub bounciness: f32,
    /// `Friction`, default 0.3.
    pub friction: f32,
    /// `Anchored`, default false.
    pub anchored: bool,
    /// `CanCollide`, default true.
    pub can_collide: bool,
    /// `GravityScale`, default 1.
    pub gravity_scale: f32,
    /// `LockedX`.
    pub locked_x: bool,
    /// `LockedY`.
    pub locked_y: bool,
    /// `LockedRotation`.
    pub locked_rotation: bool,
    /// `ZIndex`, default 0.
    pub z_index: i32,
    /// `Size`, default (100, 100).
    pub size: Vec2,
    /// `ConstantForce`, default (0, 0).
    pub constant_force: Vec2,
    /// `ImpulseDirection` waiting for the next tick (0 once applied).
    pub impulse_direction: Vec2,
}

impl Default for GuiObjectSettings {
    fn default() -> Self {
        GuiObjectSettings {
            mass: 1.0,
            bounciness: 0.0,
            friction: 0.3,
            anchored: false,
            can_collide: true,
            gravity_scale: 1.0,
            locked_x: false,
            locked_y: false,
            locked_rotation: false,
            z_index: 0,
            size: [100.0, 100.0],
            constant_force: [0.0; 2],
            impulse_direction: [0.0; 2],
        }
    }
}

/// Largest Friction.
pub const MAX_GUI_FRICTION: f32 = 4.0;

impl GuiObjectProp {
    /// The property's name in the API.
    pub fn name(&self) -> &'static str {
        use GuiObjectProp::*;
        match self {
            Position(_) => "Position",
            Velocity(_) => "Velocity",
            Rotation(_) => "Rotation",
            AngularVelocity(_) => "AngularVelocity",
            ImpulseDirection(_) => "ImpulseDirection",
            ConstantForce(_) => "ConstantForce",
            Mass(_) => "Mass",
            Bounciness(_) => "Bounciness",
            Friction(_) => "Friction",
            Anchored(_) => "Anchored",
            CanCollide(_) => "CanCollide",
            GravityScale(_) => "GravityScale",
            LockedX(_) => "LockedX",
            LockedY(_) => "LockedY",
            LockedRotation(_) => "LockedRotation",
            ZIndex(_) => "ZIndex",
            Size(_) => "Size",
            Held(_) => "Held",
        }
    }

    /// The property as the daemon applies it (clamped where documented), or an error naming
    /// it and the value.
    pub fn checked(self) -> Result<GuiObjectProp, CommandError> {
        use GuiObjectProp::*;
        Ok(match self {
            Position(p) => Position(finite2("Position", p)?),
            Velocity(v) => Velocity(finite2("Velocity", v)?),
            Rotation(r) => Rotation(finite("Rotation", r)?),
            AngularVelocity(w) => AngularVelocity(finite("AngularVelocity", w)?),
            ImpulseDirection(j) => ImpulseDirection(finite2("ImpulseDirection", j)?),
            ConstantForce(f) => ConstantForce(finite2("ConstantForce", f)?),
            Mass(m) => Mass(positive("Mass", m)?.max(MIN_MASS)),
            Bounciness(e) => Bounciness(clamped("Bounciness", e, 0.0, 1.0)?),
            Friction(mu) => Friction(in_range("Friction", mu, 0.0, MAX_GUI_FRICTION)?),
            GravityScale(g) => GravityScale(finite("GravityScale", g)?),
            Size(s) => Size([extent("Size.X", s[0])?, extent("Size.Y", s[1])?]),
            other => other,
        })
    }
}

impl GuiObjectSettings {
    /// Stores a checked property; the ones that live in the engine (pose, velocities) are
    /// left to the caller. Returns the property as stored.
    pub fn apply(&mut self, prop: GuiObjectProp) -> Result<GuiObjectProp, CommandError> {
        let prop = prop.checked()?;
        use GuiObjectProp::*;
        match prop {
            Mass(m) => self.mass = m,
            Bounciness(e) => self.bounciness = e,
            Friction(mu) => self.friction = mu,
            Anchored(on) => self.anchored = on,
            CanCollide(on) => self.can_collide = on,
            GravityScale(g) => self.gravity_scale = g,
            LockedX(on) => self.locked_x = on,
            LockedY(on) => self.locked_y = on,
            LockedRotation(on) => self.locked_rotation = on,
            ZIndex(z) => self.z_index = z,
            Size(s) => self.size = s,
            ConstantForce(f) => self.constant_force = f,
            ImpulseDirection(j) => {
                self.impulse_direction = [
                    self.impulse_direction[0] + j[0],
                    self.impulse_direction[1] + j[1],
                ]
            }
            Position(_) | Velocity(_) | Rotation(_) | AngularVelocity(_) | Held(_) => {}
        }
        Ok(prop)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn checks_name_the_field() {
        let e = GuiObjectProp::Friction(5.0).checked().unwrap_err();
        assert!(e.message.contains("Friction") && e.message.contains('5'));
        let e = GuiObjectProp::Size([10.0, f32::NAN]).checked().unwrap_err();
        assert!(e.message.contains("Size.Y"), "{}", e.message);
        assert_eq!(
            GuiObjectProp::Mass(1e-9).checked().unwrap(),
            GuiObjectProp::Mass(MIN_MASS)
        );
        assert!(GuiObjectProp::Mass(0.0).checked().is_err());
        assert_eq!(
            GuiObjectProp::Bounciness(3.0).checked().unwrap(),
            GuiObjectProp::Bounciness(1.0)
        );
    }
}

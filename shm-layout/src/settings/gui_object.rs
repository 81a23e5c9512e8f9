//! GUI object properties (`PhysicsGuiObject`): the shapes of GUI primitives, the wire
//! variant of each property, its default and its check. Pixels, degrees and seconds, +Y down.

use serde::{Deserialize, Serialize};

use super::row::Range;
use crate::error::CommandError;
use crate::geometry::Vec2;
use crate::validate::MIN_MASS;

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

/// Largest Friction.
pub const MAX_GUI_FRICTION: f32 = 4.0;

super::table::settings_table! {
    /// A property of a GUI object. One row each: wire variant (row order is wire order: new
    /// rows go last), API name, default, range, stored field and flags (see
    /// [`super::table`]).
    #[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
    pub enum GuiObjectProp;
    /// The stored properties of a GUI object (the ones not read from the engine).
    /// [`Default`] holds the documented defaults.
    #[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
    pub struct GuiObjectSettings;
    rows {
        /// Centre of the body (px); writing teleports and wakes it.
        Position(Vec2) "Position" = [0.0; 2], flags: [published];
        /// Linear velocity (px/s); wakes the body.
        Velocity(Vec2) "Velocity" = [0.0; 2], flags: [published];
        /// Rotation in degrees (clockwise on screen, +Y down).
        Rotation(f32) "Rotation" = 0.0, flags: [published];
        /// Angular velocity in degrees per second.
        AngularVelocity(f32) "AngularVelocity" = 0.0, flags: [published];
        /// One-shot impulse applied at the next tick, then cleared (`Δv = J / Mass`); writes
        /// in one tick add up.
        ImpulseDirection(Vec2) "ImpulseDirection" = [0.0; 2],
            field: impulse_direction via add_impulse => Vec2 = [0.0; 2];
        /// Per-body force re-applied every tick.
        ConstantForce(Vec2) "ConstantForce" = [0.0; 2], field: constant_force, flags: [lua];
        /// Mass, default 1; at least 0.0001 (smaller positive values are raised to it).
        Mass(f32) "Mass" = 1.0, range: Range::Positive, check: at_least_min_mass, field: mass,
            flags: [lua];
        /// Coefficient of restitution, clamped to [0, 1]; a pair uses the higher, walls the
        /// body's own. Default 0.
        Bounciness(f32) "Bounciness" = 0.0, range: Range::Clamped(0.0, 1.0), field: bounciness,
            flags: [lua];
        /// Friction in [0, 4]; a pair uses the geometric mean. Default 0.3.
        Friction(f32) "Friction" = 0.3, range: Range::Within(0.0, MAX_GUI_FRICTION as f64),
            field: friction, flags: [lua];
        /// Anchored bodies do not move (others collide with them); setting true zeroes velocity.
        Anchored(bool) "Anchored" = false, field: anchored, flags: [published];
        /// When false the body passes through others and rays (it still integrates).
        CanCollide(bool) "CanCollide" = true, field: can_collide, flags: [lua];
        /// Multiplier on the plane's Gravity. Default 1.
        GravityScale(f32) "GravityScale" = 1.0, field: gravity_scale, flags: [lua];
        /// Zeroes the X velocity every tick.
        LockedX(bool) "LockedX" = false, field: locked_x, flags: [lua];
        /// Zeroes the Y velocity every tick.
        LockedY(bool) "LockedY" = false, field: locked_y, flags: [lua];
        /// Freezes rotation.
        LockedRotation(bool) "LockedRotation" = false, field: locked_rotation, flags: [lua];
        /// The collision layer: bodies collide only with bodies of the same ZIndex.
        ZIndex(i32) "ZIndex" = 0, field: z_index;
        /// Size of the primitive's box (px), each side within [0.001, 100,000].
        Size(Vec2) "Size" = [100.0, 100.0], range: Range::Extent, field: size;
        /// Held: steps leave the body where it is until `Held(false)`, or for at most
        /// [`crate::settings::object::MAX_HELD_TICKS`] ticks (see `ObjectProp::Held`).
        Held(bool) "Held" = false;
    }
}

/// `Mass`: smaller positive values are raised to [`MIN_MASS`].
fn at_least_min_mass(m: f32) -> Result<f32, CommandError> {
    Ok(m.max(MIN_MASS))
}

/// `ImpulseDirection`: writes before the next tick add up.
fn add_impulse(pending: &mut Vec2, j: Vec2) {
    *pending = [pending[0] + j[0], pending[1] + j[1]];
}

impl GuiObjectProp {
    /// The property's name in the API.
    pub fn name(&self) -> &'static str {
        self.row().name
    }
}

impl GuiObjectSettings {
    /// Checks and stores a property; the ones that live in the engine (pose, velocities)
    /// are left to the caller. Returns the property as stored (clamped where documented).
    pub fn apply(&mut self, prop: GuiObjectProp) -> Result<GuiObjectProp, CommandError> {
        let prop = prop.checked()?;
        self.store(&prop);
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

//! Character-controller options and properties: the wire variant, the default and the check
//! of each (the reference's `Controller`, plus the movement-model knobs it leaves implicit).

use serde::{Deserialize, Serialize};

use super::row::Range;
use crate::error::CommandError;
use crate::geometry::Vec3;
use crate::validate::{in_range, MAX_COORDINATE, MAX_SIZE, MIN_SIZE};

/// Steepest `MaxSlope` (degrees): a wall is never walkable.
pub const MAX_SLOPE_LIMIT: f32 = 89.0;
/// Largest speed-like option (units/s).
pub const MAX_CONTROLLER_SPEED: f32 = 10_000.0;

super::table::settings_table! {
    /// A controller property. Options of `NewController` are the same values. One row each:
    /// wire variant (row order is wire order: new rows go last), API name, default, range,
    /// stored field and flags (see [`super::table`]). The capsule's defaults follow the
    /// part ([`ControllerSettings::defaults`]); the table's are those of a 1 × 2 × 1 part.
    #[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
    pub enum ControllerProp;
    /// A controller's settings as set. [`ControllerSettings::defaults`] holds the documented
    /// defaults for a part of a given size.
    #[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
    pub struct ControllerSettings;
    rows {
        /// Top horizontal speed (units/s). Default 16.
        WalkSpeed(f32) "WalkSpeed" = 16.0, range: SPEED, field: walk_speed, flags: [lua];
        /// Jump launch speed (units/s): apex = JumpPower² / (2·g). Default 28.
        JumpPower(f32) "JumpPower" = 28.0, range: SPEED, field: jump_power, flags: [lua];
        /// The controller's own gravity magnitude (units/s², pulling down); setting it turns
        /// `UsePlaneGravity` off. Default 50 (used only without UsePlaneGravity).
        Gravity(f32) "Gravity" = 50.0, range: Range::Within(-1e5, 1e5), field: gravity,
            flags: [lua];
        /// Gravity from the plane's `Gravity.Y` each tick (default true).
        UsePlaneGravity(bool) "UsePlaneGravity" = true, field: use_plane_gravity, flags: [lua];
        /// Yaw blending rate (1/s) when LookWhereMoving. Default 12.
        TurnSpeed(f32) "TurnSpeed" = 12.0, range: RATE, field: turn_speed, flags: [lua];
        /// Steepest walkable slope, degrees in [0, 89]. Steeper slopes are not climbed and
        /// slide. Default 45.
        MaxSlope(f32) "MaxSlope" = 45.0, range: Range::Within(0.0, MAX_SLOPE_LIMIT as f64),
            field: max_slope, flags: [lua];
        /// Height of an infinite fallback floor under the controller when nothing is under
        /// its capsule; `None` (the default): no fallback, it falls.
        GroundY(Option<f32>) "GroundY" = None, check: check_ground_y, field: ground_y;
        /// Capsule radius (units). Default: half the smaller of the part's Size.X / Size.Z.
        CapsuleRadius(f32) "CapsuleRadius" = 0.5,
            range: Range::Within(MIN_SIZE as f64, MAX_SIZE as f64), field: capsule_radius,
            flags: [lua];
        /// Half the capsule's straight segment (units; rapier's convention): total height is
        /// 2·(CapsuleHalfHeight + CapsuleRadius). Default: Size.Y / 2 − radius.
        CapsuleHalfHeight(f32) "CapsuleHalfHeight" = 0.5, range: LENGTH,
            field: capsule_half_height, flags: [lua];
        /// Horizontal distance at which a waypoint counts as reached. Default 1.
        WaypointThreshold(f32) "WaypointThreshold" = 1.0,
            range: Range::Within(1e-3, MAX_SIZE as f64), field: waypoint_threshold,
            flags: [lua];
        /// Auto-yaw toward the velocity (default true for NewController, false for
        /// NewControlledController).
        LookWhereMoving(bool) "LookWhereMoving" = true, field: look_where_moving,
            flags: [lua];
        /// Tallest step walked up without jumping (units). Default 0.6 × CapsuleRadius + 0.5,
        /// set explicitly to override.
        StepHeight(f32) "StepHeight" = 0.8, range: LENGTH, field: step_height, flags: [lua];
        /// Ground acceleration (1/s, Quake's `accelerate`: the speed gained per second is
        /// Acceleration × WalkSpeed). Default 10.
        Acceleration(f32) "Acceleration" = 10.0, range: RATE, field: acceleration,
            flags: [lua];
        /// Ground friction (1/s, Quake's): speed lost per second is Friction × max(speed,
        /// WalkSpeed / 4). Default 8.
        Friction(f32) "Friction" = 8.0, range: RATE, field: friction, flags: [lua];
        /// Share of Acceleration available in the air, in [0, 1]. Default 0.3.
        AirControl(f32) "AirControl" = 0.3, range: Range::Within(0.0, 1.0),
            field: air_control, flags: [lua];
        /// Largest force (mass·units/s²) the controller pushes dynamic bodies with.
        /// Default 500.
        PushStrength(f32) "PushStrength" = 500.0, range: Range::NonNegative,
            field: push_strength, flags: [lua];
        /// Teleports the controller (zeroes its velocity, keeps its path).
        Position(Vec3) "Position" = [0.0; 3], range: Range::Bounded(MAX_COORDINATE as f64);
        /// Adds free motion: replaces the velocity (units/s).
        Velocity(Vec3) "Velocity" = [0.0; 3],
            range: Range::Bounded(MAX_CONTROLLER_SPEED as f64);
        /// Facing, Euler radians; Y is the yaw (X and Z are ignored: the capsule stays
        /// upright).
        Rotation(Vec3) "Rotation" = [0.0; 3];
        /// Motion intent in local space (+Z forward, +X right), each in [-1, 1].
        MoveVector([f32; 2]) "MoveVector" = [0.0; 2], range: Range::UnitAxes("X", "Z");
        /// Publish a `Moved` event every tick the controller moves (only while a script
        /// listens).
        ReportMoved(bool) "ReportMoved" = false, field: report_moved;
        /// Made by NewControlledController (read-only: the creation call sets it).
        Controlled(bool) "Controlled" = false, check: read_only, field: controlled;
    }
}

/// Speed-like options: [0, MAX_CONTROLLER_SPEED].
const SPEED: Range = Range::Within(0.0, MAX_CONTROLLER_SPEED as f64);
/// Rates (1/s): [0, 10,000].
const RATE: Range = Range::Within(0.0, 1e4);
/// Lengths that may be zero: [0, MAX_SIZE].
const LENGTH: Range = Range::Within(0.0, MAX_SIZE as f64);

fn check_ground_y(y: Option<f32>) -> Result<Option<f32>, CommandError> {
    y.map(|y| in_range("GroundY", y, -MAX_COORDINATE, MAX_COORDINATE))
        .transpose()
}

fn read_only(_: bool) -> Result<bool, CommandError> {
    Err(CommandError::invalid_field(
        "Controlled",
        "Controller.Controlled is read-only (NewControlledController sets it)",
    ))
}

impl ControllerSettings {
    /// The defaults for a part of full `size` (capsule from the size), `controlled` for
    /// NewControlledController.
    pub fn defaults(size: [f32; 3], controlled: bool) -> ControllerSettings {
        let radius = (size[0].min(size[2]) / 2.0).max(0.01);
        ControllerSettings {
            capsule_radius: radius,
            capsule_half_height: (size[1] / 2.0 - radius).max(0.0),
            look_where_moving: !controlled,
            step_height: 0.6 * radius + 0.5,
            controlled,
            ..ControllerSettings::default()
        }
    }

    /// Checks `prop` and stores it when it is a setting (`Gravity` also turns
    /// `UsePlaneGravity` off). Returns false for the per-tick state (Position, Velocity,
    /// Rotation, MoveVector), which the controller holds itself.
    pub fn apply(&mut self, prop: ControllerProp) -> Result<bool, CommandError> {
        let prop = prop.checked()?;
        if let ControllerProp::Gravity(_) = prop {
            self.use_plane_gravity = false;
        }
        Ok(self.store(&prop))
    }
}

impl ControllerProp {
    /// The API name of the property.
    pub fn name(&self) -> &'static str {
        self.row().name
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_follow_the_part_and_gravity_turns_plane_gravity_off() {
        let mut s = ControllerSettings::defaults([2.0, 5.0, 3.0], false);
        assert_eq!(s.capsule_radius, 1.0);
        assert_eq!(s.capsule_half_height, 1.5);
        assert!(s.look_where_moving && !s.controlled);
        assert!(ControllerSettings::defaults([2.0, 5.0, 2.0], true).controlled);
        assert!(s.apply(ControllerProp::Gravity(20.0)).unwrap());
        assert!(!s.use_plane_gravity);
        assert_eq!(s.gravity, 20.0);
    }

    #[test]
    fn bad_values_name_the_property() {
        let e = ControllerProp::WalkSpeed(f32::NAN).checked().unwrap_err();
        assert_eq!(e.field.as_deref(), Some("WalkSpeed"));
        let e = ControllerProp::MaxSlope(95.0).checked().unwrap_err();
        assert_eq!(e.field.as_deref(), Some("MaxSlope"));
        let e = ControllerProp::MoveVector([0.0, 2.0])
            .checked()
            .unwrap_err();
        assert_eq!(e.field.as_deref(), Some("MoveVector.Z"));
    }
}

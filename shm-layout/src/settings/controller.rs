//! Character-controller options and properties: the wire variant, the default and the check
//! of each (the reference's `Controller`, plus the movement-model knobs it leaves implicit).

use serde::{Deserialize, Serialize};

use crate::validate::{finite, in_range, non_negative, MAX_COORDINATE, MAX_SIZE};
use crate::CommandError;

/// Steepest `MaxSlope` (degrees): a wall is never walkable.
pub const MAX_SLOPE_LIMIT: f32 = 89.0;
/// Largest speed-like option (units/s).
pub const MAX_CONTROLLER_SPEED: f32 = 10_000.0;

/// A controller property. Options of `NewController` are the same values.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum ControllerProp {
    /// Top horizontal speed (units/s). Default 16.
    WalkSpeed(f32),
    /// Jump launch speed (units/s): apex = JumpPower² / (2·g). Default 28.
    JumpPower(f32),
    /// The controller's own gravity magnitude (units/s², pulling down); setting it turns
    /// `UsePlaneGravity` off.
    Gravity(f32),
    /// Gravity from the plane's `Gravity.Y` each tick (default true).
    UsePlaneGravity(bool),
    /// Yaw blending rate (1/s) when LookWhereMoving. Default 12.
    TurnSpeed(f32),
    /// Steepest walkable slope, degrees in [0, 89]. Steeper slopes are not climbed and
    /// slide. Default 45.
    MaxSlope(f32),
    /// Height of an infinite fallback floor under the controller when nothing is under its
    /// capsule; `None` (the default): no fallback, it falls.
    GroundY(Option<f32>),
    /// Capsule radius (units). Default: half the smaller of the part's Size.X / Size.Z.
    CapsuleRadius(f32),
    /// Half the capsule's straight segment (units; rapier's convention): total height is
    /// 2·(CapsuleHalfHeight + CapsuleRadius). Default: Size.Y / 2 − radius.
    CapsuleHalfHeight(f32),
    /// Horizontal distance at which a waypoint counts as reached. Default 1.
    WaypointThreshold(f32),
    /// Auto-yaw toward the velocity (default true for NewController, false for
    /// NewControlledController).
    LookWhereMoving(bool),
    /// Tallest step walked up without jumping (units). Default 0.6 × CapsuleRadius + 0.5,
    /// set explicitly to override.
    StepHeight(f32),
    /// Ground acceleration (1/s, Quake's `accelerate`: the speed gained per second is
    /// Acceleration × WalkSpeed). Default 10.
    Acceleration(f32),
    /// Ground friction (1/s, Quake's): speed lost per second is Friction × max(speed,
    /// WalkSpeed / 4). Default 8.
    Friction(f32),
    /// Share of Acceleration available in the air, in [0, 1]. Default 0.3.
    AirControl(f32),
    /// Largest force (mass·units/s²) the controller pushes dynamic bodies with. Default 500.
    PushStrength(f32),
    /// Teleports the controller (zeroes its velocity, keeps its path).
    Position([f32; 3]),
    /// Adds free motion: replaces the velocity (units/s).
    Velocity([f32; 3]),
    /// Facing, Euler radians; Y is the yaw (X and Z are ignored: the capsule stays upright).
    Rotation([f32; 3]),
    /// Motion intent in local space (+Z forward, +X right), each in [-1, 1].
    MoveVector([f32; 2]),
    /// Publish a `Moved` event every tick the controller moves (only while a script listens).
    ReportMoved(bool),
}

/// A controller's settings as set. [`ControllerSettings::defaults`] holds the documented
/// defaults for a part of a given size.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ControllerSettings {
    /// `WalkSpeed`, default 16.
    pub walk_speed: f32,
    /// `JumpPower`, default 28.
    pub jump_power: f32,
    /// `Gravity` (own magnitude), default 50 (used only without UsePlaneGravity).
    pub gravity: f32,
    /// `UsePlaneGravity`, default true.
    pub use_plane_gravity: bool,
    /// `TurnSpeed`, default 12.
    pub turn_speed: f32,
    /// `MaxSlope` in degrees, default 45.
    pub max_slope: f32,
    /// `GroundY`, default none.
    pub ground_y: Option<f32>,
    /// `CapsuleRadius`.
    pub capsule_radius: f32,
    /// `CapsuleHalfHeight`.
    pub capsule_half_height: f32,
    /// `WaypointThreshold`, default 1.
    pub waypoint_threshold: f32,
    /// `LookWhereMoving`.
    pub look_where_moving: bool,
    /// `StepHeight`.
    pub step_height: f32,
    /// `Acceleration`, default 10.
    pub acceleration: f32,
    /// `Friction`, default 8.
    pub friction: f32,
    /// `AirControl`, default 0.3.
    pub air_control: f32,
    /// `PushStrength`, default 500.
    pub push_strength: f32,
    /// `Controlled` (read-only): made by NewControlledController.
    pub controlled: bool,
    /// Whether `Moved` events are published.
    pub report_moved: bool,
}

impl ControllerSettings {
    /// The defaults for a part of full `size` (capsule from the size), `controlled` for
    /// NewControlledController.
    pub fn defaults(size: [f32; 3], controlled: bool) -> ControllerSettings {
        let radius = (size[0].min(size[2]) / 2.0).max(0.01);
        ControllerSettings {
            walk_speed: 16.0,
            jump_power: 28.0,
            gravity: 50.0,
            use_plane_gravity: true,
            turn_speed: 12.0,
            max_slope: 45.0,
            ground_y: None,
            capsule_radius: radius,
            capsule_half_height: (size[1] / 2.0 - radius).max(0.0),
            waypoint_threshold: 1.0,
            look_where_moving: !controlled,
            step_height: 0.6 * radius + 0.5,
            acceleration: 10.0,
            friction: 8.0,
            air_control: 0.3,
            push_strength: 500.0,
            controlled,
            report_moved: false,
        }
    }

    /// Checks `prop` and stores it when it is a setting. Returns false for the per-tick
    /// state (Position, Velocity, Rotation, MoveVector), which the controller holds itself.
    pub fn apply(&mut self, prop: ControllerProp) -> Result<bool, CommandError> {
        use ControllerProp::*;
        match prop.checked()? {
            WalkSpeed(v) => self.walk_speed = v,
            JumpPower(v) => self.jump_power = v,
            Gravity(g) => {
                self.gravity = g;
                self.use_plane_gravity = false;
            }
            UsePlaneGravity(on) => self.use_plane_gravity = on,
            TurnSpeed(v) => self.turn_speed = v,
            MaxSlope(v) => self.max_slope = v,
            GroundY(y) => self.ground_y = y,
            CapsuleRadius(r) => self.capsule_radius = r,
            CapsuleHalfHeight(h) => self.capsule_half_height = h,
            WaypointThreshold(v) => self.waypoint_threshold = v,
            LookWhereMoving(on) => self.look_where_moving = on,
            StepHeight(h) => self.step_height = h,
            Acceleration(a) => self.acceleration = a,
            Friction(f) => self.friction = f,
            AirControl(a) => self.air_control = a,
            PushStrength(f) => self.push_strength = f,
            ReportMoved(on) => self.report_moved = on,
            Position(_) | Velocity(_) | Rotation(_) | MoveVector(_) => return Ok(false),
        }
        Ok(true)
    }
}

impl ControllerProp {
    /// The API name of the property.
    pub fn name(&self) -> &'static str {
        use ControllerProp::*;
        match self {
            WalkSpeed(_) => "WalkSpeed",
            JumpPower(_) => "JumpPower",
            Gravity(_) => "Gravity",
            UsePlaneGravity(_) => "UsePlaneGravity",
            TurnSpeed(_) => "TurnSpeed",
            MaxSlope(_) => "MaxSlope",
            GroundY(_) => "GroundY",
            CapsuleRadius(_) => "CapsuleRadius",
            CapsuleHalfHeight(_) => "CapsuleHalfHeight",
            WaypointThreshold(_) => "WaypointThreshold",
            LookWhereMoving(_) => "LookWhereMoving",
            StepHeight(_) => "StepHeight",
            Acceleration(_) => "Acceleration",
            Friction(_) => "Friction",
            AirControl(_) => "AirControl",
            PushStrength(_) => "PushStrength",
            Position(_) => "Position",
            Velocity(_) => "Velocity",
            Rotation(_) => "Rotation",
            MoveVector(_) => "MoveVector",
            ReportMoved(_) => "ReportMoved",
        }
    }

    /// The property as the daemon applies it, or an error naming it and the value.
    pub fn checked(self) -> Result<ControllerProp, CommandError> {
        use ControllerProp::*;
        let speed = |f: &str, v: f32| in_range(f, v, 0.0, MAX_CONTROLLER_SPEED);
        let vec3 = |f: &str, v: [f32; 3], max: f32| crate::validate::bounded3(f, v, max);
        Ok(match self {
            WalkSpeed(v) => WalkSpeed(speed("WalkSpeed", v)?),
            JumpPower(v) => JumpPower(speed("JumpPower", v)?),
            Gravity(g) => Gravity(in_range("Gravity", g, -1e5, 1e5)?),
            TurnSpeed(v) => TurnSpeed(in_range("TurnSpeed", v, 0.0, 1e4)?),
            MaxSlope(v) => MaxSlope(in_range("MaxSlope", v, 0.0, MAX_SLOPE_LIMIT)?),
            GroundY(Some(y)) => GroundY(Some(in_range(
                "GroundY",
                y,
                -MAX_COORDINATE,
                MAX_COORDINATE,
            )?)),
            CapsuleRadius(r) => CapsuleRadius(crate::validate::extent("CapsuleRadius", r)?),
            CapsuleHalfHeight(h) => {
                CapsuleHalfHeight(in_range("CapsuleHalfHeight", h, 0.0, MAX_SIZE)?)
            }
            WaypointThreshold(v) => {
                WaypointThreshold(in_range("WaypointThreshold", v, 1e-3, MAX_SIZE)?)
            }
            StepHeight(h) => StepHeight(in_range("StepHeight", h, 0.0, MAX_SIZE)?),
            Acceleration(a) => Acceleration(in_range("Acceleration", a, 0.0, 1e4)?),
            Friction(f) => Friction(in_range("Friction", f, 0.0, 1e4)?),
            AirControl(a) => AirControl(in_range("AirControl", a, 0.0, 1.0)?),
            PushStrength(f) => PushStrength(non_negative("PushStrength", f)?),
            Position(p) => Position(vec3("Position", p, MAX_COORDINATE)?),
            Velocity(v) => Velocity(vec3("Velocity", v, MAX_CONTROLLER_SPEED)?),
            Rotation(r) => Rotation(crate::validate::finite3("Rotation", r)?),
            MoveVector([x, z]) => MoveVector([
                in_range("MoveVector.X", finite("MoveVector.X", x)?, -1.0, 1.0)?,
                in_range("MoveVector.Z", finite("MoveVector.Z", z)?, -1.0, 1.0)?,
            ]),
            other => other,
        })
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

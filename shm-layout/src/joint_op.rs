//! Joints between two objects (or an object and the world): the kinds, every option with
//! its check, and the ops on a plane's joints. Options are [`JointProp`] values applied in
//! order over the kind's defaults, at creation and live, like object properties.

use serde::{Deserialize, Serialize};

pub use crate::axis_motor::AxisMotor;
use crate::error::CommandError;
use crate::geometry::Vec3;
use crate::ids::Handle;
pub use crate::joint_limits::{AXIS_NAMES, MAX_ANGLE, MAX_JOINT_VALUE};
use crate::validate::{finite, finite3, non_negative, MAX_COORDINATE};

/// Which constraint a joint is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum JointKind {
    /// Point-to-point: the anchors coincide, every rotation free (SwingLimit / TwistLimit
    /// optional).
    Ball,
    /// One rotation about `Axis` (LowerAngle / UpperAngle, motors).
    Hinge,
    /// Ball with a swing cone and a twist range about `Axis` (ragdoll shoulders, hips).
    ConeTwist,
    /// Every axis chosen by `Axes`: Locked, Limited (Lower/Upper Distance or Angle) or Free.
    SixDof,
    /// The two objects move as one.
    Fixed,
    /// One translation along `Axis` (LowerDistance / UpperDistance, motors).
    Prismatic,
    /// The anchors stay at most `UpperDistance` (or `RestLength`) apart.
    Rope,
    /// A damped spring between the anchors: rest length `RestLength`, `Stiffness`
    /// (force per unit of stretch), `Damping` (force per unit of stretch speed).
    Spring,
}

impl JointKind {
    /// Every kind, in declaration order.
    pub const ALL: [JointKind; 8] = [
        JointKind::Ball,
        JointKind::Hinge,
        JointKind::ConeTwist,
        JointKind::SixDof,
        JointKind::Fixed,
        JointKind::Prismatic,
        JointKind::Rope,
        JointKind::Spring,
    ];

    /// The API name (`"Ball"`, `"Hinge"`, …).
    pub fn name(self) -> &'static str {
        match self {
            JointKind::Ball => "Ball",
            JointKind::Hinge => "Hinge",
            JointKind::ConeTwist => "ConeTwist",
            JointKind::SixDof => "SixDof",
            JointKind::Fixed => "Fixed",
            JointKind::Prismatic => "Prismatic",
            JointKind::Rope => "Rope",
            JointKind::Spring => "Spring",
        }
    }

    /// The kind of an API name.
    pub fn from_name(name: &str) -> Option<JointKind> {
        JointKind::ALL.into_iter().find(|k| k.name() == name)
    }
}

/// What a SixDof joint does along one of its axes.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum AxisMode {
    /// No motion along the axis.
    #[default]
    Locked,
    /// Motion within the joint's limits (LowerDistance / UpperDistance for X, Y, Z;
    /// LowerAngle / UpperAngle for RotX, RotY, RotZ).
    Limited,
    /// Free motion.
    Free,
}

impl AxisMode {
    /// The API name.
    pub fn name(self) -> &'static str {
        match self {
            AxisMode::Locked => "Locked",
            AxisMode::Limited => "Limited",
            AxisMode::Free => "Free",
        }
    }

    /// The mode of an API name.
    pub fn from_name(name: &str) -> Option<AxisMode> {
        [AxisMode::Locked, AxisMode::Limited, AxisMode::Free]
            .into_iter()
            .find(|m| m.name() == name)
    }
}

/// One joint option. Each is checked on its own ([`JointProp::checked`]) and against the
/// others once all are applied ([`JointSettings::check`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum JointProp {
    /// Anchor on object A, in A's local frame.
    AnchorA(Vec3),
    /// Anchor on object B (or the world point when B is the world), in B's local frame.
    AnchorB(Vec3),
    /// Hinge / prismatic / twist axis, local to A (normalised; not zero).
    Axis(Vec3),
    /// Lower angle limit (radians) of a Hinge or of SixDof's Limited rotations.
    LowerAngle(f32),
    /// Upper angle limit (radians).
    UpperAngle(f32),
    /// Half-angle of the swing cone (radians) of a ConeTwist or Ball.
    SwingLimit(f32),
    /// Twist range ±limit (radians) about the axis of a ConeTwist or Ball.
    TwistLimit(f32),
    /// Lower distance limit of a Prismatic, of SixDof's Limited translations.
    LowerDistance(f32),
    /// Upper distance limit (the length of a Rope).
    UpperDistance(f32),
    /// Rest length of a Spring (and the length of a Rope without UpperDistance).
    RestLength(f32),
    /// Spring stiffness (force per unit of stretch).
    Stiffness(f32),
    /// Spring damping (force per unit of stretch speed).
    Damping(f32),
    /// Motor target speed (rad/s for a Hinge, units/s for a Prismatic); NaN-free.
    MotorSpeed(f32),
    /// Motor target position (angle or distance), reached as a spring of `Stiffness` and
    /// `Damping` (defaults used when those are 0).
    MotorTarget(f32),
    /// Most force (torque for a Hinge) the motor may apply; 0 turns the motor off.
    MotorMaxForce(f32),
    /// SixDof per-axis modes, X, Y, Z, RotX, RotY, RotZ.
    Axes([AxisMode; 6]),
    /// The joint breaks when its constraint force exceeds this (0 = unbreakable).
    BreakForce(f32),
    /// Whether the two objects still collide with each other.
    CollideConnected(bool),
    /// A SixDof joint's motor (or spring) on one axis (0..6: X, Y, Z, RotX, RotY, RotZ);
    /// None removes it.
    AxisMotor {
        /// The axis, an index into [`AXIS_NAMES`].
        axis: u8,
        /// The motor, or None for none.
        motor: Option<AxisMotor>,
    },
    /// Removes an optional limit or motor (Luau `joint.LowerAngle = nil`).
    Unset(OptionalJointProp),
}

/// The joint options that may be absent (no limit, no motor): what [`JointProp::Unset`]
/// removes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum OptionalJointProp {
    /// `LowerAngle` (see [`JointProp::LowerAngle`]).
    LowerAngle,
    /// `UpperAngle` (see [`JointProp::UpperAngle`]).
    UpperAngle,
    /// `SwingLimit` (see [`JointProp::SwingLimit`]).
    SwingLimit,
    /// `TwistLimit` (see [`JointProp::TwistLimit`]).
    TwistLimit,
    /// `LowerDistance` (see [`JointProp::LowerDistance`]).
    LowerDistance,
    /// `UpperDistance` (see [`JointProp::UpperDistance`]).
    UpperDistance,
    /// `MotorSpeed` (see [`JointProp::MotorSpeed`]).
    MotorSpeed,
    /// `MotorTarget` (see [`JointProp::MotorTarget`]).
    MotorTarget,
}

impl OptionalJointProp {
    /// Every optional option, in declaration order.
    pub const ALL: [OptionalJointProp; 8] = [
        OptionalJointProp::LowerAngle,
        OptionalJointProp::UpperAngle,
        OptionalJointProp::SwingLimit,
        OptionalJointProp::TwistLimit,
        OptionalJointProp::LowerDistance,
        OptionalJointProp::UpperDistance,
        OptionalJointProp::MotorSpeed,
        OptionalJointProp::MotorTarget,
    ];

    /// The API name of the option.
    pub fn name(self) -> &'static str {
        match self {
            OptionalJointProp::LowerAngle => "LowerAngle",
            OptionalJointProp::UpperAngle => "UpperAngle",
            OptionalJointProp::SwingLimit => "SwingLimit",
            OptionalJointProp::TwistLimit => "TwistLimit",
            OptionalJointProp::LowerDistance => "LowerDistance",
            OptionalJointProp::UpperDistance => "UpperDistance",
            OptionalJointProp::MotorSpeed => "MotorSpeed",
            OptionalJointProp::MotorTarget => "MotorTarget",
        }
    }

    /// The optional option called `name`, if `name` is one.
    pub fn from_name(name: &str) -> Option<OptionalJointProp> {
        Self::ALL.into_iter().find(|o| o.name() == name)
    }
}

impl JointProp {
    /// The API name of the option.
    pub fn name(&self) -> &'static str {
        match self {
            JointProp::AnchorA(_) => "AnchorA",
            JointProp::AnchorB(_) => "AnchorB",
            JointProp::Axis(_) => "Axis",
            JointProp::LowerAngle(_) => "LowerAngle",
            JointProp::UpperAngle(_) => "UpperAngle",
            JointProp::SwingLimit(_) => "SwingLimit",
            JointProp::TwistLimit(_) => "TwistLimit",
            JointProp::LowerDistance(_) => "LowerDistance",
            JointProp::UpperDistance(_) => "UpperDistance",
            JointProp::RestLength(_) => "RestLength",
            JointProp::Stiffness(_) => "Stiffness",
            JointProp::Damping(_) => "Damping",
            JointProp::MotorSpeed(_) => "MotorSpeed",
            JointProp::MotorTarget(_) => "MotorTarget",
            JointProp::MotorMaxForce(_) => "MotorMaxForce",
            JointProp::Axes(_) => "Axes",
            JointProp::BreakForce(_) => "BreakForce",
            JointProp::CollideConnected(_) => "CollideConnected",
            JointProp::AxisMotor { .. } => "AxisMotor",
            JointProp::Unset(o) => o.name(),
        }
    }

    /// The value checked on its own: finite, in range; the axis normalised.
    pub fn checked(self) -> Result<JointProp, CommandError> {
        let name = self.name();
        let angle = |v: f32| {
            let v = finite(name, v)?;
            if v.abs() > MAX_ANGLE {
                return Err(CommandError::invalid_field(
                    name,
                    format!("{name} must be within ±{MAX_ANGLE} radians, got {v}"),
                ));
            }
            Ok(v)
        };
        let distance = |v: f32| {
            let v = finite(name, v)?;
            if v.abs() > MAX_COORDINATE {
                return Err(CommandError::invalid_field(
                    name,
                    format!("{name} must be within ±{MAX_COORDINATE}, got {v}"),
                ));
            }
            Ok(v)
        };
        let amount = |v: f32| {
            let v = non_negative(name, v)?;
            if v > MAX_JOINT_VALUE {
                return Err(CommandError::invalid_field(
                    name,
                    format!("{name} must be at most {MAX_JOINT_VALUE}, got {v}"),
                ));
            }
            Ok(v)
        };
        let point = |v: Vec3| {
            let v = finite3(name, v)?;
            crate::validate::bounded3(name, v, MAX_COORDINATE)
        };
        Ok(match self {
            JointProp::AnchorA(v) => JointProp::AnchorA(point(v)?),
            JointProp::AnchorB(v) => JointProp::AnchorB(point(v)?),
            JointProp::Axis(v) => {
                let v = finite3(name, v)?;
                let len = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
                if !(len > 1e-6 && len.is_finite()) {
                    return Err(CommandError::invalid_field(
                        name,
                        format!(
                            "Axis must be a non-zero finite vector, got {}",
                            crate::validate::show_vector(v)
                        ),
                    ));
                }
                JointProp::Axis([v[0] / len, v[1] / len, v[2] / len])
            }
            JointProp::LowerAngle(v) => JointProp::LowerAngle(angle(v)?),
            JointProp::UpperAngle(v) => JointProp::UpperAngle(angle(v)?),
            JointProp::SwingLimit(v) => {
                let v = angle(v)?;
                if !(0.0..=std::f32::consts::PI).contains(&v) {
                    return Err(CommandError::invalid_field(
                        name,
                        format!("SwingLimit must be within [0, π], got {v}"),
                    ));
                }
                JointProp::SwingLimit(v)
            }
            JointProp::TwistLimit(v) => {
                let v = angle(v)?;
                if !(0.0..=std::f32::consts::PI).contains(&v) {
                    return Err(CommandError::invalid_field(
                        name,
                        format!("TwistLimit must be within [0, π], got {v}"),
                    ));
                }
                JointProp::TwistLimit(v)
            }
            JointProp::LowerDistance(v) => JointProp::LowerDistance(distance(v)?),
            JointProp::UpperDistance(v) => JointProp::UpperDistance(distance(v)?),
            JointProp::RestLength(v) => JointProp::RestLength({
                let v = distance(v)?;
                non_negative(name, v)?
            }),
            JointProp::Stiffness(v) => JointProp::Stiffness(amount(v)?),
            JointProp::Damping(v) => JointProp::Damping(amount(v)?),
            JointProp::MotorSpeed(v) => JointProp::MotorSpeed({
                let v = finite(name, v)?;
                if v.abs() > MAX_JOINT_VALUE {
                    return Err(CommandError::invalid_field(
                        name,
                        format!("MotorSpeed must be within ±{MAX_JOINT_VALUE}, got {v}"),
                    ));
                }
                v
            }),
            JointProp::MotorTarget(v) => JointProp::MotorTarget(distance(v)?),
            JointProp::MotorMaxForce(v) => JointProp::MotorMaxForce(amount(v)?),
            JointProp::BreakForce(v) => JointProp::BreakForce(amount(v)?),
            p @ (JointProp::Axes(_) | JointProp::CollideConnected(_) | JointProp::Unset(_)) => p,
            JointProp::AxisMotor { axis, motor } => JointProp::AxisMotor {
                axis,
                motor: match motor {
                    Some(m) => Some(m.checked(axis)?),
                    // The axis is still checked: a bad index is an error, not a no-op.
                    None => AxisMotor::default().checked(axis).map(|_| None)?,
                },
            },
        })
    }
}

/// Every option of one joint as set (the defaults are the kind's).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct JointSettings {
    /// `AnchorA`.
    pub anchor_a: Vec3,
    /// `AnchorB`.
    pub anchor_b: Vec3,
    /// `Axis` (unit).
    pub axis: Vec3,
    /// `LowerAngle` (None: no lower limit).
    pub lower_angle: Option<f32>,
    /// `UpperAngle`.
    pub upper_angle: Option<f32>,
    /// `SwingLimit`.
    pub swing_limit: Option<f32>,
    /// `TwistLimit`.
    pub twist_limit: Option<f32>,
    /// `LowerDistance`.
    pub lower_distance: Option<f32>,
    /// `UpperDistance`.
    pub upper_distance: Option<f32>,
    /// `RestLength`.
    pub rest_length: f32,
    /// `Stiffness`.
    pub stiffness: f32,
    /// `Damping`.
    pub damping: f32,
    /// `MotorSpeed` (None: no velocity motor).
    pub motor_speed: Option<f32>,
    /// `MotorTarget` (None: no position motor).
    pub motor_target: Option<f32>,
    /// `MotorMaxForce` (infinite by default).
    pub motor_max_force: f32,
    /// `Axes` (SixDof).
    pub axes: [AxisMode; 6],
    /// `BreakForce` (0: unbreakable).
    pub break_force: f32,
    /// `CollideConnected`.
    pub collide_connected: bool,
    /// SixDof per-axis motors (`AxisMotor`), X, Y, Z, RotX, RotY, RotZ.
    pub axis_motors: [Option<AxisMotor>; 6],
}

impl Default for JointSettings {
    fn default() -> Self {
        JointSettings {
            anchor_a: [0.0; 3],
            anchor_b: [0.0; 3],
            axis: [1.0, 0.0, 0.0],
            lower_angle: None,
            upper_angle: None,
            swing_limit: None,
            twist_limit: None,
            lower_distance: None,
            upper_distance: None,
            rest_length: 0.0,
            stiffness: 0.0,
            damping: 0.0,
            motor_speed: None,
            motor_target: None,
            motor_max_force: f32::MAX,
            axes: [AxisMode::Locked; 6],
            break_force: 0.0,
            collide_connected: false,
            axis_motors: [None; 6],
        }
    }
}

impl JointSettings {
    /// Stores a checked option.
    pub fn store(&mut self, prop: JointProp) {
        match prop {
            JointProp::AnchorA(v) => self.anchor_a = v,
            JointProp::AnchorB(v) => self.anchor_b = v,
            JointProp::Axis(v) => self.axis = v,
            JointProp::LowerAngle(v) => self.lower_angle = Some(v),
            JointProp::UpperAngle(v) => self.upper_angle = Some(v),
            JointProp::SwingLimit(v) => self.swing_limit = Some(v),
            JointProp::TwistLimit(v) => self.twist_limit = Some(v),
            JointProp::LowerDistance(v) => self.lower_distance = Some(v),
            JointProp::UpperDistance(v) => self.upper_distance = Some(v),
            JointProp::RestLength(v) => self.rest_length = v,
            JointProp::Stiffness(v) => self.stiffness = v,
            JointProp::Damping(v) => self.damping = v,
            JointProp::MotorSpeed(v) => self.motor_speed = Some(v),
            JointProp::MotorTarget(v) => self.motor_target = Some(v),
            JointProp::MotorMaxForce(v) => self.motor_max_force = v,
            JointProp::Axes(v) => self.axes = v,
            JointProp::BreakForce(v) => self.break_force = v,
            JointProp::CollideConnected(v) => self.collide_connected = v,
            JointProp::AxisMotor { axis, motor } => {
                if let Some(slot) = self.axis_motors.get_mut(axis as usize) {
                    *slot = motor;
                }
            }
            JointProp::Unset(o) => {
                *match o {
                    OptionalJointProp::LowerAngle => &mut self.lower_angle,
                    OptionalJointProp::UpperAngle => &mut self.upper_angle,
                    OptionalJointProp::SwingLimit => &mut self.swing_limit,
                    OptionalJointProp::TwistLimit => &mut self.twist_limit,
                    OptionalJointProp::LowerDistance => &mut self.lower_distance,
                    OptionalJointProp::UpperDistance => &mut self.upper_distance,
                    OptionalJointProp::MotorSpeed => &mut self.motor_speed,
                    OptionalJointProp::MotorTarget => &mut self.motor_target,
                } = None
            }
        }
    }

    /// Checks the options against each other and against the kind.
    pub fn check(&self, kind: JointKind) -> Result<(), CommandError> {
        let order = |lo: &str, l: Option<f32>, hi: &str, h: Option<f32>| {
            if let (Some(l), Some(h)) = (l, h) {
                if l > h {
                    return Err(CommandError::invalid_field(
                        lo,
                        format!("{lo} ({l}) must not exceed {hi} ({h})"),
                    ));
                }
            }
            Ok(())
        };
        order(
            "LowerAngle",
            self.lower_angle,
            "UpperAngle",
            self.upper_angle,
        )?;
        order(
            "LowerDistance",
            self.lower_distance,
            "UpperDistance",
            self.upper_distance,
        )?;
        if kind == JointKind::Rope {
            let len = self.upper_distance.unwrap_or(self.rest_length);
            if len.is_nan() || len <= 0.0 {
                return Err(CommandError::invalid_field(
                    "UpperDistance",
                    format!("a Rope needs UpperDistance (or RestLength) > 0, got {len}"),
                ));
            }
        }
        if kind == JointKind::Spring && self.stiffness <= 0.0 {
            return Err(CommandError::invalid_field(
                "Stiffness",
                format!("a Spring needs Stiffness > 0, got {}", self.stiffness),
            ));
        }
        if (self.motor_speed.is_some() || self.motor_target.is_some())
            && !matches!(kind, JointKind::Hinge | JointKind::Prismatic)
        {
            {
                let field = if self.motor_speed.is_some() {
                    "MotorSpeed"
                } else {
                    "MotorTarget"
                };
                return Err(CommandError::invalid_field(
                    field,
                    format!(
                        "{field} applies to Hinge and Prismatic joints, not {}",
                        kind.name()
                    ),
                ));
            }
        }
        for (i, motor) in self.axis_motors.iter().enumerate() {
            if motor.is_none() {
                continue;
            }
            let axis = AXIS_NAMES[i];
            if kind != JointKind::SixDof {
                return Err(CommandError::invalid_field(
                    "AxisMotor",
                    format!(
                        "axis motors apply to SixDof joints, not {} (axis {axis})",
                        kind.name()
                    ),
                ));
            }
            if self.axes[i] == AxisMode::Locked {
                return Err(CommandError::invalid_field(
                    "AxisMotor",
                    format!(
                        "axis {axis} is Locked: a motor there cannot move it (set Axes.{axis} \
                         to \"Free\" or \"Limited\" first)"
                    ),
                ));
            }
        }
        Ok(())
    }
}

/// What the daemon reports about a joint.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct JointInfo {
    /// The joint's handle.
    pub handle: Handle,
    /// Its kind.
    pub kind: JointKind,
    /// Object A.
    pub a: Handle,
    /// Object B (None: the world).
    pub b: Option<Handle>,
    /// Every option as set.
    pub settings: JointSettings,
    /// Positional error after the last step (units): how far the anchors are from where
    /// the constraint wants them (separation along locked axes, overshoot of distance
    /// limits and rope length).
    pub error: f32,
    /// Angular error after the last step (radians): rotation along locked axes plus the
    /// overshoot of angle, swing and twist limits.
    pub angular_error: f32,
    /// The joint broke (its force exceeded BreakForce); it no longer constrains.
    pub broken: bool,
    /// The constraint force of the last step (force units), what BreakForce compares.
    pub force: f32,
    /// Current angle about the axis (Hinge; radians) or offset along it (Prismatic).
    pub position: f32,
}

/// Most joints one plane may hold.
pub const MAX_JOINTS: usize = 1 << 20;

/// Most joints one [`JointOp::List`] answers (a larger `limit` is cut to this): bounds one
/// reply (a few hundred bytes per joint) whatever the plane holds.
pub const MAX_JOINT_PAGE: u32 = 4096;

/// An op on a plane's joints.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum JointOp {
    /// Creates a joint between `a` and `b` (None = the world); `props` applied in order over
    /// the kind's defaults. Replies [`crate::Reply::Joint`].
    Create {
        /// The kind.
        kind: JointKind,
        /// Object A.
        a: Handle,
        /// Object B, or the world.
        b: Option<Handle>,
        /// Options.
        props: Vec<JointProp>,
    },
    /// Changes one option of a live joint.
    Set {
        /// The joint.
        joint: Handle,
        /// The option.
        prop: JointProp,
    },
    /// Describes a joint ([`crate::Reply::JointInfo`]).
    Info {
        /// The joint.
        joint: Handle,
    },
    /// Removes a joint; its handle becomes stale.
    Destroy {
        /// The joint.
        joint: Handle,
    },
    /// Describes the plane's live joints in ascending slot order, starting at slot `after`,
    /// at most `limit` of them (cut to [`MAX_JOINT_PAGE`]): [`crate::Reply::Joints`]. The
    /// first page asks from `after` 0; the next from the last listed joint's slot + 1; an
    /// answer shorter than the limit is the last page. Read-only.
    List {
        /// The first slot looked at (0: from the start).
        after: u32,
        /// Most joints answered, 1 to [`MAX_JOINT_PAGE`] (more is cut to the page size).
        limit: u32,
    },
}

impl JointOp {
    /// Every prop checked on its own (the SDK checks before sending, the daemon again).
    pub fn checked(self) -> Result<JointOp, CommandError> {
        Ok(match self {
            JointOp::Create { kind, a, b, props } => {
                let props = props
                    .into_iter()
                    .map(JointProp::checked)
                    .collect::<Result<Vec<_>, _>>()?;
                let mut s = JointSettings::default();
                for p in &props {
                    s.store(*p);
                }
                s.check(kind)?;
                JointOp::Create { kind, a, b, props }
            }
            JointOp::Set { joint, prop } => JointOp::Set {
                joint,
                prop: prop.checked()?,
            },
            JointOp::List { after, limit } => {
                if limit == 0 {
                    return Err(CommandError::invalid_field(
                        "limit",
                        format!("a joint list needs a limit of 1 to {MAX_JOINT_PAGE}, got 0"),
                    ));
                }
                JointOp::List {
                    after,
                    limit: limit.min(MAX_JOINT_PAGE),
                }
            }
            op => op,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bad_values_name_the_option() {
        let e = JointProp::LowerAngle(f32::NAN).checked().unwrap_err();
        assert_eq!(e.field.as_deref(), Some("LowerAngle"));
        let e = JointProp::Axis([0.0; 3]).checked().unwrap_err();
        assert!(e.message.contains("Axis"), "{}", e.message);
        let e = JointProp::BreakForce(-1.0).checked().unwrap_err();
        assert_eq!(e.field.as_deref(), Some("BreakForce"));
        assert_eq!(
            JointProp::Axis([0.0, 2.0, 0.0]).checked().unwrap(),
            JointProp::Axis([0.0, 1.0, 0.0])
        );
    }

    #[test]
    fn cross_checks_catch_inverted_limits_and_missing_lengths() {
        let mut s = JointSettings::default();
        s.store(JointProp::LowerAngle(1.0));
        s.store(JointProp::UpperAngle(0.5));
        assert!(s.check(JointKind::Hinge).is_err());
        assert!(JointSettings::default().check(JointKind::Rope).is_err());
        assert!(JointSettings::default().check(JointKind::Spring).is_err());
        let mut m = JointSettings::default();
        m.store(JointProp::MotorSpeed(1.0));
        assert!(m.check(JointKind::Ball).is_err());
        assert!(m.check(JointKind::Hinge).is_ok());
        for k in JointKind::ALL {
            assert_eq!(JointKind::from_name(k.name()), Some(k));
        }
    }

    #[test]
    fn unset_removes_each_optional_limit_and_motor() {
        let mut s = JointSettings::default();
        for (o, v) in OptionalJointProp::ALL.into_iter().zip(1..) {
            let v = v as f32 * 0.1;
            let set = match o {
                OptionalJointProp::LowerAngle => JointProp::LowerAngle(-v),
                OptionalJointProp::UpperAngle => JointProp::UpperAngle(v),
                OptionalJointProp::SwingLimit => JointProp::SwingLimit(v),
                OptionalJointProp::TwistLimit => JointProp::TwistLimit(v),
                OptionalJointProp::LowerDistance => JointProp::LowerDistance(-v),
                OptionalJointProp::UpperDistance => JointProp::UpperDistance(v),
                OptionalJointProp::MotorSpeed => JointProp::MotorSpeed(v),
                OptionalJointProp::MotorTarget => JointProp::MotorTarget(v),
            };
            assert_eq!(set.name(), o.name());
            assert_eq!(OptionalJointProp::from_name(o.name()), Some(o));
            s.store(set.checked().unwrap());
        }
        assert_ne!(s, JointSettings::default());
        for o in OptionalJointProp::ALL {
            let unset = JointProp::Unset(o).checked().unwrap();
            assert_eq!(unset.name(), o.name());
            s.store(unset);
        }
        assert_eq!(s, JointSettings::default());
        assert_eq!(OptionalJointProp::from_name("AnchorA"), None);
    }

    #[test]
    fn a_list_needs_a_limit_and_is_cut_to_a_page() {
        let e = JointOp::List { after: 0, limit: 0 }.checked().unwrap_err();
        assert_eq!(e.field.as_deref(), Some("limit"));
        assert_eq!(
            JointOp::List {
                after: 7,
                limit: u32::MAX
            }
            .checked()
            .unwrap(),
            JointOp::List {
                after: 7,
                limit: MAX_JOINT_PAGE
            }
        );
        assert_eq!(
            JointOp::List { after: 0, limit: 3 }.checked().unwrap(),
            JointOp::List { after: 0, limit: 3 }
        );
    }

    #[test]
    fn a_full_page_of_the_largest_joints_fits_well_within_a_reply() {
        // Every optional field set, every axis motor with a target position, handles with
        // the largest varints: the most bytes one joint may take in a reply.
        let motor = Some(AxisMotor {
            target_position: Some(1.0),
            ..AxisMotor::default()
        });
        let big = Handle {
            slot: u32::MAX,
            generation: u32::MAX,
        };
        let joint = JointInfo {
            handle: big,
            kind: JointKind::SixDof,
            a: big,
            b: Some(big),
            settings: JointSettings {
                lower_angle: Some(-1.0),
                upper_angle: Some(1.0),
                swing_limit: Some(1.0),
                twist_limit: Some(1.0),
                lower_distance: Some(-1.0),
                upper_distance: Some(1.0),
                motor_speed: Some(1.0),
                motor_target: Some(1.0),
                axis_motors: [motor; 6],
                ..JointSettings::default()
            },
            error: 1.0,
            angular_error: 1.0,
            broken: true,
            force: 1.0,
            position: 1.0,
        };
        let one = crate::codec::result_size(&Ok(crate::Reply::Joints(vec![joint.clone()])));
        let page = crate::codec::result_size(&Ok(crate::Reply::Joints(vec![
            joint;
            MAX_JOINT_PAGE
                as usize
        ])));
        // A page stays under 2 MiB (measured: 1,163,268 bytes, 284 per joint): a quarter of
        // the daemon's default reply limit (8 MiB), leaving room for the other answers of
        // the same request.
        assert!(
            page <= 2 << 20,
            "a page takes {page} bytes ({one} for one joint)"
        );
        assert!(
            page >= (one - 4) * MAX_JOINT_PAGE as usize,
            "{page} vs {one}"
        );
    }

    #[test]
    fn axis_motors_need_a_sixdof_joint_and_an_axis_that_moves() {
        let mut s = JointSettings::default();
        s.store(JointProp::AxisMotor {
            axis: 4,
            motor: Some(AxisMotor::spring(10.0, 1.0, 0.0)),
        });
        let e = s.check(JointKind::SixDof).unwrap_err();
        assert!(e.message.contains("RotY is Locked"), "{}", e.message);
        let e = s.check(JointKind::Hinge).unwrap_err();
        assert!(e.message.contains("SixDof"), "{}", e.message);
        s.store(JointProp::Axes([
            AxisMode::Locked,
            AxisMode::Locked,
            AxisMode::Locked,
            AxisMode::Locked,
            AxisMode::Free,
            AxisMode::Locked,
        ]));
        assert!(s.check(JointKind::SixDof).is_ok());
        // A forged axis index is refused, with or without a motor.
        for motor in [None, Some(AxisMotor::default())] {
            let e = JointProp::AxisMotor { axis: 9, motor }
                .checked()
                .unwrap_err();
            assert!(e.message.contains("got 9"), "{}", e.message);
        }
    }
}

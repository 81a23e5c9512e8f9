//! Per-axis motors and springs of SixDof joints: [`Joint::set_axis_motor`] and
//! [`Joint::set_axis_spring`] (one round trip each, checked here and by the daemon).

use shm_layout::joint_op::AXIS_NAMES;
use shm_layout::{AxisMotor, JointProp};

use crate::{error::Error, joint::Joint};

/// The index of an axis name (`"X"`, `"Y"`, `"Z"`, `"RotX"`, `"RotY"`, `"RotZ"`).
pub fn axis_index(name: &str) -> Option<u8> {
    AXIS_NAMES.iter().position(|a| *a == name).map(|i| i as u8)
}

impl Joint {
    /// Sets (Some) or removes (None) the motor on axis `axis` (0..6: X, Y, Z, RotX, RotY,
    /// RotZ) of a SixDof joint; the axis must be Free or Limited.
    pub fn set_axis_motor(&self, axis: u8, motor: Option<AxisMotor>) -> Result<(), Error> {
        self.set(JointProp::AxisMotor { axis, motor })
    }

    /// A spring on axis `axis` toward `rest`: force `stiffness · (rest − x) − damping · v`.
    pub fn set_axis_spring(
        &self,
        axis: u8,
        stiffness: f32,
        damping: f32,
        rest: f32,
    ) -> Result<(), Error> {
        self.set_axis_motor(axis, Some(AxisMotor::spring(stiffness, damping, rest)))
    }
}

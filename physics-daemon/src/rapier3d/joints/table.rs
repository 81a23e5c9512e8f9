//! The plane's joint table: each joint's ends, settings, figures and rapier handles, and
//! the motor defaults every joint kind shares.

use rapier3d::prelude::*;
use shm_layout::joint_op::MAX_JOINTS;
use shm_layout::joint_op::{JointKind, JointSettings};
use shm_layout::{CommandError, Handle};

use crate::backend::SlotTable;
use crate::rapier3d::joints::articulations::Articulations;

/// Damping of a velocity motor when `Damping` is 0: stiff enough to hold the speed within
/// a few ticks (acceleration-based: the gain per second).
pub(crate) const VELOCITY_MOTOR_GAIN: f32 = 1.0e4;
/// Position motor spring when `Stiffness` is 0 (acceleration-based, 1/s²) and its damping.
pub(crate) const POSITION_MOTOR_STIFFNESS: f32 = 400.0;
pub(crate) const POSITION_MOTOR_DAMPING: f32 = 40.0;

/// One joint of the plane.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub(crate) struct Joint {
    pub(in crate::rapier3d::joints) kind: JointKind,
    pub(in crate::rapier3d::joints) a: Handle,
    pub(in crate::rapier3d::joints) b: Option<Handle>,
    pub(in crate::rapier3d::joints) body_a: RigidBodyHandle,
    pub(in crate::rapier3d::joints) body_b: RigidBodyHandle,
    /// Rotation of B relative to A at creation (`rot_b⁻¹ · rot_a`).
    pub(in crate::rapier3d::joints) rel: Rotation,
    /// The rapier joint; None once broken.
    pub(in crate::rapier3d::joints) rapier: Option<ImpulseJointHandle>,
    pub(in crate::rapier3d::joints) settings: JointSettings,
    pub(in crate::rapier3d::joints) error: f32,
    pub(in crate::rapier3d::joints) angular_error: f32,
    pub(in crate::rapier3d::joints) force: f32,
    pub(in crate::rapier3d::joints) position: f32,
    pub(in crate::rapier3d::joints) broken: bool,
    /// What A and B were at the last step, and whether the options changed since: either
    /// rebuilds the rapier joint before the next step.
    pub(in crate::rapier3d::joints) seen: Option<(EndState, EndState)>,
    pub(in crate::rapier3d::joints) dirty: bool,
    /// The multibody joint while the joint is articulated (see `articulations`).
    pub(in crate::rapier3d::joints) link: Option<MultibodyJointHandle>,
    /// The companion impulse joint holding an articulated ball joint's limits.
    pub(in crate::rapier3d::joints) limit: Option<ImpulseJointHandle>,
}

/// What one end of a joint is to the solver.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub(in crate::rapier3d::joints) enum EndState {
    /// Dynamic and simulated.
    Dynamic,
    /// Fixed (anchored, the world, a map part).
    Fixed,
    /// Out of the simulation: gone, disabled by rapier's quarantine of non-finite state, or
    /// about to be (a non-finite pose or velocity, which rapier disables at the start of the
    /// step).
    Disabled,
}

impl EndState {
    pub(in crate::rapier3d::joints) fn of(body: Option<&RigidBody>) -> EndState {
        let Some(b) = body else {
            return EndState::Disabled;
        };
        let finite = b.position().translation.is_finite()
            && b.position().rotation.is_finite()
            && b.linvel().is_finite()
            && b.angvel().is_finite();
        if !b.is_enabled() || !finite {
            EndState::Disabled
        } else if b.is_dynamic() {
            EndState::Dynamic
        } else {
            EndState::Fixed
        }
    }
}

/// The plane's joints.
#[derive(Clone, serde::Serialize, serde::Deserialize)]
pub(crate) struct Joints {
    pub(in crate::rapier3d::joints) table: SlotTable<Joint>,
    /// A fixed body without colliders: the "world" end of joints to the world.
    pub(in crate::rapier3d::joints) ground: Option<RigidBodyHandle>,
    /// Largest positional error after the last step.
    pub max_error: f32,
    /// The articulated joint trees.
    pub articulations: Articulations,
}

impl Default for Joints {
    fn default() -> Self {
        Joints {
            table: SlotTable::new("joint", MAX_JOINTS),
            ground: None,
            max_error: 0.0,
            articulations: Articulations::default(),
        }
    }
}

impl Joints {
    /// See [`SlotTable::adopt_limits`] (a snapshot's joint table).
    pub fn adopt_limits(&mut self, like: &Joints) -> Result<(), CommandError> {
        self.table.adopt_limits(&like.table)
    }

    /// Live joints (they count as objects for the quotas).
    pub fn live(&self) -> u32 {
        self.table.live()
    }
}

impl Joint {
    pub(in crate::rapier3d::joints) fn break_check(&self, force: f32) -> bool {
        !self.broken && self.settings.break_force > 0.0 && force > self.settings.break_force
    }
}

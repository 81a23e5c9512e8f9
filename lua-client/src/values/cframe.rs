//! `CFrame`: an immutable position + rotation. Rotation is read and written as Euler radians
//! (see `rotation` for the convention) and kept as a quaternion.

use std::fmt;

use client_sdk::Pose;

use super::rotation::{self, Quat, V3};

/// A pose: position and rotation. `repr(C)`: the bytes of its Lua value (see `cframe_ud`).
#[derive(Debug, Clone, Copy, PartialEq)]
#[repr(C)]
pub struct CFrame {
    /// World-space position.
    pub position: V3,
    /// Rotation as a unit quaternion.
    pub rotation: Quat,
}

impl CFrame {
    /// At the origin, not rotated.
    pub const IDENTITY: CFrame = CFrame {
        position: [0.0; 3],
        rotation: rotation::IDENTITY,
    };

    /// As the SDK's pose.
    pub fn pose(&self) -> Pose {
        Pose {
            position: self.position,
            rotation: self.rotation,
        }
    }

    /// From the SDK's pose.
    pub fn from_pose(p: Pose) -> CFrame {
        CFrame {
            position: p.position,
            rotation: p.rotation,
        }
    }

    /// `self * other`: `other` given in this frame's local space, returned in world space.
    pub fn compose(&self, other: &CFrame) -> CFrame {
        CFrame {
            position: self.point_to_world(other.position),
            rotation: rotation::mul(self.rotation, other.rotation),
        }
    }

    /// The frame that undoes this one: `cf * cf:Inverse()` is the identity.
    pub fn inverse(&self) -> CFrame {
        let inv = rotation::conjugate(self.rotation);
        let p = rotation::rotate(inv, self.position);
        CFrame {
            position: [-p[0], -p[1], -p[2]],
            rotation: inv,
        }
    }

    /// `v`, given in this frame's local space, in world space.
    pub fn point_to_world(&self, v: V3) -> V3 {
        let r = rotation::rotate(self.rotation, v);
        [
            r[0] + self.position[0],
            r[1] + self.position[1],
            r[2] + self.position[2],
        ]
    }

    /// Whether both hold the same bits (unlike `==`, tells -0 from 0, as `tostring` does).
    pub fn same_bits(&self, other: &CFrame) -> bool {
        let same = |a: &[f32], b: &[f32]| a.iter().zip(b).all(|(a, b)| a.to_bits() == b.to_bits());
        same(&self.position, &other.position) && same(&self.rotation, &other.rotation)
    }
}

impl fmt::Display for CFrame {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let [x, y, z] = self.position;
        let [a, b, c] = rotation::to_euler(self.rotation);
        write!(f, "CFrame(Position {x}, {y}, {z}; Rotation {a}, {b}, {c})")
    }
}

//! The plain values of geometry on the wire: 3D and 2D vectors and poses.

use serde::{Deserialize, Serialize};

/// A 3D vector on the wire.
pub type Vec3 = [f32; 3];
/// A 2D vector on the wire (GUI planes: pixels, pixels/s, ...).
pub type Vec2 = [f32; 2];

/// Position plus unit quaternion `[x, y, z, w]`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Pose {
    /// Position.
    pub position: Vec3,
    /// Unit quaternion `[x, y, z, w]`.
    pub rotation: [f32; 4],
}

impl Pose {
    /// The origin, unrotated.
    pub const IDENTITY: Pose = Pose {
        position: [0.0; 3],
        rotation: [0.0, 0.0, 0.0, 1.0],
    };

    /// Unrotated at `position`.
    pub fn at(position: Vec3) -> Pose {
        Pose {
            position,
            ..Pose::IDENTITY
        }
    }
}

impl Default for Pose {
    fn default() -> Self {
        Pose::IDENTITY
    }
}

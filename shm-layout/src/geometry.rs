//! The plain values of geometry on the wire: 3D and 2D vectors and poses.

use serde::{Deserialize, Serialize};

/// A 3D vector on the wire.
pub type Vec3 = [f32; 3];
/// A 2D vector on the wire (GUI planes: pixels, pixels/s, ...).
pub type Vec2 = [f32; 2];

/// `q · v` for a unit quaternion `q = [x, y, z, w]`: `v` rotated by `q`.
pub fn rotate(q: [f32; 4], v: Vec3) -> Vec3 {
    let u = [q[0], q[1], q[2]];
    let s = q[3];
    let cross = |a: Vec3, b: Vec3| {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    };
    let dot = |a: Vec3, b: Vec3| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let uv = cross(u, v);
    let (d, uu) = (dot(u, v), dot(u, u));
    [0, 1, 2].map(|k| 2.0 * d * u[k] + (s * s - uu) * v[k] + 2.0 * s * uv[k])
}

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

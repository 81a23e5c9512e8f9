//! Collision shapes of objects and their checks.

use serde::{Deserialize, Serialize};

use crate::error::CommandError;
use crate::geometry::Vec3;
use crate::validate::{bounded3, extent, size, MAX_MESH_TRIANGLES, MAX_MESH_VERTICES, MAX_SIZE};

/// Collision shape of an object.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum Shape {
    /// A box with the given full size along x, y, z.
    Cube {
        /// Full size along x, y, z.
        size: Vec3,
    },
    /// A sphere with the given radius.
    Sphere {
        /// Radius.
        radius: f32,
    },
    /// A capsule along the body's Y axis: radius `min(size.x, size.z) / 2`, total height
    /// `size.y` (caps included), so its segment is `size.y - 2·radius` long; a capsule no
    /// taller than its diameter is a ball.
    Capsule {
        /// Full size along x, y, z.
        size: Vec3,
    },
    /// A cylinder along the body's Y axis: radius `min(size.x, size.z) / 2`, height `size.y`.
    Cylinder {
        /// Full size along x, y, z.
        size: Vec3,
    },
    /// A ramp filling half of its size box (Roblox's WedgePart): the bottom face (-Y) is
    /// full, the vertical face is at the back (+Z), and the slope falls from the top-back
    /// edge to the bottom-front edge (-Z). Its cross-section in YZ has the corners
    /// (-y/2, -z/2), (-y/2, +z/2), (+y/2, +z/2), extruded over x. The body's origin is the
    /// centre of the size box, so its centre of mass is off the origin, at
    /// (0, -size.y/6, +size.z/6).
    Wedge {
        /// Full size along x, y, z.
        size: Vec3,
    },
    /// A part that carries a mesh (body-local vertices, triangles as vertex indices). It
    /// collides as the convex hull of its vertices.
    Mesh {
        /// Body-local vertices.
        vertices: Vec<Vec3>,
        /// Triangles as indices into `vertices`.
        triangles: Vec<[u32; 3]>,
    },
}

/// The kind of an object's shape, as reported back.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum ShapeKind {
    /// A box.
    Cube,
    /// A sphere.
    Sphere,
    /// A convex hull of mesh vertices.
    Mesh,
    /// A capsule along Y.
    Capsule,
    /// A cylinder along Y.
    Cylinder,
    /// A ramp: half of its size box, sloping down toward -Z.
    Wedge,
    /// A static triangle-mesh map (`MapOp::Build`).
    TriMesh,
}

impl Shape {
    /// The kind of this shape.
    pub fn kind(&self) -> ShapeKind {
        match self {
            Shape::Cube { .. } => ShapeKind::Cube,
            Shape::Sphere { .. } => ShapeKind::Sphere,
            Shape::Mesh { .. } => ShapeKind::Mesh,
            Shape::Capsule { .. } => ShapeKind::Capsule,
            Shape::Cylinder { .. } => ShapeKind::Cylinder,
            Shape::Wedge { .. } => ShapeKind::Wedge,
        }
    }

    /// Number of mesh vertices the shape carries (0 for primitives).
    pub fn mesh_vertices(&self) -> usize {
        match self {
            Shape::Mesh { vertices, .. } => vertices.len(),
            _ => 0,
        }
    }

    /// Positive sizes, finite vertices, triangle indices in range, bounded mesh size.
    pub fn check(&self) -> Result<(), CommandError> {
        match self {
            Shape::Cube { size: s }
            | Shape::Capsule { size: s }
            | Shape::Cylinder { size: s }
            | Shape::Wedge { size: s } => size("Size", *s).map(|_| ()),
            Shape::Sphere { radius } => extent("radius", *radius).map(|_| ()),
            Shape::Mesh {
                vertices,
                triangles,
            } => {
                if vertices.len() < 4 || vertices.len() > MAX_MESH_VERTICES {
                    return Err(CommandError::invalid_field(
                        "Mesh.vertices",
                        format!(
                            "Mesh.vertices must hold 4 to {MAX_MESH_VERTICES} points, got {}",
                            vertices.len()
                        ),
                    ));
                }
                if triangles.len() > MAX_MESH_TRIANGLES {
                    return Err(CommandError::invalid_field(
                        "Mesh.triangles",
                        format!(
                            "Mesh.triangles must hold at most {MAX_MESH_TRIANGLES} triangles, \
                             got {}",
                            triangles.len()
                        ),
                    ));
                }
                for (i, v) in vertices.iter().enumerate() {
                    bounded3(&format!("Mesh.vertices[{i}]"), *v, MAX_SIZE)?;
                }
                let n = vertices.len() as u32;
                if let Some((i, t)) = triangles
                    .iter()
                    .enumerate()
                    .find(|(_, t)| t.iter().any(|&k| k >= n))
                {
                    return Err(CommandError::invalid_field(
                        format!("Mesh.triangles[{i}]"),
                        format!("Mesh.triangles[{i}] = {t:?} indexes past the {n} vertices"),
                    ));
                }
                Ok(())
            }
        }
    }
}

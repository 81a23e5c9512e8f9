//! Static triangle-mesh maps. The client reads the map file (a .glb) and uploads its
//! triangles in pieces ([`MapOp::Upload`], each within the per-object mesh quota); the daemon
//! never opens a file for a client. [`MapOp::Build`] turns everything uploaded into one
//! anchored object with a BVH-accelerated triangle mesh (duplicate vertices merged, internal
//! edges fixed) and reports what it found; a failed build leaves nothing behind.

use serde::{Deserialize, Serialize};

use crate::error::CommandError;
use crate::geometry::{Pose, Vec3};
use crate::ids::Handle;
use crate::validate::{bounded3, pose, MAX_SIZE};

/// Most vertices plus triangles of one upload piece (the SDK's piece size; the daemon's
/// `--max-mesh-vertices` quota applies to each piece too).
pub const MAX_PIECE: usize = 16_000;
/// Most triangles one map may have (bounds the build's time and memory; the per-client
/// mesh quota usually binds first).
pub const MAX_MAP_TRIANGLES: usize = 1 << 24;

/// What a map build found, and what it did about it.
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct MapReport {
    /// Triangles uploaded.
    pub triangles_in: u64,
    /// Triangles in the collider (degenerate ones removed).
    pub triangles: u64,
    /// Vertices uploaded.
    pub vertices_in: u64,
    /// Vertices after merging duplicates.
    pub vertices: u64,
    /// Triangles of zero area (or repeated corners), removed.
    pub degenerate_triangles: u64,
    /// Vertices merged into another at exactly the same position.
    pub duplicate_vertices_merged: u64,
    /// Edges shared by more than two triangles.
    pub non_manifold_edges: u64,
    /// Edges shared by exactly two triangles: welded, their normals fixed so that a body
    /// sliding across them meets no ghost bump.
    pub welded_edges: u64,
    /// Edges of one triangle only (the map's border, holes).
    pub open_edges: u64,
    /// The built mesh's content hash: the daemon keeps one copy of each, shared by every
    /// plane that builds (or restores) the same mesh.
    pub content_hash: u64,
    /// The daemon held this mesh already (another plane's map, or one a restore brought):
    /// this map shares that copy.
    pub shared: bool,
}

/// A built map.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MapInfo {
    /// The map's object (anchored; queries hit it, `Destroy` removes it).
    pub handle: Handle,
    /// The validation report.
    pub report: MapReport,
}

/// An op on a plane's map upload.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum MapOp {
    /// Appends a piece to the plane's pending upload (indices are piece-local). Counts
    /// `vertices + triangles` against the owner's mesh-vertices quota until the build
    /// (and while the map lives).
    Upload {
        /// Map-space vertices.
        vertices: Vec<Vec3>,
        /// Triangles as indices into this piece's `vertices`.
        triangles: Vec<[u32; 3]>,
    },
    /// Builds the pending upload into one anchored object at `pose`, each vertex scaled
    /// by `scale` first. Replies [`crate::Reply::Map`]. The pending upload is consumed
    /// either way.
    Build {
        /// Where the map's origin goes.
        pose: Pose,
        /// Per-axis scale applied to vertices before `pose`.
        scale: Vec3,
        /// Vertices the client uploaded for this map: a build whose pending upload holds
        /// another count (a piece was refused, say by a quota) fails instead of building
        /// part of the map.
        vertices: u64,
        /// Triangles the client uploaded for this map.
        triangles: u64,
    },
    /// Drops the pending upload.
    Discard,
}

impl MapOp {
    /// Sizes, finiteness and index ranges.
    pub fn checked(self) -> Result<MapOp, CommandError> {
        match &self {
            MapOp::Upload {
                vertices,
                triangles,
            } => {
                if vertices.len() + triangles.len() > MAX_PIECE {
                    return Err(CommandError::invalid_field(
                        "Map.piece",
                        format!(
                            "a map piece holds at most {MAX_PIECE} vertices + triangles, got {}",
                            vertices.len() + triangles.len()
                        ),
                    ));
                }
                for (i, v) in vertices.iter().enumerate() {
                    bounded3(
                        &format!("Map.vertices[{i}]"),
                        *v,
                        crate::validate::MAX_COORDINATE,
                    )?;
                }
                let n = vertices.len() as u32;
                if let Some((i, t)) = triangles
                    .iter()
                    .enumerate()
                    .find(|(_, t)| t.iter().any(|&k| k >= n))
                {
                    return Err(CommandError::invalid_field(
                        format!("Map.triangles[{i}]"),
                        format!("Map.triangles[{i}] = {t:?} indexes past the {n} vertices"),
                    ));
                }
            }
            MapOp::Build { pose: p, scale, .. } => {
                pose("Map.Position", *p)?;
                let s = bounded3("Map.Scale", *scale, MAX_SIZE)?;
                if s.iter().any(|c| c.abs() < 1e-6) {
                    return Err(CommandError::invalid_field(
                        "Map.Scale",
                        format!("Map.Scale must have no zero component, got {s:?}"),
                    ));
                }
            }
            MapOp::Discard => {}
        }
        Ok(self)
    }

    /// What the op adds to the mesh quota.
    pub fn cost(&self) -> u64 {
        match self {
            MapOp::Upload {
                vertices,
                triangles,
            } => (vertices.len() + triangles.len()) as u64,
            _ => 0,
        }
    }
}

//! Static triangle-mesh maps: pieces uploaded by the client ([`MapOp::Upload`]) are
//! checked, merged (exact duplicate vertices), cleaned (degenerate triangles dropped),
//! analysed (open, welded and non-manifold edges) and built into one anchored object whose
//! collider is a BVH-accelerated rapier triangle mesh with `FIX_INTERNAL_EDGES`: contacts
//! at the welded edges take the neighbouring triangles' normals, so a body sliding across a
//! seam meets no ghost bump. Every check runs before the world changes: a failed build
//! leaves nothing behind.
//!
//! [`MapOp::Upload`]: shm_layout::map_op::MapOp::Upload

use std::collections::HashMap;

use rapier3d::prelude::*;
use shm_layout::map_op::MapReport;
use shm_layout::{CommandError, ObjectProp, Vec3};

/// Pieces uploaded since the last build.
#[derive(Debug, Default)]
pub(crate) struct PendingMap {
    pub(in crate::rapier3d::objects) vertices: Vec<Vec3>,
    pub(in crate::rapier3d::objects) triangles: Vec<[u32; 3]>,
}

impl PendingMap {
    /// What the pending upload counts against the mesh quota.
    pub fn cost(&self) -> u64 {
        (self.vertices.len() + self.triangles.len()) as u64
    }
}

/// The cleaned mesh and its report.
pub(crate) struct Cleaned {
    pub vertices: Vec<Vector>,
    pub triangles: Vec<[u32; 3]>,
    pub report: MapReport,
}

/// Merges exact duplicates, drops degenerate triangles and counts edge kinds.
pub(crate) fn clean(vertices: &[Vec3], triangles: &[[u32; 3]], scale: Vec3) -> Cleaned {
    let mut report = MapReport {
        triangles_in: triangles.len() as u64,
        vertices_in: vertices.len() as u64,
        ..MapReport::default()
    };
    let mut index: HashMap<[u32; 3], u32> = HashMap::with_capacity(vertices.len());
    let mut merged: Vec<Vector> = Vec::with_capacity(vertices.len());
    let remap: Vec<u32> = vertices
        .iter()
        .map(|v| {
            let p = Vector::new(v[0] * scale[0], v[1] * scale[1], v[2] * scale[2]);
            // +0.0 and -0.0 are one position.
            let key = [p.x + 0.0, p.y + 0.0, p.z + 0.0].map(f32::to_bits);
            *index.entry(key).or_insert_with(|| {
                merged.push(p);
                merged.len() as u32 - 1
            })
        })
        .collect();
    report.vertices = merged.len() as u64;
    report.duplicate_vertices_merged = report.vertices_in - report.vertices;
    let mut kept = Vec::with_capacity(triangles.len());
    for t in triangles {
        let t = t.map(|i| remap[i as usize]);
        let [a, b, c] = t.map(|i| merged[i as usize]);
        let area2 = (b - a).cross(c - a).length();
        let scale_sq = (b - a).length_squared().max((c - a).length_squared());
        if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] || area2 <= 1e-7 * scale_sq {
            report.degenerate_triangles += 1;
            continue;
        }
        kept.push(t);
    }
    let mut edges: HashMap<(u32, u32), u32> = HashMap::with_capacity(kept.len() * 2);
    for t in &kept {
        for k in 0..3 {
            let (i, j) = (t[k], t[(k + 1) % 3]);
            *edges.entry((i.min(j), i.max(j))).or_insert(0) += 1;
        }
    }
    for n in edges.values() {
        match n {
            1 => report.open_edges += 1,
            2 => report.welded_edges += 1,
            _ => report.non_manifold_edges += 1,
        }
    }
    report.triangles = kept.len() as u64;
    Cleaned {
        vertices: merged,
        triangles: kept,
        report,
    }
}

/// A map object is static: only the properties its settings rows flag `on_maps` (pose,
/// material, collision, contact reporting, held) may change, and Anchored only to true.
pub(crate) fn check_map_prop(prop: &ObjectProp) -> Result<(), CommandError> {
    if prop.changes_on_map() {
        return Ok(());
    }
    let name = prop.name();
    Err(CommandError::invalid_field(
        name,
        format!(
            "{name} cannot change on a map (a static triangle mesh): only {} can",
            ObjectProp::map_changeable()
        ),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_grid_of_two_triangle_tiles_is_merged_and_welded() {
        // 2 × 2 tiles, each with its own 4 vertices: 16 in, 9 after merging.
        let mut v = Vec::new();
        let mut t = Vec::new();
        for i in 0..2 {
            for j in 0..2 {
                let b = v.len() as u32;
                let (x, z) = (i as f32, j as f32);
                v.extend([
                    [x, 0.0, z],
                    [x + 1.0, 0.0, z],
                    [x + 1.0, 0.0, z + 1.0],
                    [x, 0.0, z + 1.0],
                ]);
                t.push([b, b + 2, b + 1]);
                t.push([b, b + 3, b + 2]);
            }
        }
        t.push([0, 0, 1]); // degenerate
        let c = clean(&v, &t, [1.0; 3]);
        assert_eq!(c.report.vertices, 9);
        assert_eq!(c.report.duplicate_vertices_merged, 7);
        assert_eq!(c.report.degenerate_triangles, 1);
        assert_eq!(c.report.triangles, 8);
        // 16 edges in a 2×2 grid with diagonals: 8 on the border, 8 inside.
        assert_eq!(c.report.open_edges, 8);
        assert_eq!(c.report.welded_edges, 8);
        assert_eq!(c.report.non_manifold_edges, 0);
    }
}

//! Map ops: small uploads, builds and discards, valid or wild.

use shm_layout::MapOp;

use super::Gen;

impl Gen<'_> {
    /// A map op: small uploads (valid grids, or wild: NaN vertices, indices past the end,
    /// degenerate triangles), builds at valid or wild poses and scales, discards.
    pub(super) fn map_op(&mut self, wild: bool) -> MapOp {
        match self.rng.below(100) {
            0..=59 => {
                let n = self.rng.range(1, 6);
                let mut vertices = Vec::new();
                for i in 0..=n {
                    for j in 0..=n {
                        vertices.push([i as f32, 0.0, j as f32]);
                    }
                }
                let mut triangles = Vec::new();
                let w = n as u32 + 1;
                for i in 0..n as u32 {
                    for j in 0..n as u32 {
                        let a = i * w + j;
                        triangles.push([a, a + 1, a + w]);
                        triangles.push([a + 1, a + w + 1, a + w]);
                    }
                }
                if wild {
                    match self.rng.below(4) {
                        0 => vertices[0] = self.rng.vec3(true, 1.0),
                        1 => triangles.push([0, 0, self.rng.special_u32()]),
                        2 => triangles.push([0, 0, 1]),
                        _ => triangles.clear(),
                    }
                }
                MapOp::Upload {
                    vertices,
                    triangles,
                }
            }
            60..=89 => MapOp::Build {
                pose: self.rng.pose(wild, 30.0),
                scale: if wild && self.rng.chance(0.5) {
                    self.rng.vec3(true, 1.0)
                } else {
                    [self.rng.f32_in(0.5, 2.0); 3]
                },
                vertices: if wild { self.rng.u64() % 100 } else { 0 },
                triangles: if wild { self.rng.u64() % 100 } else { 0 },
            },
            _ => MapOp::Discard,
        }
    }
}

//! Shapes: the primitive parts and meshes (valid point clouds, or degenerate and
//! out-of-range ones), and part sizes.

use shm_layout::{Shape, Vec3};

use super::Gen;
use crate::rng::Rng;

impl Gen<'_> {
    /// A shape: cube, sphere, capsule, cylinder, wedge or mesh.
    pub(super) fn shape(&mut self, wild: bool) -> Shape {
        match self.rng.below(100) {
            0..=29 => Shape::Cube {
                size: self.size(wild),
            },
            30..=39 => Shape::Capsule {
                size: self.size(wild),
            },
            40..=49 => Shape::Cylinder {
                size: self.size(wild),
            },
            50..=59 => Shape::Wedge {
                size: self.size(wild),
            },
            60..=79 => {
                let r = self.rng.f32_in(0.05, 2.0);
                Shape::Sphere {
                    radius: self.rng.maybe_wild(wild, r),
                }
            }
            _ => self.mesh(wild),
        }
    }

    pub(super) fn size(&mut self, wild: bool) -> Vec3 {
        [0; 3].map(|_| {
            let s = self.rng.f32_in(0.1, 4.0);
            self.rng.maybe_wild(wild, s)
        })
    }

    /// A mesh part: a valid point cloud with valid triangles, or (wild) too few vertices,
    /// coplanar, collinear or coincident points, non-finite, huge or tiny coordinates, bad
    /// triangle indices, or many vertices.
    pub(super) fn mesh(&mut self, wild: bool) -> Shape {
        let cloud = |rng: &mut Rng, n: usize, scale: f32| -> Vec<Vec3> {
            (0..n)
                .map(|_| [0; 3].map(|_| rng.f32_in(-scale, scale)))
                .collect()
        };
        let n = self.rng.range(4, 32);
        let mut vertices = cloud(self.rng, n, 1.0);
        let mut triangles = self.triangles(vertices.len(), 0);
        if wild {
            match self.rng.below(11) {
                0 => vertices.truncate(self.rng.below(4)),
                1 => vertices.iter_mut().for_each(|v| v[2] = 0.0),
                2 => vertices
                    .iter_mut()
                    .for_each(|v| *v = [v[0], 2.0 * v[0], -v[0]]),
                3 => {
                    let p = vertices[0];
                    vertices.iter_mut().for_each(|v| *v = p);
                }
                4 => {
                    let i = self.rng.below(vertices.len());
                    vertices[i][self.rng.below(3)] = self.rng.special_f32();
                }
                5 => {
                    let scale = *self.rng.pick(&[1e20, 1e30, 1e38]);
                    vertices = cloud(self.rng, n, scale);
                }
                6 => {
                    let scale = *self.rng.pick(&[1e-20, 1e-30, 1e-38]);
                    vertices = cloud(self.rng, n, scale);
                }
                7 => {
                    let bad = 1 + self.rng.below(3);
                    triangles = self.triangles(vertices.len(), bad);
                }
                8 => {
                    let n = self.rng.range(1_000, 4_000);
                    vertices = cloud(self.rng, n, 3.0);
                    triangles = self.triangles(n, 0);
                }
                9 => vertices.iter_mut().for_each(|v| v[2] *= 1e-7),
                _ => {
                    // More triangles than any real part, all in range.
                    let m = self.rng.range(1_000, 20_000);
                    triangles = (0..m)
                        .map(|_| [0; 3].map(|_| self.rng.below(n) as u32))
                        .collect();
                }
            }
        }
        Shape::Mesh {
            vertices,
            triangles,
        }
    }

    /// Up to 16 triangles over `n` vertices, `bad` of them with an index out of range.
    pub(super) fn triangles(&mut self, n: usize, bad: usize) -> Vec<[u32; 3]> {
        let mut t: Vec<[u32; 3]> = (0..self.rng.below(17))
            .map(|_| [0; 3].map(|_| self.rng.below(n) as u32))
            .collect();
        for _ in 0..bad {
            let k = *self.rng.pick(&[n as u32, n as u32 + 1, u32::MAX, 1 << 31]);
            let tri = [self.rng.below(n.max(1)) as u32, k, 0];
            let at = self.rng.below(t.len() + 1);
            t.insert(at, tri);
        }
        t
    }
}

//! The GPU broadphase against brute force: on random scenes (spheres and rotated boxes of
//! mixed sizes, anchored floors and walls larger than a cell, bodies that do not collide,
//! collision groups that ignore each other), the pairs found through the spatial hash equal
//! the pairs found by testing every pair, and both equal the overlaps computed here on the
//! CPU from the same shapes. Runs on the machine's GPU adapter (lavapipe in CI).

use physics_daemon::gpu::GpuPlane as Plane;
use physics_daemon::gpu::PairMode;
use proptest::prelude::*;
use shm_layout::{CollisionGroups, ObjectProp, PlaneProp, Pose, Shape};

#[derive(Debug, Clone)]
struct Body {
    at: [f32; 3],
    /// Sphere radius, or box size.
    sphere: Option<f32>,
    size: [f32; 3],
    rotation: [f32; 4],
    anchored: bool,
    collide: bool,
    group: u8,
}

fn body() -> impl Strategy<Value = Body> {
    (
        prop::array::uniform3(-6.0f32..6.0),
        prop::bool::weighted(0.4),
        prop::array::uniform3(0.2f32..2.0),
        prop::array::uniform4(-1.0f32..1.0),
        prop::bool::weighted(0.15),
        prop::bool::weighted(0.9),
        prop::bool::weighted(0.2),
    )
        .prop_map(|(at, sphere, size, q, anchored, collide, other_group)| {
            let n = q.iter().map(|c| c * c).sum::<f32>().sqrt();
            let rotation = if n > 0.1 && !sphere {
                [q[0] / n, q[1] / n, q[2] / n, q[3] / n]
            } else {
                [0.0, 0.0, 0.0, 1.0]
            };
            Body {
                at,
                sphere: sphere.then(|| size[0] / 2.0),
                size,
                rotation,
                anchored,
                collide,
                group: other_group as u8,
            }
        })
}

/// Large anchored slabs (a floor and a wall) that the grid keeps in its "large" list.
fn slabs() -> Vec<Body> {
    let slab = |at, size| Body {
        at,
        sphere: None,
        size,
        rotation: [0.0, 0.0, 0.0, 1.0],
        anchored: true,
        collide: true,
        group: 0,
    };
    vec![
        slab([0.0, -5.5, 0.0], [20.0, 1.0, 20.0]),
        slab([5.5, 0.0, 0.0], [1.0, 12.0, 20.0]),
    ]
}

/// Group 1 collides with group 0 but not with itself.
fn groups() -> CollisionGroups {
    let mut g = CollisionGroups::default();
    g.register("Debris").unwrap();
    g.set_collidable("Debris", "Debris", false).unwrap();
    g
}

fn half_extents(b: &Body) -> [f32; 3] {
    if let Some(r) = b.sphere {
        return [r; 3];
    }
    // |R| · half of the rotated box.
    let [x, y, z, w] = b.rotation;
    let m = [
        [
            1.0 - 2.0 * (y * y + z * z),
            2.0 * (x * y - z * w),
            2.0 * (x * z + y * w),
        ],
        [
            2.0 * (x * y + z * w),
            1.0 - 2.0 * (x * x + z * z),
            2.0 * (y * z - x * w),
        ],
        [
            2.0 * (x * z - y * w),
            2.0 * (y * z + x * w),
            1.0 - 2.0 * (x * x + y * y),
        ],
    ];
    let h = [b.size[0] / 2.0, b.size[1] / 2.0, b.size[2] / 2.0];
    let mut out = [0.0; 3];
    for (i, row) in m.iter().enumerate() {
        out[i] = row.iter().zip(h).map(|(r, h)| r.abs() * h).sum();
    }
    out
}

/// Whether two bodies overlap as the GPU path sees them (spheres, world boxes). Pairs
/// within 1e-4 of touching are left out of the comparison (f32 rounding may go either way).
fn overlap(a: &Body, b: &Body) -> Option<bool> {
    let (ha, hb) = (half_extents(a), half_extents(b));
    let d: Vec<f32> = (0..3).map(|i| a.at[i] - b.at[i]).collect();
    let depth = match (a.sphere, b.sphere) {
        (Some(ra), Some(rb)) => ra + rb - d.iter().map(|c| c * c).sum::<f32>().sqrt(),
        (Some(r), None) | (None, Some(r)) => {
            let (s, h, d) = if a.sphere.is_some() {
                (a, hb, d.clone())
            } else {
                (b, ha, d.iter().map(|c| -c).collect())
            };
            let _ = s;
            let e: Vec<f32> = (0..3).map(|i| d[i] - d[i].clamp(-h[i], h[i])).collect();
            let l = e.iter().map(|c| c * c).sum::<f32>().sqrt();
            if l > 0.0 {
                r - l
            } else {
                (0..3)
                    .map(|i| h[i] + r - d[i].abs())
                    .fold(f32::MAX, f32::min)
            }
        }
        (None, None) => (0..3)
            .map(|i| ha[i] + hb[i] - d[i].abs())
            .fold(f32::MAX, f32::min),
    };
    if depth.abs() < 1e-4 {
        None
    } else {
        Some(depth > 0.0)
    }
}

fn build(bodies: &[Body]) -> Plane {
    let mut plane = Plane::new(1, &[PlaneProp::TickRate(0.0)]).unwrap();
    plane.set_collision_groups(groups()).unwrap();
    for b in bodies {
        let shape = match b.sphere {
            Some(radius) => Shape::Sphere { radius },
            None => Shape::Cube { size: b.size },
        };
        let pose = Pose {
            position: b.at,
            rotation: b.rotation,
        };
        plane
            .add_object(
                &shape,
                pose,
                &[
                    ObjectProp::Anchored(b.anchored),
                    ObjectProp::CanCollide(b.collide),
                    ObjectProp::CollisionGroup(b.group),
                ],
            )
            .unwrap();
    }
    plane.set(PlaneProp::DeferGpu(true)).unwrap();
    plane
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

    #[test]
    fn hash_pairs_equal_brute_force_pairs(mut bodies in prop::collection::vec(body(), 1..400)) {
        bodies.extend(slabs());
        let mut plane = build(&bodies);
        let hash = plane.gpu_pairs(PairMode::Hash).expect("on the GPU").unwrap();
        let brute = plane.gpu_pairs(PairMode::BruteForce).expect("on the GPU").unwrap();
        prop_assert_eq!(&hash, &brute);
        // The CPU's view of the same shapes agrees on every pair not within rounding of
        // touching.
        let found: std::collections::HashSet<(u32, u32)> = hash.iter().copied().collect();
        let g = groups();
        for i in 0..bodies.len() {
            for j in i + 1..bodies.len() {
                let (a, b) = (&bodies[i], &bodies[j]);
                let filtered = !a.collide || !b.collide
                    || g.mask(a.group) & (1 << b.group) == 0;
                let expected = if filtered { Some(false) } else { overlap(a, b) };
                if let Some(expected) = expected {
                    prop_assert_eq!(
                        found.contains(&(i as u32, j as u32)),
                        expected,
                        "pair ({}, {}): {:?} / {:?}", i, j, a, b
                    );
                }
            }
        }
    }
}

#[test]
fn dense_scene_pairs_match() {
    // 3,000 small spheres packed into a 10-unit cube: many per cell, many hash collisions.
    let bodies: Vec<Body> = (0..3000)
        .map(|i| {
            let f = i as f32;
            Body {
                at: [
                    (f * 0.618_034).fract() * 10.0,
                    (f * 0.414_213).fract() * 10.0,
                    (f * 0.732_050).fract() * 10.0,
                ],
                sphere: Some(0.3),
                size: [0.6; 3],
                rotation: [0.0, 0.0, 0.0, 1.0],
                anchored: false,
                collide: true,
                group: 0,
            }
        })
        .collect();
    let mut plane = build(&bodies);
    let hash = plane.gpu_pairs(PairMode::Hash).unwrap().unwrap();
    let brute = plane.gpu_pairs(PairMode::BruteForce).unwrap().unwrap();
    assert!(hash.len() > 1000, "{} pairs", hash.len());
    assert_eq!(hash, brute);
}

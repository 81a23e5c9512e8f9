//! Hitscan against player hitboxes: capsule parts hit by rays and by swept bullets, the
//! shooter excluded, the nearest one reported at the ray–capsule closed-form distance; and
//! cylinders hit on their side and top.

use client_sdk::{Object, Pose, QueryParams, Ray, Shape};
use integration_tests::{zero_gravity, Scene};

/// Hitbox: Size (1, 4, 1): radius 0.5, total height 4, segment half-height 1.5.
const R: f32 = 0.5;
const HALF: f32 = 1.5;

/// xorshift: a deterministic crowd.
struct Rng(u64);
impl Rng {
    fn unit(&mut self) -> f32 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 40) as f32 / (1u64 << 24) as f32
    }
}

fn capsule(s: &Scene, at: [f32; 3]) -> Object {
    s.plane
        .add(
            Shape::Capsule {
                size: [1.0, 4.0, 1.0],
            },
            Pose::at(at),
            &[],
        )
        .expect("add capsule")
}

/// Where a ray from (0, y0, 0) along +x first meets a sphere of radius `r` swept along the
/// vertical segment of the capsule at (cx, 0, cz): the point of the ray at distance r from the
/// segment, i.e. (t - cx)² + (y0 - clamp(y0))² + cz² = r².
fn capsule_distance(centre: [f32; 3], y0: f32, r: f32) -> Option<f32> {
    let [cx, cy, cz] = centre;
    let dy = y0 - (y0 - cy).clamp(-HALF, HALF) - cy;
    let k = r * r - dy * dy - cz * cz;
    (k >= 0.0 && cx > 0.0).then(|| cx - k.sqrt())
}

#[test]
fn the_nearest_capsule_in_a_crowd_is_hit_at_the_closed_form_distance() {
    let s = Scene::new("hitscan", zero_gravity());
    let shooter = capsule(&s, [0.0, 0.0, 0.0]);
    let mut rng = Rng(0x2545_f491_4f6c_dd1d);
    let crowd: Vec<([f32; 3], Object)> = (0..40)
        .map(|_| {
            let at = [
                4.0 + rng.unit() * 60.0,
                rng.unit() * 0.6 - 0.3,
                rng.unit() * 1.6 - 0.8,
            ];
            (at, capsule(&s, at))
        })
        .collect();
    let exclude = QueryParams::excluding(&[&shooter]);
    let mut checked = 0;
    // Head (cap) and body (cylinder) heights, straight ahead.
    for y0 in [0.0f32, 1.0, 1.7, 1.85] {
        let expected = crowd
            .iter()
            .filter_map(|(at, o)| capsule_distance(*at, y0, R).map(|d| (d, o.handle())))
            .min_by(|a, b| a.0.total_cmp(&b.0));
        let hit = s
            .plane
            .raycast([0.0, y0, 0.0], [100.0, 0.0, 0.0], Some(&exclude))
            .unwrap();
        match (expected, hit) {
            (Some((d, who)), Some(hit)) => {
                assert_eq!(hit.object, who, "height {y0}: wrong capsule");
                assert!(
                    (hit.distance - d).abs() < 1e-4,
                    "height {y0}: {} vs closed form {d}",
                    hit.distance
                );
                checked += 1;
            }
            (None, None) => {}
            other => panic!("height {y0}: {other:?}"),
        }
        // A bullet of radius 0.1: the swept sphere meets the capsule at r + 0.1.
        let bullet = 0.1;
        let expected = crowd
            .iter()
            .filter_map(|(at, o)| capsule_distance(*at, y0, R + bullet).map(|d| (d, o.handle())))
            .min_by(|a, b| a.0.total_cmp(&b.0));
        let hit = s
            .plane
            .spherecast([0.0, y0, 0.0], bullet, [100.0, 0.0, 0.0], Some(&exclude))
            .unwrap();
        match (expected, hit) {
            (Some((d, who)), Some(hit)) => {
                assert_eq!(hit.object, who, "bullet at {y0}: wrong capsule");
                // Swept shapes stop within the shape-cast tolerance of the collision
                // library (its time of impact converges to a few 1e-3 units).
                assert!(
                    (hit.distance - d).abs() < 5e-3,
                    "bullet at {y0}: {} vs closed form {d}",
                    hit.distance
                );
                checked += 1;
            }
            (None, None) => {}
            other => panic!("bullet at {y0}: {other:?}"),
        }
    }
    assert!(checked >= 6, "the crowd must block most shots ({checked})");

    // 64 players firing at once: one request, each ray answered like a single one.
    let rays: Vec<Ray> = (0..64)
        .map(|i| Ray {
            origin: [0.0, -1.0 + i as f32 * 0.04, 0.0],
            direction: [100.0, 0.0, 0.0],
        })
        .collect();
    let hits = s.plane.raycast_many(&rays, Some(&exclude)).unwrap();
    for (ray, hit) in rays.iter().zip(&hits) {
        let single = s
            .plane
            .raycast(ray.origin, ray.direction, Some(&exclude))
            .unwrap();
        assert_eq!(*hit, single);
    }
}

#[test]
fn cylinders_are_hit_on_their_side_and_top() {
    let s = Scene::new("hitscan-cyl", zero_gravity());
    // Radius 1 (Size.X = Size.Z = 2), height 3, centred at (10, 0, 0.6).
    let cyl = s
        .plane
        .add(
            Shape::Cylinder {
                size: [2.0, 3.0, 2.0],
            },
            Pose::at([10.0, 0.0, 0.6]),
            &[],
        )
        .unwrap();
    let side = s
        .plane
        .raycast([0.0, 1.0, 0.0], [50.0, 0.0, 0.0], None)
        .unwrap()
        .unwrap();
    assert_eq!(side.object, cyl.handle());
    let d = 10.0 - (1.0f32 - 0.36).sqrt();
    assert!((side.distance - d).abs() < 1e-4, "{side:?} vs {d}");
    // The collision library finds a cylinder's side normal iteratively (GJK): a few 1e-3.
    let n = [d - 10.0, 0.0, -0.6];
    assert!(
        side.normal.iter().zip(n).all(|(a, b)| (a - b).abs() < 5e-3),
        "{side:?}"
    );
    let top = s
        .plane
        .raycast([10.5, 10.0, 0.6], [0.0, -50.0, 0.0], None)
        .unwrap()
        .unwrap();
    assert!((top.distance - 8.5).abs() < 1e-4, "{top:?}");
    assert!((top.normal[1] - 1.0).abs() < 1e-4, "{top:?}");
    // Just past the rim: a miss.
    assert!(s
        .plane
        .raycast([11.05, 10.0, 0.6], [0.0, -50.0, 0.0], None)
        .unwrap()
        .is_none());
}

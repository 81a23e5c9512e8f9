//! Scene queries through a real daemon: hit distances and normals against closed forms for
//! rays and sweeps, overlap sets, filters, batches, and errors that name the field.

use client_sdk::{ErrorKind, FilterType, Object, ObjectProp, Pose, QueryParams, Ray, Shape};
use integration_tests::{quat, zero_gravity, Scene};

/// Distances are f32 geometry on shapes of size ~1 at ~10 units: 1e-4 is ~100 ulps.
const EPS: f32 = 1e-4;

fn scene(tag: &str) -> Scene {
    Scene::new(tag, zero_gravity())
}

fn add(scene: &Scene, shape: Shape, pose: Pose, props: &[ObjectProp]) -> Object {
    scene.plane.add(shape, pose, props).expect("add")
}

fn ball(scene: &Scene, radius: f32, at: [f32; 3]) -> Object {
    add(scene, Shape::Sphere { radius }, Pose::at(at), &[])
}

fn cube(scene: &Scene, size: f32, pose: Pose) -> Object {
    add(scene, Shape::Cube { size: [size; 3] }, pose, &[])
}

fn close(a: [f32; 3], b: [f32; 3], eps: f32) -> bool {
    a.iter().zip(b).all(|(x, y)| (x - y).abs() <= eps)
}

#[test]
fn rays_hit_spheres_and_boxes_at_closed_form_distances() {
    let s = scene("q-rays");
    // Added and never stepped: a query sees objects as soon as they exist.
    let sphere = ball(&s, 1.0, [10.0, 0.0, 0.0]);
    let boxed = cube(&s, 2.0, Pose::at([0.0, 0.0, 10.0]));
    let diamond = cube(
        &s,
        2.0,
        Pose {
            position: [0.0, 0.0, -10.0],
            rotation: quat([0.0, 1.0, 0.0], std::f32::consts::FRAC_PI_4),
        },
    );

    // Off-centre ray into the sphere: d = 10 - sqrt(r² - b²), normal = (p - c) / r.
    let hit = s
        .plane
        .raycast([0.0, 0.5, 0.0], [100.0, 0.0, 0.0], None)
        .unwrap()
        .expect("the sphere is hit");
    let d = 10.0 - (1.0f32 - 0.25).sqrt();
    assert_eq!(hit.object, sphere.handle());
    assert!((hit.distance - d).abs() < EPS, "{hit:?} vs {d}");
    assert!(close(hit.position, [d, 0.5, 0.0], EPS), "{hit:?}");
    assert!(
        close(hit.normal, [d - 10.0, 0.5, 0.0], EPS),
        "normal {:?}",
        hit.normal
    );

    // Face of the box: distance 9, normal -z.
    let hit = s
        .plane
        .raycast([0.0, 0.3, 0.0], [0.0, 0.0, 50.0], None)
        .unwrap()
        .unwrap();
    assert_eq!(hit.object, boxed.handle());
    assert!((hit.distance - 9.0).abs() < EPS, "{hit:?}");
    assert!(close(hit.normal, [0.0, 0.0, -1.0], EPS), "{hit:?}");

    // The box turned 45° about y presents an edge: distance 10 - √2.
    let hit = s
        .plane
        .raycast([0.0, 0.0, 0.0], [0.0, 0.0, -50.0], None)
        .unwrap()
        .unwrap();
    assert_eq!(hit.object, diamond.handle());
    assert!((hit.distance - (10.0 - 2f32.sqrt())).abs() < EPS, "{hit:?}");

    // The direction's length is the reach.
    assert!(s
        .plane
        .raycast([0.0, 0.5, 0.0], [8.0, 0.0, 0.0], None)
        .unwrap()
        .is_none());
    assert!(s
        .plane
        .raycast([0.0, 0.5, 0.0], [0.0, 0.0, 0.0], None)
        .unwrap()
        .is_none());

    // A ray starting inside the sphere does not hit it (Roblox): it hits what lies behind.
    let behind = cube(&s, 2.0, Pose::at([20.0, 0.0, 0.0]));
    let hit = s
        .plane
        .raycast([10.0, 0.0, 0.0], [50.0, 0.0, 0.0], None)
        .unwrap()
        .unwrap();
    assert_eq!(hit.object, behind.handle());
    assert!((hit.distance - 9.0).abs() < EPS, "{hit:?}");

    // A teleport is seen at once, without a step.
    sphere.set_pose(Pose::at([5.0, 0.0, 0.0])).unwrap();
    let hit = s
        .plane
        .raycast([0.0, 0.0, 0.0], [100.0, 0.0, 0.0], None)
        .unwrap()
        .unwrap();
    assert!((hit.distance - 4.0).abs() < EPS, "{hit:?}");
    // And a destroyed object is gone at once.
    sphere.destroy();
    let hit = s
        .plane
        .raycast([0.0, 0.0, 0.0], [100.0, 0.0, 0.0], None)
        .unwrap()
        .unwrap();
    assert_eq!(hit.object, behind.handle());
}

#[test]
fn raycast_many_answers_every_ray_in_order_in_one_request() {
    let s = scene("q-many");
    let targets: Vec<Object> = (0..8)
        .map(|i| ball(&s, 0.5, [i as f32 * 3.0, 10.0, 0.0]))
        .collect();
    // One ray down onto each ball, and a miss between each pair.
    let mut rays = Vec::new();
    for i in 0..8 {
        rays.push(Ray {
            origin: [i as f32 * 3.0, 0.0, 0.0],
            direction: [0.0, 20.0, 0.0],
        });
        rays.push(Ray {
            origin: [i as f32 * 3.0 + 1.5, 0.0, 0.0],
            direction: [0.0, 20.0, 0.0],
        });
    }
    let hits = s.plane.raycast_many(&rays, None).unwrap();
    assert_eq!(hits.len(), 16);
    for (i, hit) in hits.iter().enumerate() {
        match (i % 2, hit) {
            (0, Some(h)) => {
                assert_eq!(h.object, targets[i / 2].handle());
                assert!((h.distance - 9.5).abs() < EPS, "{h:?}");
                assert!(close(h.normal, [0.0, -1.0, 0.0], EPS), "{h:?}");
            }
            (1, None) => {}
            other => panic!("ray {i}: {other:?}"),
        }
    }
    // Past the batch limit: an error naming the field, nothing cast.
    let too_many = vec![rays[0]; shm_layout::query::MAX_RAYS + 1];
    let e = s.plane.raycast_many(&too_many, None).unwrap_err();
    assert!(e.to_string().contains("rays"), "{e}");
}

#[test]
fn sweeps_stop_at_first_contact() {
    let s = scene("q-sweeps");
    let wall = cube(&s, 2.0, Pose::at([10.0, 0.0, 0.0]));
    let round = ball(&s, 1.0, [0.0, 0.5, 10.0]);

    // A sphere of radius 0.5 meets the wall's face x = 9 when its centre is at 8.5.
    let hit = s
        .plane
        .spherecast([0.0, 0.0, 0.0], 0.5, [100.0, 0.0, 0.0], None)
        .unwrap()
        .unwrap();
    assert_eq!(hit.object, wall.handle());
    assert!((hit.distance - 8.5).abs() < 1e-3, "{hit:?}");
    assert!(close(hit.position, [9.0, 0.0, 0.0], 1e-3), "{hit:?}");
    assert!(close(hit.normal, [-1.0, 0.0, 0.0], 1e-3), "{hit:?}");

    // Sphere against sphere: centres 1.5 apart at contact, off-axis by 0.5 → 10 - √2.
    let hit = s
        .plane
        .spherecast([0.0, 0.0, 0.0], 0.5, [0.0, 0.0, 100.0], None)
        .unwrap()
        .unwrap();
    assert_eq!(hit.object, round.handle());
    assert!(
        (hit.distance - (10.0 - 2f32.sqrt())).abs() < 1e-3,
        "{hit:?}"
    );

    // A unit box swept along x meets the face at 8.5 as well.
    let hit = s
        .plane
        .blockcast(Pose::IDENTITY, [1.0; 3], [100.0, 0.0, 0.0], None)
        .unwrap()
        .unwrap();
    assert!((hit.distance - 8.5).abs() < 1e-3, "{hit:?}");

    // The shape of an object, swept from where it is; it never hits itself.
    let mover = cube(&s, 1.0, Pose::at([0.0, 0.0, 0.0]));
    let hit = s
        .plane
        .shapecast(&mover, [100.0, 0.0, 0.0], None)
        .unwrap()
        .unwrap();
    assert_eq!(hit.object, wall.handle());
    assert!((hit.distance - 8.5).abs() < 1e-3, "{hit:?}");

    // A sweep starting inside an object skips it (Roblox).
    let hit = s
        .plane
        .spherecast([10.0, 0.0, 0.0], 0.5, [0.0, 0.0, 100.0], None)
        .unwrap();
    assert!(hit.is_none(), "{hit:?}");
}

#[test]
fn overlaps_use_bounds_or_exact_shapes_as_named() {
    let s = scene("q-overlap");
    let centre = ball(&s, 1.0, [0.0, 0.0, 0.0]);
    // Its bounding box [0.8, 2.8]² meets the ball's, its nearest corner (0.8, 0.8) is
    // √1.28 ≈ 1.131 from the centre: outside the ball.
    let corner = cube(&s, 2.0, Pose::at([1.8, 1.8, 0.0]));
    let far = cube(&s, 1.0, Pose::at([30.0, 0.0, 0.0]));

    let exact = s.plane.parts_in_part(&centre, None).unwrap();
    assert!(exact.is_empty(), "{exact:?}");
    let in_box = s
        .plane
        .bounds_in_box(Pose::IDENTITY, [2.0; 3], None)
        .unwrap();
    assert_eq!(in_box, vec![centre.handle(), corner.handle()]);

    let d = 1.28f32.sqrt();
    let near = s.plane.bounds_in_radius([0.0; 3], d - 0.01, None).unwrap();
    assert_eq!(near, vec![centre.handle()]);
    let near = s.plane.bounds_in_radius([0.0; 3], d + 0.01, None).unwrap();
    assert_eq!(near, vec![centre.handle(), corner.handle()]);

    // Move the cube into the ball: the exact test now lists it.
    corner.set_pose(Pose::at([1.5, 0.0, 0.0])).unwrap();
    let exact = s.plane.parts_in_part(&centre, None).unwrap();
    assert_eq!(exact, vec![corner.handle()]);
    let _ = far;
}

#[test]
fn filters_include_exclude_can_collide_and_groups() {
    let s = scene("q-filter");
    let first = ball(&s, 0.5, [5.0, 0.0, 0.0]);
    let second = ball(&s, 0.5, [10.0, 0.0, 0.0]);
    let ray = |params: Option<&QueryParams>| {
        s.plane
            .raycast([0.0; 3], [100.0, 0.0, 0.0], params)
            .unwrap()
            .map(|h| h.object)
    };
    assert_eq!(ray(None), Some(first.handle()));
    assert_eq!(
        ray(Some(&QueryParams::excluding(&[&first]))),
        Some(second.handle())
    );
    assert_eq!(
        ray(Some(&QueryParams::including(&[&second]))),
        Some(second.handle())
    );
    assert_eq!(
        ray(Some(&QueryParams {
            filter_type: FilterType::Include,
            ..QueryParams::default()
        })),
        None,
        "an empty include list hits nothing"
    );

    // CanCollide = false is seen unless RespectCanCollide.
    first.set_can_collide(false).unwrap();
    assert_eq!(ray(None), Some(first.handle()));
    let respect = QueryParams {
        respect_can_collide: true,
        ..QueryParams::default()
    };
    assert_eq!(ray(Some(&respect)), Some(second.handle()));
    first.set_can_collide(true).unwrap();

    // Group filter: a query in group "Bullets" skips groups that do not collide with it.
    s.client.register_collision_group("Bullets").unwrap();
    s.client.register_collision_group("Ghosts").unwrap();
    s.client
        .collision_group_set_collidable("Bullets", "Ghosts", false)
        .unwrap();
    first.set_collision_group("Ghosts").unwrap();
    let bullets = QueryParams {
        collision_group: Some("Bullets".into()),
        ..QueryParams::default()
    };
    assert_eq!(ray(Some(&bullets)), Some(second.handle()));
    assert_eq!(ray(None), Some(first.handle()));
    let e = s
        .plane
        .raycast(
            [0.0; 3],
            [1.0, 0.0, 0.0],
            Some(&QueryParams {
                collision_group: Some("Nope".into()),
                ..QueryParams::default()
            }),
        )
        .unwrap_err();
    assert!(e.to_string().contains("\"Nope\""), "{e}");
}

#[test]
fn bad_queries_name_the_field_and_value() {
    let s = scene("q-bad");
    let b = ball(&s, 0.5, [0.0; 3]);
    let e = s
        .plane
        .raycast([f32::NAN, 0.0, 0.0], [1.0, 0.0, 0.0], None)
        .unwrap_err();
    assert!(
        e.to_string().contains("origin") && e.to_string().contains("NaN"),
        "{e}"
    );
    let e = s
        .plane
        .spherecast([0.0; 3], -1.0, [1.0, 0.0, 0.0], None)
        .unwrap_err();
    assert!(e.to_string().contains("radius"), "{e}");
    let e = s
        .plane
        .blockcast(Pose::IDENTITY, [1.0, 0.0, 1.0], [1.0, 0.0, 0.0], None)
        .unwrap_err();
    assert!(e.to_string().contains("size.Y"), "{e}");
    b.destroy();
    match s.plane.shapecast(&b, [1.0, 0.0, 0.0], None) {
        Err(client_sdk::Error::Command(e)) => assert_eq!(e.kind, ErrorKind::StaleHandle),
        other => panic!("{other:?}"),
    }
    // The daemon still answers.
    assert!(s
        .plane
        .raycast([0.0; 3], [1.0, 0.0, 0.0], None)
        .unwrap()
        .is_none());
}

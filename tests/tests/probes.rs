//! Proximity queries and explosions through a real daemon: `ProbeGround`, `ClosestPoint`,
//! `Clearance`, `ProbeWall`, `Explode` and the controllers' `OnWall` / `WallNormal`, each
//! against closed forms (plane geometry for probes, Δv = J / m for explosions).

use client_sdk::map::MapOptions;
use client_sdk::{
    Controller, ControllerProp, Falloff, Object, ObjectProp, PlaneOptions, Pose, ProbeHit,
    QueryParams, Shape,
};
use integration_tests::{assets, quat, zero_gravity, Scene};

/// Point projections and face contacts are exact to f32 rounding on shapes of size ~1 at
/// ~10 units: 1e-4 is ~100 ulps.
const EPS: f32 = 1e-4;
/// Sweeps converge by conservative advancement to 1e-4 (clipped.rs): allow 1e-3.
const SWEEP_EPS: f32 = 1e-3;

fn close(a: [f32; 3], b: [f32; 3], eps: f32) -> bool {
    a.iter().zip(b).all(|(x, y)| (x - y).abs() <= eps)
}

fn hit(h: Option<ProbeHit>, what: &str) -> ProbeHit {
    h.unwrap_or_else(|| panic!("{what}: expected a hit"))
}

fn ball(s: &Scene, radius: f32, at: [f32; 3]) -> Object {
    s.plane
        .add(Shape::Sphere { radius }, Pose::at(at), &[])
        .expect("add ball")
}

/// An anchored 40 × 2 × 40 slab turned `angle` radians about +Z, centred at `centre`: its
/// top face is the plane n·(p − centre) = 1 with n = (−sin θ, cos θ, 0).
fn incline(s: &Scene, centre: [f32; 3], angle: f32) -> Object {
    s.anchored_box(
        [40.0, 2.0, 40.0],
        Pose {
            position: centre,
            rotation: quat([0.0, 0.0, 1.0], angle),
        },
    )
}

#[test]
fn probe_ground_finds_floors_and_slopes_at_closed_form_distances() {
    let s = Scene::new("pr-ground", zero_gravity());
    // Floor: top face y = 0.
    let floor = s.anchored_box([40.0, 2.0, 40.0], Pose::at([0.0, -1.0, 0.0]));
    let (r, from) = (0.5f32, [0.0f32, 5.0, 0.0]);
    let h = hit(
        s.plane.probe_ground(from, r, 10.0, None, None).unwrap(),
        "floor",
    );
    assert_eq!(h.object, floor.handle());
    // The sphere's bottom reaches y = 0 after 5 − r.
    assert!((h.distance - (5.0 - r)).abs() < SWEEP_EPS, "{h:?}");
    assert!(close(h.position, [0.0, 0.0, 0.0], SWEEP_EPS), "{h:?}");
    assert!(close(h.normal, [0.0, 1.0, 0.0], EPS), "{h:?}");
    assert!(close(h.point_on_shape, [0.0, 0.0, 0.0], SWEEP_EPS), "{h:?}");
    assert!(h.walkable);
    // The reach is a limit: 4.4 < 4.5 finds nothing.
    assert!(s
        .plane
        .probe_ground(from, r, 4.4, None, None)
        .unwrap()
        .is_none());
    // A ball on the way is found first (its top at y = 3): 5 − 3 − r; excluded, the floor.
    let rock = ball(&s, 1.0, [0.0, 2.0, 0.0]);
    let h = hit(
        s.plane.probe_ground(from, r, 10.0, None, None).unwrap(),
        "rock",
    );
    assert_eq!(h.object, rock.handle());
    assert!((h.distance - (5.0 - 3.0 - r)).abs() < SWEEP_EPS, "{h:?}");
    let h = hit(
        s.plane
            .probe_ground(from, r, 10.0, None, Some(&QueryParams::excluding(&[&rock])))
            .unwrap(),
        "past the rock",
    );
    assert_eq!(h.object, floor.handle());

    // Slopes: the sphere meets n·(c − centre) = 1 + r when its centre has dropped
    // t = 10 − (1 + r) / cos θ from 10 above the slab's centre; contact at c − r·n.
    for (deg, walkable_by_default) in [(30.0f32, true), (60.0, false)] {
        let theta = deg.to_radians();
        let centre = [100.0 + deg * 10.0, 0.0, 0.0];
        let slope = incline(&s, centre, theta);
        let from = [centre[0], 10.0, 0.0];
        let h = hit(
            s.plane.probe_ground(from, r, 20.0, None, None).unwrap(),
            "slope",
        );
        let n = [-theta.sin(), theta.cos(), 0.0];
        let t = 10.0 - (1.0 + r) / theta.cos();
        assert_eq!(h.object, slope.handle(), "{deg}°");
        assert!((h.distance - t).abs() < SWEEP_EPS, "{deg}°: {h:?} vs {t}");
        assert!(close(h.normal, n, EPS), "{deg}°: {h:?}");
        let contact = [from[0] - r * n[0], from[1] - t - r * n[1], 0.0];
        assert!(close(h.position, contact, SWEEP_EPS), "{deg}°: {h:?}");
        assert_eq!(h.walkable, walkable_by_default, "{deg}° under 45°");
        // Spherecast's hit point is the same contact (read at the touch, not where the
        // cast started).
        let sc = s
            .plane
            .spherecast(from, r, [0.0, -20.0, 0.0], None)
            .unwrap()
            .expect("spherecast hits the slope");
        assert!(close(sc.position, contact, SWEEP_EPS), "{deg}°: {sc:?}");
        assert!(close(sc.normal, n, EPS), "{deg}°: {sc:?}");
        // The limit is a parameter: 70° makes both walkable, 20° neither.
        let steep = s
            .plane
            .probe_ground(from, r, 20.0, Some(70.0), None)
            .unwrap();
        assert!(steep.unwrap().walkable, "{deg}° under 70°");
        let flat = s
            .plane
            .probe_ground(from, r, 20.0, Some(20.0), None)
            .unwrap();
        assert!(!flat.unwrap().walkable, "{deg}° under 20°");
    }

    // Bad input names the field; the daemon keeps answering.
    let e = s
        .plane
        .probe_ground([0.0, f32::NAN, 0.0], r, 1.0, None, None)
        .unwrap_err();
    assert!(e.to_string().contains("position"), "{e}");
    let e = s.plane.probe_ground(from, r, -1.0, None, None).unwrap_err();
    assert!(e.to_string().contains("maxDistance"), "{e}");
    let e = s
        .plane
        .probe_ground(from, r, 1.0, Some(95.0), None)
        .unwrap_err();
    assert!(
        e.to_string().contains("MaxSlopeAngle") && e.to_string().contains("95"),
        "{e}"
    );
    assert!(s
        .plane
        .probe_ground(from, r, 10.0, None, None)
        .unwrap()
        .is_some());
}

#[test]
fn closest_point_projects_onto_boxes_spheres_and_maps() {
    let s = Scene::new("pr-closest", zero_gravity());
    let cube = s.anchored_box([2.0; 3], Pose::at([0.0; 3]));
    // Off a face: straight across.
    let h = hit(
        s.plane.closest_point([3.0, 0.5, 0.0], None, None).unwrap(),
        "face",
    );
    assert_eq!(h.object, cube.handle());
    assert!(close(h.position, [1.0, 0.5, 0.0], EPS), "{h:?}");
    assert!((h.distance - 2.0).abs() < EPS, "{h:?}");
    assert!(close(h.normal, [1.0, 0.0, 0.0], EPS), "{h:?}");
    // Off an edge: to the edge, the normal along the gap.
    let h = hit(
        s.plane.closest_point([2.0, 2.0, 0.3], None, None).unwrap(),
        "edge",
    );
    let k = std::f32::consts::FRAC_1_SQRT_2;
    assert!(close(h.position, [1.0, 1.0, 0.3], EPS), "{h:?}");
    assert!((h.distance - 2f32.sqrt()).abs() < EPS, "{h:?}");
    assert!(close(h.normal, [k, k, 0.0], EPS), "{h:?}");
    // Inside: the nearest face, a negative distance, the face's outward normal.
    let h = hit(
        s.plane.closest_point([0.0, 0.2, 0.0], None, None).unwrap(),
        "inside",
    );
    assert!(close(h.position, [0.0, 1.0, 0.0], EPS), "{h:?}");
    assert!((h.distance + 0.8).abs() < EPS, "{h:?}");
    assert!(close(h.normal, [0.0, 1.0, 0.0], EPS), "{h:?}");
    // MaxDistance bounds it.
    assert!(s
        .plane
        .closest_point([3.0, 0.5, 0.0], Some(1.9), None)
        .unwrap()
        .is_none());

    // A sphere: centre + r·(p − centre)/|p − centre|.
    let round = ball(&s, 1.5, [20.0, 0.0, 0.0]);
    let h = hit(
        s.plane.closest_point([23.0, 4.0, 0.0], None, None).unwrap(),
        "sphere",
    );
    assert_eq!(h.object, round.handle());
    assert!(
        close(h.position, [20.0 + 1.5 * 0.6, 1.5 * 0.8, 0.0], EPS),
        "{h:?}"
    );
    assert!((h.distance - 3.5).abs() < EPS, "{h:?}");
    assert!(close(h.normal, [0.6, 0.8, 0.0], EPS), "{h:?}");

    // A triangle-mesh map (a 20 × 2 × 20 box mesh whose top is y = 0, at x = −40).
    s.plane
        .load_map_meshes(
            &[assets::box_mesh([-40.0, -1.0, 0.0], [20.0, 2.0, 20.0])],
            &MapOptions::default(),
        )
        .expect("map");
    let h = hit(
        s.plane
            .closest_point([-37.0, 2.5, 4.0], None, None)
            .unwrap(),
        "map top",
    );
    assert!(close(h.position, [-37.0, 0.0, 4.0], EPS), "{h:?}");
    assert!((h.distance - 2.5).abs() < EPS, "{h:?}");
    assert!(close(h.normal, [0.0, 1.0, 0.0], EPS), "{h:?}");
    // Beside its +X wall (x = −30), below its top.
    let h = hit(
        s.plane
            .closest_point([-29.0, -1.0, 2.0], None, None)
            .unwrap(),
        "map side",
    );
    assert!(close(h.position, [-30.0, -1.0, 2.0], EPS), "{h:?}");
    assert!((h.distance - 1.0).abs() < EPS, "{h:?}");
    assert!(close(h.normal, [1.0, 0.0, 0.0], EPS), "{h:?}");
    // Filters apply: without the cube the sphere is the nearest to a point by the cube.
    let h = hit(
        s.plane
            .closest_point(
                [3.0, 0.0, 0.0],
                None,
                Some(&QueryParams::excluding(&[&cube])),
            )
            .unwrap(),
        "filtered",
    );
    assert_eq!(h.object, round.handle());
    assert!((h.distance - 15.5).abs() < EPS, "{h:?}");
}

#[test]
fn clearance_gives_the_gap_and_both_closest_points() {
    let s = Scene::new("pr-clear", zero_gravity());
    let cube = s.anchored_box([2.0; 3], Pose::at([0.0; 3]));
    // A sphere of 0.5 at x = 3: gap 3 − 1 − 0.5.
    let h = hit(
        s.plane
            .clearance(
                Shape::Sphere { radius: 0.5 },
                Pose::at([3.0, 0.2, 0.0]),
                None,
                None,
                None,
            )
            .unwrap(),
        "sphere",
    );
    assert_eq!(h.object, cube.handle());
    assert!((h.distance - 1.5).abs() < EPS, "{h:?}");
    assert!(close(h.point_on_shape, [2.5, 0.2, 0.0], EPS), "{h:?}");
    assert!(close(h.position, [1.0, 0.2, 0.0], EPS), "{h:?}");
    assert!(close(h.normal, [1.0, 0.0, 0.0], EPS), "{h:?}");
    // Overlapping by 0.3: distance −0.3 (minus the depth).
    let h = hit(
        s.plane
            .clearance(
                Shape::Sphere { radius: 0.5 },
                Pose::at([1.2, 0.0, 0.0]),
                None,
                None,
                None,
            )
            .unwrap(),
        "overlap",
    );
    assert!((h.distance + 0.3).abs() < EPS, "{h:?}");
    // A unit box turned 45° about Z at y = 3: its lowest edge is √2/2 below its centre.
    let h = hit(
        s.plane
            .clearance(
                Shape::Cube { size: [1.0; 3] },
                Pose {
                    position: [0.0, 3.0, 0.0],
                    rotation: quat([0.0, 0.0, 1.0], std::f32::consts::FRAC_PI_4),
                },
                None,
                None,
                None,
            )
            .unwrap(),
        "turned box",
    );
    let gap = 2.0 - std::f32::consts::FRAC_1_SQRT_2;
    assert!((h.distance - gap).abs() < EPS, "{h:?} vs {gap}");
    assert!(close(h.normal, [0.0, 1.0, 0.0], EPS), "{h:?}");
    assert!((h.point_on_shape[1] - (3.0 - std::f32::consts::FRAC_1_SQRT_2)).abs() < EPS);
    // A part's own shape at a new pose never finds the part itself; MaxDistance bounds it.
    let mover = s
        .plane
        .add(
            Shape::Cube { size: [1.0; 3] },
            Pose::at([10.0, 0.0, 0.0]),
            &[],
        )
        .unwrap();
    let h = hit(
        s.plane
            .clearance(
                Shape::Cube { size: [1.0; 3] },
                Pose::at([10.0, 0.0, 0.0]),
                Some(&mover),
                None,
                None,
            )
            .unwrap(),
        "own",
    );
    assert_eq!(h.object, cube.handle());
    assert!((h.distance - 8.5).abs() < EPS, "{h:?}");
    assert!(s
        .plane
        .clearance(
            Shape::Cube { size: [1.0; 3] },
            Pose::at([10.0, 0.0, 0.0]),
            Some(&mover),
            Some(8.0),
            None
        )
        .unwrap()
        .is_none());
    // Against a very large box (the case parry's GJK gets wrong): a capsule 0.01 above a
    // 400-wide floor, exactly over its middle.
    let floor = s.anchored_box([400.0, 1.0, 400.0], Pose::at([0.0, -100.5, 0.0]));
    let h = hit(
        s.plane
            .clearance(
                Shape::Capsule {
                    size: [2.0, 5.0, 2.0],
                },
                Pose::at([0.0, -100.0 + 2.5 + 0.01, 0.0]),
                None,
                Some(1.0),
                None,
            )
            .unwrap(),
        "big floor",
    );
    assert_eq!(h.object, floor.handle());
    assert!((h.distance - 0.01).abs() < EPS, "{h:?}");
    // Bad shapes name the field.
    let e = s
        .plane
        .clearance(
            Shape::Sphere { radius: -1.0 },
            Pose::IDENTITY,
            None,
            None,
            None,
        )
        .unwrap_err();
    assert!(e.to_string().contains("radius"), "{e}");
}

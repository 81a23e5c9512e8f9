//! Proximity queries and explosions through a real daemon: `ProbeGround`, `ClosestPoint`,
//! `Clearance`, `ProbeWall`, `Explode` and the controllers' `OnWall` / `WallNormal`, each
//! against closed forms (plane geometry for probes, Δv = J / m for explosions).

use client_sdk::map::MapOptions;
use client_sdk::{Controller, Falloff, Object, PlaneOptions, Pose, ProbeHit, QueryParams, Shape};
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

#[test]
fn probe_wall_finds_walls_not_floors_including_a_maps() {
    let s = Scene::new("pr-wall", zero_gravity());
    // Floor top y = 0; wall face x = 4 (an anchored 2 × 10 × 40 box at x = 5).
    s.anchored_box([40.0, 2.0, 40.0], Pose::at([0.0, -1.0, 0.0]));
    let wall = s.anchored_box([2.0, 10.0, 40.0], Pose::at([5.0, 5.0, 0.0]));
    // A capsule of radius 0.5, height 3 standing 0.02 above the floor, 0.1 from the wall.
    let (r, height) = (0.5f32, 3.0f32);
    let at = Pose::at([4.0 - r - 0.1, 1.5 + 0.02, 0.0]);
    let h = hit(
        s.plane.probe_wall(at, r, height, 0.5, None, None).unwrap(),
        "wall",
    );
    assert_eq!(h.object, wall.handle());
    assert!((h.distance - 0.1).abs() < EPS, "{h:?}");
    assert!(close(h.normal, [-1.0, 0.0, 0.0], EPS), "{h:?}");
    assert!((h.position[0] - 4.0).abs() < EPS, "{h:?}");
    assert!((h.point_on_shape[0] - (4.0 - 0.1)).abs() < EPS, "{h:?}");
    // The floor is nearer (0.02) but is no wall; beyond the reach, no wall.
    assert!(s
        .plane
        .probe_wall(at, r, height, 0.09, None, None)
        .unwrap()
        .is_none());
    // A 60° slope is a wall under the default 45° limit and ground under 70°: its face
    // n = (−sin 60°, cos 60°, 0) through the slab's top.
    let theta = 60f32.to_radians();
    let centre = [-50.0, 0.0, 0.0];
    let slope = incline(&s, centre, theta);
    let n = [-theta.sin(), theta.cos(), 0.0];
    // The capsule's centre 0.3 + r + 1 along n from the slab's centre (its sphere caps are
    // what meet a slope: gap 0.3 from the nearer cap, which sits 1 along the capsule's axis).
    let axis_gap = |k: f32| [centre[0] + n[0] * k, centre[1] + n[1] * k, 0.0];
    let c = axis_gap(1.0 + r + 0.3);
    let h = hit(
        s.plane
            .probe_wall(Pose::at(c), r, height, 2.0, None, None)
            .unwrap(),
        "slope as wall",
    );
    assert_eq!(h.object, slope.handle());
    assert!(close(h.normal, n, EPS), "{h:?}");
    // The lower cap's centre (axis offset −1 along Y) is nearer the slope by cos θ · 1.
    let expected = 0.3 - theta.cos() * (height / 2.0 - r);
    assert!((h.distance - expected).abs() < EPS, "{h:?} vs {expected}");
    assert!(s
        .plane
        .probe_wall(Pose::at(c), r, height, 2.0, Some(70.0), None)
        .unwrap()
        .is_none());

    // A map's floor and wall in one triangle mesh: the floor's triangles do not hide the
    // wall's (floor top y = 0 over x in [80, 100], wall face x = 96).
    s.plane
        .load_map_meshes(
            &[
                assets::box_mesh([90.0, -1.0, 0.0], [20.0, 2.0, 20.0]),
                assets::box_mesh([98.0, 5.0, 0.0], [4.0, 10.0, 20.0]),
            ],
            &MapOptions::default(),
        )
        .expect("map");
    let at = Pose::at([96.0 - r - 0.1, 1.5 + 0.02, 0.0]);
    let h = hit(
        s.plane.probe_wall(at, r, height, 0.5, None, None).unwrap(),
        "map wall",
    );
    assert!((h.distance - 0.1).abs() < EPS, "{h:?}");
    assert!(close(h.normal, [-1.0, 0.0, 0.0], EPS), "{h:?}");
    let e = s
        .plane
        .probe_wall(at, r, f32::NAN, 0.5, None, None)
        .unwrap_err();
    assert!(e.to_string().contains("height"), "{e}");
}

/// A controller of the default character size (radius 1, height 5) facing +Z.
fn character(s: &Scene, at: [f32; 3]) -> Controller {
    s.plane
        .new_controller(
            Pose {
                position: at,
                rotation: quat([0.0, 1.0, 0.0], std::f32::consts::PI),
            },
            [2.0, 5.0, 2.0],
            false,
            &[],
        )
        .expect("new controller")
}

#[test]
fn controllers_report_the_wall_beside_them() {
    let s = Scene::new("pr-onwall", PlaneOptions::default());
    s.floor();
    // Wall face x = −4.
    s.anchored_box([2.0, 20.0, 40.0], Pose::at([-5.0, 10.0, 0.0]));
    let c = character(&s, [-2.5, 2.51, 0.0]);
    s.run(1.0 / 60.0, 5);
    let info = c.info().unwrap();
    assert!(info.on_ground, "standing");
    assert_eq!(info.wall_normal, [0.0; 3], "0.5 from the wall: not on it");
    // Facing +Z, the intent's +x is −X: walk into the wall.
    c.set_move_vector(1.0, 0.0).unwrap();
    s.run(1.0 / 60.0, 60);
    let x = c.object().position().unwrap()[0];
    assert!(
        (x - (-4.0 + 1.0 + 0.01)).abs() < 0.01,
        "against the wall at {x}"
    );
    let info = c.info().unwrap();
    assert!(close(info.wall_normal, [1.0, 0.0, 0.0], EPS), "{info:?}");
    // In the air beside it (0.03 off, within the 0.05 skin): still on the wall, not on
    // the ground; 0.1 off: not.
    c.set_move_vector(0.0, 0.0).unwrap();
    c.teleport(Pose::at([-4.0 + 1.0 + 0.03, 10.0, 0.0]))
        .unwrap();
    s.run(1.0 / 60.0, 1);
    let info = c.info().unwrap();
    assert!(!info.on_ground);
    let p = c.object().position().unwrap();
    assert!(
        close(info.wall_normal, [1.0, 0.0, 0.0], EPS),
        "{info:?} at {p:?}"
    );
    c.teleport(Pose::at([-4.0 + 1.0 + 0.1, 10.0, 0.0])).unwrap();
    s.run(1.0 / 60.0, 1);
    assert_eq!(c.info().unwrap().wall_normal, [0.0; 3]);
}

#[test]
fn explosions_push_by_falloff_skip_anchored_and_kick_controllers() {
    let s = Scene::new("pr-explode", zero_gravity());
    let (radius, impulse) = (10.0f32, 100.0f32);
    let near = ball(&s, 0.5, [2.0, 0.0, 0.0]);
    let side = ball(&s, 0.5, [0.0, 0.0, 5.0]);
    let far = ball(&s, 0.5, [30.0, 0.0, 0.0]);
    let wall = s.anchored_box([1.0; 3], Pose::at([0.0, -3.0, 0.0]));
    let mass = near.info().unwrap().mass;
    let hit_list = s
        .plane
        .explode([0.0; 3], radius, impulse, Falloff::Linear, None)
        .unwrap();
    assert_eq!(hit_list, vec![near.handle(), side.handle()]);
    // Linear: Δv = J (1 − d/R) / m along the centre → object direction (read after a step:
    // no gravity, no damping, nothing touches).
    s.run(1.0 / 60.0, 1);
    let v = near.velocity().unwrap();
    let expected = impulse * (1.0 - 2.0 / radius) / mass;
    assert!(
        close(v, [expected, 0.0, 0.0], expected * 1e-4),
        "{v:?} vs {expected}"
    );
    let v = side.velocity().unwrap();
    let expected = impulse * (1.0 - 5.0 / radius) / mass;
    assert!(
        close(v, [0.0, 0.0, expected], expected * 1e-4),
        "{v:?} vs {expected}"
    );
    assert_eq!(far.velocity().unwrap(), [0.0; 3]);
    assert_eq!(wall.velocity().unwrap(), [0.0; 3], "anchored: unmoved");

    // None and InverseSquare, on fresh balls at rest (d = 2: full, then J / 4).
    for (falloff, share) in [(Falloff::None, 1.0f32), (Falloff::InverseSquare, 0.25)] {
        let b = ball(&s, 0.5, [100.0, 2.0, 0.0]);
        let found = s
            .plane
            .explode([100.0, 0.0, 0.0], radius, impulse, falloff, None)
            .unwrap();
        assert_eq!(found, vec![b.handle()]);
        s.run(1.0 / 60.0, 1);
        let v = b.velocity().unwrap();
        let expected = impulse * share / mass;
        assert!(
            close(v, [0.0, expected, 0.0], expected * 1e-4),
            "{falloff:?}: {v:?}"
        );
        b.destroy();
    }

    // Filters: excluded or in a group that does not collide with the blast's, untouched.
    let a = ball(&s, 0.5, [200.0, 1.0, 0.0]);
    let b = ball(&s, 0.5, [200.0, -1.0, 0.0]);
    s.client.register_collision_group("Blast").unwrap();
    s.client.register_collision_group("Shielded").unwrap();
    s.client
        .collision_group_set_collidable("Blast", "Shielded", false)
        .unwrap();
    b.set_collision_group("Shielded").unwrap();
    let found = s
        .plane
        .explode(
            [200.0, 0.0, 0.0],
            radius,
            impulse,
            Falloff::Linear,
            Some(&QueryParams {
                collision_group: Some("Blast".into()),
                ..QueryParams::default()
            }),
        )
        .unwrap();
    assert_eq!(found, vec![a.handle()]);
    let found = s
        .plane
        .explode(
            [200.0, 0.0, 0.0],
            radius,
            impulse,
            Falloff::Linear,
            Some(&QueryParams::excluding(&[&a, &b])),
        )
        .unwrap();
    assert!(found.is_empty(), "{found:?}");

    // Bad input names the field; a sleeping body is woken (it moves after the step).
    let e = s
        .plane
        .explode([0.0; 3], radius, f32::NAN, Falloff::Linear, None)
        .unwrap_err();
    assert!(e.to_string().contains("impulse"), "{e}");
    let e = s
        .plane
        .explode([0.0; 3], -1.0, impulse, Falloff::Linear, None)
        .unwrap_err();
    assert!(e.to_string().contains("radius"), "{e}");
}

#[test]
fn explosions_wake_sleepers_and_kick_controllers() {
    let s = Scene::new("pr-explode-kcc", PlaneOptions::default());
    s.floor();
    let c = character(&s, [0.0, 2.51, 0.0]);
    let crate_ = s
        .plane
        .add(
            Shape::Cube { size: [1.0; 3] },
            Pose::at([20.0, 0.5, 0.0]),
            &[],
        )
        .unwrap();
    // Let everything settle and the crate fall asleep.
    s.run(1.0 / 60.0, 240);
    assert!(c.on_ground().unwrap());
    assert!(crate_.is_sleeping().unwrap(), "the crate sleeps");
    // A blast 4 units behind the controller (−Z side), level with its centre: a kick of
    // J (1 − 4/10) / m along +Z, read straight from its velocity before any step.
    let mass = c.object().info().unwrap().mass;
    let centre = c.object().position().unwrap();
    let found = s
        .plane
        .explode(
            [centre[0], centre[1], centre[2] - 4.0],
            10.0,
            300.0,
            Falloff::Linear,
            None,
        )
        .unwrap();
    assert!(found.contains(&c.handle()), "{found:?}");
    let v = c.info().unwrap().velocity;
    let expected = 300.0 * 0.6 / mass;
    assert!(
        close(v, [0.0, 0.0, expected], expected * 1e-4),
        "{v:?} vs {expected}"
    );
    // The sleeping crate, 3 from a blast beside it, wakes and moves.
    let found = s
        .plane
        .explode(
            [17.0, 0.5, 0.0],
            10.0,
            50.0,
            Falloff::Linear,
            Some(&QueryParams::including(&[&crate_])),
        )
        .unwrap();
    assert_eq!(found, vec![crate_.handle()]);
    s.run(1.0 / 60.0, 1);
    assert!(!crate_.is_sleeping().unwrap());
    assert!(crate_.velocity().unwrap()[0] > 0.0);
}

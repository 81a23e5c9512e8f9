//! Capsule, Cylinder and Wedge through a real daemon: mass from Density against the closed
//! forms, the wedge's centre of mass and orientation, resting heights on a floor, and sizes
//! refused by field name.
//!
//! Mass tolerance: parry computes these volumes in closed form (the capsule as a cylinder
//! plus a ball, the cylinder as π r² h, the wedge as a convex polyhedron split into
//! tetrahedra), so the only difference from the formulas is f32 rounding over a few dozen
//! operations: a relative 1e-4 leaves two orders of magnitude of margin and still catches
//! any wrong radius, height or half-size (those are off by 10 % or more).
//!
//! Resting heights: colliders have no contact skin, so a body rests touching the floor (as in
//! object_properties.rs); 0.02 of tolerance.

use std::f32::consts::PI;

use client_sdk::{ErrorKind, ObjectProp, PlaneOptions, Pose, Shape, ShapeKind};
use integration_tests::{angle_between, no_damping, quat, zero_gravity, Scene};
use shm_layout::codec::{decode_response, encode_request};
use shm_layout::{Command, PlaneOp, Request, Response};

const REL: f32 = 1e-4;
/// Gap a resting pair keeps (no contact skins).
const SKINS: f32 = 0.0;

fn close(a: f32, b: f32) -> bool {
    (a - b).abs() <= REL * b.abs()
}

fn add(scene: &Scene, shape: Shape, pose: Pose, props: &[ObjectProp]) -> client_sdk::Object {
    scene.plane.add(shape, pose, props).expect("add part")
}

/// The body's local +Y axis in world space.
fn up_axis(q: [f32; 4]) -> [f32; 3] {
    let [x, y, z, w] = q;
    [
        2.0 * (x * y - w * z),
        1.0 - 2.0 * (x * x + z * z),
        2.0 * (y * z + w * x),
    ]
}

/// `v` rotated by the unit quaternion `q`.
fn rotate(q: [f32; 4], v: [f32; 3]) -> [f32; 3] {
    let [x, y, z, w] = q;
    let u = [x, y, z];
    let cross = |a: [f32; 3], b: [f32; 3]| {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    };
    let t = cross(u, v).map(|c| 2.0 * c);
    let ut = cross(u, t);
    [0, 1, 2].map(|i| v[i] + w * t[i] + ut[i])
}

#[test]
fn each_shape_has_its_closed_form_mass_at_a_density() {
    let scene = Scene::new("shape-mass", zero_gravity());
    let rho = 2.5;
    // Capsule [2, 5, 3]: r = min(2, 3)/2 = 1, segment h = 5 − 2r = 3.
    let capsule = (
        Shape::Capsule {
            size: [2.0, 5.0, 3.0],
        },
        PI * 1.0 * (3.0 + 4.0 / 3.0),
    );
    // Size.Y ≤ 2r: only the caps remain, a ball of r = 1.
    let short_capsule = (
        Shape::Capsule {
            size: [2.0, 1.5, 2.0],
        },
        4.0 / 3.0 * PI,
    );
    // Cylinder [2, 3, 4]: r = 1, h = 3.
    let cylinder = (
        Shape::Cylinder {
            size: [2.0, 3.0, 4.0],
        },
        PI * 3.0,
    );
    // Wedge: half the box.
    let wedge = (
        Shape::Wedge {
            size: [2.0, 3.0, 4.0],
        },
        2.0 * 3.0 * 4.0 / 2.0,
    );
    for (i, (shape, volume)) in [capsule, short_capsule, cylinder, wedge]
        .into_iter()
        .enumerate()
    {
        let kind = shape.kind();
        let at = Pose::at([10.0 * i as f32, 0.0, 0.0]);
        let b = add(&scene, shape, at, &[ObjectProp::Density(rho)]);
        let info = b.info().unwrap();
        assert_eq!(info.shape, kind);
        assert!(
            close(info.mass, rho * volume),
            "{kind:?}: mass {} vs ρ·V = {}",
            info.mass,
            rho * volume
        );
        assert!(
            close(info.density, rho),
            "{kind:?}: density {}",
            info.density
        );
        // Weight instead of Density: the mass is the Weight, the density reads Weight ÷ V.
        b.set_density(0.0).unwrap();
        b.set_weight(7.0).unwrap();
        let info = b.info().unwrap();
        assert_eq!(info.mass, 7.0);
        assert!(
            close(info.density, 7.0 / volume),
            "{kind:?}: {}",
            info.density
        );
        // An impulse moves it by J / mass.
        b.set_density(rho).unwrap();
        b.apply_impulse([rho * volume, 0.0, 0.0]).unwrap();
        scene.plane.step(0.01).unwrap();
        let v = b.velocity().unwrap()[0];
        assert!((v - 1.0).abs() < 1e-3, "{kind:?}: v = {v}");
    }
}

#[test]
fn a_wedge_centre_of_mass_is_its_centroid_and_it_spins_about_it() {
    let scene = Scene::new("wedge-com", zero_gravity());
    let size = [2.0, 3.0, 6.0];
    let centroid = [0.0, -0.5, 1.0]; // (0, −Y/6, +Z/6)
    let w = add(
        &scene,
        Shape::Wedge { size },
        Pose::at([0.0; 3]),
        &[ObjectProp::HitBoxQuality(2)],
    );
    let com = w.info().unwrap().settings.center_of_mass;
    assert_eq!(com, centroid, "CenterOfMass reads the centroid");
    // Spun about X (a principal axis: the wedge is symmetric in x), it turns about its
    // centre of mass: that point stays put while the box centre circles around it.
    w.set_angular_velocity([3.0, 0.0, 0.0]).unwrap();
    scene.run(1.0 / 60.0, 30);
    let pose = w.pose().unwrap();
    let turned = angle_between(pose.rotation, [0.0, 0.0, 0.0, 1.0]);
    assert!(turned > 1.0, "it turned {turned} rad");
    let c = rotate(pose.rotation, centroid);
    let world_com = [0, 1, 2].map(|i| pose.position[i] + c[i]);
    let drift = (0..3)
        .map(|i| (world_com[i] - centroid[i]).powi(2))
        .sum::<f32>()
        .sqrt();
    assert!(
        drift < 1e-3,
        "the centre of mass moved {drift}: {world_com:?}"
    );
    let moved = pose.position.iter().map(|p| p * p).sum::<f32>().sqrt();
    assert!(moved > 0.5, "the box centre circles the centroid: {moved}");

    // The centroid follows Size; RecalculateCenterOfMass returns it.
    w.set_size([2.0, 6.0, 3.0]).unwrap();
    assert_eq!(w.info().unwrap().settings.center_of_mass, [0.0, -1.0, 0.5]);
    // Set by hand, it stays through a resize; Recalculate puts the centroid back.
    w.set_center_of_mass([0.0; 3]).unwrap();
    w.set_size([2.0, 3.0, 6.0]).unwrap();
    assert_eq!(w.info().unwrap().settings.center_of_mass, [0.0; 3]);
    assert_eq!(w.recalculate_center_of_mass().unwrap(), centroid);
    assert_eq!(w.info().unwrap().settings.center_of_mass, centroid);
    // Symmetric primitives keep theirs.
    let c = add(
        &scene,
        Shape::Cylinder { size: [1.0; 3] },
        Pose::at([20.0, 0.0, 0.0]),
        &[],
    );
    assert_eq!(c.recalculate_center_of_mass().unwrap(), [0.0; 3]);
}

#[test]
fn hit_box_quality_one_locks_capsules_cylinders_and_wedges_against_contacts() {
    let scene = Scene::new("shape-quality", zero_gravity());
    for (i, shape) in [
        Shape::Capsule { size: [1.0; 3] },
        Shape::Cylinder { size: [1.0; 3] },
        Shape::Wedge { size: [1.0; 3] },
    ]
    .into_iter()
    .enumerate()
    {
        let b = add(&scene, shape, Pose::at([5.0 * i as f32, 0.0, 0.0]), &[]);
        let info = b.info().unwrap();
        assert!(info.rotation_locked_by_quality, "{:?}", info.shape);
        b.set_hit_box_quality(2).unwrap();
        let info = b.info().unwrap();
        assert!(
            !info.rotation_locked_by_quality && info.ccd,
            "{:?}",
            info.shape
        );
        // A CenterOfMass off the shape's own centroid frees rotation at quality 1 too.
        b.set_hit_box_quality(1).unwrap();
        b.set_center_of_mass([0.1, 0.0, 0.0]).unwrap();
        assert!(!b.info().unwrap().rotation_locked_by_quality);
    }
}

#[test]
fn a_capsule_rests_upright_on_its_cap_and_lying_on_its_radius() {
    let scene = Scene::new("capsule-rest", PlaneOptions::default());
    scene.floor();
    // Upright, total height 3: the bottom of the cap is at the floor, the centre at 1.5.
    let upright = add(
        &scene,
        Shape::Capsule {
            size: [1.0, 3.0, 1.0],
        },
        Pose::at([0.0, 3.0, 0.0]),
        &[],
    );
    // Lying along X at quality 4 (free to roll): radius min(1, 3)/2 = 0.5 holds it up.
    let lying = add(
        &scene,
        Shape::Capsule {
            size: [1.0, 4.0, 3.0],
        },
        Pose {
            position: [10.0, 2.0, 0.0],
            rotation: quat([0.0, 0.0, 1.0], PI / 2.0),
        },
        &[ObjectProp::HitBoxQuality(4)],
    );
    scene.run(1.0 / 60.0, 120);
    let y = upright.position().unwrap()[1];
    assert!((y - (1.5 + SKINS)).abs() < 0.02, "upright capsule at {y}");
    let up = up_axis(upright.pose().unwrap().rotation);
    assert!(up[1] > 0.999, "still upright: {up:?}");
    // Quality 4 on the capsule, 1 on the floor: no skins either.
    let y = lying.position().unwrap()[1];
    assert!((y - 0.5).abs() < 0.02, "lying capsule at {y}");
}

#[test]
fn a_cylinder_rests_on_its_flat_face() {
    let scene = Scene::new("cylinder-rest", PlaneOptions::default());
    scene.floor();
    // Quality 4: rotation is free, so lying flat is the contacts' doing. Released tilted
    // by 0.15 rad, it lands on its rim and settles onto the face (a rounded bottom would
    // roll about instead).
    let c = add(
        &scene,
        Shape::Cylinder {
            size: [2.0, 1.0, 2.0],
        },
        Pose {
            position: [0.0, 1.5, 0.0],
            rotation: quat([1.0, 0.0, 0.0], 0.15),
        },
        &[ObjectProp::HitBoxQuality(4)],
    );
    scene.run(1.0 / 60.0, 180);
    let pose = c.pose().unwrap();
    let up = up_axis(pose.rotation);
    assert!(up[1] > 0.9999, "flat on its face: axis {up:?}");
    let y = pose.position[1];
    assert!((y - 0.5).abs() < 0.02, "centre at {y}");
    let v = c.velocity().unwrap();
    assert!(v.iter().all(|c| c.abs() < 0.05), "at rest: {v:?}");
}

#[test]
fn a_sphere_on_a_wedge_slope_goes_down_toward_minus_z() {
    let scene = Scene::new("wedge-slope", no_damping());
    // A wedge 8 long (z), 4 high: the slope runs from (y 4, z +4) down to (y 0, z −4) in
    // world space. Its outward normal is (0, 2, −1)/√5.
    let wedge = add(
        &scene,
        Shape::Wedge {
            size: [6.0, 4.0, 8.0],
        },
        Pose::at([0.0, 2.0, 0.0]),
        &[ObjectProp::Anchored(true)],
    );
    assert_eq!(wedge.info().unwrap().shape, ShapeKind::Wedge);
    // A ball of radius 0.5 on the middle of the slope (world y 2 at z 0).
    let n = [0.0, 2.0 / 5f32.sqrt(), -1.0 / 5f32.sqrt()];
    let lift = 0.5 + SKINS;
    let ball = add(
        &scene,
        Shape::Sphere { radius: 0.5 },
        Pose::at([0.0, 2.0 + lift * n[1], lift * n[2]]),
        &[],
    );
    // A ball dropped over the front half from above the box's top: the front top corner
    // is empty, so it falls past y = 4 onto the low part of the slope.
    let front = add(
        &scene,
        Shape::Sphere { radius: 0.5 },
        Pose::at([2.0, 6.0, -3.0]),
        &[],
    );
    let start = ball.position().unwrap();
    scene.run(1.0 / 60.0, 30);
    let p = ball.position().unwrap();
    let v = ball.velocity().unwrap();
    // Rolling without slipping: a = (5/7)·g·sin θ ≈ 16 along the slope, 2 units in 0.5 s,
    // so Δz ≈ −1.8 and Δy ≈ −0.9.
    assert!(p[2] - start[2] < -1.0, "moved toward −Z: {start:?} → {p:?}");
    assert!(p[1] < start[1] - 0.4, "and down: {start:?} → {p:?}");
    assert!(v[2] < -2.0 && v[1] < 0.0, "velocity down the slope: {v:?}");
    assert!(p[0].abs() < 1e-3, "no sideways drift: {p:?}");
    let y = front.position().unwrap()[1];
    assert!(y < 3.0, "the front top is empty: the ball fell to {y}");
}

#[test]
fn bad_sizes_are_refused_naming_the_field() {
    let scene = Scene::new("shape-size", PlaneOptions::default());
    let shapes: [fn([f32; 3]) -> Shape; 3] = [
        |size| Shape::Capsule { size },
        |size| Shape::Cylinder { size },
        |size| Shape::Wedge { size },
    ];
    for make in shapes {
        for (size, field, value) in [
            ([1.0, 0.0, 1.0], "Size.Y", "0"),
            ([-1.0, 1.0, 1.0], "Size.X", "-1"),
            ([1.0, 1.0, f32::NAN], "Size.Z", "NaN"),
            ([1.0, 1e9, 1.0], "Size.Y", "1000000000"),
        ] {
            let shape = make(size);
            // The SDK refuses at once...
            let err = scene
                .plane
                .add(shape.clone(), Pose::at([0.0; 3]), &[])
                .unwrap_err()
                .to_string();
            assert!(err.contains(field) && err.contains(value), "{err}");
            // ...and so does the daemon for a client that bypasses the SDK.
            let request = Request {
                commands: vec![Command::plane(
                    scene.plane.id(),
                    PlaneOp::AddObject {
                        shape,
                        pose: Pose::at([0.0; 3]),
                        props: vec![],
                    },
                )],
            };
            let reply = scene.client.raw_request(&encode_request(&request)).unwrap();
            let Response::Results(r) = decode_response(&reply).unwrap() else {
                panic!("expected results");
            };
            let e = r[0].as_ref().unwrap_err();
            assert_eq!(e.kind, ErrorKind::InvalidValue);
            assert_eq!(e.field.as_deref(), Some(field), "{}", e.message);
        }
        // A bad resize is refused and leaves the part as it was.
        let b = scene
            .plane
            .add(make([1.0; 3]), Pose::at([0.0; 3]), &[])
            .unwrap();
        let err = b.set_size([1.0, 1.0, 0.0]).unwrap_err().to_string();
        assert!(err.contains("Size.Z"), "{err}");
        assert_eq!(b.info().unwrap().size, [1.0; 3]);
    }
    assert_eq!(scene.plane.info().unwrap().object_count, 3);
}

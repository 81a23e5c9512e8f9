//! Object methods and plane members: FieldRestraint, RotateTo, SetPin,
//! RecalculateCenterOfMass, mesh hulls, Unlink, Destroy, Alive, ObjectCount, solver options.

use client_sdk::{ObjectProp, Pin, PlaneOptions, PlaneProp, Pose, Restraint, Shape};
use integration_tests::{angle_between, no_damping, quat, zero_gravity, Scene};

const G: f32 = 50.0;

fn cube(scene: &Scene, at: [f32; 3], props: &[ObjectProp]) -> client_sdk::Object {
    scene
        .plane
        .add(Shape::Cube { size: [1.0; 3] }, Pose::at(at), props)
        .unwrap()
}

#[test]
fn field_restraint_locks_axes_and_leaves_unspecified_flags() {
    let scene = Scene::new("locks", no_damping());
    let b = cube(&scene, [0.0, 10.0, 0.0], &[ObjectProp::HitBoxQuality(2)]);
    b.field_restraint(Restraint {
        lock_y: Some(true),
        lock_rot_y: Some(true),
        ..Default::default()
    })
    .unwrap();
    b.set_velocity([2.0, 5.0, 0.0]).unwrap();
    b.set_angular_velocity([0.0, 3.0, 1.0]).unwrap();
    b.apply_impulse([0.0, 50.0, 0.0]).unwrap();
    scene.run(1.0 / 60.0, 60);
    let p = b.position().unwrap();
    assert!(
        (p[1] - 10.0).abs() < 1e-5,
        "LockY keeps y under gravity: {p:?}"
    );
    assert!((p[0] - 2.0).abs() < 1e-3, "x moves freely: {p:?}");
    let w = b.angular_velocity().unwrap();
    assert!(w[1].abs() < 1e-6 && (w[2] - 1.0).abs() < 1e-3, "{w:?}");
    // Unspecified flags stay; a flag set false frees the axis.
    b.field_restraint(Restraint {
        lock_x: Some(true),
        ..Default::default()
    })
    .unwrap();
    assert_eq!(
        b.info().unwrap().locks,
        [true, true, false, false, true, false]
    );
    b.field_restraint(Restraint {
        lock_y: Some(false),
        ..Default::default()
    })
    .unwrap();
    scene.run(1.0 / 60.0, 30);
    assert!(b.position().unwrap()[1] < 9.0, "free to fall again");
}

#[test]
fn rotate_to_converges_exponentially_and_stop_leaves_the_spin() {
    let scene = Scene::new("rotate", zero_gravity());
    // A quality-1 cube: rotation locked against contacts, but direct rotation works.
    let b = cube(&scene, [0.0; 3], &[]);
    let target = quat([0.0, 1.0, 0.0], std::f32::consts::FRAC_PI_2);
    b.rotate_to(target, 8.0).unwrap();
    scene.run(1.0 / 60.0, 15);
    // Discrete P-control: the error shrinks by (1 − k·dt) per tick.
    let err = angle_between(b.pose().unwrap().rotation, target);
    let predicted = std::f32::consts::FRAC_PI_2 * (1.0f32 - 8.0 / 60.0).powi(15);
    assert!(
        (err - predicted).abs() < 0.02,
        "error {err}, predicted {predicted}"
    );
    scene.run(1.0 / 60.0, 45);
    let err = angle_between(b.pose().unwrap().rotation, target);
    assert!(err < 1e-3, "converged: {err}");
    // Stop: set a spin; without the controller it stays.
    b.stop_rotate_to().unwrap();
    b.set_angular_velocity([0.0, 1.0, 0.0]).unwrap();
    scene.run(1.0 / 60.0, 30);
    assert!((b.angular_velocity().unwrap()[1] - 1.0).abs() < 1e-4);
    assert!(b.info().unwrap().rotate_to.is_none());
}

#[test]
fn set_pin_pulls_light_bodies_to_the_target_and_cannot_lift_heavy_ones() {
    let scene = Scene::new("pin", no_damping());
    scene.floor();
    let light = cube(&scene, [0.0, 0.52, 0.0], &[ObjectProp::HitBoxQuality(2)]);
    let heavy = cube(
        &scene,
        [5.0, 0.52, 0.0],
        &[ObjectProp::Weight(100.0), ObjectProp::HitBoxQuality(2)],
    );
    let force = 1000.0f32;
    let target = |x: f32| Pin {
        force,
        relative: [0.0, 0.5, 0.0],
        target: Pose::at([x, 5.0, 0.0]),
    };
    light.set_pin(Some(target(0.0))).unwrap();
    heavy.set_pin(Some(target(5.0))).unwrap();
    let dt = 1.0 / 120.0;
    let mut last_v = light.velocity().unwrap();
    for _ in 0..120 {
        scene.plane.step(dt).unwrap();
        let v = light.velocity().unwrap();
        // The pin's acceleration is capped at force/mass; gravity adds at most g.
        let dv =
            ((v[0] - last_v[0]).powi(2) + (v[1] - last_v[1]).powi(2) + (v[2] - last_v[2]).powi(2))
                .sqrt();
        assert!(
            dv / dt <= force + G + 1.0,
            "acceleration {} over the cap",
            dv / dt
        );
        last_v = v;
    }
    // The grab point (0.5 above the centre) sits on the target: the centre is at 4.5.
    let p = light.position().unwrap();
    assert!(
        (p[1] - 4.5).abs() < 0.02 && p[0].abs() < 0.02,
        "pinned at {p:?}"
    );
    // m·g = 5000 > 1000: the heavy crate stays on the floor.
    let ph = heavy.position().unwrap();
    assert!((ph[1] - 0.5).abs() < 0.02, "heavy lifted to {ph:?}");
    // Release: it falls back.
    light.set_pin(None).unwrap();
    scene.run(dt, 120);
    assert!(light.position().unwrap()[1] < 0.6);
}

fn wedge() -> Shape {
    // A tetrahedron with most vertices toward +x, plus an interior point.
    Shape::Mesh {
        vertices: vec![
            [0.0, 0.0, 0.0],
            [2.0, 0.0, 0.0],
            [2.0, 0.0, 1.0],
            [2.0, 1.0, 0.0],
            [1.5, 0.2, 0.2],
        ],
        triangles: vec![[0, 1, 2], [0, 1, 3], [0, 2, 3], [1, 2, 3]],
    }
}

#[test]
fn mesh_parts_collide_as_their_hull_and_recalculate_their_center_of_mass() {
    let scene = Scene::new("mesh", no_damping());
    scene.floor();
    let m = scene
        .plane
        .add(wedge(), Pose::at([0.0, 3.0, 0.0]), &[])
        .unwrap();
    // The hull's lowest vertices are at local y = 0: it rests at 0 (no contact skins).
    scene.run(1.0 / 60.0, 120);
    let y = m.position().unwrap()[1];
    assert!(y.abs() < 0.01, "hull rests at {y}");
    // Vertex centroid: (7.5, 1.2, 1.2) / 5.
    let c = m.recalculate_center_of_mass().unwrap();
    let expected = [1.5, 0.24, 0.24];
    for i in 0..3 {
        assert!((c[i] - expected[i]).abs() < 1e-5, "{c:?}");
    }
    assert_eq!(m.info().unwrap().center_of_mass, c);
    // A plain cube has no mesh: no-op.
    let b = cube(
        &scene,
        [5.0, 1.0, 0.0],
        &[ObjectProp::CenterOfMass([0.0, 0.1, 0.0])],
    );
    assert_eq!(b.recalculate_center_of_mass().unwrap(), [0.0, 0.1, 0.0]);
    // Coplanar vertices span no volume: a clear error.
    let flat = Shape::Mesh {
        vertices: vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 1.0]],
        triangles: vec![],
    };
    let err = scene.plane.add(flat, Pose::IDENTITY, &[]).unwrap_err();
    assert!(err.to_string().contains("Mesh"), "{err}");
}

#[test]
fn unlink_destroy_alive_and_object_count() {
    let scene = Scene::new("life", no_damping());
    let a = cube(&scene, [0.0, 10.0, 0.0], &[]);
    let b = cube(&scene, [5.0, 10.0, 0.0], &[]);
    assert_eq!(scene.plane.object_count().unwrap(), 2);
    scene.run(1.0 / 60.0, 10);
    let before = a.pose().unwrap();
    let left_at = a.unlink().unwrap();
    assert_eq!(left_at, before);
    assert!(!a.is_alive().unwrap());
    assert_eq!(scene.plane.object_count().unwrap(), 1);
    scene.run(1.0 / 60.0, 10);
    // Plane destroy: the plane dies, its objects keep reading their last pose.
    let last = b.pose().unwrap();
    assert!(scene.plane.is_alive());
    scene.plane.destroy().unwrap();
    assert!(!scene.plane.is_alive());
    assert_eq!(b.pose().unwrap(), last);
    assert!(scene.plane.step(0.01).is_err());
}

#[test]
fn solver_options_are_clamped_reported_and_buy_accuracy() {
    // A heavy box (100:1) on a light one: more iterations, less sinking of the top box
    // below its exact resting height 1.5 (two unit boxes, no contact skins). Adaptive solving
    // off: it would give the pair its own substeps and carry the heavy box whatever the
    // plane's setting.
    let sink = |options: PlaneOptions| {
        let scene = Scene::new("solver", options.with(PlaneProp::AdaptiveSolving(false)));
        scene.floor();
        cube(&scene, [0.0, 0.5, 0.0], &[]);
        let top = cube(&scene, [0.0, 1.5, 0.0], &[ObjectProp::Weight(100.0)]);
        scene.run(1.0 / 60.0, 120);
        let info = scene.plane.info().unwrap();
        (1.5 - top.position().unwrap()[1], info)
    };
    let (loose, info) = sink(PlaneOptions {
        solver_iterations: Some(1),
        ..Default::default()
    });
    assert_eq!(info.effective_solver_iterations, 1);
    let (tight, info) = sink(PlaneOptions {
        loop_solver: Some(true),
        ..Default::default()
    });
    assert_eq!(info.effective_solver_iterations, 64);
    assert!(
        tight.abs() < loose.abs(),
        "sink with 64 iterations {tight} vs 1 iteration {loose}"
    );
    let scene = Scene::new("clamp", PlaneOptions::default());
    scene.plane.set(PlaneProp::SolverIterations(1000)).unwrap();
    let info = scene.plane.info().unwrap();
    assert_eq!(
        (info.solver_iterations, info.effective_solver_iterations),
        (64, 64)
    );
    assert_eq!(info.linear_damping, 0.10);
    assert_eq!(info.angular_damping, 0.30);
    assert_eq!(info.rest_threshold, 0.5);
    assert_eq!(info.gravity, [0.0, -G, 0.0]);
}

#[test]
fn never_sleep_keeps_resting_bodies_awake() {
    let sleeps = |never: bool| {
        let scene = Scene::new(
            "sleep",
            PlaneOptions {
                never_sleep: Some(never),
                ..Default::default()
            },
        );
        scene.floor();
        let b = cube(&scene, [0.0, 0.52, 0.0], &[]);
        let mut slept = false;
        for _ in 0..180 {
            scene.plane.step(1.0 / 60.0).unwrap();
            slept |= b.state().unwrap().is_sleeping();
        }
        slept
    };
    assert!(sleeps(false), "a resting body falls asleep by default");
    assert!(!sleeps(true), "NeverSleep keeps it awake");
}

#[test]
fn setters_name_the_property_and_the_value() {
    let scene = Scene::new("errors", PlaneOptions::default());
    let b = cube(&scene, [0.0; 3], &[]);
    for (result, field, value) in [
        (b.set_friction(-1.0), "Friction", "-1"),
        (b.set_weight(0.0), "Weight", "0"),
        (b.set_size([1.0, f32::NAN, 1.0]), "Size.Y", "NaN"),
        (b.set_density(-3.0), "Density", "-3"),
        (
            b.set_impulse_direction([f32::INFINITY, 0.0, 0.0]),
            "ImpulseDirection",
            "inf",
        ),
        (
            b.rotate_to([0.0; 4], 8.0),
            "RotateTo.target",
            "(0, 0, 0, 0)",
        ),
        (
            scene.plane.set(PlaneProp::LinearDamping(-0.1)),
            "LinearDamping",
            "-0.1",
        ),
        (scene.plane.set(PlaneProp::Drag(f32::NAN)), "Drag", "NaN"),
    ] {
        let e = result.unwrap_err().to_string();
        assert!(e.contains(field) && e.contains(value), "{e}");
    }
    // Documented clamps clamp rather than fail.
    b.set_bounciness(7.0).unwrap();
    assert_eq!(b.info().unwrap().bounciness, 1.0);
}

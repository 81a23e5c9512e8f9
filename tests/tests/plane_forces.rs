//! Plane-wide forces against closed forms: LinearDamping, Drag, Buoyancy, ConstantForce,
//! live Gravity. Gravity is the default (0, -50, 0) unless a test says otherwise.

use client_sdk::{ObjectProp, PlaneOptions, PlaneProp};
use integration_tests::Scene;

const G: f32 = 50.0;

/// A ball of radius 0.5 at `x`, `y`; tests keep balls 5 apart so they never touch.
fn ball(scene: &Scene, x: f32, y: f32, props: &[ObjectProp]) -> client_sdk::Object {
    physics_scenes::ball(&mut &scene.plane, [x, y, 0.0], props).unwrap()
}

#[test]
fn free_fall_under_linear_damping_follows_the_closed_form() {
    let k = 0.5f32;
    let scene = Scene::new(
        "damp",
        PlaneOptions {
            linear_damping: Some(k),
            ..Default::default()
        },
    );
    let y0 = 1000.0;
    let b = ball(&scene, 0.0, y0, &[]);
    let dt = 1.0 / 240.0;
    let steps = 480;
    scene.run(dt, steps);
    let t = steps as f32 * dt;
    // dv/dt = -g - k·v from rest: v = -(g/k)(1 - e^{-kt}), y = y0 - (g/k)(t - (1 - e^{-kt})/k).
    let decay = (-k * t).exp();
    let v_exact = -(G / k) * (1.0 - decay);
    let y_exact = y0 - (G / k) * (t - (1.0 - decay) / k);
    let v = b.velocity().unwrap()[1];
    let y = b.position().unwrap()[1];
    // First-order integrators: velocity error below g·dt, position error below g·dt·t
    // (twice the semi-implicit Euler bound of plain free fall), plus f32 rounding at y≈1000.
    assert!((v - v_exact).abs() < G * dt, "v={v}, exact={v_exact}");
    assert!(
        (y - y_exact).abs() < G * dt * t + 0.01,
        "y={y}, exact={y_exact}"
    );
    // And it is really damped: undamped free fall would be at -g·t = -100.
    assert!(v > -70.0, "v={v}");
}

#[test]
fn drag_reaches_the_terminal_velocity_and_heavier_bodies_fall_faster() {
    let drag = 2.0f32;
    let scene = Scene::new(
        "drag",
        PlaneOptions {
            drag: Some(drag),
            linear_damping: Some(0.0),
            ..Default::default()
        },
    );
    let light = ball(&scene, 0.0, 1000.0, &[]);
    let heavy = ball(&scene, 5.0, 1000.0, &[ObjectProp::Weight(4.0)]);
    let dt = 1.0 / 60.0;
    scene.run(dt, 180);
    // m·g = Drag·v²  →  v_t = sqrt(m·g / Drag). The drag update runs before gravity in a
    // tick, so a published velocity lies between v_t and v_t + g·dt.
    for (body, m) in [(&light, 1.0f32), (&heavy, 4.0)] {
        let vt = (m * G / drag).sqrt();
        let v = -body.velocity().unwrap()[1];
        assert!(
            v >= vt - 1e-3 && v <= vt + G * dt + 1e-3,
            "mass {m}: |v|={v}, terminal {vt}"
        );
    }
}

#[test]
fn extreme_drag_never_overshoots_at_a_coarse_step() {
    let scene = Scene::new(
        "drag-stiff",
        PlaneOptions {
            drag: Some(1.0e4),
            gravity: Some([0.0, 0.0, 0.0]),
            ..Default::default()
        },
    );
    let b = ball(&scene, 0.0, 0.0, &[ObjectProp::Velocity([300.0, 0.0, 0.0])]);
    let mut last = 300.0f32;
    for _ in 0..30 {
        scene.plane.step(1.0 / 30.0).unwrap();
        let v = b.velocity().unwrap()[0];
        // An explicit update would flip the sign (and blow up); backward Euler only slows.
        assert!(v.is_finite() && v >= 0.0 && v <= last, "v={v} after {last}");
        last = v;
    }
    assert!(last < 0.01, "drag stops the body: v={last}");
}

#[test]
fn buoyancy_equal_to_gravity_floats_and_larger_buoyancy_rises() {
    let scene = Scene::new(
        "buoy",
        PlaneOptions {
            buoyancy: Some(G),
            linear_damping: Some(0.0),
            ..Default::default()
        },
    );
    let b = ball(&scene, 0.0, 10.0, &[]);
    let dt = 1.0 / 60.0;
    scene.run(dt, 120);
    let p = b.position().unwrap();
    assert!((p[1] - 10.0).abs() < 1e-4, "neutral float drifted to {p:?}");
    assert!(b.velocity().unwrap()[1].abs() < 1e-4);

    // Twice gravity: net +g upward, y = y0 + g t²/2 within the semi-implicit bound g·dt·t/2.
    scene.plane.set(PlaneProp::Buoyancy(2.0 * G)).unwrap();
    scene.run(dt, 60);
    let t = 1.0;
    let y = b.position().unwrap()[1];
    let exact = 10.0 + 0.5 * G * t * t;
    assert!(
        y > 10.0 && (y - exact).abs() <= 0.5 * G * dt * t + 1e-3,
        "y={y}, exact={exact}"
    );
}

#[test]
fn plane_constant_force_accelerates_a_heavier_body_less() {
    let scene = Scene::new(
        "wind",
        PlaneOptions {
            gravity: Some([0.0; 3]),
            constant_force: Some([10.0, 0.0, 0.0]),
            linear_damping: Some(0.0),
            ..Default::default()
        },
    );
    let light = ball(&scene, 0.0, 0.0, &[]);
    let heavy = ball(&scene, 0.0, 5.0, &[ObjectProp::Weight(5.0)]);
    scene.run(1.0 / 60.0, 60);
    // a = F/m: after 1 s, v = 10 and 2.
    let vl = light.velocity().unwrap()[0];
    let vh = heavy.velocity().unwrap()[0];
    assert!((vl - 10.0).abs() < 1e-3, "light v={vl}");
    assert!((vh - 2.0).abs() < 1e-3, "heavy v={vh}");
    // Live-editable: switching it off leaves the velocity constant.
    scene.plane.set(PlaneProp::ConstantForce([0.0; 3])).unwrap();
    scene.run(1.0 / 60.0, 30);
    assert!((light.velocity().unwrap()[0] - vl).abs() < 1e-4);
}

#[test]
fn gravity_is_live_editable() {
    let scene = Scene::new(
        "gravity",
        PlaneOptions {
            linear_damping: Some(0.0),
            ..Default::default()
        },
    );
    let b = ball(&scene, 0.0, 100.0, &[]);
    scene.run(0.01, 10);
    let v1 = b.velocity().unwrap()[1];
    assert!((v1 + G * 0.1).abs() < 1e-3, "v={v1}");
    scene
        .plane
        .set(PlaneProp::Gravity([0.0, 10.0, 0.0]))
        .unwrap();
    scene.run(0.01, 10);
    let v2 = b.velocity().unwrap()[1];
    assert!((v2 - (v1 + 10.0 * 0.1)).abs() < 1e-3, "v={v2}");
    let info = scene.plane.info().unwrap();
    assert_eq!(info.gravity, [0.0, 10.0, 0.0]);
}

#[test]
fn angular_damping_decays_spin_by_the_documented_factor() {
    let k = 0.3f32; // the default
    let scene = Scene::new(
        "spin",
        PlaneOptions {
            gravity: Some([0.0; 3]),
            ..Default::default()
        },
    );
    let b = ball(
        &scene,
        0.0,
        0.0,
        &[ObjectProp::AngularVelocity([0.0, 10.0, 0.0])],
    );
    let dt = 1.0 / 60.0;
    scene.run(dt, 120);
    // ω_n = ω_0 · (1 − k·dt)^n, exactly (f32 rounding only).
    let expected = 10.0 * (1.0 - k * dt).powi(120);
    let w = b.angular_velocity().unwrap()[1];
    assert!((w - expected).abs() < 1e-3, "ω={w}, expected {expected}");
}

#[test]
fn a_threaded_plane_simulates_the_same_physics() {
    let run = |threads: u32| {
        let scene = Scene::new(
            "threads",
            PlaneOptions {
                threads: Some(threads),
                ..Default::default()
            },
        );
        scene.floor();
        let balls: Vec<_> = (0..100)
            .map(|i| {
                let (x, z) = ((i % 10) as f32 * 1.5, (i / 10) as f32 * 1.5);
                physics_scenes::ball(&mut &scene.plane, [x, 5.0, z], &[]).unwrap()
            })
            .collect();
        scene.run(1.0 / 60.0, 60);
        assert_eq!(scene.plane.info().unwrap().threads, threads);
        balls
            .iter()
            .map(|b| b.position().unwrap()[1])
            .collect::<Vec<_>>()
    };
    // 100 separated balls land on the floor: same heights whatever the pool size.
    let one = run(1);
    let two = run(2);
    for (a, b) in one.iter().zip(&two) {
        assert!((a - b).abs() < 1e-3 && (a - 0.5).abs() < 0.02, "{a} vs {b}");
    }
}

//! MaxLinearSpeed and MaxAngularSpeed through a real daemon: the defaults keep fast bodies
//! fast (rapier's own 400 units/s and quarter-turn-per-tick caps do not apply), a lower
//! limit holds a body at exactly that speed, and bad values are refused by name.

use client_sdk::{ErrorKind, ObjectProp, PlaneOptions, PlaneProp, Pose, Shape};
use integration_tests::{angle_between, zero_gravity, Scene};
use shm_layout::codec::{decode_response, encode_request};
use shm_layout::settings::plane::{DEFAULT_MAX_ANGULAR_SPEED, DEFAULT_MAX_LINEAR_SPEED};
use shm_layout::{Command, PlaneOp, Request, Response};

const DT: f32 = 1.0 / 60.0;

fn length(v: [f32; 3]) -> f32 {
    v.iter().map(|c| c * c).sum::<f32>().sqrt()
}

/// A unit-mass ball at `at` (Weight 1 is the default mass).
fn ball(scene: &Scene, at: [f32; 3]) -> client_sdk::Object {
    scene
        .plane
        .add(Shape::Sphere { radius: 0.5 }, Pose::at(at), &[])
        .unwrap()
}

#[test]
fn the_defaults_are_documented_and_keep_1000_units_per_second() {
    assert_eq!(DEFAULT_MAX_LINEAR_SPEED, 10_000.0);
    assert_eq!(DEFAULT_MAX_ANGULAR_SPEED, 1_000.0);
    let scene = Scene::new("speed-default", zero_gravity());
    let settings = scene.plane.info().unwrap().settings;
    assert_eq!(settings.max_linear_speed, DEFAULT_MAX_LINEAR_SPEED);
    assert_eq!(settings.max_angular_speed, DEFAULT_MAX_ANGULAR_SPEED);
    // An impulse of 1,000 on a unit mass: rapier's default cap would leave 400.
    let b = ball(&scene, [0.0; 3]);
    b.apply_impulse([1000.0, 0.0, 0.0]).unwrap();
    scene.run(DT, 30);
    let v = b.velocity().unwrap();
    assert!((v[0] - 1000.0).abs() < 1e-2, "v = {v:?}");
    let x = b.position().unwrap()[0];
    assert!((x - 500.0).abs() < 0.5, "0.5 s at 1,000: x = {x}");
    // 5,000 units/s is kept too.
    b.set_velocity([0.0, 0.0, -5000.0]).unwrap();
    scene.run(DT, 1);
    let v = b.velocity().unwrap();
    assert!((v[2] + 5000.0).abs() < 0.1, "v = {v:?}");
}

#[test]
fn max_linear_speed_holds_a_body_at_the_limit() {
    let scene = Scene::new(
        "speed-linear",
        PlaneOptions {
            max_linear_speed: Some(50.0),
            ..zero_gravity()
        },
    );
    assert_eq!(scene.plane.info().unwrap().settings.max_linear_speed, 50.0);
    let b = ball(&scene, [0.0; 3]);
    // 200 along a diagonal: the speed is capped, the direction kept.
    let s = 200.0 / 2f32.sqrt();
    b.set_velocity([s, 0.0, s]).unwrap();
    scene.run(DT, 1);
    let v = b.velocity().unwrap();
    assert!((length(v) - 50.0).abs() < 1e-3, "|v| = {}", length(v));
    assert!(
        (v[0] - v[2]).abs() < 1e-3 && v[1] == 0.0,
        "direction kept: {v:?}"
    );
    // It moved at 50 from the first substep on: 1 s covers 50 units.
    scene.run(DT, 59);
    let travelled = length(b.position().unwrap());
    assert!((travelled - 50.0).abs() < 0.05, "travelled {travelled}");

    // Under gravity a falling body stops speeding up at the limit, changed live.
    scene
        .plane
        .set(PlaneProp::Gravity([0.0, -50.0, 0.0]))
        .unwrap();
    scene.plane.set(PlaneProp::MaxLinearSpeed(20.0)).unwrap();
    let f = ball(&scene, [100.0, 0.0, 0.0]);
    scene.run(DT, 60);
    let v = f.velocity().unwrap();
    assert!((v[1] + 20.0).abs() < 1e-3, "terminal speed 20: {v:?}");
    // Raised again, it is free to go past the old limit.
    scene
        .plane
        .set(PlaneProp::MaxLinearSpeed(DEFAULT_MAX_LINEAR_SPEED))
        .unwrap();
    scene.run(DT, 60);
    assert!(f.velocity().unwrap()[1] < -60.0);
}

#[test]
fn max_angular_speed_caps_spin_and_rapiers_own_cap_is_off() {
    let scene = Scene::new("speed-angular", zero_gravity());
    // 200 rad/s: far over rapier's internal quarter turn per tick (47 rad/s at 60 Hz),
    // under the default 1,000. It keeps spinning at 200.
    let fast = ball(&scene, [0.0; 3]);
    fast.set_angular_velocity([0.0, 200.0, 0.0]).unwrap();
    scene.run(DT, 10);
    let w = fast.angular_velocity().unwrap();
    assert!((w[1] - 200.0).abs() < 1e-2, "ω = {w:?}");

    // MaxAngularSpeed 20: a body set spinning at 100 turns at 20 from the first step on.
    scene.plane.set(PlaneProp::MaxAngularSpeed(20.0)).unwrap();
    let b = ball(&scene, [10.0, 0.0, 0.0]);
    b.set_angular_velocity([60.0, 0.0, 80.0]).unwrap();
    let q0 = b.pose().unwrap().rotation;
    scene.run(DT, 1);
    let w = b.angular_velocity().unwrap();
    assert!((length(w) - 20.0).abs() < 1e-3, "|ω| = {}", length(w));
    assert!((w[0] / w[2] - 0.75).abs() < 1e-3, "axis kept: {w:?}");
    let turned = angle_between(q0, b.pose().unwrap().rotation);
    assert!(
        (turned - 20.0 * DT).abs() < 1e-2,
        "the step turned it {turned} rad, 20·dt = {}",
        20.0 * DT
    );
    // The body that was already spinning is capped as well.
    scene.run(DT, 1);
    assert!((length(fast.angular_velocity().unwrap()) - 20.0).abs() < 1e-3);
    // A cube spun through an object property is capped too.
    let cube = scene
        .plane
        .add(
            Shape::Cube { size: [1.0; 3] },
            Pose::at([20.0, 0.0, 0.0]),
            &[ObjectProp::AngularVelocity([0.0, 0.0, -500.0])],
        )
        .unwrap();
    scene.run(DT, 3);
    let w = cube.angular_velocity().unwrap();
    assert!((w[2] + 20.0).abs() < 1e-3, "ω = {w:?}");
}

#[test]
fn speed_limits_must_be_positive_and_finite() {
    let scene = Scene::new("speed-bad", PlaneOptions::default());
    type Make = fn(f32) -> PlaneProp;
    let props: [(&str, Make); 2] = [
        ("MaxLinearSpeed", PlaneProp::MaxLinearSpeed),
        ("MaxAngularSpeed", PlaneProp::MaxAngularSpeed),
    ];
    for (name, make) in props {
        for (value, text) in [
            (0.0, "got 0"),
            (-5.0, "got -5"),
            (f32::NAN, "got NaN"),
            (f32::INFINITY, "got inf"),
        ] {
            // The SDK refuses a Set...
            let err = scene.plane.set(make(value)).unwrap_err().to_string();
            assert!(err.contains(name) && err.contains(text), "{err}");
            // ...the daemon refuses a creation option...
            let mut options = PlaneOptions::manual();
            match make(value) {
                PlaneProp::MaxLinearSpeed(v) => options.max_linear_speed = Some(v),
                PlaneProp::MaxAngularSpeed(v) => options.max_angular_speed = Some(v),
                _ => unreachable!(),
            }
            let err = scene.client.create_plane(&options).unwrap_err().to_string();
            assert!(err.contains(name) && err.contains(text), "{err}");
            // ...and a Set from a client that bypasses the SDK.
            let request = Request {
                commands: vec![Command::plane(scene.plane.id(), PlaneOp::Set(make(value)))],
            };
            let reply = scene.client.raw_request(&encode_request(&request)).unwrap();
            let Response::Results(r) = decode_response(&reply).unwrap() else {
                panic!("expected results");
            };
            let e = r[0].as_ref().unwrap_err();
            assert_eq!(e.kind, ErrorKind::InvalidValue);
            assert_eq!(e.field.as_deref(), Some(name));
            assert!(e.message.contains(text), "{}", e.message);
        }
    }
    // Nothing changed.
    let settings = scene.plane.info().unwrap().settings;
    assert_eq!(settings.max_linear_speed, DEFAULT_MAX_LINEAR_SPEED);
    assert_eq!(settings.max_angular_speed, DEFAULT_MAX_ANGULAR_SPEED);
}

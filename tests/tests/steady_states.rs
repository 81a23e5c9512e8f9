//! Accuracy through a real daemon, against closed forms: terminal velocity under Drag is
//! exact at any dt, bodies rest on what they stand on without a visible gap, the tick of an
//! impact publishes the solved velocity, and a fast box does not rebound off a wall.

use client_sdk::{ObjectProp, PlaneOptions, PlaneProp, Pose};
use integration_tests::Scene;
use physics_scenes::{ball, cube, launched_box, thin_wall};

const G: f32 = 50.0;

#[test]
fn terminal_velocity_under_drag_is_exact_at_any_tick_rate() {
    // m·dv/dt = m·g − Drag·|v|·v − m·k·v has the steady state k·v + (Drag/m)·v² = g. The
    // plane integrates drag, damping and gravity together (backward Euler), whose fixed
    // point is that steady state at any dt. Bound: f32 rounding (1e-5 relative, 1e-4
    // absolute).
    for (drag, damping, mass) in [(2.0f32, 0.0f32, 1.0f32), (2.0, 0.5, 1.0), (0.5, 0.0, 8.0)] {
        let c = drag / mass;
        let exact = (-damping + (damping * damping + 4.0 * c * G).sqrt()) / (2.0 * c);
        for hz in [10.0f32, 30.0, 60.0, 240.0] {
            let s = Scene::new(
                "drag-vt",
                PlaneOptions {
                    drag: Some(drag),
                    linear_damping: Some(damping),
                    ..PlaneOptions::default()
                },
            );
            let b = ball(
                &mut &s.plane,
                [0.0, 5000.0, 0.0],
                &[ObjectProp::Weight(mass)],
            )
            .unwrap();
            s.run(1.0 / hz, (4.0 * hz) as u32);
            let v = b.velocity().unwrap();
            assert!(
                (v[1] + exact).abs() < 1e-5 * exact + 1e-4 && v[0] == 0.0 && v[2] == 0.0,
                "Drag {drag}, damping {damping}, mass {mass} at {hz} Hz: v = {v:?}, exact -{exact}"
            );
        }
    }
}

#[test]
fn resting_bodies_touch_what_they_stand_on() {
    // A unit ball and a unit cube on a floor whose top is y = 0: centres at 0.5. Bound: 0.005
    // (rapier's allowed linear error; a skin of 0.01 per collider used to leave 0.02).
    let s = Scene::new("rest-gap", PlaneOptions::default());
    s.floor();
    let b = ball(&mut &s.plane, [0.0, 1.0, 0.0], &[]).unwrap();
    let c = s
        .plane
        .add(cube(1.0), Pose::at([3.0, 1.0, 0.0]), &[])
        .unwrap();
    let q4 = s
        .plane
        .add(
            cube(1.0),
            Pose::at([-3.0, 1.0, 0.0]),
            &[ObjectProp::HitBoxQuality(4)],
        )
        .unwrap();
    s.run(1.0 / 60.0, 120);
    for (name, o) in [("ball", &b), ("cube", &c), ("quality-4 cube", &q4)] {
        let y = o.position().unwrap()[1];
        assert!((y - 0.5).abs() <= 0.005, "{name} rests at {y}");
    }
}

#[test]
fn the_tick_of_impact_publishes_the_solved_velocity() {
    // Balls dropped from 40 heights (impacts at every phase of the tick) at 60 Hz and 30 Hz.
    // Contacts are predicted along the velocity a tick starts with (rapier's soft CCD: up
    // to dt·|v| ahead, at least the 0.02 prediction distance). A ball that starts a tick
    // within that reach of the floor is stopped in that tick: if it is published touching
    // the floor, its velocity is the solved one (not moving into the floor faster than one
    // tick of gravity, g·dt). Only a ball whose gap lies within the extra distance gravity
    // adds during the tick (≤ g·dt², 0.014 at 60 Hz) is seen one tick late; it sinks at
    // most that far. Before, every impact published the fall speed and sank up to v·dt.
    for hz in [60.0f32, 30.0] {
        let dt = 1.0 / hz;
        let s = Scene::new(
            "impact",
            PlaneOptions {
                linear_damping: Some(0.0),
                ..PlaneOptions::default()
            },
        );
        s.floor();
        let balls: Vec<_> = (0..40)
            .map(|i| {
                let h = 2.0 + i as f32 * 0.137;
                ball(&mut &s.plane, [i as f32 * 2.0 - 40.0, 0.5 + h, 0.0], &[]).unwrap()
            })
            .collect();
        let mut before: Vec<[f32; 2]> = balls
            .iter()
            .map(|b| [b.position().unwrap()[1], 0.0])
            .collect();
        // Impacts (first touching tick of each ball) predicted in their tick / seen late.
        let (mut predicted, mut late) = (0, 0);
        let mut landed = vec![false; balls.len()];
        for tick in 0..(2.0 * hz) as u32 {
            s.plane.step(dt).unwrap();
            let snap = s.plane.snapshot().unwrap();
            for (i, b) in balls.iter().enumerate() {
                let st = snap.get(b.handle()).unwrap();
                let (y, vy) = (st.position[1], st.linear_velocity[1]);
                let [y0, v0] = before[i];
                before[i] = [y, vy];
                if y > 0.5 + 1e-3 {
                    continue;
                }
                let reach = (0.02f32).max(dt * v0.abs());
                let impact = !std::mem::replace(&mut landed[i], true);
                if y0 - 0.5 <= reach {
                    predicted += impact as u32;
                    assert!(
                        vy >= -G * dt * 1.01,
                        "{hz} Hz, ball {i}, tick {tick}: started {} above the floor (reach \
                         {reach}), published at y = {y} with v = {vy}",
                        y0 - 0.5
                    );
                } else {
                    late += impact as u32;
                    assert!(
                        y >= 0.5 - G * dt * dt * 1.01,
                        "{hz} Hz, ball {i}, tick {tick}: sank to {y}"
                    );
                }
            }
        }
        println!("{hz} Hz: {predicted} impacts predicted, {late} seen a tick late");
        assert_eq!(predicted + late, 40, "every ball landed");
        // The window is ≈ g·dt²·0.6 of a tick's travel of ≈ 0.3–0.5: a few percent.
        assert!(late <= 4, "{late} of 40 impacts seen a tick late");
    }
}

#[test]
fn a_fast_box_does_not_rebound_off_a_wall_at_bounciness_zero() {
    // A 0.5 box at 400 units/s into an anchored 0.1 wall, no gravity, Bounciness 0 (the
    // default) at HitBoxQuality 4 (free rotation, CCD). Bound: 1 unit/s in any direction
    // (it rebounded at 14 units/s and spun at 17 rad/s when one PGS sweep per substep
    // handed the first contact point of the face the whole impact).
    let s = Scene::new(
        "wall-rebound",
        PlaneOptions {
            gravity: Some([0.0; 3]),
            ..PlaneOptions::default()
        },
    );
    s.plane.set(PlaneProp::LinearDamping(0.0)).unwrap();
    let q = [ObjectProp::HitBoxQuality(4)];
    thin_wall(&mut &s.plane, &q).unwrap();
    let b = launched_box(&mut &s.plane, -30.0, 400.0, &q).unwrap();
    s.run(1.0 / 60.0, 30);
    let p = b.position().unwrap();
    let v = b.velocity().unwrap();
    let speed = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    assert!(
        p[0] <= -0.25 + 1e-2,
        "the box stays in front of the wall: {p:?}"
    );
    assert!(speed <= 1.0, "rebound speed {speed}: {v:?}");
}

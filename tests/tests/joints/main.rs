//! Joints through a real daemon, against closed forms: a hinge pendulum's period, a motor's
//! speed, a spring's frequency, a rope's length, the load that breaks a joint, a heavy-ended
//! chain's error (an articulation, see tests/tests/articulations.rs), and what destroying
//! an object does to its joints.

// Listing a plane's joints page by page (`JointOp::List`).
mod list;

use client_sdk::{
    Error, ErrorKind, JointBroke, JointKind, JointProp, Object, ObjectProp, Pose, Shape,
};
use integration_tests::{no_damping, zero_gravity, Scene};

fn ball(s: &Scene, at: [f32; 3], radius: f32, weight: f32) -> Object {
    s.plane
        .add(
            Shape::Sphere { radius },
            Pose::at(at),
            &[ObjectProp::Weight(weight)],
        )
        .unwrap()
}

/// Times of upward zero crossings of `f`, linearly interpolated between ticks.
fn crossings(samples: &[(f32, f32)]) -> Vec<f32> {
    samples
        .windows(2)
        .filter(|w| w[0].1 < 0.0 && w[1].1 >= 0.0)
        .map(|w| w[0].0 + (w[1].0 - w[0].0) * (-w[0].1) / (w[1].1 - w[0].1))
        .collect()
}

fn mean_period(c: &[f32]) -> f32 {
    (c[c.len() - 1] - c[0]) / (c.len() - 1) as f32
}

/// Period of a hinge pendulum of length L released from θ0.
fn pendulum_period(rate: f32) -> (f32, f32) {
    let s = Scene::new("pendulum", no_damping());
    let (g, l, theta0) = (50.0f32, 2.0f32, 0.3f32);
    let pivot = [0.0, 10.0, 0.0];
    let start = [
        pivot[0] + l * theta0.sin(),
        pivot[1] - l * theta0.cos(),
        0.0,
    ];
    // A small bob: its own inertia (2/5·m·r²) lengthens the period by a factor
    // √(1 + 0.4·r²/L²) = 1.00005, far below the tolerance.
    let bob = ball(&s, start, 0.05, 1.0);
    s.plane
        .joint(
            JointKind::Hinge,
            &bob,
            None,
            &[
                JointProp::AnchorA([pivot[0] - start[0], pivot[1] - start[1], 0.0]),
                JointProp::AnchorB(pivot),
                JointProp::Axis([0.0, 0.0, 1.0]),
            ],
        )
        .unwrap();
    let dt = 1.0 / rate;
    let mut samples = Vec::new();
    for n in 1..=(6.5 * rate) as u32 {
        s.plane.step(dt).unwrap();
        samples.push((n as f32 * dt, bob.position().unwrap()[0]));
    }
    let c = crossings(&samples);
    assert!(c.len() >= 4, "only {} crossings", c.len());
    let exact = 2.0 * std::f32::consts::PI * (l / g).sqrt() * (1.0 + theta0 * theta0 / 16.0);
    (mean_period(&c), exact)
}

#[test]
fn hinge_pendulum_period_matches_the_closed_form_at_60_and_240_hz() {
    for rate in [60.0f32, 240.0] {
        let (t, exact) = pendulum_period(rate);
        let rel = (t - exact).abs() / exact;
        println!(
            "pendulum at {rate} Hz: period {t:.5} s, closed form {exact:.5} s, error {:.3} %",
            rel * 100.0
        );
        // The series' next term (11θ0⁴/3072 = 3e-5) and the symplectic integrator's
        // phase error ((ωh)²/24 ≈ 2e-5 at 60 Hz, 4 substeps) are far below 0.5 %; the
        // crossing interpolation is exact to (ω·dt)²/8 of a tick.
        assert!(rel < 0.005, "{rate} Hz: period {t}, exact {exact}");
    }
}

#[test]
fn a_hinge_motor_reaches_its_speed() {
    let s = Scene::new("motor", zero_gravity());
    let wheel = ball(&s, [0.0, 0.0, 0.0], 1.0, 5.0);
    let j = s
        .plane
        .joint(
            JointKind::Hinge,
            &wheel,
            None,
            &[JointProp::Axis([0.0, 1.0, 0.0]), JointProp::MotorSpeed(4.0)],
        )
        .unwrap();
    s.run(1.0 / 60.0, 30);
    let w = wheel.angular_velocity().unwrap();
    println!("motor: ω = {w:?} (MotorSpeed 4)");
    // The motor acts on the hinge angle (B relative to A): A turns at -MotorSpeed about
    // +Y when B is the world. The stiff default gain settles within a few ticks.
    assert!((w[1].abs() - 4.0).abs() < 0.04, "ω {w:?}");
    assert!(w[0].abs() < 1e-3 && w[2].abs() < 1e-3, "ω {w:?}");
    // A capped motor accelerates at most at MotorMaxForce / I: I = 2/5·m·r² = 2.
    j.set(JointProp::MotorSpeed(-4.0)).unwrap();
    j.set(JointProp::MotorMaxForce(10.0)).unwrap();
    let before = wheel.angular_velocity().unwrap()[1];
    s.run(1.0 / 60.0, 6);
    let after = wheel.angular_velocity().unwrap()[1];
    let alpha = (after - before).abs() / 0.1;
    println!("capped motor: α = {alpha} rad/s² (bound 10 / 2 = 5)");
    assert!(alpha <= 5.0 * 1.02 && alpha > 4.5, "α {alpha}");
}

#[test]
fn a_spring_oscillates_at_sqrt_k_over_m() {
    let s = Scene::new("spring", zero_gravity());
    let (k, m, rest) = (200.0f32, 2.0f32, 1.0f32);
    let b = ball(&s, [rest + 0.2, 0.0, 0.0], 0.1, m);
    s.plane
        .joint(
            JointKind::Spring,
            &b,
            None,
            &[JointProp::RestLength(rest), JointProp::Stiffness(k)],
        )
        .unwrap();
    let rate = 240.0;
    let mut samples = Vec::new();
    for n in 1..=(3.0 * rate) as u32 {
        s.plane.step(1.0 / rate).unwrap();
        samples.push((n as f32 / rate, b.position().unwrap()[0] - rest));
    }
    let c = crossings(&samples);
    let period = mean_period(&c);
    let exact = 2.0 * std::f32::consts::PI / (k / m).sqrt();
    let amplitude = samples.iter().map(|s| s.1.abs()).fold(0.0f32, f32::max);
    println!("spring: period {period:.5} s, 2π/√(k/m) = {exact:.5} s, amplitude {amplitude}");
    // Rapier's implicit spring shifts the frequency by O((ω·h)²) = 2e-4 at 240 Hz with
    // 4 substeps; 1 % leaves room for the interpolated crossings.
    assert!((period - exact).abs() / exact < 0.01, "{period} vs {exact}");
    assert!(amplitude <= 0.2 * 1.01, "amplitude grew to {amplitude}");
}

#[test]
fn a_rope_never_exceeds_its_length() {
    let s = Scene::new("rope", no_damping());
    let len = 3.0f32;
    let b = ball(&s, [0.0, 5.0, 0.0], 0.2, 1.0);
    let rope = s
        .plane
        .joint(
            JointKind::Rope,
            &b,
            None,
            &[
                JointProp::AnchorB([0.0, 5.0, 0.0]),
                JointProp::UpperDistance(len),
            ],
        )
        .unwrap();
    b.set_velocity([30.0, 10.0, -20.0]).unwrap();
    let mut worst = 0.0f32;
    let mut slack_seen = false;
    for _ in 0..240 {
        s.plane.step(1.0 / 60.0).unwrap();
        let p = b.position().unwrap();
        let d = (p[0] * p[0] + (p[1] - 5.0).powi(2) + p[2] * p[2]).sqrt();
        worst = worst.max(d - len);
        slack_seen |= d < len - 0.5;
    }
    let header_err = s.plane.snapshot().unwrap().header().max_joint_error;
    println!(
        "rope: worst overshoot {worst}, header max_joint_error {header_err}, error {}",
        rope.error().unwrap()
    );
    // A thrown ball pulled up short at 30+ units/s: the solver's position correction
    // leaves at most a few hundredths of stretch for a tick.
    assert!(worst < 0.03, "rope stretched by {worst}");
    assert!(slack_seen, "the rope was never slack: it behaved as a rod");
}

#[test]
fn break_force_breaks_at_the_right_load_and_fires_an_event() {
    let s = Scene::new("break", no_damping());
    // g = 50: a weight of 1.9 pulls with 95, 2.1 with 105; BreakForce 100.
    let b = ball(&s, [0.0, 0.0, 0.0], 0.2, 1.9);
    let j = s
        .plane
        .joint(
            JointKind::Ball,
            &b,
            None,
            &[
                JointProp::AnchorA([0.0, 1.0, 0.0]),
                JointProp::AnchorB([0.0, 1.0, 0.0]),
                JointProp::BreakForce(100.0),
            ],
        )
        .unwrap();
    let _ = s.plane.events().unwrap();
    s.run(1.0 / 60.0, 60);
    let info = j.info().unwrap();
    println!("below the load: force {}", info.force);
    assert!(!info.broken && (info.force - 95.0).abs() < 2.0, "{info:?}");
    b.set_weight(2.1).unwrap();
    let mut broke_at = None;
    for n in 1..=10 {
        s.plane.step(1.0 / 60.0).unwrap();
        if j.is_broken().unwrap() {
            broke_at = Some(n);
            break;
        }
    }
    let info = j.info().unwrap();
    println!(
        "above the load: broke after {broke_at:?} ticks at force {}",
        info.force
    );
    assert!(broke_at.is_some(), "joint held 105 against BreakForce 100");
    assert!(info.force > 100.0 && info.force < 115.0, "{info:?}");
    let broke: Vec<JointBroke> = s
        .plane
        .events()
        .unwrap()
        .records
        .iter()
        .filter_map(JointBroke::from_record)
        .collect();
    assert_eq!(broke.len(), 1, "{broke:?}");
    assert_eq!(broke[0].joint, j.handle());
    assert_eq!(broke[0].object, b.handle());
    // Broken: the ball falls freely.
    s.run(1.0 / 60.0, 30);
    assert!(b.position().unwrap()[1] < -5.0);
}

#[test]
fn a_twenty_link_chain_with_a_1000x_heavier_end_holds_together_at_the_defaults() {
    // Point-like links (anchors at the link centres) with a 1,000:1 end. As impulse joints
    // the worst gap reached ~50 units at the default 4 iterations (0.98 at 16); the chain
    // is a joint tree, so it runs as one articulation whose joints cannot drift apart:
    // what is left is float rounding of the forward kinematics (~1e-5 per link).
    let s = Scene::new("chain", no_damping());
    let n = 20;
    let mut links: Vec<Object> = Vec::new();
    for i in 0..n {
        let w = if i == n - 1 { 1000.0 } else { 1.0 };
        let l = ball(&s, [i as f32 * 0.5 + 0.5, 20.0, 0.0], 0.2, w);
        let (anchor_b, other) = match links.last() {
            Some(prev) => ([0.5, 0.0, 0.0], Some(prev)),
            None => ([0.5, 20.0, 0.0], None),
        };
        s.plane
            .joint(
                JointKind::Ball,
                &l,
                other,
                &[JointProp::AnchorA([0.0; 3]), JointProp::AnchorB(anchor_b)],
            )
            .unwrap();
        links.push(l);
    }
    let (mut worst, mut lowest) = (0.0f32, f32::MAX);
    // 5 s at 60 Hz.
    for _ in 0..300 {
        s.plane.step(1.0 / 60.0).unwrap();
        let h = *s.plane.snapshot().unwrap().header();
        assert!(h.max_joint_error.is_finite());
        worst = worst.max(h.max_joint_error);
        lowest = lowest.min(links[n - 1].position().unwrap()[1]);
    }
    let end = links[n - 1].position().unwrap();
    let reach = (end[0].powi(2) + (end[1] - 20.0).powi(2)).sqrt();
    println!(
        "chain 1000:1 at the defaults: worst max_joint_error {worst}, end at distance {reach} \
         (rest length 10), lowest end height {lowest}"
    );
    assert!(worst < 0.01, "joint error {worst}");
    // The links are rigidly 0.5 apart: the end never gets further than 10 from the pivot,
    // and it swings down to about 10 below it (a swinging chain, not a stuck one).
    assert!(reach < 10.0 + 0.01, "chain stretched to {reach}");
    assert!(
        lowest < 20.0 - 9.0,
        "the chain never swung down: lowest {lowest}"
    );
}

#[test]
fn destroying_an_object_removes_its_joints_and_bad_options_name_the_field() {
    let s = Scene::new("jointlife", zero_gravity());
    let a = ball(&s, [0.0, 0.0, 0.0], 0.5, 1.0);
    let b = ball(&s, [2.0, 0.0, 0.0], 0.5, 1.0);
    let j = s
        .plane
        .joint(
            JointKind::Fixed,
            &a,
            Some(&b),
            &[JointProp::AnchorA([2.0, 0.0, 0.0])],
        )
        .unwrap();
    assert_eq!(s.plane.info().unwrap().object_count, 2);
    match s.plane.joint(
        JointKind::Hinge,
        &a,
        Some(&b),
        &[JointProp::LowerAngle(f32::NAN)],
    ) {
        Err(Error::Invalid { field, .. }) => assert_eq!(field, "LowerAngle"),
        Err(e) => panic!("{e}"),
        Ok(_) => panic!("NaN accepted"),
    }
    let e = s
        .plane
        .joint(JointKind::Ball, &a, Some(&a), &[])
        .err()
        .unwrap()
        .to_string();
    assert!(e.contains("objB"), "{e}");
    let e = s
        .plane
        .joint(JointKind::Ball, &a, None, &[JointProp::MotorSpeed(1.0)])
        .err()
        .unwrap()
        .to_string();
    assert!(e.contains("MotorSpeed") && e.contains("Ball"), "{e}");
    b.destroy();
    match j.info() {
        Err(Error::Command(c)) => assert_eq!(c.kind, ErrorKind::StaleHandle, "{c}"),
        other => panic!("joint outlived its object: {other:?}"),
    }
    s.run(1.0 / 60.0, 2);
    assert_eq!(s.plane.snapshot().unwrap().header().max_joint_error, 0.0);
}

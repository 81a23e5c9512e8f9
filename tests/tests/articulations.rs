//! Articulated joint trees through a real daemon: joints that form a tree over dynamic
//! objects (unbreakable Ball, ConeTwist, Hinge, Prismatic, Fixed) run as one reduced-coordinate
//! articulation. Checked against closed forms: a ball-joint pendulum's period, the force
//! each joint of a hanging chain carries (the weight below it), the height a pushed bob
//! swings to (a velocity written to a link is taken in), and the switch back to impulse
//! joints when a joint becomes breakable or a loop closes.

use client_sdk::{JointBroke, JointKind, JointProp, Object, ObjectProp, Pose, Shape};
use integration_tests::{no_damping, Scene};

fn ball(s: &Scene, at: [f32; 3], radius: f32, weight: f32) -> Object {
    s.plane
        .add(
            Shape::Sphere { radius },
            Pose::at(at),
            &[ObjectProp::Weight(weight)],
        )
        .unwrap()
}

/// A vertical chain hanging from (0, 20, 0): link i at 20 − (i + 1)·gap, each joined at
/// the point `gap` above its centre to the centre of the link above (point-like links),
/// link `weights[i]` heavy.
fn hanging_chain(s: &Scene, weights: &[f32], gap: f32) -> (Vec<Object>, Vec<client_sdk::Joint>) {
    let mut links: Vec<Object> = Vec::new();
    let mut joints = Vec::new();
    for (i, w) in weights.iter().enumerate() {
        let l = ball(s, [0.0, 20.0 - (i + 1) as f32 * gap, 0.0], 0.1, *w);
        let (anchor_b, other) = match links.last() {
            Some(prev) => ([0.0; 3], Some(prev)),
            None => ([0.0, 20.0, 0.0], None),
        };
        let j = s
            .plane
            .joint(
                JointKind::Ball,
                &l,
                other,
                &[
                    JointProp::AnchorA([0.0, gap, 0.0]),
                    JointProp::AnchorB(anchor_b),
                ],
            )
            .unwrap();
        links.push(l);
        joints.push(j);
    }
    (links, joints)
}

#[test]
fn a_ball_joint_pendulum_swings_at_the_closed_form_period() {
    let s = Scene::new("art-pendulum", no_damping());
    let (g, l, theta0) = (50.0f32, 2.0f32, 0.3f32);
    let start = [l * theta0.sin(), 10.0 - l * theta0.cos(), 0.0];
    // A small bob: its own inertia lengthens the period by √(1 + 0.4·r²/L²) = 1.00005.
    let bob = ball(&s, start, 0.05, 1.0);
    s.plane
        .joint(
            JointKind::Ball,
            &bob,
            None,
            &[
                JointProp::AnchorA([-start[0], 10.0 - start[1], 0.0]),
                JointProp::AnchorB([0.0, 10.0, 0.0]),
            ],
        )
        .unwrap();
    let dt = 1.0 / 60.0;
    let mut samples = Vec::new();
    let mut worst = 0.0f32;
    for n in 1..=390 {
        s.plane.step(dt).unwrap();
        let p = bob.position().unwrap();
        samples.push((n as f32 * dt, p[0]));
        let r = (p[0].powi(2) + (p[1] - 10.0).powi(2) + p[2].powi(2)).sqrt();
        worst = worst.max((r - l).abs());
    }
    let c: Vec<f32> = samples
        .windows(2)
        .filter(|w| w[0].1 < 0.0 && w[1].1 >= 0.0)
        .map(|w| w[0].0 + (w[1].0 - w[0].0) * (-w[0].1) / (w[1].1 - w[0].1))
        .collect();
    assert!(c.len() >= 4, "only {} crossings", c.len());
    let period = (c[c.len() - 1] - c[0]) / (c.len() - 1) as f32;
    // Large-amplitude correction to second order: T = 2π√(L/g)(1 + θ0²/16).
    let exact = 2.0 * std::f32::consts::PI * (l / g).sqrt() * (1.0 + theta0 * theta0 / 16.0);
    println!("ball pendulum: period {period}, closed form {exact}, rod length off by {worst}");
    assert!((period / exact - 1.0).abs() < 0.005, "{period} vs {exact}");
    // The rod keeps its length exactly (reduced coordinates: only rounding).
    assert!(worst < 1e-3, "rod length off by {worst}");
}

#[test]
fn each_joint_of_a_hanging_chain_carries_the_weight_below_it() {
    let s = Scene::new("art-force", no_damping());
    let weights = [1.0, 2.0, 1000.0];
    let (_, joints) = hanging_chain(&s, &weights, 0.5);
    s.run(1.0 / 60.0, 60);
    // g = 50: the joint above link i holds 50 · Σ weights[i..].
    for (i, j) in joints.iter().enumerate() {
        let info = j.info().unwrap();
        let load = 50.0 * weights[i..].iter().sum::<f32>();
        println!(
            "joint {i}: force {} (load {load}), error {}",
            info.force, info.error
        );
        assert!(
            (info.force / load - 1.0).abs() < 0.01,
            "joint {i}: {} vs {load}",
            info.force
        );
        assert!(info.error < 1e-3, "joint {i}: error {}", info.error);
    }
}

#[test]
fn a_velocity_written_to_a_link_swings_it_to_v_squared_over_2g() {
    let s = Scene::new("art-push", no_damping());
    let (links, _) = hanging_chain(&s, &[1.0], 2.0);
    s.run(1.0 / 60.0, 5);
    let bob = &links[0];
    // 5 sideways at the bottom, g = 50: it rises h = v²/2g = 0.25 (on a rod of 2, the
    // push is all along the swing).
    bob.set_velocity([5.0, 0.0, 0.0]).unwrap();
    let bottom = bob.position().unwrap()[1];
    let mut top = f32::MIN;
    for _ in 0..240 {
        s.plane.step(1.0 / 240.0).unwrap();
        top = top.max(bob.position().unwrap()[1]);
    }
    let h = top - bottom;
    println!("pushed bob rose {h} (v²/2g = 0.25)");
    // Sampling at 240 Hz near the turning point (speed ~0 there) costs far below 1 %.
    assert!((h - 0.25).abs() < 0.0025, "rose {h}");
}

#[test]
fn a_joint_made_breakable_leaves_the_articulation_and_breaks_at_its_load() {
    let s = Scene::new("art-break", no_damping());
    let (links, joints) = hanging_chain(&s, &[1.0, 1.0, 1.0], 0.5);
    s.run(1.0 / 60.0, 30);
    let _ = s.plane.events().unwrap();
    // The middle joint holds the last link: 50. A BreakForce of 40 breaks it.
    joints[2].set(JointProp::BreakForce(40.0)).unwrap();
    let mut broke_at = None;
    for n in 1..=10 {
        s.plane.step(1.0 / 60.0).unwrap();
        if joints[2].is_broken().unwrap() {
            broke_at = Some(n);
            break;
        }
    }
    let info = joints[2].info().unwrap();
    println!("broke after {broke_at:?} ticks at force {}", info.force);
    assert!(broke_at.is_some(), "a BreakForce of 40 held a load of 50");
    assert!((info.force - 50.0).abs() < 5.0, "{info:?}");
    let broke: Vec<JointBroke> = s
        .plane
        .events()
        .unwrap()
        .records
        .iter()
        .filter_map(JointBroke::from_record)
        .collect();
    assert_eq!(broke.len(), 1, "{broke:?}");
    // The freed link falls; the rest of the chain still hangs, still articulated.
    s.run(1.0 / 60.0, 30);
    assert!(links[2].position().unwrap()[1] < 17.0);
    for j in &joints[..2] {
        let e = j.error().unwrap();
        assert!(e < 1e-3, "remaining chain error {e}");
    }
}

#[test]
fn a_closed_loop_runs_as_impulse_joints_and_an_opened_one_as_an_articulation() {
    let s = Scene::new("art-loop", no_damping());
    // A square ring of four balls (one 100× heavier), hung by one corner.
    let corners = [
        [0.0, 19.0, 0.0],
        [1.0, 19.0, 0.0],
        [1.0, 18.0, 0.0],
        [0.0, 18.0, 0.0],
    ];
    let weights = [1.0, 1.0, 100.0, 1.0];
    let balls: Vec<Object> = corners
        .iter()
        .zip(weights)
        .map(|(c, w)| ball(&s, *c, 0.1, w))
        .collect();
    s.plane
        .joint(
            JointKind::Ball,
            &balls[0],
            None,
            &[JointProp::AnchorB([0.0, 19.0, 0.0])],
        )
        .unwrap();
    let mut ring = Vec::new();
    for i in 0..4 {
        let (a, b) = (&balls[i], &balls[(i + 1) % 4]);
        let d = [
            corners[(i + 1) % 4][0] - corners[i][0],
            corners[(i + 1) % 4][1] - corners[i][1],
            0.0,
        ];
        ring.push(
            s.plane
                .joint(JointKind::Ball, a, Some(b), &[JointProp::AnchorA(d)])
                .unwrap(),
        );
    }
    let worst_over = |n: u32| {
        let mut worst = 0.0f32;
        for _ in 0..n {
            s.plane.step(1.0 / 60.0).unwrap();
            let h = *s.plane.snapshot().unwrap().header();
            assert!(h.max_joint_error.is_finite());
            worst = worst.max(h.max_joint_error);
        }
        worst
    };
    // A loop: impulse joints, which stretch under the 100:1 load.
    let looped = worst_over(120);
    // Opened (one ring joint destroyed): a tree again, articulated, rigid.
    ring[3].destroy().unwrap();
    s.run(1.0 / 60.0, 2);
    let opened = worst_over(120);
    println!("ring 100:1: worst error as a loop {looped}, opened {opened}");
    assert!(
        looped > 0.01,
        "the loop was not simulated with impulse joints ({looped})"
    );
    assert!(
        opened < 0.01,
        "the opened ring is not articulated ({opened})"
    );
}

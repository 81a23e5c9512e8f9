//! Joint tests on a whole plane.

use shm_layout::{JointOp, JointProp, ObjectProp, PlaneOp, PlaneProp, Pose, Reply, Shape};

use crate::backend::Backend;
use crate::rapier3d::Plane;

fn plane() -> Plane {
    Plane::new(
        1,
        &[
            PlaneProp::TickRate(0.0),
            PlaneProp::LinearDamping(0.0),
            PlaneProp::AngularDamping(0.0),
        ],
    )
    .unwrap()
}

fn ball(p: &mut Plane, at: [f32; 3], weight: f32) -> shm_layout::Handle {
    p.add_object(
        &Shape::Sphere { radius: 0.25 },
        Pose::at(at),
        &[ObjectProp::Weight(weight)],
    )
    .unwrap()
}

/// A xorshift generator from `seed`: `rnd(n)` is in `0..n` (the random-sequence tests).
fn xorshift(mut seed: u64) -> impl FnMut(u64) -> u64 {
    move |n| {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        seed % n
    }
}

fn joint(p: &mut Plane, op: JointOp) -> shm_layout::Handle {
    match p.apply(PlaneOp::Joint(op)).unwrap() {
        Reply::Joint { handle, .. } => handle,
        r => panic!("{r:?}"),
    }
}

#[test]
fn a_hanging_mass_loads_its_joint_with_its_weight() {
    let mut p = plane();
    let b = ball(&mut p, [0.0, -2.0, 0.0], 2.0);
    let j = joint(
        &mut p,
        JointOp::Create {
            kind: shm_layout::JointKind::Ball,
            a: b,
            b: None,
            props: vec![JointProp::AnchorA([0.0, 2.0, 0.0])],
        },
    );
    for _ in 0..120 {
        p.step(1.0 / 60.0).unwrap();
    }
    let Reply::JointInfo(info) = p.apply(PlaneOp::Joint(JointOp::Info { joint: j })).unwrap()
    else {
        panic!()
    };
    // m·g = 2 × 50 = 100.
    assert!((info.force - 100.0).abs() < 5.0, "force {}", info.force);
    assert!(info.error < 0.01, "error {}", info.error);
}

/// Bodies whose state went non-finite are disabled by rapier (its quarantine), yet its
/// joint selection still hands their joints to the solver with both ends world-attached,
/// which panics there. The sequence the fuzzer found: forced bodies stepped with the
/// smallest positive dt (1e-45 s, which overflowed the force drive until it fell back to
/// setting velocities: see `tiny_steps_leave_forced_bodies_enabled`), then joints made on
/// them and a normal step. Quarantine is reproduced here as rapier leaves it (bodies
/// disabled); the joints are parked, no step panics, a joint made afterwards works, and
/// re-enabled bodies get their joints back.
#[test]
fn joints_of_quarantined_bodies_are_parked_instead_of_panicking_the_solver() {
    use shm_layout::JointKind;
    let mut p = Plane::new(
        1,
        &[
            shm_layout::PlaneProp::TickRate(0.0),
            shm_layout::PlaneProp::AngularDamping(3.4382944),
            shm_layout::PlaneProp::SolverIterations(13),
            shm_layout::PlaneProp::RestThreshold(0.8737293),
        ],
    )
    .unwrap();
    let a = p
        .add_object(
            &Shape::Cube {
                size: [1.0, 1.0, 1.0],
            },
            Pose::at([0.0, 0.0, 0.0]),
            &[],
        )
        .unwrap();
    let b = ball(&mut p, [0.4, 0.0, 0.0], 1.0);
    let c = ball(&mut p, [5.0, 0.0, 0.0], 1.0);
    let parked = |p: &Plane| {
        (0..p.joints.table.slot_count())
            .filter_map(|i| p.joints.table.at(i))
            .filter(|j| j.rapier.is_none() && j.link.is_none())
            .count()
    };
    let step = |p: &mut Plane, i: usize, dt: f32| {
        let stepped = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| p.step(dt)));
        assert!(stepped.is_ok(), "step {i} (dt {dt}) panicked");
    };
    step(&mut p, 0, 1.0 / 60.0);
    let bodies: Vec<_> = [a, b, c]
        .iter()
        .map(|h| p.objects.get(*h).unwrap().handle)
        .collect();
    for h in &bodies {
        p.world.bodies[*h].set_enabled(false);
    }
    step(&mut p, 0, 1.0 / 60.0);
    // Free balls, more than the quarantined ones, so that rapier's joint selection scans
    // every joint rather than only those next to awake bodies.
    for k in 0..6 {
        ball(&mut p, [20.0 + k as f32, 0.0, 0.0], 1.0);
    }
    // Joints made on the quarantined balls (as the fuzzer did) are parked at once.
    for (kind, x, y) in [
        (JointKind::Hinge, a, Some(b)),
        (JointKind::Ball, c, None),
        (JointKind::Fixed, b, Some(c)),
    ] {
        joint(
            &mut p,
            JointOp::Create {
                kind,
                a: x,
                b: y,
                props: vec![],
            },
        );
    }
    for i in 1..4 {
        step(&mut p, i, 1.0 / 60.0);
    }
    let quarantined = p
        .world
        .bodies
        .iter()
        .filter(|(_, b)| !b.is_enabled())
        .count();
    assert_eq!(quarantined, 3, "the three balls are quarantined");
    assert_eq!(parked(&p), 3, "their joints are parked");

    // A pendulum made now swings on its 2-unit rod.
    let pendulum = ball(&mut p, [10.0, -2.0, 0.0], 1.0);
    let rod = joint(
        &mut p,
        JointOp::Create {
            kind: JointKind::Ball,
            a: pendulum,
            b: None,
            props: vec![JointProp::AnchorA([0.0, 2.0, 0.0])],
        },
    );
    p.apply(PlaneOp::Object {
        handle: pendulum,
        op: shm_layout::ObjectOp::Set(ObjectProp::Velocity([5.0, 0.0, 0.0])),
    })
    .unwrap();
    for _ in 0..30 {
        p.step(1.0 / 60.0).unwrap();
    }
    let Reply::JointInfo(info) = p
        .apply(PlaneOp::Joint(JointOp::Info { joint: rod }))
        .unwrap()
    else {
        panic!()
    };
    // Off the rod by under 1 % of its length.
    assert!(info.error < 0.02, "pendulum joint error {}", info.error);
    let body = p.joints.table.get(rod).unwrap().body_a;
    let x = p.world.bodies[body].translation().x;
    assert!((x - 10.0).abs() > 0.1, "the pendulum swung: x = {x}");

    // Re-enabled (set_enabled(true) is how rapier lifts a quarantine), the balls get
    // their joints back.
    for h in &bodies {
        p.world.bodies[*h].set_enabled(true);
    }
    step(&mut p, 4, 1.0 / 60.0);
    assert_eq!(parked(&p), 0, "joints restored");
}

/// A forced body stepped with the smallest positive dt (its force drive's mass / dt
/// overflows) keeps a finite state and stays in the simulation instead of being
/// quarantined by rapier.
#[test]
fn tiny_steps_leave_forced_bodies_enabled() {
    let mut p = plane();
    let a = ball(&mut p, [0.0, 0.0, 0.0], 1.0);
    p.apply(PlaneOp::Object {
        handle: a,
        op: shm_layout::ObjectOp::Set(ObjectProp::ConstantForce([0.0, 1.0, 0.0])),
    })
    .unwrap();
    p.step(1.0e-45).unwrap();
    p.step(1.0 / 60.0).unwrap();
    let body = &p.world.bodies[p.objects.get(a).unwrap().handle];
    assert!(body.is_enabled(), "quarantined by a tiny step");
    assert!(body.translation().is_finite() && body.linvel().is_finite());
    // Gravity (-50) and the force (+1 on weight 1) over the 1/60 s step.
    let vy = body.linvel().y;
    assert!((vy - (-49.0 / 60.0)).abs() < 0.02, "vy {vy}");
}

/// Articulated joints with motors and limits stepped with tiny time steps (found by the
/// fuzzer: an articulated joint with a motor target and limits, a step of 1e-38 s: the
/// solver's rates (1 / dt) overflowed into NaN motor bounds and panicked it). A step
/// under `MIN_DYNAMIC_DT` is simulated as that long; no step may panic, every body stays
/// finite and the plane's clock counts every step.
#[test]
fn articulations_with_motors_survive_tiny_steps() {
    use shm_layout::JointKind;
    let motor = [JointProp::MotorTarget(1.5), JointProp::MotorMaxForce(50.0)];
    let cases = [
        (
            JointKind::Prismatic,
            vec![JointProp::LowerDistance(0.5), JointProp::UpperDistance(3.0)],
        ),
        (
            JointKind::Hinge,
            vec![JointProp::LowerAngle(-0.5), JointProp::UpperAngle(0.5)],
        ),
        (JointKind::Ball, vec![JointProp::SwingLimit(1.0)]),
        (
            JointKind::ConeTwist,
            vec![JointProp::SwingLimit(1.0), JointProp::TwistLimit(1.5)],
        ),
    ];
    for (kind, limits) in cases {
        let mut props = limits.clone();
        if matches!(kind, JointKind::Prismatic | JointKind::Hinge) {
            props.extend(motor);
        }
        for tiny in [1e-45f32, 1e-38, 1e-30, 1e-20, 1e-12, 1e-9] {
            let mut p = plane();
            let a = ball(&mut p, [0.0, 0.0, 0.0], 1.0);
            let b = ball(&mut p, [1.0, 0.0, 0.0], 1.0);
            let c = ball(&mut p, [2.0, 0.5, 0.0], 1.0);
            for (x, y) in [(a, b), (b, c)] {
                joint(
                    &mut p,
                    JointOp::Create {
                        kind,
                        a: x,
                        b: Some(y),
                        props: props.clone(),
                    },
                );
            }
            let steps = [
                1.0 / 60.0,
                tiny,
                tiny,
                1.0 / 60.0,
                tiny,
                1.0 / 60.0,
                1.0 / 60.0,
            ];
            for dt in steps {
                let done = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| p.step(dt)));
                assert!(
                    matches!(done, Ok(Ok(true))),
                    "{kind:?}: a step of {dt:e} s (tiny {tiny:e}) panicked or failed"
                );
            }
            assert_eq!(p.tick(), steps.len() as u64);
            for h in [a, b, c] {
                let body = &p.world.bodies[p.objects.get(h).unwrap().handle];
                assert!(
                    body.translation().is_finite() && body.linvel().is_finite(),
                    "{kind:?}, tiny {tiny:e}: {:?} {:?}",
                    body.translation(),
                    body.linvel()
                );
            }
        }
    }
}

/// Random articulations (every articulable kind, with its limits and motors) on parts
/// of very different weights, pushed by forces and impulses up to the largest floats,
/// stepped with steps from 1e-45 s to 0.7 s (what the fuzzer found: a force so large on
/// a light link that the velocity it asked for overflowed f32; the link's joint
/// coordinates went NaN within the step and the solver panicked on its motor bounds).
/// No step may panic.
#[test]
fn random_articulations_under_extreme_pushes_never_panic() {
    use shm_layout::{JointKind, ObjectOp};
    let mut rnd = xorshift(0x2545_f491_4f6c_dd1d);
    let huge = [1.0, 50.0, 1e20, f32::MAX];
    for round in 0..150 {
        let mut p = plane();
        let mut objs = Vec::new();
        let mut log = Vec::new();
        for _ in 0..40 {
            let pick = |rnd: &mut dyn FnMut(u64) -> u64| objs[rnd(objs.len() as u64) as usize];
            let op = match rnd(8) {
                0 | 1 => PlaneOp::AddObject {
                    shape: Shape::Sphere { radius: 0.25 },
                    pose: Pose::at([rnd(4) as f32, rnd(3) as f32 * 0.4, 0.0]),
                    props: vec![ObjectProp::Weight([0.005, 1.0, 100.0][rnd(3) as usize])],
                },
                2 | 3 if objs.len() >= 2 => {
                    let (a, b) = (pick(&mut rnd), pick(&mut rnd));
                    let (kind, props) = match rnd(4) {
                        0 => (
                            JointKind::Hinge,
                            vec![
                                JointProp::LowerAngle(-0.5),
                                JointProp::UpperAngle(0.5),
                                JointProp::MotorTarget(1.5),
                                JointProp::MotorMaxForce(huge[rnd(4) as usize]),
                            ],
                        ),
                        1 => (
                            JointKind::Prismatic,
                            vec![
                                JointProp::LowerDistance(0.5),
                                JointProp::UpperDistance(3.0),
                                JointProp::MotorTarget(1.5),
                                JointProp::MotorMaxForce(huge[rnd(4) as usize]),
                            ],
                        ),
                        2 => (JointKind::Ball, vec![JointProp::SwingLimit(1.0)]),
                        _ => (
                            JointKind::ConeTwist,
                            vec![JointProp::SwingLimit(1.0), JointProp::TwistLimit(1.5)],
                        ),
                    };
                    PlaneOp::Joint(JointOp::Create {
                        kind,
                        a,
                        b: Some(b),
                        props,
                    })
                }
                4 if !objs.is_empty() => {
                    let f = huge[rnd(4) as usize] * [-1.0, 1.0][rnd(2) as usize];
                    PlaneOp::Object {
                        handle: pick(&mut rnd),
                        op: ObjectOp::Set(ObjectProp::ConstantForce([f, 26.4, -f])),
                    }
                }
                5 if !objs.is_empty() => {
                    let j = huge[rnd(4) as usize];
                    PlaneOp::Object {
                        handle: pick(&mut rnd),
                        op: ObjectOp::ApplyImpulse([j, -2.9, -13.1]),
                    }
                }
                _ => PlaneOp::Step {
                    dt: [1.0 / 60.0, 1e-45, 0.1, 0.7][rnd(4) as usize],
                },
            };
            log.push(format!("{op:?}"));
            let outcome = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                if let PlaneOp::Step { dt } = op {
                    p.step(dt).map(|_| Reply::Applied { tick: 0 })
                } else {
                    p.apply(op)
                }
            }));
            match outcome {
                Ok(Ok(Reply::Object { handle, .. })) => objs.push(handle),
                Ok(_) => {}
                Err(_) => panic!("round {round} panicked after:\n{}", log.join("\n")),
            }
        }
        // What such pushes leave is not physics any more (a body they make non-finite
        // is quarantined by rapier at its next step); what must hold is that the plane
        // goes on stepping.
        let next = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| p.step(1.0 / 60.0)));
        assert!(
            matches!(next, Ok(Ok(_))),
            "round {round}: the plane does not step on after:\n{}",
            log.join("\n")
        );
    }
}

/// Random sequences of joint, anchoring, waking, teleporting, forcing, destroying and
/// stepping ops on a few objects: no step may panic (rapier's solver must never receive a joint
/// whose two bodies are both world-attached).
#[test]
fn random_joint_sequences_never_panic_the_solver() {
    use shm_layout::{JointKind, ObjectOp};
    let mut rnd = xorshift(0x9e37_79b9_7f4a_7c15);
    let kinds = [
        JointKind::Ball,
        JointKind::Hinge,
        JointKind::ConeTwist,
        JointKind::SixDof,
        JointKind::Fixed,
        JointKind::Prismatic,
        JointKind::Rope,
        JointKind::Spring,
    ];
    for round in 0..300 {
        let mut p = plane();
        let mut objs = Vec::new();
        let mut joints = Vec::new();
        let mut log = Vec::new();
        for _ in 0..60 {
            let op = match rnd(11) {
                0 => {
                    let props = if rnd(3) == 0 {
                        vec![ObjectProp::Anchored(true)]
                    } else {
                        vec![]
                    };
                    PlaneOp::AddObject {
                        shape: Shape::Sphere { radius: 0.25 },
                        pose: Pose::at([rnd(4) as f32, rnd(3) as f32 * 0.4, 0.0]),
                        props,
                    }
                }
                1 | 2 if !objs.is_empty() => {
                    let a = objs[rnd(objs.len() as u64) as usize];
                    let b = (rnd(3) != 0).then(|| objs[rnd(objs.len() as u64) as usize]);
                    let mut props = vec![];
                    if rnd(3) == 0 {
                        props.push(JointProp::BreakForce(rnd(100) as f32));
                    }
                    PlaneOp::Joint(JointOp::Create {
                        kind: kinds[rnd(8) as usize],
                        a,
                        b,
                        props,
                    })
                }
                3 if !objs.is_empty() => PlaneOp::Object {
                    handle: objs[rnd(objs.len() as u64) as usize],
                    op: ObjectOp::Set(ObjectProp::Anchored(rnd(2) == 0)),
                },
                4 if !objs.is_empty() => PlaneOp::Object {
                    handle: objs[rnd(objs.len() as u64) as usize],
                    op: if rnd(2) == 0 {
                        ObjectOp::Wake
                    } else {
                        ObjectOp::Set(ObjectProp::Pose(Pose::at([0.0, 5.0, 0.0])))
                    },
                },
                5 if !objs.is_empty() && rnd(3) == 0 => PlaneOp::Object {
                    handle: objs[rnd(objs.len() as u64) as usize],
                    op: ObjectOp::Destroy,
                },
                6 if !joints.is_empty() => {
                    let joint = joints[rnd(joints.len() as u64) as usize];
                    if rnd(3) == 0 {
                        PlaneOp::Joint(JointOp::Destroy { joint })
                    } else {
                        PlaneOp::Joint(JointOp::Set {
                            joint,
                            prop: JointProp::CollideConnected(rnd(2) == 0),
                        })
                    }
                }
                8 if !objs.is_empty() && rnd(4) == 0 => {
                    // What rapier's quarantine does to a body gone non-finite.
                    let h = objs[rnd(objs.len() as u64) as usize];
                    if let Ok(b) = p.objects.get(h) {
                        let on = rnd(3) == 0;
                        p.world.bodies[b.handle].set_enabled(on);
                    }
                    PlaneOp::Info
                }
                7 if !objs.is_empty() => PlaneOp::Object {
                    handle: objs[rnd(objs.len() as u64) as usize],
                    op: ObjectOp::Set(ObjectProp::ConstantForce([0.0, 1.0, 0.0])),
                },
                // 1e-45 s overflows the force drive of forced bodies: rapier quarantines
                // (disables) them.
                _ => PlaneOp::Step {
                    dt: [1.0 / 60.0, 1e-5, 0.1, 1e-45][rnd(4) as usize],
                },
            };
            log.push(format!("{op:?}"));
            let outcome = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                if let PlaneOp::Step { dt } = op {
                    // Long idle stretches let bodies fall asleep.
                    for _ in 0..[1, 1, 90][rnd(3) as usize] {
                        p.step(dt).map(|_| Reply::Applied { tick: 0 })?;
                    }
                    Ok(Reply::Applied { tick: 0 })
                } else {
                    p.apply(op)
                }
            }));
            match outcome {
                Ok(Ok(Reply::Object { handle, .. })) => objs.push(handle),
                Ok(Ok(Reply::Joint { handle, .. })) => joints.push(handle),
                Ok(_) => {}
                Err(_) => panic!("round {round} panicked after:\n{}", log.join("\n")),
            }
        }
    }
}

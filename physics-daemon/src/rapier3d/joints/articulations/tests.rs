//! Articulation tests on a whole plane.

use shm_layout::{JointKind, JointOp, JointProp, ObjectOp, ObjectProp, PlaneOp, PlaneProp};
use shm_layout::{Pose, Reply, Shape};

use crate::backend::Backend;
use crate::rapier3d::Plane;

#[test]
fn a_pushed_pendulum_bob_takes_the_push_once() {
    let mut p = Plane::new(
        1,
        &[
            PlaneProp::TickRate(0.0),
            PlaneProp::LinearDamping(0.0),
            PlaneProp::AngularDamping(0.0),
        ],
    )
    .unwrap();
    let bob = p
        .add_object(
            &Shape::Sphere { radius: 0.1 },
            Pose::at([0.0, 18.0, 0.0]),
            &[ObjectProp::Weight(1.0)],
        )
        .unwrap();
    let Reply::Joint { .. } = p
        .apply(PlaneOp::Joint(JointOp::Create {
            kind: JointKind::Ball,
            a: bob,
            b: None,
            props: vec![
                JointProp::AnchorA([0.0, 2.0, 0.0]),
                JointProp::AnchorB([0.0, 20.0, 0.0]),
            ],
        }))
        .unwrap()
    else {
        panic!()
    };
    for _ in 0..5 {
        p.step(1.0 / 60.0).unwrap();
    }
    p.apply(PlaneOp::Object {
        handle: bob,
        op: ObjectOp::Set(ObjectProp::Velocity([5.0, 0.0, 0.0])),
    })
    .unwrap();
    let h = p.objects.get(bob).unwrap().handle;
    for i in 0..6 {
        p.step(1.0 / 240.0).unwrap();
        let b = &p.world.bodies[h];
        assert!(b.linvel().is_finite(), "step {i}");
    }
    let v = p.world.bodies[h].linvel().length();
    assert!((v - 5.0).abs() < 0.2, "speed {v}");
}

/// A 1,000:1 chain of point-like links swinging for 15 s: rapier's articulation stays
/// finite (it diverged at 2.9 s without the armature) and every gap stays below 0.01.
#[test]
fn a_heavy_ended_chain_publishes_finite_states() {
    let mut p = Plane::new(
        1,
        &[
            PlaneProp::TickRate(0.0),
            PlaneProp::LinearDamping(0.0),
            PlaneProp::AngularDamping(0.0),
        ],
    )
    .unwrap();
    let mut prev = None;
    for i in 0..20 {
        let w = if i == 19 { 1000.0 } else { 1.0 };
        let link = p
            .add_object(
                &Shape::Sphere { radius: 0.2 },
                Pose::at([i as f32 * 0.5 + 0.5, 20.0, 0.0]),
                &[ObjectProp::Weight(w)],
            )
            .unwrap();
        let anchor_b = if prev.is_some() {
            [0.5, 0.0, 0.0]
        } else {
            [0.5, 20.0, 0.0]
        };
        p.apply(PlaneOp::Joint(JointOp::Create {
            kind: JointKind::Ball,
            a: link,
            b: prev,
            props: vec![JointProp::AnchorA([0.0; 3]), JointProp::AnchorB(anchor_b)],
        }))
        .unwrap();
        prev = Some(link);
    }
    for t in 0..900 {
        p.step(1.0 / 60.0).unwrap();
        for i in 0..p.objects.slot_count() {
            let s = p.body_state(i);
            assert!(s.is_finite(), "tick {t} slot {i}: {s:?}");
        }
        assert!(
            p.joints.max_error < 0.01,
            "tick {t}: error {}",
            p.joints.max_error
        );
    }
}

/// A velocity written to one link of a free (unanchored) articulation moves the pair's
/// centre of mass with the written momentum, in its direction: two unit balls in zero
/// gravity, one pushed at 4 along +Z, move their centre at 2 along +Z.
#[test]
fn a_push_on_a_free_articulation_keeps_its_momentum() {
    let mut p = Plane::new(
        1,
        &[
            PlaneProp::TickRate(0.0),
            PlaneProp::Gravity([0.0; 3]),
            PlaneProp::LinearDamping(0.0),
            PlaneProp::AngularDamping(0.0),
        ],
    )
    .unwrap();
    let a = p
        .add_object(
            &Shape::Sphere { radius: 0.1 },
            Pose::at([0.0, 5.0, 0.0]),
            &[],
        )
        .unwrap();
    let b = p
        .add_object(
            &Shape::Sphere { radius: 0.1 },
            Pose::at([1.0, 5.0, 0.0]),
            &[],
        )
        .unwrap();
    p.apply(PlaneOp::Joint(JointOp::Create {
        kind: JointKind::Ball,
        a,
        b: Some(b),
        props: vec![
            JointProp::AnchorA([0.5, 0.0, 0.0]),
            JointProp::AnchorB([-0.5, 0.0, 0.0]),
        ],
    }))
    .unwrap();
    p.step(1.0 / 60.0).unwrap();
    p.apply(PlaneOp::Object {
        handle: a,
        op: ObjectOp::Set(ObjectProp::Velocity([0.0, 0.0, 4.0])),
    })
    .unwrap();
    for _ in 0..30 {
        p.step(1.0 / 60.0).unwrap();
    }
    let (ha, hb) = (
        p.objects.get(a).unwrap().handle,
        p.objects.get(b).unwrap().handle,
    );
    let v = (p.world.bodies[ha].linvel() + p.world.bodies[hb].linvel()) * 0.5;
    assert!(
        (v.z - 2.0).abs() < 0.02 && v.x.abs() < 0.02 && v.y.abs() < 0.02,
        "{v:?}"
    );
}

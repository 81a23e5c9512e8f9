//! Ragdolls through a real daemon: the default humanoid hit by a projectile at 1,000 u/s.

use client_sdk::{ObjectProp, PlaneOptions, Pose, RagdollDesc, Shape};
use integration_tests::Scene;

/// Worst figures over a run.
#[derive(Default, Debug)]
struct Worst {
    /// Radians beyond a swing or twist limit, with the bone and tick.
    angle: (f32, String, u32),
    /// Anchor separation (units), with the bone and tick.
    separation: (f32, String, u32),
    /// Largest bone angular speed.
    spin: f32,
    /// Largest UpperTorso speed (that the hit landed).
    torso_speed: f32,
    /// Worst limit violation and anchor separation from 1 s after the hit on.
    settled: (f32, f32),
    /// How far the ball's centre got behind the UpperTorso's back (centre − radius 0.5 −
    /// ball radius 0.4, along the shot) in the first 0.5 s: > 0 means it passed through.
    behind: f32,
}

fn hit_ragdoll(
    max_angular_speed: Option<f32>,
    weight: f32,
    iterations: Option<u32>,
) -> (Worst, f32) {
    let s = Scene::new(
        "ragdoll",
        PlaneOptions {
            max_angular_speed,
            solver_iterations: iterations,
            ..PlaneOptions::default()
        },
    );
    s.floor();
    let cap = s.plane.info().unwrap().settings.max_angular_speed;
    let desc = RagdollDesc::humanoid(Pose::at([0.0, 2.95, 0.0]), 1.0);
    assert_eq!(desc.bones.len(), 15);
    let doll = s.plane.ragdoll(&desc, &[]).unwrap();
    assert_eq!(doll.joints.len(), 14);
    // A heavy ball at 1,000 u/s into the chest, starting 0.02 in front of it: at 16.7 units
    // a tick it would otherwise cross the 1-unit-thick chest between two ticks.
    let ball = s
        .plane
        .add(
            Shape::Sphere { radius: 0.4 },
            Pose::at([0.0, 4.15, 0.92]),
            &[
                ObjectProp::Weight(weight),
                ObjectProp::HitBoxQuality(2),
                ObjectProp::Velocity([0.0, 0.0, -1000.0]),
            ],
        )
        .unwrap();
    let torso = doll.bone("UpperTorso").unwrap().clone();
    let mut w = Worst {
        behind: f32::MIN,
        ..Worst::default()
    };
    for tick in 1..=180u32 {
        s.plane.step(1.0 / 60.0).unwrap();
        for (name, o) in &doll.bones {
            let st = o.state().unwrap();
            let values = st
                .position
                .iter()
                .chain(&st.rotation)
                .chain(&st.linear_velocity)
                .chain(&st.angular_velocity);
            for v in values {
                assert!(
                    v.is_finite(),
                    "{name} went non-finite at tick {tick}: {st:?}"
                );
            }
            let spin = st
                .angular_velocity
                .iter()
                .map(|c| c * c)
                .sum::<f32>()
                .sqrt();
            w.spin = w.spin.max(spin);
        }
        let v = torso.velocity().unwrap();
        if tick <= 30 {
            let gap = torso.position().unwrap()[2] - 0.5 - 0.4 - ball.position().unwrap()[2];
            w.behind = w.behind.max(gap);
        }

        w.torso_speed = w
            .torso_speed
            .max(v.iter().map(|c| c * c).sum::<f32>().sqrt());
        for (name, j) in &doll.joints {
            let info = j.info().unwrap();
            assert!(!info.broken);
            if info.angular_error > w.angle.0 {
                w.angle = (info.angular_error, name.clone(), tick);
            }
            if tick > 60 {
                w.settled.0 = w.settled.0.max(info.angular_error);
                w.settled.1 = w.settled.1.max(info.error);
            }
            if info.error > w.separation.0 {
                w.separation = (info.error, name.clone(), tick);
            }
        }
    }
    assert!(ball.position().unwrap()[2].is_finite());
    (w, cap)
}

/// The humanoid at the default settings hit in the chest at 1,000 u/s by a ball of a bone's
/// weight: every bone stays finite and spins within the plane's MaxAngularSpeed, the ball
/// never gets behind the chest, and the joints hold.
///
/// The ragdoll's joints form a tree, so it runs as one articulation: its anchors cannot part
/// (what is left is float rounding), and a swing or twist limit a step overshoots by more
/// than 0.05 rad is put back on the limit at the end of the step (an inelastic stop):
/// measured 0.049 rad at worst. The bounds are the goals of the issue that asked for
/// it: overshoot ≤ 0.2 rad and separation ≤ 0.02 (as impulse joints at SolverIterations
/// 16: 1.23 rad and 0.36, and the ball passed through the chest).
#[test]
fn a_humanoid_ragdoll_hit_at_1000_stays_finite_and_within_its_limits() {
    let (w, cap) = hit_ragdoll(None, 1.0, None);
    println!(
        "ragdoll hit at 1000 u/s: worst limit violation {:.4} rad ({} at tick {}), {:.4} rad \
         after 1 s; worst anchor separation {:.6} ({} at tick {}), {:.6} after 1 s; max spin \
         {:.1} rad/s (cap {cap}); torso speed {:.1}; ball behind the chest by {:.3}",
        w.angle.0,
        w.angle.1,
        w.angle.2,
        w.settled.0,
        w.separation.0,
        w.separation.1,
        w.separation.2,
        w.settled.1,
        w.spin,
        w.torso_speed,
        w.behind
    );
    assert!(w.torso_speed > 20.0, "the ball hit the chest: {w:?}");
    assert!(w.behind <= 0.0, "the ball passed through the chest: {w:?}");
    assert!(w.spin <= cap * 1.001, "spin {} above the cap {cap}", w.spin);
    assert!(w.angle.0 <= 0.2, "limit violation {w:?}");
    assert!(w.separation.0 <= 0.02, "anchor separation {w:?}");
}

/// With MaxAngularSpeed 20 rad/s the bones' spins stay at or under 20 while the hit lands.
#[test]
fn a_ragdolls_spin_stays_under_a_low_max_angular_speed() {
    let (w, cap) = hit_ragdoll(Some(20.0), 1.0, Some(16));
    println!("ragdoll with cap {cap}: max spin {:.3}, {w:?}", w.spin);
    assert_eq!(cap, 20.0);
    assert!(w.torso_speed > 20.0, "the ball hit the chest: {w:?}");
    assert!(w.spin <= 20.0 * 1.001, "spin {} above the cap 20", w.spin);
    assert!(w.spin > 5.0, "the hit set the bones spinning: {}", w.spin);
}

/// Bad descriptions are refused before anything is made, naming the bone and field.
#[test]
fn bad_ragdoll_descriptions_name_the_bone_and_field() {
    let s = Scene::new("ragdoll-bad", PlaneOptions::default());
    let good = RagdollDesc::humanoid(Pose::at([0.0, 3.0, 0.0]), 1.0);
    type Edit = Box<dyn Fn(&mut RagdollDesc)>;
    let cases: Vec<(Edit, &str)> = vec![
        (
            Box::new(|d| d.bones[2].radius = -1.0),
            "bones[3] \"Head\".Radius",
        ),
        (
            Box::new(|d| d.bones[2].length = 0.1),
            "bones[3] \"Head\".Length",
        ),
        (
            Box::new(|d| d.bones[1].parent = Some("Tail".into())),
            "bones[2] \"UpperTorso\".Parent",
        ),
        (Box::new(|d| d.bones[3].swing_limit = 4.0), "SwingLimit"),
        (
            Box::new(|d| d.bones[4].twist_limit = f32::NAN),
            "TwistLimit",
        ),
        (
            Box::new(|d| d.bones[5].name = "Head".into()),
            "two bones are called \"Head\"",
        ),
        (Box::new(|d| d.bones.clear()), "at least one bone"),
    ];
    for (edit, expect) in cases {
        let mut d = good.clone();
        edit(&mut d);
        let err = s.plane.ragdoll(&d, &[]).err().expect("refused").to_string();
        assert!(err.contains(expect), "{expect:?} not in {err:?}");
    }
    assert_eq!(s.plane.info().unwrap().object_count, 0, "nothing half-made");
}

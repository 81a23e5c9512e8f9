//! Object properties against numbers: Weight, Density, Bounciness, Friction, Anchored,
//! CanCollide, HitBoxQuality, Size, CenterOfMass, ImpulseDirection, ConstantForce, CFrame.

use client_sdk::{ObjectProp, PlaneOptions, Pose, Shape, ShapeKind};
use integration_tests::{angle_between, no_damping, quat, zero_gravity, Scene};

const G: f32 = 50.0;

fn cube(scene: &Scene, size: f32, at: [f32; 3], props: &[ObjectProp]) -> client_sdk::Object {
    scene
        .plane
        .add(Shape::Cube { size: [size; 3] }, Pose::at(at), props)
        .unwrap()
}

fn sphere(scene: &Scene, radius: f32, at: [f32; 3], props: &[ObjectProp]) -> client_sdk::Object {
    scene
        .plane
        .add(Shape::Sphere { radius }, Pose::at(at), props)
        .unwrap()
}

#[test]
fn weight_scales_impulses_but_not_free_fall() {
    let scene = Scene::new("weight", no_damping());
    let light = sphere(&scene, 0.5, [0.0, 100.0, 0.0], &[]);
    let heavy = sphere(&scene, 0.5, [5.0, 100.0, 0.0], &[ObjectProp::Weight(4.0)]);
    light.apply_impulse([10.0, 0.0, 0.0]).unwrap();
    heavy.apply_impulse([10.0, 0.0, 0.0]).unwrap();
    scene.run(1.0 / 60.0, 30);
    // velocity += impulse / Weight.
    assert!((light.velocity().unwrap()[0] - 10.0).abs() < 1e-4);
    assert!((heavy.velocity().unwrap()[0] - 2.5).abs() < 1e-4);
    // Every body falls alike.
    let (yl, yh) = (light.position().unwrap()[1], heavy.position().unwrap()[1]);
    assert!((yl - yh).abs() < 1e-4, "{yl} vs {yh}");
    assert!(yl < 100.0 - 5.0, "it fell: {yl}");
}

#[test]
fn density_sets_mass_from_volume_and_wins_over_weight() {
    let scene = Scene::new("density", zero_gravity());
    let b = cube(&scene, 2.0, [0.0; 3], &[ObjectProp::Weight(5.0)]);
    let info = b.info().unwrap();
    assert_eq!(info.mass, 5.0);
    assert!(
        (info.density - 5.0 / 8.0).abs() < 1e-6,
        "reads Weight ÷ volume"
    );
    b.set_density(3.0).unwrap();
    let info = b.info().unwrap();
    assert!(
        (info.mass - 24.0).abs() < 1e-4,
        "3 × 2³ = 24, got {}",
        info.mass
    );
    assert!((info.density - 3.0).abs() < 1e-6);
    b.apply_impulse([24.0, 0.0, 0.0]).unwrap();
    scene.run(0.01, 1);
    assert!((b.velocity().unwrap()[0] - 1.0).abs() < 1e-4);
    // Back to Weight.
    b.set_density(0.0).unwrap();
    assert_eq!(b.info().unwrap().mass, 5.0);
    // Resizing keeps the density and changes the mass.
    b.set_density(3.0).unwrap();
    b.set_size([1.0, 1.0, 1.0]).unwrap();
    assert!((b.info().unwrap().mass - 3.0).abs() < 1e-4);
}

/// Drops a ball from `h0` above the floor and returns the apex height of the first bounce.
fn first_bounce(e_ball: f32, e_floor: f32, threshold: Option<f32>) -> f32 {
    let scene = Scene::new(
        "bounce",
        PlaneOptions {
            rest_threshold: threshold,
            ..no_damping()
        },
    );
    let floor = scene.floor();
    floor.set_bounciness(e_floor).unwrap();
    let h0 = 10.0;
    let b = sphere(
        &scene,
        0.5,
        [0.0, h0 + 0.5, 0.0],
        &[ObjectProp::Bounciness(e_ball)],
    );
    let mut rising = false;
    let mut apex = 0.0f32;
    for _ in 0..(240 * 3) {
        scene.plane.step(1.0 / 240.0).unwrap();
        let s = b.state().unwrap();
        if s.linear_velocity[1] > 0.0 {
            rising = true;
        }
        if rising {
            apex = apex.max(s.position[1] - 0.5);
            if s.linear_velocity[1] < 0.0 {
                break;
            }
        }
    }
    apex
}

#[test]
fn bounciness_sets_the_bounce_height_ratio_and_the_pair_uses_the_higher() {
    // Restitution e reflects the impact speed times e: the apex is e²·h0.
    let e = 0.7f32;
    let apex = first_bounce(e, 0.0, None);
    let ratio = apex / 10.0;
    assert!(
        (ratio - e * e).abs() < 0.05 * e * e,
        "h1/h0 = {ratio}, e² = {}",
        e * e
    );
    // A dead ball on a bouncy floor bounces with the floor's value.
    let apex = first_bounce(0.0, e, None);
    assert!(
        (apex / 10.0 - e * e).abs() < 0.05 * e * e,
        "h1/h0 = {}",
        apex / 10.0
    );
    // Nothing bouncy: no rebound worth the name.
    assert!(first_bounce(0.0, 0.0, None) < 0.01);
}

#[test]
fn rest_threshold_stops_slow_contacts_from_bouncing() {
    // Zero gravity, a ball approaching the floor at 0.4 u/s with Bounciness 1.
    let run = |threshold: f32| {
        let scene = Scene::new(
            "rest",
            PlaneOptions {
                rest_threshold: Some(threshold),
                ..zero_gravity()
            },
        );
        scene.floor();
        let b = sphere(
            &scene,
            0.5,
            [0.0, 0.6, 0.0],
            &[
                ObjectProp::Bounciness(1.0),
                ObjectProp::Velocity([0.0, -0.4, 0.0]),
            ],
        );
        scene.run(1.0 / 60.0, 60);
        b.velocity().unwrap()[1]
    };
    let below = run(0.5);
    assert!(below.abs() < 0.02, "0.4 < 0.5: no bounce, vy={below}");
    let above = run(0.3);
    assert!(
        (above - 0.4).abs() < 0.04,
        "0.4 > 0.3: reflected, vy={above}"
    );
    // Billiard mode: 0 always reflects.
    let zero = run(0.0);
    assert!((zero - 0.4).abs() < 0.04, "vy={zero}");
}

/// A block on an anchored slope of angle `theta`: returns its displacement and its
/// acceleration along the slope over one second, after a quarter second to settle.
fn slide_on_slope(theta: f32, mu_block: f32, mu_slope: f32) -> (f32, f32) {
    let scene = Scene::new("slope", no_damping());
    let rot = quat([0.0, 0.0, 1.0], theta);
    let slope = scene.anchored_box(
        [40.0, 1.0, 10.0],
        Pose {
            position: [0.0; 3],
            rotation: rot,
        },
    );
    slope.set_friction(mu_slope).unwrap();
    // Up the slope's normal by half the slope and half the block (no contact skins).
    let (s, c) = theta.sin_cos();
    let lift = 0.5 + 0.5;
    let block = scene
        .plane
        .add(
            Shape::Cube { size: [1.0; 3] },
            Pose {
                position: [-s * lift, c * lift, 0.0],
                rotation: rot,
            },
            &[ObjectProp::Friction(mu_block)],
        )
        .unwrap();
    scene.run(1.0 / 120.0, 30);
    let (p0, v0) = (block.position().unwrap(), block.velocity().unwrap());
    scene.run(1.0 / 120.0, 120);
    let (p1, v1) = (block.position().unwrap(), block.velocity().unwrap());
    let norm = |a: [f32; 3], b: [f32; 3]| ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)).sqrt();
    (norm(p1, p0), norm(v1, v0))
}

#[test]
fn friction_holds_a_block_on_a_slope_or_lets_it_slide_at_the_coulomb_rate() {
    let theta = 30f32.to_radians(); // tan θ = 0.577
                                    // μ = 1 > tan θ: holds.
    let (held, _) = slide_on_slope(theta, 1.0, 1.0);
    assert!(held < 0.01, "high friction slid {held}");
    // μ = 0.2: slides with a = g(sin θ − μ cos θ).
    let expected = G * (theta.sin() - 0.2 * theta.cos());
    let (_, a) = slide_on_slope(theta, 0.2, 0.2);
    assert!(
        (a - expected).abs() < 0.02 * expected,
        "a = {a}, Coulomb {expected}"
    );
    // The pair uses sqrt(a·b): 1.0 on 0.04 acts like 0.2 on 0.2.
    let (_, mixed) = slide_on_slope(theta, 1.0, 0.04);
    assert!((mixed - expected).abs() < 0.02 * expected, "a = {mixed}");
}

#[test]
fn anchored_parts_never_move_and_anchoring_zeroes_velocity() {
    let scene = Scene::new("anchor", PlaneOptions::default());
    let a = cube(&scene, 1.0, [0.0, 5.0, 0.0], &[ObjectProp::Anchored(true)]);
    let b = cube(&scene, 1.0, [0.0, 7.0, 0.0], &[]);
    a.apply_impulse([100.0, 100.0, 0.0]).unwrap();
    scene.run(1.0 / 60.0, 120);
    assert_eq!(a.position().unwrap(), [0.0, 5.0, 0.0]);
    assert_eq!(a.velocity().unwrap(), [0.0; 3]);
    // b landed on it: top of a (5.5) + half of b (no skins).
    let yb = b.position().unwrap()[1];
    assert!(
        (yb - 6.0).abs() < 0.02,
        "b rests on the anchored part: {yb}"
    );
    b.set_velocity([3.0, 0.0, 0.0]).unwrap();
    b.set_anchored(true).unwrap();
    scene.run(1.0 / 60.0, 10);
    assert_eq!(b.velocity().unwrap(), [0.0; 3]);
    assert!((b.position().unwrap()[1] - yb).abs() < 1e-6);
}

#[test]
fn can_collide_false_passes_through_the_floor() {
    let scene = Scene::new("ghost", no_damping());
    scene.floor();
    let ghost = sphere(
        &scene,
        0.5,
        [0.0, 2.0, 0.0],
        &[ObjectProp::CanCollide(false)],
    );
    let solid = sphere(&scene, 0.5, [3.0, 2.0, 0.0], &[]);
    scene.run(1.0 / 60.0, 60);
    // Free fall for 1 s from 2: y = 2 − 25 (minus the integrator's lag).
    assert!(ghost.position().unwrap()[1] < -20.0);
    assert!((solid.position().unwrap()[1] - 0.5).abs() < 0.02);
    assert!(!ghost.info().unwrap().can_collide);
}

#[test]
fn size_resizes_the_collider() {
    let scene = Scene::new("size", PlaneOptions::default());
    scene.floor();
    let b = cube(&scene, 1.0, [0.0, 0.52, 0.0], &[]);
    let s = sphere(&scene, 0.5, [5.0, 0.52, 0.0], &[]);
    scene.run(1.0 / 60.0, 30);
    assert!((b.position().unwrap()[1] - 0.5).abs() < 0.01);
    b.set_size([3.0, 3.0, 3.0]).unwrap();
    // A sphere's radius is half the smallest side.
    s.set_size([4.0, 2.0, 6.0]).unwrap();
    scene.run(1.0 / 60.0, 120);
    let yb = b.position().unwrap()[1];
    let ys = s.position().unwrap()[1];
    assert!((yb - 1.5).abs() < 0.02, "resized cube rests at {yb}");
    assert!((ys - 1.0).abs() < 0.02, "resized sphere rests at {ys}");
    assert_eq!(s.info().unwrap().size, [4.0, 2.0, 6.0]);
}

#[test]
fn hit_box_quality_locks_rotation_at_one_tightens_contacts_and_enables_ccd() {
    let scene = Scene::new("quality", PlaneOptions::default());
    let floor = scene.floor();
    let low = cube(&scene, 1.0, [0.0, 3.0, 0.0], &[]);
    let info = low.info().unwrap();
    assert!(info.rotation_locked_by_quality && !info.ccd);
    let ball = sphere(&scene, 0.5, [5.0, 3.0, 0.0], &[]);
    assert!(!ball.info().unwrap().rotation_locked_by_quality);
    // One quality-32 part scales the whole plane's solver (×2.5).
    assert_eq!(scene.plane.info().unwrap().effective_solver_iterations, 4);
    floor.set_hit_box_quality(32).unwrap();
    ball.set_hit_box_quality(32).unwrap();
    let plane = scene.plane.info().unwrap();
    assert_eq!(plane.max_hit_box_quality, 32);
    assert_eq!(plane.effective_solver_iterations, 10);
    assert!(ball.info().unwrap().ccd);
    // No contact skins at any quality: both rest touching the floor.
    scene.run(1.0 / 60.0, 120);
    let y_ball = ball.position().unwrap()[1];
    assert!((y_ball - 0.5).abs() < 0.003, "tight contact: {y_ball}");
    let y_low = low.position().unwrap()[1];
    assert!((y_low - 0.5).abs() < 0.005, "quality-1 contact: {y_low}");
    // Clamped to [1, 32].
    low.set_hit_box_quality(1000).unwrap();
    assert_eq!(low.info().unwrap().hit_box_quality, 32);
    floor.set_hit_box_quality(1).unwrap();
    ball.set_hit_box_quality(1).unwrap();
    low.set_hit_box_quality(0).unwrap();
    assert_eq!(low.info().unwrap().hit_box_quality, 1);
    assert_eq!(scene.plane.info().unwrap().max_hit_box_quality, 1);
}

/// A unit cube resting 70 % on a ledge whose edge is x = 0; returns its largest tilt
/// over 1 s (a box that tips goes past 0.5 rad within 0.3 s).
fn tilt_on_ledge(props: &[ObjectProp]) -> f32 {
    let scene = Scene::new("ledge", no_damping());
    scene.anchored_box([10.0, 1.0, 10.0], Pose::at([-5.0, -0.5, 0.0]));
    let b = cube(&scene, 1.0, [-0.3, 0.52, 0.0], props);
    let mut tilt = 0.0f32;
    for _ in 0..120 {
        scene.plane.step(1.0 / 120.0).unwrap();
        tilt = tilt.max(angle_between(
            b.pose().unwrap().rotation,
            [0.0, 0.0, 0.0, 1.0],
        ));
    }
    tilt
}

#[test]
fn center_of_mass_beyond_the_edge_tips_the_box() {
    // CoM at x = −0.3 + 0.4 = +0.1, past the edge: it tips over.
    let tipped = tilt_on_ledge(&[ObjectProp::CenterOfMass([0.4, 0.0, 0.0])]);
    assert!(tipped > 0.5, "tilt {tipped} rad");
    // CoM over the ledge: stays flat.
    let inside = tilt_on_ledge(&[ObjectProp::CenterOfMass([-0.2, 0.0, 0.0])]);
    assert!(inside < 0.02, "tilt {inside} rad");
    // No CoM at quality 1: rotation locked, it does not tip even though 30 % overhangs...
    assert!(tilt_on_ledge(&[]) < 1e-3);
    // ...and with real rotation (quality 2) a balanced box over 70 % of support stays.
    assert!(tilt_on_ledge(&[ObjectProp::HitBoxQuality(2)]) < 0.02);
}

#[test]
fn impulse_direction_is_a_mass_independent_acceleration_and_constant_force_is_a_force() {
    let scene = Scene::new("drive", zero_gravity());
    let a = sphere(
        &scene,
        0.5,
        [0.0; 3],
        &[ObjectProp::ImpulseDirection([0.0, 5.0, 0.0])],
    );
    let b = sphere(
        &scene,
        0.5,
        [5.0, 0.0, 0.0],
        &[
            ObjectProp::Weight(10.0),
            ObjectProp::ImpulseDirection([0.0, 5.0, 0.0]),
        ],
    );
    let c = sphere(
        &scene,
        0.5,
        [10.0, 0.0, 0.0],
        &[
            ObjectProp::Weight(2.0),
            ObjectProp::ConstantForce([0.0, 10.0, 0.0]),
        ],
    );
    scene.run(1.0 / 60.0, 60);
    for (o, v) in [(&a, 5.0), (&b, 5.0), (&c, 5.0)] {
        let vy = o.velocity().unwrap()[1];
        assert!((vy - v).abs() < 1e-3, "vy={vy}, expected {v}");
    }
    a.set_impulse_direction([0.0; 3]).unwrap();
    scene.run(1.0 / 60.0, 30);
    assert!(
        (a.velocity().unwrap()[1] - 5.0).abs() < 1e-3,
        "cleared: constant speed"
    );
    assert_eq!(c.info().unwrap().constant_force, [0.0, 10.0, 0.0]);
}

#[test]
fn cframe_write_teleports_and_velocities_read_back() {
    let scene = Scene::new("cframe", zero_gravity());
    let b = cube(&scene, 1.0, [0.0; 3], &[]);
    let rot = quat([0.0, 1.0, 0.0], 1.0);
    b.set_pose(Pose {
        position: [3.0, 4.0, 5.0],
        rotation: rot,
    })
    .unwrap();
    b.set_velocity([1.0, 0.0, 0.0]).unwrap();
    b.set_angular_velocity([0.0, 0.5, 0.0]).unwrap();
    // Read-your-writes before the daemon saw them...
    assert_eq!(b.position().unwrap(), [3.0, 4.0, 5.0]);
    scene.run(0.1, 10);
    // ...and the simulation continues from there (direct rotation works on a quality-1 cube).
    let p = b.position().unwrap();
    assert!(
        (p[0] - 4.0).abs() < 1e-4 && p[1] == 4.0 && p[2] == 5.0,
        "{p:?}"
    );
    let turned = angle_between(b.pose().unwrap().rotation, rot);
    assert!((turned - 0.5).abs() < 1e-3, "turned {turned}");
    assert_eq!(b.info().unwrap().shape, ShapeKind::Cube);
}

#[test]
fn continuous_collision_above_quality_one_stops_a_bullet_at_a_thin_wall() {
    // 300 u/s at 60 Hz travels 5 units a tick: 50 times the wall's thickness. The wall is a
    // heavy dynamic body: fast bodies are swept against moving ones when either side has
    // HitBoxQuality > 1, or (at quality 1) when they move more than the soft-CCD reach (2
    // units) in a tick, so both stop here (quality 1 used to tunnel).
    let run = |quality: u32| {
        let scene = Scene::new("bullet", zero_gravity());
        cube(&scene, 1.0, [0.0; 3], &[ObjectProp::Weight(1000.0)])
            .set_size([0.1, 10.0, 10.0])
            .unwrap();
        let b = sphere(
            &scene,
            0.1,
            [-3.0, 0.0, 0.0],
            &[
                ObjectProp::HitBoxQuality(quality),
                ObjectProp::Velocity([300.0, 0.0, 0.0]),
            ],
        );
        scene.run(1.0 / 60.0, 10);
        b.position().unwrap()[0]
    };
    let x = run(4);
    assert!(x < 0.0, "quality 4 tunnelled to x={x}");
    let x = run(1);
    assert!(x < 0.0, "quality 1 at 5 units a tick tunnelled to x={x}");
}

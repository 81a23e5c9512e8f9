//! The 2D GUI plane through a real daemon, with numbers: free fall in pixels against the
//! closed form, bounce apex ratio e², friction slide distance v0²/(2μg), ZIndex layers,
//! bounds, GravityScale, locks, sleep after 0.5 s below RestThreshold, Raycast, and the
//! controller (MoveSpeed reached at Acceleration, jumps only on the ground, waypoints in
//! order with PathFinished once).

// Named, persistent and rewound GUI planes.
mod named;

use client_sdk::{
    Client, GuiControllerProp, GuiEvent, GuiObject, GuiObjectProp as P, GuiPlane, GuiPlaneOptions,
    GuiShape,
};
use integration_tests::TestDaemon;

const DT: f32 = 1.0 / 60.0;

fn gui_plane(client: &Client, options: GuiPlaneOptions) -> GuiPlane {
    client.create_gui_plane(&options).unwrap()
}

/// A manual plane without damping (so closed forms apply).
fn undamped() -> GuiPlaneOptions {
    GuiPlaneOptions {
        linear_damping: Some(0.0),
        angular_damping: Some(0.0),
        ..GuiPlaneOptions::manual()
    }
}

fn floor(plane: &GuiPlane, y_top: f32, z: i32) -> GuiObject {
    plane
        .add(
            GuiShape::Square,
            [4000.0, 40.0],
            [0.0, y_top + 20.0],
            &[P::Anchored(true), P::ZIndex(z), P::Friction(0.5)],
        )
        .unwrap()
}

fn run(plane: &GuiPlane, n: u32) {
    for _ in 0..n {
        plane.step(DT).unwrap();
    }
}

#[test]
fn free_fall_in_pixels_follows_the_closed_form() {
    let daemon = TestDaemon::start("gui-fall");
    let client = daemon.client();
    let plane = gui_plane(&client, undamped());
    let y0 = 100.0;
    let ball = plane
        .add(GuiShape::Circle, [32.0, 32.0], [200.0, y0], &[])
        .unwrap();
    let g = 980.0f32;
    let mut worst = 0.0f32;
    for n in 1..=60u32 {
        plane.step(DT).unwrap();
        let t = n as f32 * DT;
        let [x, y] = ball.position().unwrap();
        let exact = y0 + 0.5 * g * t * t;
        // Semi-implicit Euler leads the parabola by at most g·h·t/2.
        let bound = 0.5 * g * DT * t + 1e-3 * n as f32;
        assert!((y - exact).abs() <= bound, "t={t}: y={y} exact={exact}");
        assert!(
            (ball.velocity().unwrap()[1] - g * t).abs() < 0.05,
            "vy at {t}"
        );
        assert_eq!(x, 200.0);
        worst = worst.max((y - exact).abs());
    }
    println!("free fall 1 s at 60 Hz: worst |y - (y0 + g t²/2)| = {worst:.3} px");
    let info = plane.info().unwrap();
    assert_eq!(info.gravity, [0.0, 980.0]);
    assert_eq!(info.object_count, 1);
    assert_eq!(
        plane.plane().info().unwrap().kind,
        client_sdk::PlaneKind::Gui2d
    );
}

#[test]
fn bounce_apex_ratio_is_e_squared() {
    let daemon = TestDaemon::start("gui-bounce");
    let client = daemon.client();
    let plane = gui_plane(&client, undamped());
    floor(&plane, 500.0, 0);
    let r = 10.0;
    let e = 0.8f32;
    let ball = plane
        .add(
            GuiShape::Circle,
            [2.0 * r, 2.0 * r],
            [0.0, 100.0],
            &[P::Bounciness(e)],
        )
        .unwrap();
    let h0 = 500.0 - r - 100.0;
    // Track apexes: the highest points between bounces (smallest y).
    let mut apexes = Vec::new();
    let mut prev_vy = 0.0f32;
    for _ in 0..(240 * 6) {
        plane.step(1.0 / 240.0).unwrap();
        let vy = ball.velocity().unwrap()[1];
        if prev_vy < 0.0 && vy >= 0.0 {
            apexes.push(500.0 - r - ball.position().unwrap()[1]);
        }
        prev_vy = vy;
        if apexes.len() == 2 {
            break;
        }
    }
    assert!(apexes.len() == 2, "apexes {apexes:?}");
    let ratio1 = apexes[0] / h0;
    let ratio2 = apexes[1] / apexes[0];
    println!(
        "bounce e={e}: h1/h0 = {ratio1:.4}, h2/h1 = {ratio2:.4} (e² = {:.4})",
        e * e
    );
    assert!((ratio1 - e * e).abs() < 0.03, "h1/h0 = {ratio1}");
    assert!((ratio2 - e * e).abs() < 0.04, "h2/h1 = {ratio2}");
}

#[test]
fn friction_slide_distance_matches_v0_squared_over_2_mu_g() {
    let daemon = TestDaemon::start("gui-slide");
    let client = daemon.client();
    let plane = gui_plane(&client, undamped());
    floor(&plane, 500.0, 0);
    let block = plane
        .add(
            GuiShape::Square,
            [20.0, 20.0],
            [0.0, 490.0],
            &[P::Friction(0.5)],
        )
        .unwrap();
    run(&plane, 30); // settle
    let x0 = block.position().unwrap()[0];
    let v0 = 300.0f32;
    block.set(P::Velocity([v0, 0.0])).unwrap();
    run(&plane, 120);
    let d = block.position().unwrap()[0] - x0;
    let expected = v0 * v0 / (2.0 * 0.5 * 980.0);
    println!("slide: d = {d:.2} px, v0²/(2μg) = {expected:.2} px");
    assert!(
        (d - expected).abs() / expected < 0.05,
        "d {d} vs {expected}"
    );
    assert!(block.velocity().unwrap()[0].abs() < 1.0);
    assert!(
        block.rotation().unwrap().abs() < 0.5,
        "the block does not tip"
    );
}

#[test]
fn zindex_is_the_collision_layer() {
    let daemon = TestDaemon::start("gui-layers");
    let client = daemon.client();
    let plane = gui_plane(&client, undamped());
    floor(&plane, 500.0, 0);
    let same = plane
        .add(GuiShape::Square, [20.0, 20.0], [0.0, 400.0], &[])
        .unwrap();
    let other = plane
        .add(
            GuiShape::Square,
            [20.0, 20.0],
            [100.0, 400.0],
            &[P::ZIndex(100)],
        )
        .unwrap();
    run(&plane, 60);
    let y_same = same.position().unwrap()[1];
    let y_other = other.position().unwrap()[1];
    assert!(
        (y_same - 490.0).abs() < 1.0,
        "same layer rests on the floor: {y_same}"
    );
    assert!(y_other > 600.0, "another layer passes through: {y_other}");
    // Changing ZIndex takes effect at the next tick: a body on layer 100 moved back to 0 on
    // top of the floor lands.
    other.set(P::Position([100.0, 400.0])).unwrap();
    other.set(P::Velocity([0.0, 0.0])).unwrap();
    other.set(P::ZIndex(0)).unwrap();
    run(&plane, 60);
    assert!((other.position().unwrap()[1] - 490.0).abs() < 1.0);
    assert_eq!(other.info().unwrap().z_index, 0);
}

#[test]
fn bounds_keep_bodies_inside_and_bounce_with_their_own_bounciness() {
    let daemon = TestDaemon::start("gui-bounds");
    let client = daemon.client();
    let plane = gui_plane(
        &client,
        GuiPlaneOptions {
            gravity: Some([0.0, 0.0]),
            bounds: Some(([0.0, 0.0], [400.0, 300.0])),
            ..undamped()
        },
    );
    let r = 10.0;
    let ball = plane
        .add(
            GuiShape::Circle,
            [2.0 * r, 2.0 * r],
            [200.0, 150.0],
            &[P::Bounciness(1.0), P::Velocity([3000.0, 0.0])],
        )
        .unwrap();
    let mut max_x = 0.0f32;
    let mut bounced = false;
    for _ in 0..30 {
        plane.step(DT).unwrap();
        let [x, y] = ball.position().unwrap();
        max_x = max_x.max(x);
        // Contacts are soft: a body at 3,000 px/s presses into the wall by under 1.5 px.
        assert!((r - 1.5..=400.0 - r + 1.5).contains(&x), "x {x} outside");
        assert!((y - 150.0).abs() < 0.5);
        bounced |= ball.velocity().unwrap()[0] < 0.0;
    }
    assert!(bounced);
    let v = ball.velocity().unwrap()[0].abs();
    println!("bounds: fastest x {max_x:.2}, |vx| after bounces {v:.1} (3000 launched, e = 1)");
    assert!((v - 3000.0).abs() < 30.0, "e = 1 keeps the speed: {v}");
    // An inelastic body stops at the wall.
    let dead = plane
        .add(
            GuiShape::Square,
            [20.0, 20.0],
            [200.0, 100.0],
            &[P::Velocity([-500.0, 0.0])],
        )
        .unwrap();
    run(&plane, 60);
    assert!((dead.position().unwrap()[0] - 10.0).abs() < 0.5);
    assert!(dead.velocity().unwrap()[0].abs() < 1.0);
    // Bounds are construction-only.
    assert!(plane
        .set(client_sdk::GuiPlaneProp::Bounds {
            min: [0.0, 0.0],
            max: [10.0, 10.0]
        })
        .and_then(|_| client.flush())
        .is_err());
}

#[test]
fn gravity_scale_and_locks() {
    let daemon = TestDaemon::start("gui-locks");
    let client = daemon.client();
    let plane = gui_plane(&client, undamped());
    let floater = plane
        .add(
            GuiShape::Circle,
            [20.0, 20.0],
            [0.0, 100.0],
            &[P::GravityScale(0.0)],
        )
        .unwrap();
    let double = plane
        .add(
            GuiShape::Circle,
            [20.0, 20.0],
            [100.0, 100.0],
            &[P::GravityScale(2.0)],
        )
        .unwrap();
    let normal = plane
        .add(GuiShape::Circle, [20.0, 20.0], [200.0, 100.0], &[])
        .unwrap();
    let locked_x = plane
        .add(
            GuiShape::Square,
            [20.0, 20.0],
            [300.0, 100.0],
            &[P::LockedX(true), P::Velocity([100.0, 0.0])],
        )
        .unwrap();
    let locked_y = plane
        .add(
            GuiShape::Square,
            [20.0, 20.0],
            [400.0, 100.0],
            &[P::LockedY(true), P::Velocity([100.0, 0.0])],
        )
        .unwrap();
    let locked_rot = plane
        .add(
            GuiShape::Triangle,
            [20.0, 20.0],
            [500.0, 100.0],
            &[P::LockedRotation(true), P::AngularVelocity(90.0)],
        )
        .unwrap();
    let spinner = plane
        .add(
            GuiShape::Triangle,
            [20.0, 20.0],
            [600.0, 100.0],
            &[P::AngularVelocity(90.0), P::GravityScale(0.0)],
        )
        .unwrap();
    run(&plane, 60);
    assert_eq!(floater.position().unwrap(), [0.0, 100.0]);
    let fall = normal.position().unwrap()[1] - 100.0;
    let fall2 = double.position().unwrap()[1] - 100.0;
    assert!((fall2 / fall - 2.0).abs() < 1e-3, "{fall2} vs {fall}");
    let [x, y] = locked_x.position().unwrap();
    assert_eq!(x, 300.0);
    assert!((y - 100.0 - fall).abs() < 1e-2);
    let [x, y] = locked_y.position().unwrap();
    assert_eq!(y, 100.0);
    assert!((x - 500.0).abs() < 0.1, "x {x}");
    assert_eq!(locked_rot.rotation().unwrap(), 0.0);
    let turned = spinner.rotation().unwrap();
    println!("rotation after 1 s at 90°/s: {turned:.3}°");
    assert!((turned - 90.0).abs() < 1.0, "{turned}");
}

#[test]
fn sleeps_after_half_a_second_below_rest_threshold_and_wakes_on_write() {
    let daemon = TestDaemon::start("gui-sleep");
    let client = daemon.client();
    let plane = gui_plane(&client, GuiPlaneOptions::manual());
    floor(&plane, 500.0, 0);
    let block = plane
        .add(GuiShape::Square, [20.0, 20.0], [0.0, 489.9], &[])
        .unwrap();
    let mut slept_at = None;
    for n in 1..=120u32 {
        plane.step(DT).unwrap();
        if block.is_sleeping().unwrap() {
            slept_at = Some(n as f32 * DT);
            break;
        }
    }
    let t = slept_at.expect("the resting block falls asleep");
    println!("resting block slept after {t:.3} s (0.5 s below RestThreshold)");
    assert!((0.45..=0.7).contains(&t), "slept at {t}");
    block.set(P::Velocity([0.0, -100.0])).unwrap();
    plane.step(DT).unwrap();
    assert!(!block.is_sleeping().unwrap());
    assert!(block.position().unwrap()[1] < 489.0);
    // RestThreshold 0 disables sleeping.
    let awake = gui_plane(
        &client,
        GuiPlaneOptions {
            rest_threshold: Some(0.0),
            ..GuiPlaneOptions::manual()
        },
    );
    floor(&awake, 500.0, 0);
    let b = awake
        .add(GuiShape::Square, [20.0, 20.0], [0.0, 489.9], &[])
        .unwrap();
    run(&awake, 90);
    assert!(!b.is_sleeping().unwrap());
}

#[test]
fn raycast_hits_across_layers_with_distance_normal_and_object() {
    let daemon = TestDaemon::start("gui-ray");
    let client = daemon.client();
    let plane = gui_plane(&client, GuiPlaneOptions::manual());
    let near = plane
        .add(
            GuiShape::Square,
            [40.0, 40.0],
            [300.0, 100.0],
            &[P::Anchored(true), P::ZIndex(7)],
        )
        .unwrap();
    let far = plane
        .add(
            GuiShape::Circle,
            [40.0, 40.0],
            [500.0, 100.0],
            &[P::Anchored(true)],
        )
        .unwrap();
    let ghost = plane
        .add(
            GuiShape::Square,
            [40.0, 40.0],
            [200.0, 100.0],
            &[P::Anchored(true), P::CanCollide(false)],
        )
        .unwrap();
    let hit = plane
        .raycast([0.0, 100.0], [2.0, 0.0], None)
        .unwrap()
        .unwrap();
    assert_eq!(hit.handle, near.handle());
    assert!((hit.distance - 280.0).abs() < 1e-3, "{hit:?}");
    assert!((hit.position[0] - 280.0).abs() < 1e-3);
    assert_eq!(hit.normal, [-1.0, 0.0]);
    // Past the square: the circle, from its far side.
    let hit = plane
        .raycast([1000.0, 100.0], [-1.0, 0.0], Some(600.0))
        .unwrap()
        .unwrap();
    assert_eq!(hit.handle, far.handle());
    assert!((hit.distance - 480.0).abs() < 1e-3);
    assert!((hit.normal[0] - 1.0).abs() < 1e-4);
    // Out of reach, and a CanCollide = false body is not seen.
    assert!(plane
        .raycast([1000.0, 100.0], [-1.0, 0.0], Some(100.0))
        .unwrap()
        .is_none());
    let _ = ghost;
    // A body moved by an op is seen by the next ray without a step.
    near.set(P::Position([300.0, 400.0])).unwrap();
    let hit = plane
        .raycast([300.0, 0.0], [0.0, 1.0], None)
        .unwrap()
        .unwrap();
    assert_eq!(hit.handle, near.handle());
    assert!((hit.distance - 380.0).abs() < 1e-3);
    // Bad input names the field.
    let err = plane.raycast([0.0, 0.0], [0.0, 0.0], None).unwrap_err();
    assert!(err.to_string().contains("dir"), "{err}");
}

#[test]
fn controller_reaches_move_speed_at_its_acceleration_and_jumps_only_on_the_ground() {
    let daemon = TestDaemon::start("gui-ctrl");
    let client = daemon.client();
    let plane = gui_plane(&client, undamped());
    floor(&plane, 500.0, 0);
    let body = plane
        .add(GuiShape::Square, [32.0, 32.0], [0.0, 300.0], &[])
        .unwrap();
    let ctrl = plane.new_controller(&body, false, &[]).unwrap();
    // Falling: a jump request is dropped.
    ctrl.jump().unwrap();
    plane.step(DT).unwrap();
    assert!(body.velocity().unwrap()[1] > 0.0, "no jump in the air");
    run(&plane, 60);
    assert!(ctrl.info().unwrap().on_ground);
    assert_eq!(body.rotation().unwrap(), 0.0);
    ctrl.move_direction([1.0, 0.0]).unwrap();
    let mut vs = Vec::new();
    for _ in 0..12 {
        plane.step(DT).unwrap();
        vs.push(body.velocity().unwrap()[0]);
    }
    // 1800 px/s² → 30 px/s per tick, capped at 240 after 8 ticks.
    for (i, v) in vs.iter().enumerate() {
        let expected = (30.0 * (i + 1) as f32).min(240.0);
        assert!(
            (v - expected).abs() < 0.5,
            "tick {}: vx {v}, expected {expected}",
            i + 1
        );
    }
    println!("controller vx per tick: {vs:?}");
    ctrl.move_direction([0.0, 0.0]).unwrap();
    ctrl.jump().unwrap();
    plane.step(DT).unwrap();
    let vy = body.velocity().unwrap()[1];
    // Δv = -700 / mass, then one tick of gravity.
    assert!((vy - (-700.0 + 980.0 * DT)).abs() < 1.0, "vy {vy}");
    // Mid-air: no second jump.
    run(&plane, 5);
    let before = body.velocity().unwrap()[1];
    ctrl.jump().unwrap();
    plane.step(DT).unwrap();
    assert!((body.velocity().unwrap()[1] - before - 980.0 * DT).abs() < 0.5);
    // MoveSpeed and Acceleration change at run time.
    run(&plane, 120);
    ctrl.set(GuiControllerProp::MoveSpeed(60.0)).unwrap();
    ctrl.move_direction([-3.0, 0.0]).unwrap();
    run(&plane, 30);
    assert!((body.velocity().unwrap()[0] + 60.0).abs() < 0.5);
    // Landing and leaving the ground fired GroundChanged in order.
    let (events, lost) = plane.events().unwrap();
    assert_eq!(lost, 0);
    let _ = events;
}

#[test]
fn waypoints_are_followed_in_order_and_path_finished_fires_once() {
    let daemon = TestDaemon::start("gui-path");
    let client = daemon.client();
    let plane = gui_plane(
        &client,
        GuiPlaneOptions {
            gravity: Some([0.0, 0.0]),
            ..undamped()
        },
    );
    plane.plane().subscribe_events().unwrap();
    let enemy = plane
        .add(GuiShape::Square, [32.0, 32.0], [100.0, 300.0], &[])
        .unwrap();
    let npc = plane
        .new_controller(&enemy, true, &[GuiControllerProp::MoveSpeed(160.0)])
        .unwrap();
    let path = [
        [100.0, 300.0],
        [800.0, 300.0],
        [800.0, 500.0],
        [100.0, 500.0],
    ];
    npc.set_waypoints(&path).unwrap();
    let mut reached = Vec::new();
    let mut finished = 0;
    let mut moved = [0.0f32; 2];
    let mut finished_at = 0.0;
    for n in 0..(60 * 15) {
        plane.step(DT).unwrap();
        let (events, lost) = plane.events().unwrap();
        assert_eq!(lost, 0);
        for e in events {
            match e {
                GuiEvent::WaypointReached { index, .. } => {
                    assert_eq!(finished, 0);
                    reached.push(index);
                }
                GuiEvent::PathFinished { .. } => {
                    finished += 1;
                    finished_at = (n + 1) as f32 * DT;
                }
                GuiEvent::Moved { dx, dy, .. } => {
                    moved[0] += dx.abs();
                    moved[1] += dy.abs();
                }
                GuiEvent::GroundChanged { .. } => {}
            }
        }
    }
    assert_eq!(reached, vec![1, 2, 3, 4]);
    assert_eq!(finished, 1);
    // 700 + 200 + 700 px at 160 px/s ≈ 10 s (plus acceleration at the corners).
    println!("path of 1600 px at 160 px/s finished after {finished_at:.2} s; Moved sums {moved:?}");
    assert!((10.0..11.0).contains(&finished_at), "{finished_at}");
    assert!((moved[0] - 1400.0).abs() < 20.0 && (moved[1] - 200.0).abs() < 20.0);
    let [x, y] = enemy.position().unwrap();
    assert!(
        (x - 100.0).abs() <= 8.0 && (y - 500.0).abs() <= 8.0,
        "{x} {y}"
    );
    let info = npc.info().unwrap();
    assert_eq!(info.waypoints.len(), 4);
    assert!(info.uncontrolled);
}

#[test]
fn bad_input_is_refused_with_the_field_named() {
    let daemon = TestDaemon::start("gui-bad");
    let client = daemon.client();
    let plane = gui_plane(&client, GuiPlaneOptions::manual());
    let o = plane
        .add(GuiShape::Square, [20.0, 20.0], [0.0, 0.0], &[])
        .unwrap();
    let e = o.set(P::Velocity([f32::NAN, 0.0])).unwrap_err();
    assert!(e.to_string().contains("Velocity.X"), "{e}");
    let e = o.set(P::Friction(9.0)).unwrap_err();
    assert!(e.to_string().contains("Friction"), "{e}");
    let e = plane
        .add(GuiShape::Circle, [0.0, 20.0], [0.0, 0.0], &[])
        .unwrap_err();
    assert!(e.to_string().contains("Size.X"), "{e}");
    // Stale handles.
    o.destroy();
    client.flush().unwrap();
    let e = o.info().unwrap_err();
    assert!(
        e.to_string().contains("no longer") || e.to_string().contains("stale"),
        "{e}"
    );
    // 3D ops on a GUI plane, and GUI ops on a 3D plane, are refused.
    let p3 = client
        .create_plane(&client_sdk::PlaneOptions::manual())
        .unwrap();
    let e = plane
        .plane()
        .add(
            client_sdk::Shape::Sphere { radius: 1.0 },
            client_sdk::Pose::IDENTITY,
            &[],
        )
        .unwrap_err();
    assert!(e.to_string().contains("GUI"), "{e}");
    let e = plane
        .set_common(client_sdk::PlaneProp::Buoyancy(1.0))
        .and_then(|_| client.flush())
        .unwrap_err();
    assert!(e.to_string().contains("Buoyancy"), "{e}");
    let _ = p3;
    // The daemon still serves.
    plane.step(DT).unwrap();
}

#[test]
fn triangles_and_circles_rest_on_their_real_shapes() {
    let daemon = TestDaemon::start("gui-shapes");
    let client = daemon.client();
    let plane = gui_plane(&client, undamped());
    floor(&plane, 500.0, 0);
    let tri = plane
        .add(GuiShape::Triangle, [40.0, 30.0], [0.0, 400.0], &[])
        .unwrap();
    // A circle of Size (40, 20) is a disc of diameter 20.
    let disc = plane
        .add(GuiShape::Circle, [40.0, 20.0], [100.0, 400.0], &[])
        .unwrap();
    run(&plane, 90);
    let [_, y] = tri.position().unwrap();
    assert!((y - 485.0).abs() < 0.5, "triangle box centre {y}");
    assert!(tri.rotation().unwrap().abs() < 0.5);
    assert!((disc.position().unwrap()[1] - 490.0).abs() < 0.5);
}

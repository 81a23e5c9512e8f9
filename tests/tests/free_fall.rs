//! Physics seen from a client process: a ball in a manual plane follows the integrator.

use client_sdk::{PlaneOptions, PlaneProp, Pose, Shape};
use integration_tests::TestDaemon;

#[test]
fn dropped_ball_follows_free_fall_within_integrator_error() {
    let daemon = TestDaemon::start("fall");
    let client = daemon.client();
    let g = 9.81f32;
    let plane = client
        .create_plane(&PlaneOptions {
            gravity: Some([0.0, -g, 0.0]),
            linear_damping: Some(0.0),
            ..PlaneOptions::manual()
        })
        .unwrap();
    let y0 = 100.0f32;
    let ball = plane
        .add(Shape::Sphere { radius: 0.5 }, Pose::at([0.0, y0, 0.0]), &[])
        .unwrap();
    let dt = 1.0f32 / 60.0;
    for n in 1..=120u32 {
        let tick = plane.step(dt).unwrap();
        assert_eq!(tick, n as u64);
        let t = n as f32 * dt;
        let y = ball.position().unwrap()[1];
        let vy = ball.velocity().unwrap()[1];
        // Semi-implicit Euler lags the exact parabola by at most g·h·t/2 (h = dt); f32
        // rounding of a 100-unit coordinate adds ~1e-5 per step.
        let exact = y0 - 0.5 * g * t * t;
        let bound = 0.5 * g * dt * t + 1e-4 * n as f32;
        assert!(
            (y - exact).abs() <= bound,
            "t={t}: y={y}, exact={exact}, bound={bound}"
        );
        // The velocity of a constant acceleration is integrated exactly.
        assert!(
            (vy + g * t).abs() <= 1e-4 * n as f32,
            "t={t}: vy={vy}, exact={}",
            -g * t
        );
    }
    // The tick header reports the step.
    let header = *plane.snapshot().unwrap().header();
    assert_eq!(header.tick, 120);
    assert!(
        (header.sim_time - 2.0).abs() < 1e-6,
        "sim_time {}",
        header.sim_time
    );
    assert!((header.dt - dt).abs() < 1e-9);
    assert_eq!(header.body_count, 1);
    assert!(header.step_time_us > 0.0);
}

#[test]
fn resting_on_an_anchored_floor_reports_small_penetration() {
    let daemon = TestDaemon::start("rest");
    let client = daemon.client();
    let plane = client.create_plane(&PlaneOptions::manual()).unwrap();
    let floor = plane
        .add(
            Shape::Cube {
                size: [10.0, 1.0, 10.0],
            },
            Pose::at([0.0, -0.5, 0.0]),
            &[],
        )
        .unwrap();
    floor.set_anchored(true).unwrap();
    let ball = plane
        .add(
            Shape::Sphere { radius: 0.5 },
            Pose::at([0.0, 2.0, 0.0]),
            &[],
        )
        .unwrap();
    for _ in 0..120 {
        plane.step(1.0 / 60.0).unwrap();
    }
    // No contact skin: the ball rests touching the floor (within rapier's allowed error).
    let y = ball.position().unwrap()[1];
    assert!((y - 0.5).abs() < 0.005, "ball rests on the floor: y={y}");
    assert_eq!(
        floor.position().unwrap(),
        [0.0, -0.5, 0.0],
        "anchored floor never moves"
    );
    let h = *plane.snapshot().unwrap().header();
    assert_eq!(h.contact_pairs, 1);
    // Measured by the last step's collision detection (before its solver pass), so it is
    // larger than the final overlap but must stay within a few percent of the radius.
    assert!(
        h.max_penetration >= 0.0 && h.max_penetration < 0.05,
        "penetration {}",
        h.max_penetration
    );
}

#[test]
fn automatic_ticks_follow_the_tick_rate() {
    let daemon = TestDaemon::start("auto");
    let client = daemon.client();
    let plane = client
        .create_plane(&PlaneOptions {
            tick_rate: Some(100.0),
            ..Default::default()
        })
        .unwrap();
    let first = plane.wait_tick(std::time::Duration::from_secs(2)).unwrap();
    let started = std::time::Instant::now();
    let mut last = first;
    while started.elapsed() < std::time::Duration::from_millis(500) {
        last = plane.wait_tick(std::time::Duration::from_secs(2)).unwrap();
    }
    let rate = (last - first) as f64 / started.elapsed().as_secs_f64();
    // Wall-clock ticking on a shared machine: generous band around 100 Hz.
    assert!((30.0..=130.0).contains(&rate), "ticks per second {rate}");
    let h = *plane.snapshot().unwrap().header();
    assert!(
        (h.sim_time - h.tick as f64 / 100.0).abs() < 1e-6,
        "each tick advances 1/100 s"
    );
    // A polling wait sees each next tick too, and falls back to sleeping after its spin.
    let polled = plane
        .wait_tick_spin(
            std::time::Duration::from_secs(2),
            std::time::Duration::from_millis(20),
        )
        .unwrap();
    assert!(polled > last, "{polled} after {last}");
    let slept = plane
        .wait_tick_spin(
            std::time::Duration::from_secs(2),
            std::time::Duration::from_micros(1),
        )
        .unwrap();
    assert!(slept > polled, "{slept} after {polled}");
    // Disabling stops the ticks.
    plane.set(PlaneProp::Enabled(false)).unwrap();
    client.flush().unwrap();
    let frozen = plane.snapshot().unwrap().tick();
    std::thread::sleep(std::time::Duration::from_millis(100));
    assert!(plane.snapshot().unwrap().tick() <= frozen + 1);
}

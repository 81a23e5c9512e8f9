//! Pipelined flushes (`ConnectOptions::refusals_at_next_call`, how the Luau host connects): a
//! frame's flush sends its writes and returns without waiting for the step the plane's
//! worker is in the middle of. The writes still apply in order before any later request of
//! the client, reads show them meanwhile, a refusal comes with the next call into the plane,
//! and a daemon that dies with a flush in flight is an error of the next call, not a hang.

use std::time::{Duration, Instant};

use client_sdk::{
    Client, ConnectOptions, Error, ObjectProp, Plane, PlaneOptions, PlaneProp, Pose, Shape,
};
use integration_tests::TestDaemon;
use shm_layout::controller_op::MAX_WAYPOINTS;

fn game_client(daemon: &TestDaemon) -> Client {
    let mut options = ConnectOptions::new(&daemon.domain);
    options.refusals_at_next_call = true;
    Client::connect_with(options).unwrap()
}

/// A manual plane whose steps stay expensive: a pile of `n` unit boxes resting on a floor
/// that never sleeps.
fn heavy_plane(client: &Client, n: usize) -> Plane {
    let plane = client
        .create_plane(&PlaneOptions::manual().with(PlaneProp::NeverSleep(true)))
        .unwrap();
    plane
        .add(
            Shape::Cube {
                size: [400.0, 1.0, 400.0],
            },
            Pose::at([0.0, -0.5, 0.0]),
            &[ObjectProp::Anchored(true)],
        )
        .unwrap();
    let side = 20;
    for i in 0..n {
        let (x, z, y) = (i % side, (i / side) % side, i / (side * side));
        plane
            .add(
                Shape::Cube { size: [1.0; 3] },
                Pose::at([x as f32 * 1.01, 0.5 + y as f32 * 1.01, z as f32 * 1.01]),
                &[],
            )
            .unwrap();
    }
    plane
}

/// The plane's step time as its newest tick header reports it.
fn step_time(plane: &Plane) -> Duration {
    Duration::from_micros(plane.snapshot().unwrap().header().step_time_us.max(0.0) as u64)
}

#[test]
fn a_flush_returns_before_the_step_in_progress_ends_and_its_writes_apply_in_order() {
    let daemon = TestDaemon::start("pipelined-flush");
    let client = game_client(&daemon);
    let plane = heavy_plane(&client, 2_000);
    let marker = plane
        .add(
            Shape::Sphere { radius: 0.5 },
            Pose::at([1000.0, 50.0, 0.0]),
            &[],
        )
        .unwrap();
    for _ in 0..3 {
        plane.step(1.0 / 60.0).unwrap();
    }
    let step = step_time(&plane);
    assert!(
        step >= Duration::from_millis(5),
        "the pile makes a step of at least 5 ms: {step:?}"
    );
    // A tick rate whose period is shorter than a step: the worker is always mid-step, and a
    // flush that waited for its reply would wait half a step on average.
    let rate = (1.25 / step.as_secs_f64()).clamp(1.0, 240.0);
    plane.set_now(PlaneProp::TickRate(rate as f32)).unwrap();
    plane.wait_tick(Duration::from_secs(30)).unwrap();
    plane.wait_tick(Duration::from_secs(30)).unwrap();
    let step = step_time(&plane).max(step);
    let mut flushes = Vec::new();
    let mut last = 0;
    for k in 0..12 {
        client.begin_frame();
        last = k;
        let x = 1000.0 + k as f32;
        marker.set_pose(Pose::at([x, 50.0, 0.0])).unwrap();
        marker.set_velocity([0.0; 3]).unwrap();
        let started = Instant::now();
        client.flush().unwrap();
        flushes.push(started.elapsed());
        // Read-your-writes while the reply is outstanding.
        assert_eq!(marker.pose().unwrap().position[0], x, "frame {k}");
        // A frame and a half of the plane: the last flush's reply has arrived by the next.
        std::thread::sleep(step.mul_f64(1.6));
    }
    flushes.sort();
    let median = flushes[flushes.len() / 2];
    assert!(
        median < step / 4,
        "a flush returns without waiting for the step in progress: median {median:?}, step \
         {step:?}, all {flushes:?}"
    );
    // Any call first takes the outstanding replies; the writes applied in the order sent.
    plane.info().unwrap();
    let applied = plane.snapshot().unwrap().tick();
    let shown = loop {
        plane.wait_tick(Duration::from_secs(30)).unwrap();
        let snap = plane.snapshot().unwrap();
        if snap.tick() > applied {
            break snap.bodies()[marker.handle().slot as usize].position;
        }
    };
    let expected = 1000.0 + last as f32;
    assert!(
        (shown[0] - expected).abs() < 1e-3,
        "the last pose written wins: x = {} (expected {expected})",
        shown[0]
    );
    // Gravity moved it since (no write pins it any more): reads follow the samples again.
    assert!(shown[1] < 50.0, "falling again: y = {}", shown[1]);
    let read = marker.pose().unwrap().position;
    assert!(
        read[1] < 50.0,
        "the read is no longer the written pose: {read:?}"
    );
}

#[test]
fn a_write_refused_after_a_pipelined_flush_is_reported_by_the_next_call_into_its_plane() {
    let daemon = TestDaemon::start("pipelined-refusal");
    let client = game_client(&daemon);
    let plane = client.create_plane(&PlaneOptions::manual()).unwrap();
    let controller = plane
        .new_controller(Pose::at([0.0, 3.0, 0.0]), [2.0, 5.0, 2.0], false, &[])
        .unwrap();
    let full: Vec<[f32; 3]> = (0..MAX_WAYPOINTS).map(|i| [i as f32, 0.0, 0.0]).collect();
    controller.compute_path(&full).unwrap();
    // Only the daemon knows the path is full: the flush sends the append and returns.
    controller.append_waypoint([0.0, 0.0, 1.0]).unwrap();
    client.flush().unwrap();
    match plane.step(1.0 / 60.0) {
        Err(Error::Refused(refused)) => {
            assert_eq!(refused.len(), 1, "{refused:?}");
            assert!(
                refused[0].message.contains("waypoint"),
                "names the write: {}",
                refused[0].message
            );
        }
        other => panic!("the next call reports the refusal, got {other:?}"),
    }
    // Reported once; the plane goes on.
    plane.step(1.0 / 60.0).unwrap();
    // A refusal no call reported: `take_refused` collects it, even straight after the flush.
    controller.append_waypoint([0.0, 0.0, 2.0]).unwrap();
    client.flush().unwrap();
    let refused = client.take_refused(None);
    assert_eq!(refused.len(), 1, "{refused:?}");
    assert!(client.take_refused(None).is_empty(), "taken once");
    plane.step(1.0 / 60.0).unwrap();
}

#[test]
fn a_daemon_gone_with_a_flush_in_flight_fails_the_next_call_in_bounded_time() {
    let mut daemon = TestDaemon::start("pipelined-gone");
    let client = game_client(&daemon);
    let plane = heavy_plane(&client, 500);
    let ball = plane
        .add(
            Shape::Sphere { radius: 0.5 },
            Pose::at([0.0, 80.0, 0.0]),
            &[],
        )
        .unwrap();
    plane.set_now(PlaneProp::TickRate(60.0)).unwrap();
    ball.set_velocity([1.0, 0.0, 0.0]).unwrap();
    client.flush().unwrap();
    daemon.kill9();
    let started = Instant::now();
    let result = plane.info();
    assert!(result.is_err(), "the daemon is gone: {result:?}");
    assert!(
        started.elapsed() < Duration::from_secs(10),
        "told within the liveness checks, not the request timeout: {:?}",
        started.elapsed()
    );
}

#[test]
fn a_queued_step_runs_behind_the_frames_writes_and_the_frame_does_not_wait_for_it() {
    let daemon = TestDaemon::start("pipelined-step");
    let client = game_client(&daemon);
    let plane = client
        .create_plane(&PlaneOptions {
            tick_rate: Some(0.0),
            ..integration_tests::zero_gravity()
        })
        .unwrap();
    let ball = plane
        .add(Shape::Sphere { radius: 0.5 }, Pose::at([0.0; 3]), &[])
        .unwrap();
    let start = plane.info().unwrap().tick;
    // Ten frames, each writing a velocity and stepping 0.1 s behind it: with neither gravity
    // nor damping the ball moves v·dt a frame, each step seeing its own frame's write.
    for k in 1..=10 {
        client.begin_frame();
        ball.set_velocity([k as f32, 0.0, 0.0]).unwrap();
        plane.queue_step(0.1).unwrap();
        client.flush().unwrap();
    }
    let info = plane.info().unwrap();
    assert_eq!(info.tick, start + 10, "one tick per frame");
    let x = plane.snapshot().unwrap().bodies()[ball.handle().slot as usize].position[0];
    assert!((x - 5.5).abs() < 1e-4, "x = Σ k·0.1 = 5.5, got {x}");
    // A bad dt is refused where it is queued, naming the field.
    for dt in [0.0, -1.0, f32::NAN, f32::INFINITY] {
        match plane.queue_step(dt) {
            Err(Error::Invalid { field, .. }) => assert_eq!(field, "dt"),
            other => panic!("dt {dt} must be refused, got {other:?}"),
        }
    }
    assert_eq!(
        client.queued(),
        0,
        "nothing was queued by the refused steps"
    );
}

//! Planes step on workers of their own: a client of a small plane is served while another
//! plane's step is in progress, the commands of a request still apply in order (also when
//! they alternate between planes), and the SDK's property mirror answers reads locally with
//! what was written, dropping what the daemon recomputes.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use client_sdk::{Client, ErrorKind, Handle, ObjectProp, PlaneOptions, PlaneProp, Pose, Shape};
use integration_tests::TestDaemon;
use shm_layout::codec::{decode_response, encode_request};
use shm_layout::{Command as Cmd, ObjectOp, PlaneOp, Reply, Request, Response};

/// A manual plane whose step takes a while: a column of overlapping boxes pushing apart.
fn heavy_plane(client: &Client, boxes: usize) -> client_sdk::Plane {
    let plane = client
        .create_plane(&PlaneOptions {
            solver_iterations: Some(16),
            ..PlaneOptions::manual()
        })
        .unwrap();
    plane
        .add(
            Shape::Cube {
                size: [60.0, 1.0, 60.0],
            },
            Pose::at([0.0, -0.5, 0.0]),
            &[ObjectProp::Anchored(true)],
        )
        .unwrap();
    let cube = Shape::Cube { size: [1.0; 3] };
    for i in 0..boxes {
        let (x, z, y) = (
            (i % 10) as f32 * 0.8,
            ((i / 10) % 10) as f32 * 0.8,
            (i / 100) as f32 * 0.8,
        );
        plane
            .add(cube.clone(), Pose::at([x - 4.0, 0.5 + y, z - 4.0]), &[])
            .unwrap();
    }
    plane
}

#[test]
fn a_small_plane_is_served_while_another_plane_steps() {
    let daemon = TestDaemon::start("hol");
    let domain = daemon.domain.clone();
    // (start, end) of each heavy step, as its client saw them.
    let steps: Arc<Mutex<Vec<(Instant, Instant)>>> = Arc::default();
    let ready = Arc::new(AtomicBool::new(false));
    let done = Arc::new(AtomicBool::new(false));
    let heavy = {
        let (steps, ready, done) = (steps.clone(), ready.clone(), done.clone());
        std::thread::spawn(move || {
            let client = Client::connect(&domain).unwrap();
            let plane = heavy_plane(&client, 1_500);
            ready.store(true, Ordering::SeqCst);
            for _ in 0..8 {
                let start = Instant::now();
                plane.step(1.0 / 60.0).unwrap();
                steps.lock().unwrap().push((start, Instant::now()));
            }
            done.store(true, Ordering::SeqCst);
        })
    };
    let client = daemon.client();
    let small = client.create_plane(&PlaneOptions::manual()).unwrap();
    let ball = small
        .add(
            Shape::Sphere { radius: 0.5 },
            Pose::at([0.0, 5.0, 0.0]),
            &[],
        )
        .unwrap();
    while !ready.load(Ordering::SeqCst) {
        std::thread::sleep(Duration::from_millis(5));
    }
    let mut replies = Vec::new();
    let mut ticks = 0;
    while !done.load(Ordering::SeqCst) {
        ticks = small.step(1.0 / 60.0).unwrap();
        replies.push(Instant::now());
    }
    heavy.join().unwrap();
    assert!(ball.position().unwrap()[1] < 5.0, "the small plane stepped");
    assert_eq!(
        ticks as usize,
        replies.len(),
        "every small step was its own tick"
    );
    let steps = steps.lock().unwrap();
    // Requests for the small plane were answered while a heavy step was in progress (one
    // loop serving both planes in turn answers at most one of them per heavy step).
    let most_inside = steps
        .iter()
        .map(|(start, end)| replies.iter().filter(|t| *t > start && *t < end).count())
        .max()
        .unwrap();
    let longest = steps.iter().map(|(s, e)| *e - *s).max().unwrap();
    assert!(
        most_inside >= 3,
        "at most {most_inside} small-plane replies during one heavy step (longest step \
         {longest:?}, {} small steps in all)",
        replies.len()
    );
}

fn results(bytes: Vec<u8>) -> Vec<shm_layout::CommandResult> {
    match decode_response(&bytes).expect("decodable reply") {
        Response::Results(r) => r,
        Response::Rejected(e) => panic!("rejected: {e}"),
    }
}

#[test]
fn a_request_alternating_between_planes_applies_in_order() {
    let daemon = TestDaemon::start("order");
    let client = daemon.client();
    let zero_g = PlaneOptions {
        gravity: Some([0.0; 3]),
        linear_damping: Some(0.0),
        never_sleep: Some(true),
        ..PlaneOptions::manual()
    };
    let a = client.create_plane(&zero_g).unwrap();
    let b = client.create_plane(&zero_g).unwrap();
    let ball = |p: &client_sdk::Plane| {
        p.add(Shape::Sphere { radius: 0.5 }, Pose::at([0.0; 3]), &[])
            .unwrap()
            .handle()
    };
    let (ha, hb) = (ball(&a), ball(&b));
    let set_v = |plane: u32, h: Handle, vx: f32| {
        Cmd::object(
            plane,
            h,
            ObjectOp::Set(ObjectProp::Velocity([vx, 0.0, 0.0])),
        )
    };
    let stale = Handle {
        slot: ha.slot,
        generation: ha.generation + 7,
    };
    // Runs of one plane, alternation, a step in the middle, bad commands in between: every
    // result comes back in request order and the last write of each plane wins.
    let mut commands = Vec::new();
    for i in 0..50 {
        commands.push(set_v(a.id(), ha, i as f32));
        commands.push(set_v(a.id(), ha, i as f32 + 0.5));
        commands.push(set_v(b.id(), hb, -(i as f32)));
    }
    commands.push(Cmd::plane(a.id(), PlaneOp::Step { dt: 0.5 }));
    commands.push(set_v(a.id(), stale, 1.0));
    commands.push(Cmd::plane(9_999, PlaneOp::Info));
    commands.push(set_v(b.id(), hb, -100.0));
    commands.push(Cmd::plane(b.id(), PlaneOp::Step { dt: 0.5 }));
    commands.push(set_v(a.id(), ha, 3.0));
    let n = commands.len();
    let r = results(
        client
            .raw_request(&encode_request(&Request { commands }))
            .unwrap(),
    );
    assert_eq!(r.len(), n);
    for (i, result) in r[..150].iter().enumerate() {
        assert!(
            matches!(result, Ok(Reply::Applied { .. })),
            "command {i}: {result:?}"
        );
    }
    assert!(
        matches!(r[150], Ok(Reply::Stepped { tick: 1 })),
        "{:?}",
        r[150]
    );
    assert_eq!(r[151].as_ref().unwrap_err().kind, ErrorKind::StaleHandle);
    assert_eq!(r[152].as_ref().unwrap_err().kind, ErrorKind::UnknownPlane);
    assert!(matches!(r[153], Ok(Reply::Applied { .. })));
    assert!(
        matches!(r[154], Ok(Reply::Stepped { tick: 1 })),
        "{:?}",
        r[154]
    );
    assert!(matches!(r[155], Ok(Reply::Applied { .. })));
    // Plane a stepped with vx = 49.5 (the last write before its step) for 0.5 s.
    let pa = client_sdk::Object::from_handle(&a, ha);
    let pb = client_sdk::Object::from_handle(&b, hb);
    let xa = pa.position().unwrap()[0];
    assert!(
        (xa - 24.75).abs() < 1e-3,
        "plane a moved {xa}, expected 24.75: tick {} {:?}",
        a.snapshot().unwrap().tick(),
        pa.state()
    );
    let xb = pb.position().unwrap()[0];
    assert!((xb + 50.0).abs() < 1e-3, "plane b moved {xb}, expected -50");
}

#[test]
fn reads_answer_from_the_mirror_and_derived_values_are_refetched() {
    let daemon = TestDaemon::start("mirror");
    let client = daemon.client();
    let plane = client
        .create_plane(&PlaneOptions {
            linear_damping: Some(0.25),
            ..PlaneOptions::manual()
        })
        .unwrap();
    let cube = plane
        .add(
            Shape::Cube { size: [1.0; 3] },
            Pose::at([0.0, 10.0, 0.0]),
            &[ObjectProp::Density(2.0)],
        )
        .unwrap();
    let first = cube.properties().unwrap();
    assert_eq!(first.mass, 2.0, "density 2 × 1 m³");
    cube.set(ObjectProp::Friction(0.75)).unwrap();
    cube.set(ObjectProp::Bounciness(0.25)).unwrap();
    plane.set(PlaneProp::LinearDamping(0.5)).unwrap();
    client.flush().unwrap();
    // With the daemon stopped, mirrored reads still answer (they send no request).
    daemon.signal(libc::SIGSTOP);
    let local = cube.properties();
    let plane_local = plane.properties();
    daemon.signal(libc::SIGCONT);
    let local = local.expect("mirrored object read");
    assert_eq!(local.friction, 0.75);
    assert_eq!(local.bounciness, 0.25);
    assert_eq!(local.mass, 2.0);
    assert_eq!(
        plane_local.expect("mirrored plane read").linear_damping,
        0.5
    );
    // The mirror agrees with the daemon.
    assert_eq!(cube.info().unwrap().settings, local.settings);
    assert_eq!(plane.info().unwrap().settings.linear_damping, 0.5);
    // A new size changes the mass the daemon derives: the mirror must not keep the old one.
    cube.set_size([2.0, 1.0, 1.0]).unwrap();
    let after = cube.properties().unwrap();
    assert_eq!(after.mass, 4.0, "density 2 × 2 m³ after the resize");
    assert_eq!(after.size, [2.0, 1.0, 1.0]);
    // Another client's view of the same plane asks the daemon and sees the same values.
    let other = daemon.client();
    let seen = other.attach_plane(plane.id()).unwrap();
    assert_eq!(seen.properties().unwrap().linear_damping, 0.5);
    let theirs = client_sdk::Object::from_handle(&seen, cube.handle());
    assert_eq!(theirs.properties().unwrap().friction, 0.75);
}

/// The friction an `Object Info` result reports.
fn friction(result: &shm_layout::CommandResult) -> f32 {
    match result {
        Ok(Reply::ObjectInfo(info)) => info.settings.friction,
        other => panic!("expected object info, got {other:?}"),
    }
}

#[test]
fn runs_applied_inline_and_handed_over_keep_their_order_and_stay_whole() {
    // The loop applies a short run itself while the plane's worker is idle and hands it
    // over while the worker steps or has runs queued. Two clients on one shared plane mix
    // both: every batch must apply whole (no other run between its commands), each client's
    // requests in order, and a Step reply only once its tick is published.
    let daemon = TestDaemon::start("inline");
    let owner = daemon.client();
    let plane = owner
        .create_plane(&PlaneOptions {
            shared: Some(true),
            solver_iterations: Some(8),
            ..PlaneOptions::manual()
        })
        .unwrap();
    // Enough bodies that a step takes a while (the other client's runs meet a busy worker).
    plane
        .add(
            Shape::Cube {
                size: [40.0, 1.0, 40.0],
            },
            Pose::at([0.0, -0.5, 0.0]),
            &[ObjectProp::Anchored(true)],
        )
        .unwrap();
    for i in 0..400 {
        let (x, z, y) = ((i % 10) as f32 * 0.9, ((i / 10) % 10) as f32 * 0.9, i / 100);
        plane
            .add(
                Shape::Cube { size: [1.0; 3] },
                Pose::at([x - 4.0, 0.5 + y as f32 * 0.9, z - 4.0]),
                &[],
            )
            .unwrap();
    }
    let ball = |y: f32| {
        plane
            .add(
                Shape::Sphere { radius: 0.5 },
                Pose::at([30.0, y, 30.0]),
                &[],
            )
            .unwrap()
            .handle()
    };
    let (mine, theirs) = (ball(100.0), ball(200.0));
    let id = plane.id();
    let set = move |h: Handle, f: f32| Cmd::object(id, h, ObjectOp::Set(ObjectProp::Friction(f)));
    let info = move |h: Handle| Cmd::object(id, h, ObjectOp::Info);
    let rounds = 300;

    let domain = daemon.domain.clone();
    let other = std::thread::spawn(move || {
        let client = Client::connect(&domain).unwrap();
        for i in 0..rounds {
            // Short runs (no step): applied inline whenever the worker is idle.
            let (f, g) = (0.3 + i as f32 * 1e-3, 0.7 + i as f32 * 1e-3);
            let r = results(
                client
                    .raw_request(&encode_request(&Request {
                        commands: vec![set(theirs, f), info(theirs), set(theirs, g)],
                    }))
                    .unwrap(),
            );
            assert_eq!(friction(&r[1]), f, "round {i}: their batch was split");
            assert!(matches!(r[2], Ok(Reply::Applied { .. })), "{:?}", r[2]);
            // The next request sees the last write of the previous one.
            let r = results(
                client
                    .raw_request(&encode_request(&Request {
                        commands: vec![info(theirs)],
                    }))
                    .unwrap(),
            );
            assert_eq!(friction(&r[0]), g, "round {i}: their requests out of order");
        }
    });

    let mut last_tick = 0;
    for i in 0..rounds {
        let f = 0.1 + i as f32 * 1e-4;
        let mut commands = vec![set(mine, f), info(mine)];
        if i % 2 == 1 {
            // A run with a step goes to the worker; the info after it must still see f.
            commands.push(Cmd::plane(id, PlaneOp::Step { dt: 1.0 / 60.0 }));
            commands.push(info(mine));
        }
        let r = results(
            owner
                .raw_request(&encode_request(&Request { commands }))
                .unwrap(),
        );
        assert_eq!(friction(&r[1]), f, "round {i}: my batch was split");
        if i % 2 == 1 {
            let Ok(Reply::Stepped { tick }) = r[2] else {
                panic!("round {i}: {:?}", r[2]);
            };
            assert_eq!(tick, last_tick + 1, "round {i}: steps out of order");
            last_tick = tick;
            assert_eq!(
                friction(&r[3]),
                f,
                "round {i}: my batch was split by a step"
            );
            // The reply came after the tick was published.
            assert!(
                plane.snapshot().unwrap().tick() >= tick,
                "round {i}: Step answered before tick {tick} was published"
            );
        }
        // A short request right after a stepping one applies after it.
        let g = 0.2 + i as f32 * 1e-4;
        owner
            .raw_request(&encode_request(&Request {
                commands: vec![set(mine, g)],
            }))
            .unwrap();
        let r = results(
            owner
                .raw_request(&encode_request(&Request {
                    commands: vec![info(mine)],
                }))
                .unwrap(),
        );
        assert_eq!(friction(&r[0]), g, "round {i}: my requests out of order");
    }
    other.join().unwrap();
    assert_eq!(last_tick, rounds as u64 / 2);
}

#[test]
fn a_tick_rate_set_between_steps_starts_and_stops_the_schedule() {
    // A rate change is a short run the loop may apply itself: the plane's worker must
    // still pick up the new schedule at once.
    let daemon = TestDaemon::start("resched");
    let client = daemon.client();
    let plane = client.create_plane(&PlaneOptions::manual()).unwrap();
    plane
        .add(Shape::Sphere { radius: 0.5 }, Pose::at([0.0; 3]), &[])
        .unwrap();
    let tick = |p: &client_sdk::Plane| p.snapshot().unwrap().tick();
    std::thread::sleep(Duration::from_millis(100));
    assert_eq!(tick(&plane), 0, "a manual plane does not tick");
    plane.set(PlaneProp::TickRate(100.0)).unwrap();
    client.flush().unwrap();
    let started = Instant::now();
    while tick(&plane) < 10 {
        assert!(
            started.elapsed() < Duration::from_secs(5),
            "TickRate 100 made {} ticks in {:?}",
            tick(&plane),
            started.elapsed()
        );
        std::thread::sleep(Duration::from_millis(5));
    }
    plane.set(PlaneProp::Enabled(false)).unwrap();
    client.flush().unwrap();
    // A tick may have been under way when the change applied.
    let stopped = tick(&plane);
    std::thread::sleep(Duration::from_millis(200));
    assert!(
        tick(&plane) <= stopped + 1,
        "a disabled plane went on ticking: {stopped} → {}",
        tick(&plane)
    );
    let stopped = tick(&plane);
    plane.set(PlaneProp::Enabled(true)).unwrap();
    client.flush().unwrap();
    let started = Instant::now();
    while tick(&plane) < stopped + 10 {
        assert!(
            started.elapsed() < Duration::from_secs(5),
            "re-enabled, {} ticks in {:?}",
            tick(&plane) - stopped,
            started.elapsed()
        );
        std::thread::sleep(Duration::from_millis(5));
    }
}

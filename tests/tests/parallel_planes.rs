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

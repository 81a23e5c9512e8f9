//! Bad input gets a clear error naming the field and value; the daemon keeps serving.

use client_sdk::{ConnectOptions, Error, ErrorKind, Handle, PlaneOptions, Pose, Shape};
use integration_tests::TestDaemon;
use shm_layout::codec::{decode_response, encode_request};
use shm_layout::{Command, ObjectOp, ObjectProp, PlaneOp, Request, Response, LAYOUT_VERSION};

fn results(bytes: Vec<u8>) -> Vec<Result<shm_layout::Reply, shm_layout::CommandError>> {
    match decode_response(&bytes).unwrap() {
        Response::Results(r) => r,
        other => panic!("expected results, got {other:?}"),
    }
}

#[test]
fn nan_and_negative_sizes_are_rejected_by_name() {
    let daemon = TestDaemon::start("nan");
    let client = daemon.client();
    let plane = client.create_plane(&PlaneOptions::manual()).unwrap();
    let ball = plane
        .add(Shape::Sphere { radius: 1.0 }, Pose::at([0.0; 3]), &[])
        .unwrap();

    // The SDK refuses at once...
    let err = ball
        .set_velocity([0.0, f32::NAN, 0.0])
        .unwrap_err()
        .to_string();
    assert!(err.contains("Velocity") && err.contains("NaN"), "{err}");

    // ...and the daemon refuses too, for clients that bypass the SDK. The good command of
    // the same batch still applies.
    let object = ball.handle();
    let request = Request {
        commands: vec![
            Command::object(
                plane.id(),
                object,
                ObjectOp::Set(ObjectProp::Velocity([f32::NAN, 0.0, 0.0])),
            ),
            Command::object(
                plane.id(),
                object,
                ObjectOp::Set(ObjectProp::Velocity([3.0, 0.0, 0.0])),
            ),
            Command::plane(plane.id(), PlaneOp::Step { dt: f32::INFINITY }),
            Command::plane(plane.id(), PlaneOp::Step { dt: -0.1 }),
        ],
    };
    let r = results(client.raw_request(&encode_request(&request)).unwrap());
    let e = r[0].as_ref().unwrap_err();
    assert_eq!(e.kind, ErrorKind::InvalidValue);
    assert!(
        e.message.contains("Velocity") && e.message.contains("NaN"),
        "{}",
        e.message
    );
    assert!(r[1].is_ok());
    assert!(
        r[2].as_ref().unwrap_err().message.contains("dt"),
        "{:?}",
        r[2]
    );
    assert!(
        r[3].as_ref().unwrap_err().message.contains("-0.1"),
        "{:?}",
        r[3]
    );
    plane.set(shm_layout::PlaneProp::Gravity([0.0; 3])).unwrap();
    plane
        .set(shm_layout::PlaneProp::LinearDamping(0.0))
        .unwrap();
    for _ in 0..50 {
        plane.step(0.01).unwrap();
    }
    let x = ball.position().unwrap()[0];
    assert!(
        (x - 1.5).abs() < 1e-4,
        "the valid velocity was applied: x={x}"
    );

    let err = plane
        .add(
            Shape::Cube {
                size: [1.0, -2.0, 1.0],
            },
            Pose::at([0.0; 3]),
            &[],
        )
        .unwrap_err();
    let msg = err.to_string();
    assert!(msg.contains("Size.Y") && msg.contains("-2"), "{msg}");
    let err = plane.add(
        Shape::Sphere { radius: 1.0 },
        Pose {
            position: [0.0; 3],
            rotation: [0.0; 4],
        },
        &[],
    );
    assert!(err.unwrap_err().to_string().contains("rotation"));
    let err = client
        .create_plane(&PlaneOptions {
            threads: Some(0),
            ..Default::default()
        })
        .unwrap_err();
    assert!(
        err.to_string().contains("Threads") && err.to_string().contains('0'),
        "{err}"
    );
    assert_eq!(
        plane.info().unwrap().object_count,
        1,
        "rejected adds added nothing"
    );
}

#[test]
fn stale_and_unknown_handles_are_detected() {
    let daemon = TestDaemon::start("stale");
    let client = daemon.client();
    let plane = client.create_plane(&PlaneOptions::manual()).unwrap();
    let first = plane
        .add(Shape::Sphere { radius: 1.0 }, Pose::at([0.0; 3]), &[])
        .unwrap();
    first.destroy();
    assert!(!first.is_alive().unwrap(), "reads see the destroy at once");
    client.flush().unwrap();
    // The slot is reused with a new generation.
    let second = plane
        .add(
            Shape::Sphere { radius: 1.0 },
            Pose::at([5.0, 0.0, 0.0]),
            &[],
        )
        .unwrap();
    assert_eq!(second.handle().slot, first.handle().slot);
    assert_ne!(second.handle().generation, first.handle().generation);
    plane.step(0.01).unwrap();
    assert!(
        !first.is_alive().unwrap(),
        "the old handle never reads the new body"
    );
    assert_eq!(second.position().unwrap()[0], 5.0);

    first.set_velocity([1.0, 0.0, 0.0]).unwrap();
    second.set_velocity([0.0, 0.0, 2.0]).unwrap();
    match client.flush() {
        Err(Error::Batch(errors)) => {
            assert_eq!(errors.len(), 1);
            assert_eq!(errors[0].kind, ErrorKind::StaleHandle);
            assert!(errors[0].message.contains("stale"), "{}", errors[0].message);
            // Objects are named as users read them, never in Rust's debug syntax.
            let m = &errors[0].message;
            assert!(m.contains("object #") && !m.contains("Handle {"), "{m}");
        }
        other => panic!("expected a batch error, got {:?}", other.err()),
    }
    assert_eq!(
        second.velocity().unwrap(),
        [0.0, 0.0, 2.0],
        "the valid write applied"
    );

    let ghost = client_sdk::Object::from_handle(
        &plane,
        Handle {
            slot: 999,
            generation: 1,
        },
    );
    ghost.apply_impulse([1.0, 0.0, 0.0]).unwrap();
    let Err(Error::Batch(errors)) = client.flush() else {
        panic!("unknown slot accepted")
    };
    assert!(
        errors[0].message.contains("does not exist"),
        "{}",
        errors[0].message
    );
    let Err(Error::Command(e)) = client.attach_plane(4242) else {
        panic!("unknown plane attached")
    };
    assert_eq!(e.kind, ErrorKind::UnknownPlane);
    assert!(e.message.contains("4242"));
}

#[test]
fn malformed_bytes_are_rejected_and_the_daemon_survives() {
    let daemon = TestDaemon::start("bytes");
    let client = daemon.client();
    let garbage: [&[u8]; 4] = [
        b"",
        b"hello world, not a frame",
        &[
            b'P',
            b'H',
            b'Y',
            b'S',
            LAYOUT_VERSION as u8,
            0,
            0,
            0,
            0xff,
            0xff,
            0xff,
            0xff,
            0x0f,
        ],
        &[
            b'P',
            b'H',
            b'Y',
            b'S',
            LAYOUT_VERSION as u8,
            0,
            0,
            0,
            1,
            200,
            7,
        ],
    ];
    for bytes in garbage {
        let reply = client.raw_request(bytes).unwrap();
        match decode_response(&reply).unwrap() {
            Response::Rejected(e) => assert_eq!(e.kind, ErrorKind::Malformed, "{e}"),
            other => panic!("{bytes:?} was accepted: {other:?}"),
        }
    }
    let plane = client.create_plane(&PlaneOptions::manual()).unwrap();
    assert_eq!(plane.step(0.01).unwrap(), 1, "daemon alive and serving");
}

#[test]
fn version_mismatch_names_both_versions() {
    let daemon = TestDaemon::start("version");
    let mut options = ConnectOptions::new(&daemon.domain);
    options.crate_version = "9.9.9".into();
    let Err(Error::VersionMismatch(msg)) = client_sdk::Client::connect_with(options) else {
        panic!("crate mismatch accepted")
    };
    assert!(
        msg.contains("9.9.9") && msg.contains(shm_layout::CRATE_VERSION),
        "{msg}"
    );

    let mut options = ConnectOptions::new(&daemon.domain);
    options.layout_version = LAYOUT_VERSION + 1;
    let Err(Error::VersionMismatch(msg)) = client_sdk::Client::connect_with(options) else {
        panic!("layout mismatch accepted")
    };
    assert!(
        msg.contains(&format!("LAYOUT_VERSION {}", LAYOUT_VERSION + 1)),
        "{msg}"
    );
    assert!(
        msg.contains(&format!("LAYOUT_VERSION {LAYOUT_VERSION}")),
        "{msg}"
    );
    // Well-behaved clients still connect.
    daemon.client();
}

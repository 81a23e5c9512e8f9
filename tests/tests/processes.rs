//! Several client processes, crashes on both sides, and orderly shutdown.

use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use client_sdk::{Error, ErrorKind, PlaneOptions, Pose, Shape};
use integration_tests::{domain_files, eventually, TestDaemon};

const TEST_CLIENT: &str = env!("CARGO_BIN_EXE_test-client");

#[test]
fn two_client_processes_see_the_same_plane() {
    let daemon = TestDaemon::start("two");
    let client = daemon.client();
    let plane = client.create_plane(&PlaneOptions::manual()).unwrap();
    let ball = plane
        .add(
            Shape::Sphere { radius: 0.5 },
            Pose::at([1.0, 20.0, -2.0]),
            &[],
        )
        .unwrap();
    for _ in 0..30 {
        plane.step(1.0 / 60.0).unwrap();
    }
    let mine = ball.position().unwrap();
    assert!(mine[1] < 19.0, "the ball fell: {mine:?}");
    let h = ball.handle();
    let out = Command::new(TEST_CLIENT)
        .args(["read", &daemon.domain])
        .args([plane.id(), h.slot, h.generation].map(|v| v.to_string()))
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout).unwrap();
    let fields: Vec<&str> = text.split_whitespace().collect();
    assert_eq!(fields[0], "tick=30", "{text}");
    let theirs: Vec<f32> = fields[1..].iter().map(|v| v.parse().unwrap()).collect();
    assert_eq!(theirs, mine.to_vec(), "both processes read the same sample");
}

#[test]
fn killed_client_releases_its_planes_and_daemon_keeps_serving() {
    let mut daemon = TestDaemon::start("crash");
    let mut holder = Command::new(TEST_CLIENT)
        .args(["hold", &daemon.domain])
        .stdout(Stdio::piped())
        .spawn()
        .unwrap();
    let mut line = String::new();
    std::io::BufRead::read_line(
        &mut std::io::BufReader::new(holder.stdout.take().unwrap()),
        &mut line,
    )
    .unwrap();
    let plane_id: u32 = line.trim().strip_prefix("plane=").unwrap().parse().unwrap();

    let client = daemon.client();
    let theirs = client.attach_plane(plane_id).unwrap();
    assert_eq!(theirs.info().unwrap().object_count, 1);
    holder.kill().unwrap(); // SIGKILL
    holder.wait().unwrap();

    let released = eventually(Duration::from_secs(3), || match theirs.info() {
        Err(Error::Command(e)) if e.kind == ErrorKind::UnknownPlane => Some(()),
        _ => None,
    });
    assert!(
        released.is_some(),
        "plane {plane_id} of the killed client was not released"
    );

    // The daemon still serves others.
    let plane = client.create_plane(&PlaneOptions::manual()).unwrap();
    assert_eq!(plane.step(0.01).unwrap(), 1);
    drop((plane, theirs));
    drop(client);

    let (status, took) = daemon.stop_with(libc::SIGINT, Duration::from_secs(2));
    assert!(status.success(), "daemon exit status {status}");
    assert!(took < Duration::from_secs(2));
    let left = eventually(Duration::from_secs(1), || {
        let f = domain_files(&daemon.domain);
        f.is_empty().then_some(())
    });
    assert!(
        left.is_some(),
        "left behind: {:?}",
        domain_files(&daemon.domain)
    );
}

#[test]
fn dead_daemon_is_an_error_within_one_second() {
    let mut daemon = TestDaemon::start("dies");
    let client = daemon.client();
    let manual = client.create_plane(&PlaneOptions::manual()).unwrap();
    manual.step(0.01).unwrap();
    daemon.kill9();

    let started = Instant::now();
    let err = manual.step(0.01).unwrap_err();
    let took = started.elapsed();
    assert!(matches!(err, Error::DaemonGone { .. }), "got {err}");
    assert!(took < Duration::from_secs(1), "took {took:?}");

    // Waiting for a tick is not a hang either.
    let started = Instant::now();
    let err = manual.wait_tick(Duration::from_secs(10)).unwrap_err();
    assert!(matches!(err, Error::DaemonGone { .. }), "got {err}");
    assert!(started.elapsed() < Duration::from_secs(1));

    // A new daemon in the same domain takes over and accepts new clients.
    let domain = daemon.domain.clone();
    let mut replacement = TestDaemon::start_in(&domain);
    let fresh = replacement.client();
    assert_eq!(
        fresh
            .create_plane(&PlaneOptions::manual())
            .unwrap()
            .step(0.01)
            .unwrap(),
        1
    );
    drop(fresh);
    drop(client);
    replacement.stop_with(libc::SIGTERM, Duration::from_secs(2));
}

#[test]
fn sigint_exits_zero_and_leaves_nothing_in_shared_memory() {
    let mut daemon = TestDaemon::start("sigint");
    {
        let client = daemon.client();
        let plane = client
            .create_plane(&PlaneOptions {
                tick_rate: Some(120.0),
                ..Default::default()
            })
            .unwrap();
        plane
            .add(
                Shape::Cube { size: [1.0; 3] },
                Pose::at([0.0, 3.0, 0.0]),
                &[],
            )
            .unwrap();
        plane.wait_tick(Duration::from_secs(2)).unwrap();
        assert!(
            !domain_files(&daemon.domain).is_empty(),
            "the domain uses shared memory"
        );
    }
    let (status, took) = daemon.stop_with(libc::SIGINT, Duration::from_secs(2));
    assert_eq!(status.code(), Some(0));
    assert!(took < Duration::from_secs(2), "took {took:?}");
    assert_eq!(
        domain_files(&daemon.domain),
        Vec::<std::path::PathBuf>::new()
    );
}

#[test]
fn second_daemon_in_a_domain_refuses_to_start() {
    let daemon = TestDaemon::start("twice");
    let out = Command::new(client_sdk::daemon_executable())
        .args(["--domain", &daemon.domain])
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("already serving"), "{err}");
    // The first one is unaffected.
    assert_eq!(
        daemon
            .client()
            .create_plane(&PlaneOptions::manual())
            .unwrap()
            .step(0.01)
            .unwrap(),
        1
    );
}

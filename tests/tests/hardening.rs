//! Reliability and security through real daemon processes: inputs that used to crash the
//! daemon, a panic inside one plane, per-client quotas, plane ownership, identity from the
//! transport, per-process client limits, a stalled daemon, and an on-demand daemon whose
//! starter is gone.

use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use client_sdk::{
    Client, ConnectOptions, Error, ErrorKind, Handle, PlaneOptions, PlaneProp, Pose, Shape,
};
use integration_tests::{eventually, TestDaemon};
use shm_layout::codec::{decode_response, encode_request};
use shm_layout::{Command as Cmd, PlaneOp, Request, Response};

fn results(bytes: Vec<u8>) -> Vec<shm_layout::CommandResult> {
    match decode_response(&bytes).expect("decodable reply") {
        Response::Results(r) => r,
        Response::Rejected(e) => panic!("rejected: {e}"),
    }
}

fn command_error(e: Error) -> client_sdk::CommandError {
    match e {
        Error::Command(e) => e,
        Error::Batch(mut v) => v.remove(0),
        other => panic!("expected a command error, got {other}"),
    }
}

fn cube() -> Shape {
    Shape::Cube { size: [1.0; 3] }
}

#[test]
fn tiny_tick_rates_are_refused_and_the_daemon_serves_on() {
    let daemon = TestDaemon::start("tickrate");
    let client = daemon.client();
    let plane = client.create_plane(&PlaneOptions::manual()).unwrap();
    for rate in [1e-20f32, 1e-45, 1.17e-38, 1e-3] {
        // Bypass the SDK's own check: the daemon must refuse on its own.
        let request = Request {
            commands: vec![Cmd::plane(
                plane.id(),
                PlaneOp::Set(PlaneProp::TickRate(rate)),
            )],
        };
        let r = results(client.raw_request(&encode_request(&request)).unwrap());
        let e = r[0].as_ref().unwrap_err();
        assert_eq!(e.kind, ErrorKind::InvalidValue, "{e}");
        assert!(e.message.contains("TickRate"), "{e}");
        assert_eq!(e.field.as_deref(), Some("TickRate"));
        // The same at creation.
        let create = Request {
            commands: vec![Cmd::CreatePlane {
                kind: Default::default(),
                props: vec![PlaneProp::TickRate(rate)],
            }],
        };
        let r = results(client.raw_request(&encode_request(&create)).unwrap());
        assert!(r[0].is_err(), "TickRate {rate} accepted at creation");
    }
    // A slow but valid rate works.
    plane.set(PlaneProp::TickRate(0.01)).unwrap();
    client.flush().unwrap();
    assert_eq!(plane.info().unwrap().tick_rate, 0.01);
    let other = daemon.client();
    assert!(other.create_plane(&PlaneOptions::manual()).is_ok());
}

#[test]
fn a_panic_inside_one_plane_fails_that_plane_only() {
    // The injected panic prints its message, not a backtrace, to the daemon's stderr.
    let daemon = TestDaemon::start_with(
        "panic",
        &[],
        &[
            ("PHYSICS_FAULT_PANIC_DT", "0.0123"),
            ("RUST_BACKTRACE", "0"),
        ],
    );
    let a = daemon.client();
    let b = daemon.client();
    let doomed = a.create_plane(&PlaneOptions::manual()).unwrap();
    let fine = b.create_plane(&PlaneOptions::manual()).unwrap();
    let ball = fine
        .add(
            Shape::Sphere { radius: 0.5 },
            Pose::at([0.0, 5.0, 0.0]),
            &[],
        )
        .unwrap();
    let e = command_error(doomed.step(0.0123).unwrap_err());
    assert_eq!(e.kind, ErrorKind::Internal);
    assert!(
        e.message.contains(&format!("plane {}", doomed.id())) && e.message.contains("failed"),
        "{e}"
    );
    // The failed plane is gone; everything else keeps working.
    let e = command_error(doomed.info().unwrap_err());
    assert_eq!(e.kind, ErrorKind::UnknownPlane);
    fine.step(1.0 / 60.0).unwrap();
    assert!(ball.position().unwrap()[1] < 5.0);
    assert!(a.create_plane(&PlaneOptions::manual()).is_ok());
    let mut daemon = daemon;
    assert!(daemon.is_running());
}

#[test]
fn quotas_refuse_with_the_quota_and_its_flag() {
    let daemon = TestDaemon::start_with(
        "quota",
        &[
            "--max-objects-per-client",
            "10",
            "--max-planes-per-client",
            "2",
            "--max-mesh-vertices",
            "100",
            "--max-mesh-vertices-per-client",
            "150",
            "--max-commands-per-request",
            "50",
            "--max-request-bytes",
            "100000",
        ],
        &[],
    );
    let client = daemon.client();
    let p1 = client.create_plane(&PlaneOptions::manual()).unwrap();
    let p2 = client.create_plane(&PlaneOptions::manual()).unwrap();
    let e = command_error(client.create_plane(&PlaneOptions::manual()).unwrap_err());
    assert_eq!(e.kind, ErrorKind::Quota);
    assert!(e.message.contains("--max-planes-per-client"), "{e}");

    // Objects count over all the client's planes.
    for i in 0..6 {
        p1.add(cube(), Pose::at([i as f32 * 2.0, 0.0, 0.0]), &[])
            .unwrap();
    }
    for i in 0..4 {
        p2.add(cube(), Pose::at([i as f32 * 2.0, 0.0, 0.0]), &[])
            .unwrap();
    }
    let e = command_error(p2.add(cube(), Pose::IDENTITY, &[]).unwrap_err());
    assert_eq!(e.kind, ErrorKind::Quota);
    assert!(
        e.message.contains("objects per client") && e.message.contains("--max-objects-per-client"),
        "{e}"
    );
    // Destroying one frees room for one.
    p2.destroy().unwrap();
    let p3 = client.create_plane(&PlaneOptions::manual()).unwrap();

    let sphere = |n: usize| {
        let vertices: Vec<[f32; 3]> = (0..n)
            .map(|i| {
                let t = i as f32 * 2.399_963; // golden angle
                let y = 1.0 - 2.0 * (i as f32 + 0.5) / n as f32;
                let r = (1.0 - y * y).sqrt();
                [r * t.cos(), y, r * t.sin()]
            })
            .collect();
        Shape::Mesh {
            vertices,
            triangles: vec![],
        }
    };
    let e = command_error(p3.add(sphere(101), Pose::IDENTITY, &[]).unwrap_err());
    assert!(e.message.contains("--max-mesh-vertices"), "{e}");
    p3.add(sphere(100), Pose::IDENTITY, &[]).unwrap();
    let e = command_error(p3.add(sphere(60), Pose::IDENTITY, &[]).unwrap_err());
    assert!(e.message.contains("--max-mesh-vertices-per-client"), "{e}");

    // Per request: commands and bytes.
    let many = Request {
        commands: (0..51)
            .map(|_| Cmd::plane(p3.id(), PlaneOp::Info))
            .collect(),
    };
    match decode_response(&client.raw_request(&encode_request(&many)).unwrap()).unwrap() {
        Response::Rejected(e) => {
            assert_eq!(e.kind, ErrorKind::Quota);
            assert!(e.message.contains("--max-commands-per-request"), "{e}");
        }
        other => panic!("51 commands accepted: {other:?}"),
    }
    let big = Request {
        commands: vec![Cmd::plane(
            p3.id(),
            PlaneOp::AddObject {
                shape: Shape::Mesh {
                    vertices: vec![[0.5; 3]; 10_000],
                    triangles: vec![],
                },
                pose: Pose::IDENTITY,
                props: vec![],
            },
        )],
    };
    match decode_response(&client.raw_request(&encode_request(&big)).unwrap()).unwrap() {
        Response::Rejected(e) => assert!(e.message.contains("--max-request-bytes"), "{e}"),
        other => panic!("a 120 kB request accepted: {other:?}"),
    }
    // The client still works.
    assert!(p3.info().is_ok());
}

#[test]
fn planes_belong_to_their_creator() {
    let daemon = TestDaemon::start("owner");
    let owner = daemon.client();
    let other = daemon.client();
    let private = owner.create_plane(&PlaneOptions::manual()).unwrap();
    let ball = private
        .add(
            Shape::Sphere { radius: 0.5 },
            Pose::at([0.0, 5.0, 0.0]),
            &[],
        )
        .unwrap();
    // Published with the next tick: other processes read what the daemon publishes.
    private.step(1.0 / 60.0).unwrap();
    let seen = other.attach_plane(private.id()).unwrap();
    // Reading is allowed: info, snapshots, object info.
    assert_eq!(seen.info().unwrap().object_count, 1);
    let remote = client_sdk::Object::from_handle(&seen, ball.handle());
    assert!(remote.info().is_ok());
    assert_eq!(remote.position().unwrap(), ball.position().unwrap());
    // Writing, stepping and destroying are not.
    for attempt in [
        seen.step(1.0 / 60.0).map(|_| ()),
        seen.add(cube(), Pose::IDENTITY, &[]).map(|_| ()),
        seen.destroy(),
        remote
            .set_velocity([1.0, 0.0, 0.0])
            .and_then(|_| other.flush()),
        {
            seen.set(PlaneProp::Gravity([0.0; 3])).unwrap();
            other.flush()
        },
    ] {
        let e = command_error(attempt.unwrap_err());
        assert_eq!(e.kind, ErrorKind::NotOwner, "{e}");
        assert!(e.message.contains("belongs to another client"), "{e}");
    }
    assert!(private.is_alive());
    assert_eq!(private.info().unwrap().gravity, [0.0, -50.0, 0.0]);

    // A shared plane takes writes from others, but only its owner destroys it.
    let shared = owner
        .create_plane(&PlaneOptions {
            shared: Some(true),
            ..PlaneOptions::manual()
        })
        .unwrap();
    assert!(shared.info().unwrap().shared);
    let joined = other.attach_plane(shared.id()).unwrap();
    joined.add(cube(), Pose::IDENTITY, &[]).unwrap();
    joined.step(1.0 / 60.0).unwrap();
    let e = command_error(joined.destroy().unwrap_err());
    assert_eq!(e.kind, ErrorKind::NotOwner);
    shared.destroy().unwrap();
}

#[test]
fn a_goodbye_releases_only_the_sender() {
    let daemon = TestDaemon::start("identity");
    let victim = daemon.client();
    let plane = victim.create_plane(&PlaneOptions::manual()).unwrap();
    let attacker = daemon.client();
    // The attacker claims the victim's id where clients used to send theirs (the request's
    // user header); the daemon takes identity from the transport, so the Goodbye is the
    // attacker's own.
    let bye = Request {
        commands: vec![Cmd::Goodbye],
    };
    let r = results(
        attacker
            .raw_request_claiming(&encode_request(&bye), victim.node_id())
            .unwrap(),
    );
    assert!(r[0].is_ok());
    assert!(
        plane.is_alive(),
        "a forged Goodbye released the victim's plane"
    );
    plane.step(1.0 / 60.0).unwrap();
    // The attacker itself was released: its next command must say Hello first.
    let info = Request {
        commands: vec![Cmd::plane(plane.id(), PlaneOp::Info)],
    };
    let r = results(attacker.raw_request(&encode_request(&info)).unwrap());
    assert_eq!(r[0].as_ref().unwrap_err().kind, ErrorKind::NotConnected);
}

#[test]
fn one_process_cannot_take_every_client_slot() {
    let daemon = TestDaemon::start_with("slots", &["--max-clients-per-process", "4"], &[]);
    // The harness's own probe connection is gone; four clients fit, the fifth does not.
    let held: Vec<Client> = (0..4).map(|_| daemon.client()).collect();
    match Client::connect(&daemon.domain) {
        Err(Error::Command(e)) => {
            assert_eq!(e.kind, ErrorKind::Quota);
            assert!(e.message.contains("--max-clients-per-process"), "{e}");
        }
        other => panic!("a fifth client of one process connected: {other:?}"),
    }
    // Another process still gets in.
    let out = Command::new(env!("CARGO_BIN_EXE_test-client"))
        .args(["hold-once", &daemon.domain])
        .output()
        .unwrap();
    assert!(
        out.status.success() && String::from_utf8_lossy(&out.stdout).contains("plane="),
        "{out:?}"
    );
    drop(held);
}

#[test]
fn a_stopped_daemon_is_reported_stalled_within_about_a_second() {
    let daemon = TestDaemon::start("stalled");
    let client = Client::connect_with(ConnectOptions {
        request_timeout: Duration::from_secs(30),
        ..ConnectOptions::new(&daemon.domain)
    })
    .unwrap();
    let plane = client.create_plane(&PlaneOptions::manual()).unwrap();
    daemon.signal(libc::SIGSTOP);
    let started = Instant::now();
    let err = plane.info().unwrap_err();
    let took = started.elapsed();
    daemon.signal(libc::SIGCONT);
    assert!(matches!(err, Error::Stalled { .. }), "{err}");
    assert!(err.to_string().contains("stalled"), "{err}");
    assert!(took < Duration::from_secs(3), "noticed after {took:?}");
    // Resumed, it answers again.
    assert!(eventually(Duration::from_secs(5), || plane.info().ok()).is_some());
}

/// A process that started a daemon on demand, killed when dropped (a failing test must not
/// leave it, and the daemon it watches, running for an hour).
struct Starter(std::process::Child);

impl Starter {
    /// Kills the starter and reaps it.
    fn kill(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

impl Drop for Starter {
    fn drop(&mut self) {
        self.kill();
    }
}

/// Runs `test-client MODE DOMAIN`, which starts a daemon on demand: the starter, and the
/// daemon's pid it prints.
fn start_on_demand(mode: &str, domain: &str) -> (Starter, i32) {
    let mut starter = Command::new(env!("CARGO_BIN_EXE_test-client"))
        .args([mode, domain])
        .stdout(Stdio::piped())
        .spawn()
        .unwrap();
    let mut line = String::new();
    {
        use std::io::BufRead;
        let stdout = starter.stdout.as_mut().unwrap();
        std::io::BufReader::new(stdout)
            .read_line(&mut line)
            .unwrap();
    }
    let pid: i32 = line
        .trim()
        .strip_prefix("daemon=")
        .and_then(|p| p.parse().ok())
        .unwrap_or_else(|| panic!("unexpected output {line:?}"));
    (Starter(starter), pid)
}

#[test]
fn a_daemon_started_on_demand_exits_once_its_starter_is_gone() {
    let domain = integration_tests::unique_domain("starter");
    // A process that starts a daemon on demand, then is killed without any cleanup.
    let (mut starter, pid) = start_on_demand("start-and-hold", &domain);
    starter.kill();
    // SAFETY: kill(pid, 0) only probes whether the process exists.
    let gone = eventually(Duration::from_secs(5), || {
        (unsafe { libc::kill(pid, 0) } != 0).then_some(())
    });
    assert!(
        gone.is_some(),
        "the on-demand daemon {pid} outlived its starter"
    );
    let _ = physics_daemon::cleanup_domain(&domain);
}

#[test]
fn a_daemon_started_on_demand_sleeps_without_clients_until_its_starter_exits() {
    let domain = integration_tests::unique_domain("starter-idle");
    // A process that starts a daemon on demand, says goodbye and lives on unconnected.
    let (mut starter, pid) = start_on_demand("start-and-leave", &domain);
    // The goodbye is handled and the resource guard has looked once more.
    std::thread::sleep(Duration::from_secs(2));
    let before = integration_tests::wake_ups(pid as u32);
    std::thread::sleep(Duration::from_secs(4));
    let woke = integration_tests::wake_ups(pid as u32) - before;
    // Looking for the starter at the housekeeping period (500 ms) wakes 8 times in 4 s; its
    // pidfd in the loop's WaitSet wakes it only when the starter exits. Up to 3 allows a
    // last look delayed by a loaded machine.
    assert!(
        woke <= 3,
        "an on-demand daemon without clients woke {woke} times in 4 s"
    );
    starter.kill();
    let started = Instant::now();
    // SAFETY: kill(pid, 0) only probes whether the process exists.
    let gone = eventually(Duration::from_secs(5), || {
        (unsafe { libc::kill(pid, 0) } != 0).then_some(())
    });
    assert!(
        gone.is_some(),
        "the on-demand daemon {pid} outlived its starter"
    );
    eprintln!("the daemon ended {:?} after its starter", started.elapsed());
    let _ = physics_daemon::cleanup_domain(&domain);
}

#[test]
fn stale_handles_name_the_object() {
    let daemon = TestDaemon::start("stale2");
    let client = daemon.client();
    let plane = client.create_plane(&PlaneOptions::manual()).unwrap();
    let o = plane.add(cube(), Pose::IDENTITY, &[]).unwrap();
    o.destroy();
    client.flush().unwrap();
    let fake = client_sdk::Object::from_handle(
        &plane,
        Handle {
            slot: 99,
            generation: 1,
        },
    );
    let e = command_error(fake.info().unwrap_err());
    assert_eq!(e.kind, ErrorKind::StaleHandle);
    assert!(e.message.contains("does not exist"), "{e}");
    assert!(
        e.message.contains("#99.1") && !e.message.contains("Handle {"),
        "{e}"
    );
}

#[test]
fn no_file_of_a_domain_is_writable_by_other_users() {
    let daemon = TestDaemon::start("perms");
    let client = daemon.client();
    let plane = client.create_plane(&PlaneOptions::manual()).unwrap();
    plane.step(1.0 / 60.0).unwrap();
    let files = integration_tests::domain_files(&daemon.domain);
    assert!(files.len() > 5, "{files:?}");
    for f in files {
        use std::os::unix::fs::PermissionsExt;
        let mode = std::fs::symlink_metadata(&f).unwrap().permissions().mode();
        assert_eq!(
            mode & 0o022,
            0,
            "{} is writable by others: {mode:o}",
            f.display()
        );
    }
}

#[test]
fn files_planted_by_another_user_stop_the_daemon_with_a_clear_error() {
    // SAFETY: geteuid(2) has no side effects.
    assert_eq!(
        unsafe { libc::geteuid() },
        0,
        "planting a file owned by another user needs root"
    );
    let domain = integration_tests::unique_domain("squat");
    let planted = format!(
        "/dev/shm/{}0000_node.0_10_0.global_mgmt",
        shm_layout::names::prefix(&domain)
    );
    std::fs::write(&planted, [0u8; 16]).unwrap();
    std::os::unix::fs::chown(&planted, Some(65534), Some(65534)).unwrap();
    let out = Command::new(client_sdk::daemon_executable())
        .args(["--domain", &domain])
        .env("PHYSICS_LOG", "error")
        .output()
        .unwrap();
    let _ = std::fs::remove_file(&planted);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{stderr}");
    assert!(
        stderr.contains(&planted) && stderr.contains("uid 65534"),
        "{stderr}"
    );
}

#[test]
fn more_connections_of_one_process_share_its_quotas() {
    let daemon = TestDaemon::start_with("quota-proc", &["--max-objects-per-client", "4"], &[]);
    let first = daemon.client();
    let second = daemon.client();
    let a = first.create_plane(&PlaneOptions::manual()).unwrap();
    let b = second.create_plane(&PlaneOptions::manual()).unwrap();
    for i in 0..2 {
        a.add(cube(), Pose::at([i as f32 * 2.0, 0.0, 0.0]), &[])
            .unwrap();
        b.add(cube(), Pose::at([i as f32 * 2.0, 0.0, 0.0]), &[])
            .unwrap();
    }
    let e = command_error(b.add(cube(), Pose::IDENTITY, &[]).unwrap_err());
    assert_eq!(e.kind, ErrorKind::Quota, "{e}");
}

/// Node-record directories of daemons of `domain` (their `node.details` names the daemon).
fn daemon_node_dirs(domain: &str) -> Vec<std::path::PathBuf> {
    let prefix = shm_layout::names::prefix(domain);
    integration_tests::domain_files(domain)
        .into_iter()
        .filter(|f| {
            f.file_name()
                .is_some_and(|n| n.to_string_lossy() == format!("{prefix}node.details"))
                && std::fs::read(f).is_ok_and(|d| {
                    String::from_utf8_lossy(&d).contains(shm_layout::names::DAEMON_NODE_NAME)
                })
        })
        .filter_map(|f| f.parent().map(|p| p.to_path_buf()))
        .collect()
}

#[test]
fn a_new_daemon_removes_what_a_crashed_one_left() {
    let mut crashed = TestDaemon::start("leftovers");
    let domain = crashed.domain.clone();
    let client = crashed.client();
    for _ in 0..3 {
        let plane = client.create_plane(&PlaneOptions::manual()).unwrap();
        plane.add(cube(), Pose::IDENTITY, &[]).unwrap();
        plane.step(1.0 / 60.0).unwrap();
    }
    // The daemon's nodes: the server's and its heartbeat's.
    let dead = daemon_node_dirs(&domain);
    assert!(!dead.is_empty());
    crashed.kill9();
    // A client still holds the domain open: the crash's leftovers stay until a daemon comes.
    let left = integration_tests::domain_files(&domain).len();
    assert!(dead.iter().all(|d| d.exists()));
    let mut replacement = TestDaemon::start_in(&domain);
    let after = integration_tests::domain_files(&domain).len();
    assert!(
        dead.iter().all(|d| !d.exists()),
        "the dead daemon's node records survived the restart"
    );
    assert!(
        after < left,
        "{after} files after the restart, {left} before"
    );
    drop(client);
    replacement.stop_with(libc::SIGTERM, Duration::from_secs(2));
    assert_eq!(
        integration_tests::domain_files(&domain),
        Vec::<std::path::PathBuf>::new()
    );
}

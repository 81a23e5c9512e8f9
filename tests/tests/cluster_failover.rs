//! Failover of a persistent plane in a cluster: two daemons on loopback, each in a domain and
//! a state folder of its own (as if on two hosts). A persistent plane lives on `west`; its
//! files are replicated to `east`; west is SIGKILLed; east restores the plane from the
//! newest replica, and a client opening it there finds it `Recovered` with the ticks west
//! ran past that snapshot, its ball where free fall puts it at the restored tick, and goes
//! on stepping.

use std::time::{Duration, Instant};

use client_sdk::{PlaneName, PlaneOptions, PlaneProp, Pose, Shape};
use integration_tests::cluster::{endpoint, free_port, member, unique_cluster};
use integration_tests::{eventually, unique_domain};

const DT: f32 = 1.0 / 60.0;
const G: f32 = 10.0;

/// Height after `n` ticks of free fall from `y0` at rest (4 substeps a tick, semi-implicit
/// Euler, as rapier integrates).
fn fallen(y0: f32, n: u64) -> f32 {
    let (h, m) = (DT / 4.0, 4.0 * n as f32);
    y0 - G * h * h * m * (m + 1.0) / 2.0
}

#[test]
fn a_persistent_plane_of_a_killed_member_comes_back_on_another() {
    let cluster = unique_cluster("fo");
    let state = std::env::temp_dir().join(unique_domain("fo-state"));
    let (pe, pw) = (free_port(), free_port());
    // A snapshot period long enough that the saved snapshot (tick 30) is the newest one
    // west writes.
    let flags = |who: &str| {
        let dir = state.join(who).display().to_string();
        [
            "--state-dir".to_string(),
            dir,
            "--snapshot-every".into(),
            "30".into(),
        ]
    };
    let (fe, fw) = (flags("east"), flags("west"));
    let east = member(
        &cluster,
        "east",
        pe,
        &[],
        &fe.each_ref().map(String::as_str),
    );
    let mut west = member(
        &cluster,
        "west",
        pw,
        &[pe],
        &fw.each_ref().map(String::as_str),
    );
    let view = client_sdk::cluster::Cluster::connect(&cluster, &[&endpoint(pe)]).unwrap();
    eventually(Duration::from_secs(10), || {
        (view.daemons().ok()?.len() == 2).then_some(())
    })
    .expect("both members joined");

    let client = west.client();
    let plane = client
        .create_plane(
            &PlaneOptions {
                tick_rate: Some(0.0),
                gravity: Some([0.0, -G, 0.0]),
                ..integration_tests::no_damping()
            }
            .with(PlaneProp::Name(PlaneName::new("arena").unwrap()))
            .with(PlaneProp::Persistent(true)),
        )
        .unwrap();
    let y0 = 1000.0;
    let ball = plane
        .add(Shape::Sphere { radius: 0.5 }, Pose::at([0.0, y0, 0.0]), &[])
        .unwrap();
    // What east receives, seen from a session of the test's own: the replica and the
    // newest tick record of west's plane.
    use zenoh::Wait;
    let replicated = std::sync::Arc::new(std::sync::atomic::AtomicU64::new(0));
    let recorded = std::sync::Arc::new(std::sync::atomic::AtomicU64::new(0));
    let (r1, r2) = (replicated.clone(), recorded.clone());
    let _replicas = view
        .session()
        .declare_subscriber(format!("physics/{cluster}/replica/west/arena"))
        .callback(move |s| {
            r1.store(
                s.payload().len() as u64,
                std::sync::atomic::Ordering::SeqCst,
            )
        })
        .wait()
        .unwrap();
    let _ticks = view
        .session()
        .declare_subscriber(format!("physics/{cluster}/replica-tick/west/arena"))
        .callback(move |s| {
            let b = s.payload().to_bytes();
            let tick = u64::from_le_bytes(b[..8].try_into().unwrap());
            r2.store(tick, std::sync::atomic::Ordering::SeqCst)
        })
        .wait()
        .unwrap();
    for _ in 0..30 {
        plane.step(DT).unwrap();
    }
    // Written (Save waits for the file), then replicated within a scan.
    assert_eq!(plane.save().unwrap(), 30);
    eventually(Duration::from_secs(10), || {
        (replicated.load(std::sync::atomic::Ordering::SeqCst) > 0).then_some(())
    })
    .expect("the plane file was replicated");
    // Ticks past the last replicated snapshot: recorded (every 100 ms) but not saved.
    for _ in 0..10 {
        plane.step(DT).unwrap();
    }
    eventually(Duration::from_secs(10), || {
        (recorded.load(std::sync::atomic::Ordering::SeqCst) == 40).then_some(())
    })
    .expect("west's tick record of tick 40 was replicated");
    // East got the same puts (one more scan period of margin for its callback).
    std::thread::sleep(Duration::from_millis(200));
    assert!((ball.position().unwrap()[1] - fallen(y0, 40)).abs() < 1e-2);
    drop((ball, plane, client));

    west.kill9();
    let killed = Instant::now();
    let local = east.client();
    let opened = eventually(Duration::from_secs(10), || local.open_named("arena").ok())
        .expect("east serves the plane west held");
    let took = killed.elapsed();
    eprintln!("failover: the plane opened on east {took:?} after west was killed");
    let tick = opened.plane.snapshot().unwrap().tick();
    let lost = opened.recovered.expect("the plane is Recovered");
    // It resumed from the saved snapshot, and the lost ticks are the ones west ran past it
    // (its tick record, replicated every 100 ms).
    assert_eq!(
        (tick, lost),
        (30, 10),
        "resumed at {tick}, {lost} ticks lost"
    );
    let ball = opened
        .plane
        .snapshot()
        .unwrap()
        .bodies()
        .iter()
        .find(|b| b.is_alive())
        .copied()
        .expect("the ball came back");
    assert!(
        (ball.position[1] - fallen(y0, tick)).abs() < 1e-2,
        "ball at {} after {tick} ticks, free fall says {}",
        ball.position[1],
        fallen(y0, tick)
    );
    // It goes on.
    assert_eq!(opened.plane.step(DT).unwrap(), tick + 1);
    assert!(took < Duration::from_secs(10));
    // The daemons go before their state folders.
    drop((opened, local, east, west));
    let _ = std::fs::remove_dir_all(state);
}

/// `--replicate-every N` (no `--state-dir`): a persistent plane is written, and so
/// replicated, every N of its ticks; the member that takes it over resumes at the last
/// multiple of N, not at a `Save`.
#[test]
fn a_plane_replicated_every_ten_ticks_resumes_at_the_last_tenth() {
    let cluster = unique_cluster("fo-ticks");
    let (pe, pw) = (free_port(), free_port());
    // Time-based writes out of the way: only the tick count writes.
    let flags = ["--replicate-every", "10", "--snapshot-every", "86400"];
    let east = member(&cluster, "east", pe, &[], &flags);
    let mut west = member(&cluster, "west", pw, &[pe], &flags);
    let view = client_sdk::cluster::Cluster::connect(&cluster, &[&endpoint(pe)]).unwrap();
    eventually(Duration::from_secs(10), || {
        (view.daemons().ok()?.len() == 2).then_some(())
    })
    .expect("both members joined");
    use zenoh::Wait;
    let recorded = std::sync::Arc::new(std::sync::atomic::AtomicU64::new(0));
    let r = recorded.clone();
    let _ticks = view
        .session()
        .declare_subscriber(format!("physics/{cluster}/replica-tick/west/arena"))
        .callback(move |s| {
            let b = s.payload().to_bytes();
            let tick = u64::from_le_bytes(b[..8].try_into().unwrap());
            r.store(tick, std::sync::atomic::Ordering::SeqCst)
        })
        .wait()
        .unwrap();

    let client = west.client();
    let plane = client
        .create_plane(
            &PlaneOptions {
                tick_rate: Some(0.0),
                gravity: Some([0.0, -G, 0.0]),
                ..integration_tests::no_damping()
            }
            .with(PlaneProp::Name(PlaneName::new("arena").unwrap()))
            .with(PlaneProp::Persistent(true)),
        )
        .unwrap();
    let y0 = 1000.0;
    plane
        .add(Shape::Sphere { radius: 0.5 }, Pose::at([0.0, y0, 0.0]), &[])
        .unwrap();
    for _ in 0..25 {
        plane.step(DT).unwrap();
    }
    eventually(Duration::from_secs(10), || {
        (recorded.load(std::sync::atomic::Ordering::SeqCst) == 25).then_some(())
    })
    .expect("west's tick record of tick 25 was replicated");
    // The file of tick 20 went out with or before that record; a scan period of margin.
    std::thread::sleep(Duration::from_millis(300));
    drop((plane, client));

    west.kill9();
    let local = east.client();
    let opened = eventually(Duration::from_secs(10), || local.open_named("arena").ok())
        .expect("east serves the plane west held");
    let tick = opened.plane.snapshot().unwrap().tick();
    assert_eq!(
        (tick, opened.recovered),
        (20, Some(5)),
        "resumed at the last write (every 10 ticks), 5 ticks lost"
    );
    let ball = opened
        .plane
        .snapshot()
        .unwrap()
        .bodies()
        .iter()
        .find(|b| b.is_alive())
        .copied()
        .expect("the ball came back");
    assert!((ball.position[1] - fallen(y0, 20)).abs() < 1e-2);
    assert_eq!(opened.plane.step(DT).unwrap(), 21);
    let dirs = [east.domain.clone(), west.domain.clone()];
    drop((opened, local, east, west));
    for d in dirs {
        let _ = std::fs::remove_dir_all(
            std::env::temp_dir()
                .join(physics_daemon::server::persist::REPLICA_DIR)
                .join(d),
        );
    }
}

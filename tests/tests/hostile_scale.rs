//! Hostile clients at scale, through real daemon processes: each test is one attack that
//! used to exhaust the daemon or starve other clients, at a size that runs in seconds in a
//! debug build yet fails the old code. Reply amplification (overlap queries capped, paged
//! and counted), queries off the request loop and bounded per request, the quota race of
//! many connections, controller paths counted against a quota, objects added to another's
//! shared plane counted against the adder, planes slower than 1 Hz, `Threads` capped by
//! cores, planes admitted within the daemon's memory, fair CPU shares between clients, and
//! a client connection's shared memory.

use std::sync::{Arc, Barrier};
use std::time::{Duration, Instant};

use client_sdk::{
    Client, ErrorKind, FilterType, Handle, PlaneOptions, PlaneProp, Pose, QueryParams, Ray, Shape,
};
use integration_tests::TestDaemon;
use shm_layout::codec::{decode_response, encode_request};
use shm_layout::query::{MAX_QUERY_RESULTS, MAX_RAY_WORK};
use shm_layout::{
    Command as Cmd, CommandResult, PlaneId, PlaneOp, QueryFilter, QueryOp, Reply, Request, Response,
};

fn send(client: &Client, commands: Vec<Cmd>) -> (Vec<CommandResult>, usize) {
    let bytes = client
        .raw_request(&encode_request(&Request { commands }))
        .expect("request answered");
    let len = bytes.len();
    match decode_response(&bytes).expect("decodable reply") {
        Response::Results(r) => (r, len),
        Response::Rejected(e) => panic!("rejected: {e}"),
    }
}

fn cube() -> Shape {
    Shape::Cube { size: [0.5; 3] }
}

/// `n` cubes of 0.5 on a grid of spacing 1 (x fastest, 20 per row, 20 rows per layer).
fn add_grid(client: &Client, plane: PlaneId, n: usize) {
    let commands = (0..n)
        .map(|i| {
            let at = [(i % 20) as f32, ((i / 400) as f32), ((i / 20) % 20) as f32];
            Cmd::plane(
                plane,
                PlaneOp::AddObject {
                    shape: cube(),
                    pose: Pose::at(at),
                    props: vec![],
                },
            )
        })
        .collect();
    let (results, _) = send(client, commands);
    assert!(results.iter().all(|r| r.is_ok()), "adds refused");
}

fn everything() -> QueryOp {
    QueryOp::BoundsInRadius {
        position: [10.0, 10.0, 10.0],
        radius: 1_000.0,
        filter: QueryFilter::default(),
    }
}

/// 5,000 objects in reach of one query. The old daemon answered each query with all of
/// them, so a request of many such queries grew the reply ~1,000× the request.
#[test]
fn overlap_replies_are_capped_paged_and_counted() {
    const N: usize = 5_000;
    const REPLY: usize = 200_000;
    let daemon = TestDaemon::start_with(
        "hostile-reply",
        &["--max-reply-bytes", &REPLY.to_string()],
        &[],
    );
    let client = daemon.client();
    let plane = client.create_plane(&PlaneOptions::manual()).unwrap();
    add_grid(&client, plane.id(), N);

    // One query: the first MAX_QUERY_RESULTS by slot, flagged as truncated.
    let (r, _) = send(
        &client,
        vec![Cmd::plane(plane.id(), PlaneOp::Query(everything()))],
    );
    let Ok(Reply::ObjectPage { objects, truncated }) = &r[0] else {
        panic!(
            "expected a truncated page, got {:?}",
            r[0].as_ref().map(|_| ())
        );
    };
    assert!(*truncated);
    assert_eq!(objects.len(), MAX_QUERY_RESULTS);
    assert!(objects.windows(2).all(|w| w[0].slot < w[1].slot));

    // The next page starts after the last slot and ends the list.
    let page = QueryOp::Page {
        query: Box::new(everything()),
        after_slot: objects.last().unwrap().slot,
    };
    let (r, _) = send(&client, vec![Cmd::plane(plane.id(), PlaneOp::Query(page))]);
    let Ok(Reply::ObjectPage {
        objects: rest,
        truncated: false,
    }) = &r[0]
    else {
        panic!("expected the last page");
    };
    assert_eq!(rest.len(), N - MAX_QUERY_RESULTS);

    // The SDK follows the pages: every object, once, ascending.
    let all = plane.bounds_in_radius([10.0; 3], 1_000.0, None).unwrap();
    assert_eq!(all.len(), N);
    assert!(all.windows(2).all(|w| w[0].slot < w[1].slot));
    // MaxParts cuts the list and says so; a MaxParts above the count does not.
    let some = plane
        .bounds_in_radius_found(
            [10.0; 3],
            1_000.0,
            Some(&QueryParams {
                max_parts: 100,
                ..QueryParams::default()
            }),
        )
        .unwrap();
    assert_eq!((some.objects.len(), some.truncated), (100, true));
    assert_eq!(some.objects[..], all[..100]);
    let whole = plane
        .bounds_in_radius_found(
            [10.0; 3],
            1_000.0,
            Some(&QueryParams {
                max_parts: N + 1,
                ..QueryParams::default()
            }),
        )
        .unwrap();
    assert_eq!((whole.objects.len(), whole.truncated), (N, false));

    // 50 queries in one request: the reply stays within --max-reply-bytes (plus the small
    // refusals), the queries past it are refused naming the flag, and the daemon serves on.
    let commands = (0..50)
        .map(|_| Cmd::plane(plane.id(), PlaneOp::Query(everything())))
        .collect();
    let (r, bytes) = send(&client, commands);
    let answered = r.iter().filter(|r| r.is_ok()).count();
    let refused: Vec<_> = r.iter().filter_map(|r| r.as_ref().err()).collect();
    assert!(bytes <= REPLY + 50 * 256, "reply of {bytes} bytes");
    assert!(answered >= 1 && !refused.is_empty(), "{answered} answered");
    for e in refused {
        assert_eq!(e.kind, ErrorKind::Quota, "{e}");
        assert!(e.message.contains("--max-reply-bytes"), "{e}");
    }
    assert_eq!(plane.info().unwrap().object_count, N as u32);
}

/// A raycast whose work (rays × filter) passes MAX_RAY_WORK is refused naming `rays`, by
/// the SDK and by the daemon on its own.
#[test]
fn raycasts_past_the_work_bound_are_refused() {
    let daemon = TestDaemon::start("hostile-rays");
    let client = daemon.client();
    let plane = client.create_plane(&PlaneOptions::manual()).unwrap();
    let rays = vec![
        Ray {
            origin: [0.0; 3],
            direction: [1.0, 0.0, 0.0],
        };
        65_536
    ];
    let filter: Vec<Handle> = (0..10_000)
        .map(|slot| Handle {
            slot,
            generation: 1,
        })
        .collect();
    let params = QueryParams {
        filter: filter.clone(),
        ..QueryParams::default()
    };
    let e = plane.raycast_many(&rays, Some(&params)).unwrap_err();
    assert!(e.to_string().contains("rays"), "{e}");
    let op = QueryOp::Raycast {
        rays,
        filter: QueryFilter {
            list: filter,
            ..QueryFilter::default()
        },
    };
    let started = Instant::now();
    let (r, _) = send(&client, vec![Cmd::plane(plane.id(), PlaneOp::Query(op))]);
    let e = r[0].as_ref().unwrap_err();
    assert_eq!(e.kind, ErrorKind::InvalidValue, "{e}");
    assert_eq!(e.field.as_deref(), Some("rays"), "{e}");
    assert!(
        e.message.contains(&MAX_RAY_WORK.to_string()) && e.message.contains("10000"),
        "{e}"
    );
    assert!(started.elapsed() < Duration::from_secs(5));
}

fn percentile(mut v: Vec<Duration>, p: f64) -> Duration {
    v.sort();
    v[((v.len() - 1) as f64 * p).round() as usize]
}

/// One client casts heavy rays (each passes 1,000 excluded objects) on its own plane while
/// another steps its own. Queries used to run on the request loop: the other client's Step
/// waited for the whole query request. Now they run on the querying plane's worker.
#[test]
fn a_heavy_query_does_not_stall_another_clients_step() {
    let daemon = TestDaemon::start("hostile-stall");
    let victim = daemon.client();
    let mine = victim.create_plane(&PlaneOptions::manual()).unwrap();
    mine.add(cube(), Pose::IDENTITY, &[]).unwrap();
    let step = |n: usize| -> Vec<Duration> {
        (0..n)
            .map(|_| {
                let t = Instant::now();
                mine.step(1.0 / 60.0).unwrap();
                t.elapsed()
            })
            .collect()
    };
    let alone = step(40);

    let domain = daemon.domain.clone();
    let stop = Arc::new(std::sync::atomic::AtomicBool::new(false));
    let ready = Arc::new(Barrier::new(2));
    let attacker = {
        let (stop, ready) = (stop.clone(), ready.clone());
        std::thread::spawn(move || {
            let client = Client::connect(&domain).unwrap();
            let plane = client.create_plane(&PlaneOptions::manual()).unwrap();
            // 1,000 cubes in a row along x; every ray passes all of them.
            let commands = (0..1_000)
                .map(|i| {
                    Cmd::plane(
                        plane.id(),
                        PlaneOp::AddObject {
                            shape: cube(),
                            pose: Pose::at([i as f32, 0.0, 0.0]),
                            props: vec![],
                        },
                    )
                })
                .collect();
            let (added, _) = send(&client, commands);
            let list: Vec<Handle> = added
                .iter()
                .map(|r| match r {
                    Ok(Reply::Object { handle, .. }) => *handle,
                    other => panic!("add: {other:?}"),
                })
                .collect();
            let rays = MAX_RAY_WORK / (1 + list.len());
            let op = QueryOp::Raycast {
                rays: vec![
                    Ray {
                        origin: [-1.0, 0.0, 0.0],
                        direction: [2_000.0, 0.0, 0.0],
                    };
                    rays
                ],
                filter: QueryFilter {
                    filter_type: FilterType::Exclude,
                    list,
                    ..QueryFilter::default()
                },
            };
            let mut took = Vec::new();
            ready.wait();
            while !stop.load(std::sync::atomic::Ordering::Relaxed) || took.is_empty() {
                let t = Instant::now();
                let (r, _) = send(
                    &client,
                    vec![Cmd::plane(plane.id(), PlaneOp::Query(op.clone()))],
                );
                assert!(matches!(&r[0], Ok(Reply::Hits(h)) if h.iter().all(|h| h.is_none())));
                took.push(t.elapsed());
            }
            took
        })
    };
    ready.wait();
    // Let the first query request start.
    std::thread::sleep(Duration::from_millis(50));
    let during = step(40);
    stop.store(true, std::sync::atomic::Ordering::Relaxed);
    let took = attacker.join().unwrap();
    let query = took.iter().min().copied().unwrap();
    let (alone99, during99) = (
        percentile(alone.clone(), 0.99),
        percentile(during.clone(), 0.99),
    );
    eprintln!(
        "step alone p50 {:?} p99 {alone99:?}; during the attack p50 {:?} p99 {during99:?}; \
         one query request {query:?}",
        percentile(alone, 0.5),
        percentile(during, 0.5),
    );
    // The attack is real: one request holds its plane for a while.
    assert!(query > Duration::from_millis(100), "query took {query:?}");
    // The victim's steps never wait for it (2 cores are shared with the querying worker:
    // a step may wait for a time slice, never for a whole query request).
    assert!(
        during99 < query / 2 && during99 <= (alone99 * 2).max(Duration::from_millis(30)),
        "step p99 {during99:?} while a query request takes {query:?} (alone {alone99:?})"
    );
}

/// Eight connections of one process add at once, each past the whole quota; the quota is
/// reserved atomically, so exactly the quota is accepted (it was 8× before). Destroyed
/// planes give their objects back.
#[test]
fn connections_of_one_process_cannot_race_past_the_object_quota() {
    const QUOTA: usize = 2_000;
    let daemon = TestDaemon::start_with(
        "hostile-race",
        &["--max-objects-per-client", &QUOTA.to_string()],
        &[],
    );
    let run = || -> usize {
        let ready = Arc::new(Barrier::new(8));
        let done = Arc::new(Barrier::new(8));
        let threads: Vec<_> = (0..8)
            .map(|_| {
                let (domain, ready, done) = (daemon.domain.clone(), ready.clone(), done.clone());
                std::thread::spawn(move || {
                    let client = Client::connect(&domain).unwrap();
                    let plane = client.create_plane(&PlaneOptions::manual()).unwrap();
                    // A Step first hands the whole run to the plane's worker: eight runs
                    // apply in parallel.
                    let mut commands = vec![Cmd::plane(plane.id(), PlaneOp::Step { dt: 0.01 })];
                    commands.extend((0..QUOTA).map(|i| {
                        Cmd::plane(
                            plane.id(),
                            PlaneOp::AddObject {
                                shape: cube(),
                                pose: Pose::at([i as f32, 0.0, 0.0]),
                                props: vec![],
                            },
                        )
                    }));
                    ready.wait();
                    let (r, _) = send(&client, commands);
                    for e in r.iter().filter_map(|r| r.as_ref().err()) {
                        assert_eq!(e.kind, ErrorKind::Quota, "{e}");
                        assert!(e.message.contains("--max-objects-per-client"), "{e}");
                    }
                    let accepted = r.iter().skip(1).filter(|r| r.is_ok()).count();
                    // Only once every run is answered: a destroyed plane gives its objects
                    // back, and the others could then add them.
                    done.wait();
                    plane.destroy().unwrap();
                    accepted
                })
            })
            .collect();
        threads.into_iter().map(|t| t.join().unwrap()).sum()
    };
    assert_eq!(run(), QUOTA, "accepted past the quota");
    // The destroyed planes released their count (their workers drop them shortly after).
    let again = integration_tests::eventually(Duration::from_secs(5), || {
        let client = daemon.client();
        let plane = client.create_plane(&PlaneOptions::manual()).unwrap();
        let commands = (0..QUOTA)
            .map(|i| {
                Cmd::plane(
                    plane.id(),
                    PlaneOp::AddObject {
                        shape: cube(),
                        pose: Pose::at([i as f32, 0.0, 0.0]),
                        props: vec![],
                    },
                )
            })
            .collect();
        let (r, _) = send(&client, commands);
        let ok = r.iter().all(|r| r.is_ok());
        plane.destroy().unwrap();
        ok.then_some(())
    });
    assert!(again.is_some(), "the quota never came back");
}

/// TickRate 0.5 and 0.9 used to be accepted and never tick ("dt must be at most 1 s").
/// Such a plane now steps each period in equal pieces of at most 1 s.
#[test]
fn planes_slower_than_one_hertz_tick() {
    const G: f32 = 10.0;
    let daemon = TestDaemon::start("hostile-slow");
    let client = daemon.client();
    let planes: Vec<_> = [0.9f32, 0.5]
        .iter()
        .map(|&rate| {
            let plane = client
                .create_plane(&PlaneOptions {
                    tick_rate: Some(rate),
                    gravity: Some([0.0, -G, 0.0]),
                    linear_damping: Some(0.0),
                    ..PlaneOptions::default()
                })
                .unwrap();
            let ball = plane
                .add(
                    Shape::Sphere { radius: 0.5 },
                    Pose::at([0.0, 100.0, 0.0]),
                    &[],
                )
                .unwrap();
            (rate, plane, ball)
        })
        .collect();
    client.flush().unwrap();
    for (rate, plane, ball) in &planes {
        let period = 1.0 / *rate as f64;
        let tick = plane
            .wait_tick(Duration::from_secs_f64(period * 2.0 + 1.0))
            .unwrap_or_else(|e| panic!("TickRate {rate} never ticked: {e}"));
        assert!(tick >= 1, "TickRate {rate}: tick {tick}");
        // Free fall from rest: after any number of steps, v = -g · (time simulated), and
        // each step simulates period / ceil(period) seconds (pieces of at most 1 s).
        let snapshot = plane.snapshot().unwrap();
        let tick = snapshot.tick();
        let dt = period / period.ceil();
        let v = snapshot.get(ball.handle()).unwrap().linear_velocity[1];
        let expected = -(G as f64 * dt * tick as f64) as f32;
        assert!(
            (v - expected).abs() <= 1e-4 * expected.abs(),
            "TickRate {rate}: v {v} after {tick} steps, expected {expected}"
        );
    }
}

/// `Threads` reads back as what the plane uses (capped by cores), and planes of the same
/// size share one pool: 8 planes asking for 64 threads no longer start 512.
#[test]
fn threads_are_capped_by_cores() {
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get()) as u32;
    let daemon = TestDaemon::start("hostile-threads");
    let threads_of = |pid: u32| {
        std::fs::read_dir(format!("/proc/{pid}/task"))
            .map(|d| d.count())
            .unwrap_or(0)
    };
    let client = daemon.client();
    let before = threads_of(daemon.pid());
    let planes: Vec<_> = (0..8)
        .map(|_| {
            client
                .create_plane(&PlaneOptions {
                    threads: Some(64),
                    ..PlaneOptions::manual()
                })
                .unwrap()
        })
        .collect();
    for plane in &planes {
        assert_eq!(plane.info().unwrap().settings.threads, 64.min(cores));
        plane.step(0.01).unwrap();
    }
    let after = threads_of(daemon.pid());
    // One worker per plane, plus one shared pool of at most `cores` threads.
    assert!(
        after <= before + 8 + cores as usize,
        "{before} threads before, {after} after 8 planes × Threads 64 on {cores} cores"
    );
    // A plane's own settings read the same.
    let one = client
        .create_plane(&PlaneOptions {
            threads: Some(1),
            ..PlaneOptions::manual()
        })
        .unwrap();
    assert_eq!(one.info().unwrap().settings.threads, 1);
    one.set(PlaneProp::TickRate(0.0)).unwrap();
}

/// Controller paths used to be counted nowhere (9,000 controllers × 65,536 waypoints took
/// the daemon down). Their bytes now count against `--max-state-bytes-per-client`, and a
/// cleared path gives them back.
#[test]
fn controller_paths_count_against_the_state_quota() {
    const POINTS: usize = shm_layout::controller_op::MAX_WAYPOINTS;
    // Room for one full path (12 bytes a point), not two.
    let quota = (12 * POINTS * 3 / 2).to_string();
    let daemon = TestDaemon::start_with(
        "hostile-paths",
        &["--max-state-bytes-per-client", &quota],
        &[],
    );
    let client = daemon.client();
    let plane = client.create_plane(&PlaneOptions::manual()).unwrap();
    let new = |x: f32| {
        plane
            .new_controller(Pose::at([x, 0.0, 0.0]), [2.0, 5.0, 2.0], false, &[])
            .unwrap()
    };
    let (a, b) = (new(0.0), new(10.0));
    let path: Vec<[f32; 3]> = (0..POINTS).map(|i| [i as f32 * 0.01, 0.0, 100.0]).collect();
    let set_path = |c: &client_sdk::Controller| {
        let op = shm_layout::ControllerOp::SetPath {
            handle: c.handle(),
            waypoints: path.clone(),
        };
        let (r, _) = send(
            &client,
            vec![Cmd::plane(plane.id(), PlaneOp::Controller(op))],
        );
        r.into_iter().next().unwrap()
    };
    set_path(&a).expect("the first path fits");
    let e = set_path(&b).expect_err("a second full path passes the quota");
    assert_eq!(e.kind, ErrorKind::Quota, "{e}");
    assert!(e.message.contains("--max-state-bytes-per-client"), "{e}");
    // A stopped controller frees its path; the other one's path then fits.
    a.stop_walking().unwrap();
    client.flush().unwrap();
    set_path(&b).expect("the freed bytes are counted back");
    // Appending one point at a time counts too (the buffer grows by doubling, so the count
    // may pass the quota by what one growth adds; the next append is then refused).
    let appends = (0..POINTS)
        .map(|i| {
            let op = shm_layout::ControllerOp::AppendWaypoint {
                handle: a.handle(),
                point: [i as f32, 0.0, 0.0],
            };
            Cmd::plane(plane.id(), PlaneOp::Controller(op))
        })
        .collect();
    let (r, _) = send(&client, appends);
    let refused = r
        .iter()
        .position(|r| r.is_err())
        .expect("appends pass the quota");
    assert!(refused < POINTS / 2 + 1, "{refused} points appended");
    let e = r[refused].as_ref().unwrap_err();
    assert!(e.message.contains("--max-state-bytes-per-client"), "{e}");
}

/// A non-owner used to fill a `Shared` plane with objects that counted against the owner, so
/// the owner's next add to its own plane was refused. Now they count against the adder, the
/// owner's SharedObjectLimit caps them, and they stop counting once destroyed.
#[test]
fn objects_added_to_a_shared_plane_count_against_the_adder() {
    use std::io::{BufRead, BufReader, Write};
    const QUOTA: u32 = 100;
    const LIMIT: u32 = 60;
    let daemon = TestDaemon::start_with(
        "hostile-shared",
        &["--max-objects-per-client", &QUOTA.to_string()],
        &[],
    );
    let mut owner = std::process::Command::new(env!("CARGO_BIN_EXE_test-client"))
        .args([
            "share",
            &daemon.domain,
            &LIMIT.to_string(),
            &QUOTA.to_string(),
        ])
        .stdin(std::process::Stdio::piped())
        .stdout(std::process::Stdio::piped())
        .spawn()
        .expect("spawn test-client");
    let mut lines = BufReader::new(owner.stdout.take().unwrap()).lines();
    let mut line = || lines.next().expect("a line").expect("readable");
    let plane_id: PlaneId = line().strip_prefix("plane=").unwrap().parse().unwrap();

    let guest = daemon.client();
    let shared = guest.attach_plane(plane_id).unwrap();
    assert_eq!(shared.info().unwrap().settings.shared_object_limit, LIMIT);
    let e = shared
        .set(PlaneProp::SharedObjectLimit(1_000))
        .and_then(|_| guest.flush())
        .unwrap_err();
    assert!(e.to_string().contains("SharedObjectLimit"), "{e}");
    // The guest adds past the owner's limit: LIMIT are accepted.
    let adds = (0..LIMIT + 10)
        .map(|i| {
            Cmd::plane(
                plane_id,
                PlaneOp::AddObject {
                    shape: cube(),
                    pose: Pose::at([i as f32, 0.0, 0.0]),
                    props: vec![],
                },
            )
        })
        .collect();
    let (r, _) = send(&guest, adds);
    let added: Vec<Handle> = r
        .iter()
        .filter_map(|r| match r {
            Ok(Reply::Object { handle, .. }) => Some(*handle),
            _ => None,
        })
        .collect();
    assert_eq!(added.len(), LIMIT as usize);
    let e = r[LIMIT as usize].as_ref().unwrap_err();
    assert_eq!(e.kind, ErrorKind::Quota, "{e}");
    assert!(e.message.contains("SharedObjectLimit"), "{e}");

    // The owner still has its whole quota for its own plane.
    owner.stdin.as_mut().unwrap().write_all(b"go\n").unwrap();
    assert_eq!(line(), format!("added={QUOTA}"));

    // The guest paid for them: its own plane takes only the rest of its quota.
    let own = guest.create_plane(&PlaneOptions::manual()).unwrap();
    let fill = |n: u32| {
        let adds = (0..n)
            .map(|i| {
                Cmd::plane(
                    own.id(),
                    PlaneOp::AddObject {
                        shape: cube(),
                        pose: Pose::at([i as f32, 0.0, 0.0]),
                        props: vec![],
                    },
                )
            })
            .collect();
        let (r, _) = send(&guest, adds);
        r.iter().filter(|r| r.is_ok()).count() as u32
    };
    assert_eq!(fill(QUOTA), QUOTA - LIMIT);
    // Destroyed, they stop counting for it.
    let destroys = added
        .iter()
        .map(|h| {
            Cmd::plane(
                plane_id,
                PlaneOp::Object {
                    handle: *h,
                    op: shm_layout::ObjectOp::Destroy,
                },
            )
        })
        .collect();
    let (r, _) = send(&guest, destroys);
    assert!(r.iter().all(|r| r.is_ok()));
    assert_eq!(fill(QUOTA), LIMIT);
    let _ = owner.kill();
    let _ = owner.wait();
}

fn rss_bytes(pid: u32) -> u64 {
    let status = std::fs::read_to_string(format!("/proc/{pid}/status")).unwrap();
    let kib: u64 = status
        .lines()
        .find(|l| l.starts_with("VmRSS:"))
        .and_then(|l| l.split_whitespace().nth(1))
        .and_then(|n| n.parse().ok())
        .unwrap();
    kib * 1024
}

/// Empty planes cost ~10 MB each (now ~1.8 MB: see `PLANE_BYTES`), so many processes each
/// creating planes up to their quota took the daemon down long before its 1,024-plane cap.
/// Now the daemon admits planes (and what they hold) only within `--max-memory-mb`, counting
/// each plane as PLANE_BYTES, which the measured cost must stay under.
#[test]
fn planes_are_admitted_within_the_daemon_memory_budget() {
    use physics_daemon::server::quota::PLANE_BYTES;
    let fit = 5u64;
    let mb = (fit * PLANE_BYTES + PLANE_BYTES / 2) >> 20;
    let daemon =
        TestDaemon::start_with("hostile-memory", &["--max-memory-mb", &mb.to_string()], &[]);
    let first = daemon.client();
    let second = daemon.client();
    let before = rss_bytes(daemon.pid());
    let mut planes: Vec<_> = (0..fit)
        .map(|i| {
            let c = if i % 2 == 0 { &first } else { &second };
            c.create_plane(&PlaneOptions::manual()).unwrap()
        })
        .collect();
    std::thread::sleep(Duration::from_millis(200));
    let per_plane = (rss_bytes(daemon.pid()) - before) / fit;
    eprintln!("an empty plane costs the daemon {} KiB", per_plane >> 10);
    assert!(
        per_plane <= PLANE_BYTES,
        "an empty plane costs {per_plane} bytes, counted as {PLANE_BYTES}"
    );
    // Full: the next plane is refused, naming the flag, whoever asks.
    let e = second.create_plane(&PlaneOptions::manual()).unwrap_err();
    assert!(e.to_string().contains("--max-memory-mb"), "{e}");
    // Objects count too: a plane's worth of cubes does not fit in the half plane left.
    let objects = (PLANE_BYTES / physics_daemon::server::quota::OBJECT_BYTES) as usize;
    let adds = (0..objects)
        .map(|i| {
            Cmd::plane(
                planes[0].id(),
                PlaneOp::AddObject {
                    shape: cube(),
                    pose: Pose::at([i as f32, 0.0, 0.0]),
                    props: vec![],
                },
            )
        })
        .collect();
    let (r, _) = send(&first, adds);
    let refused = r.iter().filter(|r| r.is_err()).count();
    assert!(
        refused > 0 && refused < objects,
        "{refused} of {objects} refused"
    );
    // A destroyed plane gives its room back.
    planes.pop().unwrap().destroy().unwrap();
    let again = integration_tests::eventually(Duration::from_secs(5), || {
        second.create_plane(&PlaneOptions::manual()).ok()
    });
    assert!(again.is_some(), "the room never came back");
}

/// One process ticks 32 planes as fast as it may (TickRate 10,000) while another steps its
/// own plane. The busy process used to take every core; now each process gets its fair
/// CPU share (cores / processes) and a process past it slows its own planes only.
#[test]
fn a_process_past_its_cpu_share_slows_itself_not_others() {
    use std::io::{BufRead, BufReader};
    let daemon = TestDaemon::start("hostile-cpu");
    let victim = daemon.client();
    let mine = victim.create_plane(&PlaneOptions::manual()).unwrap();
    for i in 0..20 {
        mine.add(cube(), Pose::at([i as f32, 0.0, 0.0]), &[])
            .unwrap();
    }
    let step = |n: usize| -> Vec<Duration> {
        (0..n)
            .map(|_| {
                let t = Instant::now();
                mine.step(1.0 / 60.0).unwrap();
                let took = t.elapsed();
                std::thread::sleep(Duration::from_millis(5));
                took
            })
            .collect()
    };
    let alone = step(60);
    let mut hog = std::process::Command::new(env!("CARGO_BIN_EXE_test-client"))
        .args(["burn", &daemon.domain, "32", "10000"])
        .stdout(std::process::Stdio::piped())
        .spawn()
        .expect("spawn test-client");
    let mut lines = BufReader::new(hog.stdout.take().unwrap()).lines();
    assert_eq!(lines.next().unwrap().unwrap(), "ready");
    std::thread::sleep(Duration::from_millis(500));
    let during = step(60);
    let _ = hog.kill();
    let _ = hog.wait();
    let (a50, a99) = (percentile(alone.clone(), 0.5), percentile(alone, 0.99));
    let (d50, d99) = (percentile(during.clone(), 0.5), percentile(during, 0.99));
    eprintln!("step alone p50 {a50:?} p99 {a99:?}; beside the hog p50 {d50:?} p99 {d99:?}");
    // 2 cores shared with the hog's threads: a step may wait for a time slice, not for the
    // hog's backlog.
    assert!(
        // Before: 11 ms (p99 350 ms). A busy machine alone gives 3.8 ms.
        d50 <= (a50 * 3).max(Duration::from_millis(8)),
        "p50 {d50:?} beside the hog, {a50:?} alone"
    );
    assert!(
        // Before: 350 ms (max 1.8 s). A machine busy with builds gave 31.5 ms.
        d99 <= (a99 * 3).max(Duration::from_millis(100)),
        "p99 {d99:?} beside the hog, {a99:?} alone"
    );
}

/// Holds `n` clients in a process of its own (`test-client clients`); returns the process
/// and what it printed: how many it holds and the first refusal, if any.
fn client_holder(domain: &str, n: usize) -> (std::process::Child, usize, Option<String>) {
    use std::io::BufRead;
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_test-client"))
        .args(["clients", domain, &n.to_string()])
        .stdout(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let mut refused = None;
    let mut lines = std::io::BufReader::new(child.stdout.take().unwrap()).lines();
    for line in lines.by_ref() {
        let line = line.unwrap();
        if let Some(e) = line.strip_prefix("refused=") {
            refused = Some(e.to_string());
        }
        if let Some(k) = line.strip_prefix("connected=") {
            return (child, k.parse().unwrap(), refused);
        }
    }
    let _ = child.kill();
    let status = child.wait();
    panic!("test-client clients {n} ended without a count ({status:?}, refused: {refused:?})");
}

/// With a 64-client table and 16 clients a process, four processes filled the daemon and
/// every other process was refused. The table now holds `--max-clients` (256) and a
/// process at most `--max-clients-per-process` (16): four full processes leave room, and
/// a table sized down by the flag is enforced, naming it.
#[test]
fn four_processes_of_sixteen_clients_leave_room_for_another() {
    let daemon = TestDaemon::start("client-table");
    let mut holders: Vec<_> = (0..4).map(|_| client_holder(&daemon.domain, 17)).collect();
    for (_, held, refused) in &holders {
        assert_eq!(
            *held, 16,
            "a process holds 16 clients (refused: {refused:?})"
        );
        let e = refused.as_deref().unwrap_or_default();
        assert!(e.contains("--max-clients-per-process"), "{e}");
    }
    // 64 clients are connected; another process (this one) still gets in and is served.
    let late = daemon.client();
    let plane = late.create_plane(&PlaneOptions::manual()).unwrap();
    plane.step(1.0 / 60.0).unwrap();
    for (child, _, _) in &mut holders {
        let _ = child.kill();
        let _ = child.wait();
    }

    // The table itself: 8 clients at most, 4 a process: two processes fill it, a third
    // process is refused with the flag named, and gets in once one of them is gone.
    let small = TestDaemon::start_with(
        "table-small",
        &["--max-clients", "8", "--max-clients-per-process", "4"],
        &[],
    );
    let mut full: Vec<_> = (0..2).map(|_| client_holder(&small.domain, 4)).collect();
    assert!(full.iter().all(|(_, held, _)| *held == 4));
    match Client::connect(&small.domain) {
        Err(client_sdk::Error::Command(e)) => {
            assert_eq!(e.kind, ErrorKind::Quota);
            assert!(e.message.contains("(daemon flag --max-clients)"), "{e}");
            assert!(e.message.contains("limited to 8"), "{e}");
        }
        other => panic!("a ninth client connected to an 8-client table: {other:?}"),
    }
    let (mut gone, _, _) = full.pop().unwrap();
    let _ = gone.kill();
    let _ = gone.wait();
    // The daemon notices the dead process within its housekeeping period.
    let back = integration_tests::eventually(Duration::from_secs(5), || {
        Client::connect(&small.domain).ok()
    });
    assert!(back.is_some(), "room came back once a process died");
    for (child, _, _) in &mut full {
        let _ = child.kill();
        let _ = child.wait();
    }
}

/// Bytes of the domain's shared-memory files actually backed by memory (allocated blocks).
fn shm_backed_bytes(domain: &str) -> u64 {
    use std::os::unix::fs::MetadataExt;
    integration_tests::domain_files(domain)
        .iter()
        .filter(|p| p.starts_with("/dev/shm"))
        .filter_map(|p| std::fs::metadata(p).ok())
        .map(|m| m.blocks() * 512)
        .sum()
}

/// Each client's reply connection spans every growth segment of the daemon's reply memory
/// (255) and every request slot (4), one flag per reply chunk: 31 MB, every byte written
/// when the connection was made (and swept again when it closed). A process holding 16
/// clients cost the machine ~490 MB of shared memory; 256 clients, 7.9 GB. Now a new
/// connection's zeroed memory is left untouched (`tests/tests/connection_memory.rs` checks
/// the connection itself, and the sweep).
#[test]
fn a_client_connection_costs_kilobytes_of_shared_memory() {
    let daemon = TestDaemon::start_with("conn-cost", &["--max-clients-per-process", "32"], &[]);
    let first = daemon.client();
    let plane = first.create_plane(&PlaneOptions::manual()).unwrap();
    plane.step(1.0 / 60.0).unwrap();
    let before = shm_backed_bytes(&daemon.domain);
    // 16 more clients, each with a plane: every reply connection carried replies.
    let others: Vec<Client> = (0..16).map(|_| daemon.client()).collect();
    let planes: Vec<_> = others
        .iter()
        .map(|c| c.create_plane(&PlaneOptions::manual()).unwrap())
        .collect();
    let grown = shm_backed_bytes(&daemon.domain).saturating_sub(before);
    eprintln!(
        "16 clients: {} KiB of shared memory backed ({} KiB each)",
        grown / 1024,
        grown / 16 / 1024
    );
    assert!(
        grown < 16 * 1024 * 1024,
        "16 clients backed {} KiB of shared memory ({} KiB each; 31 MB each before)",
        grown / 1024,
        grown / 16 / 1024
    );
    drop(planes);
    drop(others);
    plane.step(1.0 / 60.0).unwrap();
}

//! Named and persistent planes through real daemons: names unique per domain, `ListPlanes`,
//! `Open` (owner or not), persistent planes that outlive their owner, a daemon killed with
//! SIGKILL whose successor (same `--state-dir`) resumes each persistent plane from its last
//! snapshot (same tick, same state hash, same poses, and the next tick's hash equal to the
//! first run's), `Recovered` lost ticks, kills during writes that never leave half a file,
//! and damaged files skipped with an error naming them.

use std::path::{Path, PathBuf};
use std::time::Duration;

use client_sdk::{
    Error, ErrorKind, Object, Plane, PlaneKind, PlaneName, PlaneOptions, PlaneProp, PlaneSnapshot,
    Pose, Shape,
};
use integration_tests::{eventually, unique_domain, TestDaemon};

const DT: f32 = 1.0 / 60.0;

/// The two tests whose daemons tick on their own (one of them a big plane written 20 times
/// a second) take turns: on a loaded 2-core machine they would starve each other's
/// connections.
static TICKING: std::sync::Mutex<()> = std::sync::Mutex::new(());

fn ticking() -> std::sync::MutexGuard<'static, ()> {
    TICKING.lock().unwrap_or_else(|p| p.into_inner())
}

/// A state directory of its own, removed at the end.
struct StateDir(PathBuf);

impl StateDir {
    fn new(tag: &str) -> StateDir {
        let dir = std::env::temp_dir().join(unique_domain(&format!("state-{tag}")));
        std::fs::create_dir_all(&dir).unwrap();
        StateDir(dir)
    }

    fn path(&self) -> &str {
        self.0.to_str().unwrap()
    }

    /// The domain's folder.
    fn domain(&self, domain: &str) -> PathBuf {
        self.0.join(domain)
    }
}

impl Drop for StateDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

fn named(name: &str) -> PlaneOptions {
    PlaneOptions::manual().with(PlaneProp::Name(PlaneName::new(name).unwrap()))
}

fn persistent(name: &str) -> PlaneOptions {
    named(name).with(PlaneProp::Persistent(true))
}

/// A floor and `n` boxes dropped in a grid, a few of them spinning.
fn fill(plane: &Plane, n: usize) -> Vec<Object> {
    plane
        .add(
            Shape::Cube {
                size: [80.0, 1.0, 80.0],
            },
            Pose::at([0.0, -0.5, 0.0]),
            &[client_sdk::ObjectProp::Anchored(true)],
        )
        .unwrap();
    let side = (n as f32).sqrt().ceil() as usize;
    (0..n)
        .map(|i| {
            let (x, z) = ((i % side) as f32 * 1.5, (i / side) as f32 * 1.5);
            let o = plane
                .add(
                    Shape::Cube {
                        size: [1.0, 1.0, 1.0],
                    },
                    Pose::at([x - 20.0, 2.0 + (i % 3) as f32, z - 20.0]),
                    &[],
                )
                .unwrap();
            if i % 4 == 0 {
                o.set_angular_velocity([0.0, 2.0, 1.0]).unwrap();
            }
            o
        })
        .collect()
}

fn message(e: &Error) -> String {
    e.to_string()
}

#[test]
fn names_are_unique_listed_and_opened_by_any_client() {
    let daemon = TestDaemon::start("names");
    let a = daemon.client();
    let plane = a.create_plane(&named("arena-1")).unwrap();
    assert_eq!(plane.name().unwrap().as_deref(), Some("arena-1"));
    let unnamed = a.create_plane(&PlaneOptions::manual()).unwrap();
    assert_eq!(unnamed.name().unwrap(), None);

    // A taken name is an error naming it; the first plane is untouched.
    let e = a.create_plane(&named("arena-1")).unwrap_err();
    assert!(
        message(&e).contains("\"arena-1\" is taken"),
        "{}",
        message(&e)
    );
    // Bad names name the field and the value, before anything is sent.
    for bad in ["../etc", "a b", ".hidden", &"x".repeat(33)] {
        assert!(PlaneName::new(bad).is_err(), "{bad:?}");
        let e = a.open_plane(bad).unwrap_err();
        assert!(
            message(&e).contains("Name") && message(&e).contains(&bad[..3]),
            "{}",
            message(&e)
        );
    }
    // Persistent needs a name and a state directory, and says so.
    let e = a
        .create_plane(&PlaneOptions::manual().with(PlaneProp::Persistent(true)))
        .unwrap_err();
    assert!(message(&e).contains("needs a Name"), "{}", message(&e));
    let e = a.create_plane(&persistent("saved")).unwrap_err();
    assert!(
        message(&e).contains("--state-dir") && message(&e).contains("Persistent"),
        "{}",
        message(&e)
    );
    // GUI planes take names too (more in tests/tests/gui/named.rs); this one goes again
    // (and its handle with it: it holds the client).
    {
        let gui = a
            .create_plane(&PlaneOptions {
                kind: Some(PlaneKind::Gui2d),
                ..named("gui")
            })
            .unwrap();
        assert_eq!(gui.name().unwrap().as_deref(), Some("gui"));
        gui.destroy().unwrap();
    }

    // Another client (any process of the user) lists and opens it.
    let ball = plane
        .add(
            Shape::Sphere { radius: 0.5 },
            Pose::at([0.0, 10.0, 0.0]),
            &[],
        )
        .unwrap();
    for _ in 0..30 {
        plane.step(DT).unwrap();
    }
    let b = daemon.client();
    let list = b.list_planes().unwrap();
    assert_eq!(list.len(), 1, "{list:?}");
    assert_eq!(list[0].name, "arena-1");
    assert_eq!(list[0].id, plane.id());
    assert_eq!(list[0].kind, PlaneKind::Rapier3d);
    assert!(!list[0].persistent && !list[0].orphaned);
    assert_eq!(list[0].tick, 30);
    let opened = b.open_named("arena-1").unwrap();
    assert!(!opened.owner, "its owner is connected");
    assert_eq!(opened.recovered, None);
    // It reads the owner's plane: the ball after 30 ticks of free fall.
    let seen = Object::from_handle(&opened.plane, ball.handle());
    assert_eq!(seen.pose().unwrap(), ball.pose().unwrap());
    // ... but may not change it (not shared).
    let e = opened.plane.step(DT).unwrap_err();
    assert!(
        message(&e).contains("belongs to another client"),
        "{}",
        message(&e)
    );
    // An unknown name is an error naming it (and the names there are).
    let e = b.open_plane("nope").unwrap_err();
    assert!(
        message(&e).contains("\"nope\"") && message(&e).contains("arena-1"),
        "{}",
        message(&e)
    );
    match e {
        Error::Command(c) => assert_eq!(c.kind, ErrorKind::UnknownPlane),
        other => panic!("{other:?}"),
    }

    // A named plane that is not persistent goes with its owner, and its name is free.
    drop(opened);
    drop((plane, unnamed, ball, seen));
    drop(a);
    let gone = eventually(Duration::from_secs(5), || {
        b.list_planes().unwrap().is_empty().then_some(())
    });
    assert!(gone.is_some(), "{:?}", b.list_planes());
    let again = b.create_plane(&named("arena-1")).unwrap();
    assert_eq!(again.name().unwrap().as_deref(), Some("arena-1"));
}

/// What the first daemon's run recorded: the saved tick's poses and hash, and the hash of
/// the tick after it.
struct Saved {
    tick: u64,
    hash: u64,
    next_hash: u64,
    poses: Vec<(client_sdk::Handle, Pose)>,
}

#[test]
fn sigkill_then_restart_resumes_from_the_last_snapshot() {
    let state = StateDir::new("kill");
    let domain = unique_domain("pkill");
    let args = ["--state-dir", state.path(), "--snapshot-every", "3600"];
    let saved = {
        let mut daemon = TestDaemon::start_with_in(&domain, &args, &[]);
        let a = daemon.client();
        let plane = a.create_plane(&persistent("arena")).unwrap();
        let objects = fill(&plane, 40);
        for _ in 0..60 {
            plane.step(DT).unwrap();
        }
        let handles: Vec<_> = objects.iter().map(|o| o.handle()).collect();
        // The owner leaves: the persistent plane stays, orphaned.
        drop((objects, plane));
        drop(a);
        let b = daemon.client();
        let orphaned = eventually(Duration::from_secs(5), || {
            let list = b.list_planes().unwrap();
            (list.len() == 1 && list[0].orphaned).then_some(())
        });
        assert!(orphaned.is_some(), "{:?}", b.list_planes());
        let opened = b.open_named("arena").unwrap();
        assert!(opened.owner, "the opener of an orphaned plane owns it");
        assert_eq!(opened.recovered, None, "it never left this daemon");
        let plane = opened.plane;
        for _ in 0..30 {
            plane.step(DT).unwrap();
        }
        // Written now, on disk when save returns.
        assert_eq!(plane.save().unwrap(), 90);
        let file = PlaneSnapshot::load(state.domain(&domain).join("arena.physnap")).unwrap();
        assert_eq!(file.tick(), 90);
        let hash = plane.state_hash().unwrap();
        assert_eq!(file.state_hash(), hash);
        let poses = handles
            .iter()
            .map(|h| (*h, Object::from_handle(&plane, *h).pose().unwrap()))
            .collect();
        // 20 more ticks the file does not hold, recorded as reached.
        plane.step(DT).unwrap();
        let next_hash = plane.state_hash().unwrap();
        for _ in 0..19 {
            plane.step(DT).unwrap();
        }
        std::thread::sleep(Duration::from_millis(400));
        daemon.kill9();
        Saved {
            tick: 90,
            hash,
            next_hash,
            poses,
        }
    };

    // A daemon that restores the plane and is killed again before anyone opens it leaves
    // the file and the old tick record as they were.
    {
        let mut daemon = TestDaemon::start_with_in(&domain, &args, &[]);
        let list = daemon.client().list_planes().unwrap();
        assert_eq!(list[0].tick, saved.tick, "{list:?}");
        std::thread::sleep(Duration::from_millis(300));
        daemon.kill9();
    }
    let daemon = TestDaemon::start_with_in(&domain, &args, &[]);
    let c = daemon.client();
    let list = c.list_planes().unwrap();
    assert_eq!(list.len(), 1, "{list:?}");
    assert_eq!(
        (
            list[0].name.as_str(),
            list[0].tick,
            list[0].persistent,
            list[0].orphaned
        ),
        ("arena", saved.tick, true, true)
    );
    let opened = c.open_named("arena").unwrap();
    assert!(opened.owner);
    // 110 reached, 90 saved.
    assert_eq!(opened.recovered, Some(20));
    let plane = opened.plane;
    assert_eq!(plane.info().unwrap().tick, saved.tick);
    assert_eq!(plane.state_hash().unwrap(), saved.hash);
    for (h, pose) in &saved.poses {
        assert_eq!(
            Object::from_handle(&plane, *h).pose().unwrap(),
            *pose,
            "{h:?}"
        );
    }
    // It continues bit for bit: the next tick is the first run's next tick.
    plane.step(DT).unwrap();
    assert_eq!(plane.state_hash().unwrap(), saved.next_hash);
    // Recovered is told once.
    let again = daemon.client().open_named("arena").unwrap();
    assert_eq!(again.recovered, None);
    assert!(!again.owner, "its new owner is connected");
}

#[test]
fn periodic_writes_of_a_ticking_plane_survive_a_sigkill() {
    let _turn = ticking();
    let state = StateDir::new("tick");
    let domain = unique_domain("ptick");
    let args = ["--state-dir", state.path(), "--snapshot-every", "0.2"];
    let mut daemon = TestDaemon::start_with_in(&domain, &args, &[]);
    let a = daemon.client();
    let plane = a
        .create_plane(&persistent("live").with(PlaneProp::TickRate(60.0)))
        .unwrap();
    fill(&plane, 30);
    a.flush().unwrap();
    std::thread::sleep(Duration::from_millis(1200));
    daemon.kill9();
    drop((plane, a));

    let file = PlaneSnapshot::load(state.domain(&domain).join("live.physnap")).unwrap();
    // Written every 0.2 s while it ticked for ~1.2 s at 60 Hz.
    assert!(
        file.tick() >= 20,
        "the last write holds tick {}",
        file.tick()
    );
    let daemon = TestDaemon::start_with_in(&domain, &args, &[]);
    let c = daemon.client();
    let list = c.list_planes().unwrap();
    assert_eq!(
        list[0].tick,
        file.tick(),
        "held at the snapshot's tick until opened"
    );
    // A reader that only attaches (no Open) sees the snapshot's state.
    let peek = c.attach_plane(list[0].id).unwrap();
    assert_eq!(peek.state_hash().unwrap(), file.state_hash());
    let opened = c.open_named("live").unwrap();
    // Lost: at most the 0.2 s between writes plus the 0.1 s tick record (at 60 Hz), with
    // slack for a loaded machine.
    let lost = opened.recovered.expect("recovered from its file");
    assert!(lost <= 40, "lost {lost} ticks");
    // After Open it ticks on at its TickRate.
    let t0 = opened.plane.info().unwrap().tick;
    let moved = eventually(Duration::from_secs(5), || {
        (opened.plane.info().unwrap().tick > t0 + 5).then_some(())
    });
    assert!(
        moved.is_some(),
        "the restored plane does not tick after Open"
    );
}

#[test]
fn kills_during_writes_never_leave_half_a_file() {
    let _turn = ticking();
    let state = StateDir::new("half");
    let domain = unique_domain("phalf");
    // A big awake plane written as often as the daemon allows: writes are under way most
    // of the time, so kills land in them.
    let args = ["--state-dir", state.path(), "--snapshot-every", "0.05"];
    let dir = state.domain(&domain);
    let file = dir.join("big.physnap");
    {
        let mut daemon = TestDaemon::start_with_in(&domain, &args, &[]);
        let a = daemon.client();
        let plane = a
            .create_plane(&persistent("big").with(PlaneProp::TickRate(60.0)))
            .unwrap();
        fill(&plane, 600);
        a.flush().unwrap();
        let written = eventually(Duration::from_secs(20), || {
            PlaneSnapshot::load(&file)
                .ok()
                .filter(|s| s.tick() > 0)
                .map(|_| ())
        });
        assert!(written.is_some(), "no write of the big plane");
        daemon.kill9();
    }
    let mut temps_seen = 0;
    let mut last_tick = 0;
    for round in 0..6u64 {
        let mut daemon = TestDaemon::start_with_in(&domain, &args, &[]);
        // The leftover temporary file of the killed write is gone.
        assert!(
            !temp_files(&dir).iter().any(|_| true),
            "round {round}: {:?}",
            temp_files(&dir)
        );
        let c = daemon.client();
        let opened = c.open_named("big").unwrap();
        let tick = opened.plane.info().unwrap().tick;
        assert!(
            tick >= last_tick,
            "round {round}: went back from {last_tick} to {tick}"
        );
        last_tick = tick;
        std::thread::sleep(Duration::from_millis(150 + 70 * round));
        daemon.kill9();
        temps_seen += temp_files(&dir).len();
        // Whatever the moment of the kill: the file is a whole snapshot.
        let snap = PlaneSnapshot::load(&file).unwrap_or_else(|e| panic!("round {round}: {e}"));
        assert!(snap.tick() >= tick, "round {round}");
    }
    eprintln!("kills that left a temporary file: {temps_seen} of 6");
}

fn temp_files(dir: &Path) -> Vec<PathBuf> {
    std::fs::read_dir(dir)
        .unwrap()
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.to_string_lossy().ends_with(".tmp"))
        .collect()
}

#[test]
fn damaged_files_are_skipped_with_an_error_naming_them() {
    let state = StateDir::new("bad");
    let domain = unique_domain("pbad");
    let dir = state.domain(&domain);
    std::fs::create_dir_all(&dir).unwrap();
    // A good snapshot, taken from a plane of another daemon.
    let snapshot = {
        let daemon = TestDaemon::start("pbad-src");
        let client = daemon.client();
        let plane = client.create_plane(&PlaneOptions::manual()).unwrap();
        fill(&plane, 10);
        for _ in 0..12 {
            plane.step(DT).unwrap();
        }
        plane.take_snapshot().unwrap()
    };
    snapshot.save(dir.join("good.physnap")).unwrap();
    // The previous snapshot, and a half-written new one a killed write left behind.
    let bytes = snapshot.bytes();
    std::fs::write(dir.join(".good.physnap.tmp"), &bytes[..bytes.len() / 2]).unwrap();
    // A truncated file and a flipped byte, a name that is no plane name.
    std::fs::write(dir.join("cut.physnap"), &bytes[..bytes.len() - 100]).unwrap();
    let mut flipped = bytes.to_vec();
    let at = flipped.len() - 7;
    flipped[at] ^= 0x20;
    std::fs::write(dir.join("flipped.physnap"), &flipped).unwrap();
    std::fs::write(dir.join("no good.physnap"), bytes).unwrap();

    let log = state.0.join("daemon.log");
    let args = ["--state-dir", state.path()];
    let daemon = TestDaemon::start_logged_in(&domain, &args, &log);
    let c = daemon.client();
    let list = c.list_planes().unwrap();
    let names: Vec<&str> = list.iter().map(|p| p.name.as_str()).collect();
    assert_eq!(names, ["good"], "only the good file comes back");
    assert_eq!(list[0].tick, 12);
    let opened = c.open_named("good").unwrap();
    assert_eq!(opened.plane.state_hash().unwrap(), snapshot.state_hash());
    assert_eq!(
        opened.recovered,
        Some(0),
        "no tick record: nothing known lost"
    );
    assert!(temp_files(&dir).is_empty(), "{:?}", temp_files(&dir));
    let text = std::fs::read_to_string(&log).unwrap();
    for (file, why) in [
        ("cut.physnap", "skipped"),
        ("flipped.physnap", "checksum"),
        ("no good.physnap", "not a plane name"),
        (".good.physnap.tmp", "removed"),
    ] {
        let line = text
            .lines()
            .find(|l| l.contains(file))
            .unwrap_or_else(|| panic!("no log line names {file}:\n{text}"));
        assert!(line.contains(why), "{line}");
    }
}

#[test]
fn clean_shutdown_writes_and_destroy_removes() {
    let state = StateDir::new("clean");
    let domain = unique_domain("pclean");
    let args = ["--state-dir", state.path(), "--snapshot-every", "3600"];
    let file = state.domain(&domain).join("keep.physnap");
    {
        let mut daemon = TestDaemon::start_with_in(&domain, &args, &[]);
        let a = daemon.client();
        let plane = a.create_plane(&persistent("keep")).unwrap();
        fill(&plane, 5);
        for _ in 0..50 {
            plane.step(DT).unwrap();
        }
        // Only the write at creation so far (the period is an hour).
        let early = eventually(Duration::from_secs(5), || PlaneSnapshot::load(&file).ok());
        assert_eq!(early.map(|s| s.tick()), Some(0));
        let (status, _) = daemon.stop_with(libc::SIGINT, Duration::from_secs(10));
        assert!(status.success(), "{status:?}");
    }
    assert_eq!(
        PlaneSnapshot::load(&file).unwrap().tick(),
        50,
        "written at shutdown"
    );
    let daemon = TestDaemon::start_with_in(&domain, &args, &[]);
    let c = daemon.client();
    let opened = c.open_named("keep").unwrap();
    assert_eq!(opened.recovered, Some(0), "a clean shutdown loses nothing");
    assert_eq!(opened.plane.info().unwrap().tick, 50);
    // Its owner destroys it: the file goes, and the name is free.
    opened.plane.destroy().unwrap();
    let removed = eventually(Duration::from_secs(5), || (!file.exists()).then_some(()));
    assert!(removed.is_some(), "{} still there", file.display());
    assert!(c.list_planes().unwrap().is_empty());
    // Save on a plane that is not persistent names the option.
    let plain = c.create_plane(&named("keep")).unwrap();
    let e = plain.save().unwrap_err();
    assert!(message(&e).contains("Persistent"), "{}", message(&e));
}

/// Clients that bypass the SDK: an `OpenPlane` with a megabyte name or a path, and a
/// creation whose `Name` is forged bytes, get errors naming the field with the value cut
/// short; the good command of the same request still runs and the daemon serves on.
#[test]
fn forged_names_are_refused_by_name() {
    use shm_layout::codec::{decode_response, encode_request};
    use shm_layout::{Command, Request, Response};
    let daemon = TestDaemon::start("pforged");
    let client = daemon.client();
    client.create_plane(&named("real")).unwrap();
    let huge = "x".repeat(1 << 20);
    let request = Request {
        commands: vec![
            Command::OpenPlane { name: huge },
            Command::OpenPlane {
                name: "../../etc/passwd".into(),
            },
            Command::ListNamedPlanes,
        ],
    };
    let results =
        match decode_response(&client.raw_request(&encode_request(&request)).unwrap()).unwrap() {
            Response::Results(r) => r,
            other => panic!("{other:?}"),
        };
    let e = results[0].as_ref().unwrap_err();
    assert_eq!(e.field.as_deref(), Some("Name"));
    assert!(
        e.message.contains("1048576 bytes") && e.message.len() < 400,
        "{}",
        e.message
    );
    let e = results[1].as_ref().unwrap_err();
    assert!(e.message.contains("'/' is not allowed"), "{}", e.message);
    match &results[2] {
        Ok(shm_layout::Reply::NamedPlanes(list)) => assert_eq!(list[0].name, "real"),
        other => panic!("{other:?}"),
    }
    // A creation whose Name is forged bytes: refused naming the field and the value.
    let mut bytes = encode_request(&Request {
        commands: vec![Command::CreatePlane {
            kind: PlaneKind::Rapier3d,
            props: vec![PlaneProp::Name(PlaneName::new("abc").unwrap())],
        }],
    });
    let at = bytes.windows(3).rposition(|w| w == b"abc").unwrap();
    bytes[at + 1] = b'/';
    let results = match decode_response(&client.raw_request(&bytes).unwrap()).unwrap() {
        Response::Results(r) => r,
        other => panic!("{other:?}"),
    };
    let e = results[0].as_ref().unwrap_err();
    assert_eq!(e.field.as_deref(), Some("Name"));
    assert!(e.message.contains("\"a/c\""), "{}", e.message);
    assert_eq!(client.list_planes().unwrap().len(), 1);
}

//! Plane snapshots through real daemons: a snapshot at tick T, N ticks of a command log,
//! then a restore (on the same daemon, or as a new plane on a second daemon) and the same
//! log give the same state hash on every tick, for 3D planes (every object kind, a joint
//! with a motor, a controller walking a path, a triangle map; Threads 1 and 2) and GUI
//! planes. A one-bit difference in the log shows on exactly the tick it enters. Damaged
//! snapshots are refused with a message naming the damage, and the plane stays as it was.

// Snapshots between two ticks, in pieces (transfers), and the validation bench's check.
mod pending;
mod pieces;
mod validate;

use client_sdk::{
    Client, Controller, GuiPlane, GuiPlaneOptions, JointKind, JointProp, MapMesh, MapOptions,
    Object, Plane, PlaneOptions, PlaneSnapshot, Pose, Shape,
};
use integration_tests::TestDaemon;
use physics_scenes::determinism_scene;
use shm_layout::settings::GuiShape;

const DT: f32 = 1.0 / 60.0;
/// Ticks before the snapshot (the pile is still falling and the balls flying).
const BEFORE: u32 = 40;
/// Ticks of the replayed log after it.
const AFTER: u32 = 90;

/// What a game sends before the step of a tick (ticks counted from the snapshot).
#[derive(Clone, Copy, Debug)]
enum Entry {
    Velocity(u32, usize, [f32; 3]),
    Impulse(u32, usize, [f32; 3]),
    Add(u32, [f32; 3]),
    Destroy(u32, usize),
    Move(u32, f32, f32),
    Motor(u32, f32),
}

fn log() -> Vec<Entry> {
    vec![
        Entry::Velocity(3, 25, [-4.0, 6.0, 0.0]),
        Entry::Impulse(9, 3, [0.0, 8.0, 1.5]),
        Entry::Add(15, [0.3, 9.0, 0.2]),
        Entry::Move(20, 1.0, 0.5),
        Entry::Destroy(31, 7),
        Entry::Motor(40, -3.0),
        Entry::Impulse(55, 20, [2.0, 0.0, -3.0]),
    ]
}

/// The game's handles: the pile and balls, a motored wheel, a controller.
struct Game {
    plane: Plane,
    objects: Vec<Object>,
    wheel: client_sdk::Joint,
    controller: Controller,
}

fn build(client: &Client, threads: u32) -> Game {
    let plane = client
        .create_plane(&PlaneOptions {
            threads: Some(threads),
            ..PlaneOptions::manual()
        })
        .unwrap();
    let objects = determinism_scene(&mut &plane).unwrap();
    // Every shape kind besides the pile's cubes and the balls.
    let shapes = [
        Shape::Capsule {
            size: [0.6, 1.2, 0.6],
        },
        Shape::Cylinder {
            size: [0.8, 0.8, 0.8],
        },
        Shape::Wedge {
            size: [1.0, 0.6, 1.0],
        },
        Shape::Mesh {
            vertices: vec![
                [0.0, 0.5, 0.0],
                [0.5, -0.3, 0.3],
                [-0.5, -0.3, 0.3],
                [0.0, -0.3, -0.5],
            ],
            triangles: vec![[0, 1, 2], [0, 2, 3], [0, 3, 1], [1, 3, 2]],
        },
    ];
    let mut objects = objects;
    for (i, shape) in shapes.into_iter().enumerate() {
        let o = plane
            .add(shape, Pose::at([-4.0 + 2.0 * i as f32, 3.0, 4.0]), &[])
            .unwrap();
        objects.push(o);
    }
    // A wheel on a motored hinge to the world.
    let wheel = plane
        .add(
            Shape::Cylinder {
                size: [1.2, 0.3, 1.2],
            },
            Pose::at([6.0, 3.0, -4.0]),
            &[],
        )
        .unwrap();
    let joint = plane
        .joint(
            JointKind::Hinge,
            &wheel,
            None,
            &[
                JointProp::AnchorB([6.0, 3.0, -4.0]),
                JointProp::Axis([0.0, 1.0, 0.0]),
                JointProp::MotorSpeed(4.0),
            ],
        )
        .unwrap();
    // A three-link arm with limited ball joints hung from the world (an articulation with
    // limit companions), swinging from a tilted start.
    let mut prev: Option<Object> = None;
    let mut anchor = [-6.0, 6.3, -2.0];
    for i in 0..3 {
        let at = [-6.0 + 0.6 * (i + 1) as f32, 6.0 - 0.3 * i as f32, -2.0];
        let link = plane
            .add(Shape::Sphere { radius: 0.2 }, Pose::at(at), &[])
            .unwrap();
        plane
            .joint(
                JointKind::ConeTwist,
                &link,
                prev.as_ref(),
                &[
                    JointProp::AnchorA([anchor[0] - at[0], anchor[1] - at[1], 0.0]),
                    JointProp::AnchorB(if prev.is_some() { [0.0; 3] } else { anchor }),
                    JointProp::SwingLimit(0.6),
                    JointProp::TwistLimit(0.3),
                ],
            )
            .unwrap();
        prev = Some(link);
        anchor = at;
    }
    // A ramp map and a controller walking a path across the floor.
    plane
        .load_map_meshes(
            &[MapMesh {
                vertices: vec![
                    [-3.0, 0.0, -8.0],
                    [3.0, 0.0, -8.0],
                    [3.0, 1.5, -12.0],
                    [-3.0, 1.5, -12.0],
                ],
                triangles: vec![[0, 1, 2], [0, 2, 3]],
            }],
            &MapOptions::default(),
        )
        .unwrap();
    let controller = plane
        .new_controller(Pose::at([-6.0, 3.0, -6.0]), [1.0, 3.0, 1.0], false, &[])
        .unwrap();
    controller
        .compute_path(&[[-2.0, 0.0, -6.0], [0.0, 0.0, -10.0], [4.0, 0.0, -3.0]])
        .unwrap();
    Game {
        plane,
        objects,
        wheel: joint,
        controller,
    }
}

/// Replays `log` for [`AFTER`] ticks and returns each tick's state hash.
fn replay(game: &mut Game, log: &[Entry]) -> Vec<u64> {
    let mut hashes = Vec::new();
    for t in 1..=AFTER {
        for e in log {
            match *e {
                Entry::Velocity(at, i, v) if at == t => game.objects[i].set_velocity(v).unwrap(),
                Entry::Impulse(at, i, j) if at == t => game.objects[i].apply_impulse(j).unwrap(),
                Entry::Add(at, p) if at == t => {
                    let o = game
                        .plane
                        .add(Shape::Sphere { radius: 0.4 }, Pose::at(p), &[])
                        .unwrap();
                    game.objects.push(o);
                }
                Entry::Destroy(at, i) if at == t => game.objects[i].destroy(),
                Entry::Move(at, x, z) if at == t => game.controller.set_move_vector(x, z).unwrap(),
                Entry::Motor(at, s) if at == t => game.wheel.set(JointProp::MotorSpeed(s)).unwrap(),
                _ => {}
            }
        }
        game.plane.step(DT).unwrap();
        hashes.push(game.plane.state_hash().unwrap());
    }
    hashes
}

fn first_difference(a: &[u64], b: &[u64]) -> Option<usize> {
    a.iter().zip(b).position(|(x, y)| x != y)
}

/// The game after [`BEFORE`] ticks: its snapshot and the hashes of the log after it.
fn game_and_reference(client: &Client, threads: u32) -> (Game, PlaneSnapshot, Vec<u64>) {
    let mut game = build(client, threads);
    for _ in 0..BEFORE {
        game.plane.step(DT).unwrap();
    }
    let snapshot = game.plane.take_snapshot().unwrap();
    assert_eq!(snapshot.tick(), BEFORE as u64);
    assert_eq!(snapshot.state_hash(), game.plane.state_hash().unwrap());
    let reference = replay(&mut game, &log());
    (game, snapshot, reference)
}

#[test]
fn a_restored_plane_continues_bit_for_bit_on_the_same_daemon() {
    let daemon = TestDaemon::start("snap-same");
    let client = daemon.client();
    for threads in [1, 2] {
        let (mut game, snapshot, reference) = game_and_reference(&client, threads);
        assert!(
            reference.windows(2).any(|w| w[0] != w[1]),
            "the scene moves"
        );
        // Handles the script holds stay valid: the restored plane reads the snapshot's state.
        let tick = game.plane.restore(&snapshot).unwrap();
        assert_eq!(tick, BEFORE as u64);
        assert_eq!(game.plane.state_hash().unwrap(), snapshot.state_hash());
        game.objects.truncate(game.objects.len() - 1); // the sphere the log added
        let again = replay(&mut game, &log());
        assert_eq!(
            first_difference(&reference, &again),
            None,
            "Threads {threads}: the replay after a restore diverged"
        );
    }
}

#[test]
fn a_snapshot_restored_on_a_second_daemon_continues_bit_for_bit() {
    let first = TestDaemon::start("snap-first");
    let second = TestDaemon::start("snap-second");
    let (client_a, client_b) = (first.client(), second.client());
    for threads in [1, 2] {
        let (game, snapshot, reference) = game_and_reference(&client_a, threads);
        // Through bytes, as a file would carry it.
        let bytes = snapshot.bytes().to_vec();
        let carried = PlaneSnapshot::from_bytes(bytes).unwrap();
        let plane = client_b.plane_from_snapshot(&carried, &[]).unwrap();
        assert_eq!(plane.state_hash().unwrap(), snapshot.state_hash());
        // The same handles name the same things on the new plane.
        let mut copy = Game {
            objects: game
                .objects
                .iter()
                .take(game.objects.len() - 1)
                .map(|o| Object::from_handle(&plane, o.handle()))
                .collect(),
            wheel: client_sdk::Joint::from_handle(&plane, game.wheel.handle(), JointKind::Hinge),
            controller: Controller::from_handle(&plane, game.controller.handle()),
            plane,
        };
        let again = replay(&mut copy, &log());
        assert_eq!(
            first_difference(&reference, &again),
            None,
            "Threads {threads}: the replay on another daemon diverged"
        );
    }
}

#[test]
fn one_bit_of_the_log_shows_on_exactly_its_tick() {
    let daemon = TestDaemon::start("snap-bit");
    let client = daemon.client();
    let (mut game, snapshot, reference) = game_and_reference(&client, 1);
    let mut changed = log();
    let Entry::Velocity(at, i, mut v) = changed[0] else {
        unreachable!()
    };
    v[0] = f32::from_bits(v[0].to_bits() ^ 1);
    changed[0] = Entry::Velocity(at, i, v);
    game.plane.restore(&snapshot).unwrap();
    game.objects.truncate(game.objects.len() - 1);
    let again = replay(&mut game, &changed);
    // The write goes before the step of tick `at`: the hash of that tick is the first to
    // differ.
    assert_eq!(first_difference(&reference, &again), Some(at as usize - 1));
}

#[test]
fn gui_planes_restore_bit_for_bit_and_files_round_trip() {
    let daemon = TestDaemon::start("snap-gui");
    let client = daemon.client();
    let gui = client
        .create_gui_plane(&GuiPlaneOptions {
            bounds: Some(([0.0, 0.0], [800.0, 600.0])),
            ..GuiPlaneOptions::manual()
        })
        .unwrap();
    let mut objects = Vec::new();
    for i in 0..20 {
        let shape = [GuiShape::Square, GuiShape::Circle, GuiShape::Triangle][i % 3];
        let o = gui
            .add(
                shape,
                [30.0, 30.0],
                [
                    100.0 + 31.0 * (i % 10) as f32,
                    100.0 + 40.0 * (i / 10) as f32,
                ],
                &[],
            )
            .unwrap();
        objects.push(o);
    }
    let player = gui.new_controller(&objects[0], false, &[]).unwrap();
    let run = |gui: &GuiPlane, from: u32| -> Vec<u64> {
        (from..from + 60)
            .map(|t| {
                if t == 10 {
                    objects[5].apply_impulse([300.0, -200.0]).unwrap();
                }
                if t == 20 {
                    player.move_direction([1.0, 0.0]).unwrap();
                }
                gui.step(DT).unwrap();
                gui.plane().state_hash().unwrap()
            })
            .collect()
    };
    run(&gui, 0);
    let snapshot = gui.plane().take_snapshot().unwrap();
    let reference = run(&gui, 0);
    // A file, written atomically and read back.
    let dir = std::env::temp_dir().join(format!("snap-gui-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("arena.snapshot");
    snapshot.save(&path).unwrap();
    let loaded = PlaneSnapshot::load(&path).unwrap();
    std::fs::remove_dir_all(&dir).unwrap();
    assert_eq!(loaded.bytes(), snapshot.bytes());
    gui.plane().restore(&loaded).unwrap();
    let again = run(&gui, 0);
    assert_eq!(first_difference(&reference, &again), None);
}

#[test]
fn damaged_or_foreign_snapshots_are_refused_and_change_nothing() {
    let daemon = TestDaemon::start("snap-bad");
    let client = daemon.client();
    let plane = client.create_plane(&PlaneOptions::manual()).unwrap();
    let ball = plane
        .add(
            Shape::Sphere { radius: 0.5 },
            Pose::at([0.0, 5.0, 0.0]),
            &[],
        )
        .unwrap();
    plane.step(DT).unwrap();
    let good = plane.take_snapshot().unwrap();
    for _ in 0..10 {
        plane.step(DT).unwrap();
    }
    let hash = plane.state_hash().unwrap();
    let message = |bytes: Vec<u8>| -> String {
        // Damage the SDK would notice is refused there; send the rest raw to the daemon.
        match PlaneSnapshot::from_bytes(bytes) {
            Err(e) => e.to_string(),
            Ok(s) => plane.restore(&s).unwrap_err().to_string(),
        }
    };
    let mut flipped = good.bytes().to_vec();
    let n = flipped.len();
    flipped[n - 3] ^= 0x10;
    assert!(message(flipped).contains("checksum"), "a flipped bit");
    assert!(
        message(good.bytes()[..n / 2].to_vec()).contains("truncated"),
        "half a file"
    );
    assert!(message(b"PHYSNAP1 nonsense".to_vec()).contains("snapshot refused"));
    assert!(message(vec![0; 64]).contains("not a plane snapshot"));
    // A GUI snapshot into a 3D plane.
    let gui = client.create_gui_plane(&GuiPlaneOptions::manual()).unwrap();
    let foreign = gui.plane().take_snapshot().unwrap();
    let e = plane.restore(&foreign).unwrap_err().to_string();
    assert!(e.contains("a GUI plane, not a 3D one"), "{e}");
    // Nothing changed, and the plane and daemon go on.
    assert_eq!(plane.state_hash().unwrap(), hash);
    plane.step(DT).unwrap();
    assert!(ball.position().unwrap()[1] < 5.0);
    // The good one still restores.
    plane.restore(&good).unwrap();
    assert_eq!(plane.state_hash().unwrap(), good.state_hash());
}

#[test]
fn forged_snapshots_cost_the_forger_its_plane_at_most_and_only_owners_restore() {
    let daemon = TestDaemon::start("snap-forged");
    let victim = daemon.client();
    let theirs = victim.create_plane(&PlaneOptions::manual()).unwrap();
    let shared = victim
        .create_plane(&PlaneOptions {
            shared: Some(true),
            ..PlaneOptions::manual()
        })
        .unwrap();
    theirs
        .add(
            Shape::Sphere { radius: 0.5 },
            Pose::at([0.0, 5.0, 0.0]),
            &[],
        )
        .unwrap();
    let forger = daemon.client();
    let source = build(&forger, 1);
    for _ in 0..10 {
        source.plane.step(DT).unwrap();
    }
    let good = source.plane.take_snapshot().unwrap();
    // Another client may not restore a plane it does not own, shared or not.
    for plane in [&theirs, &shared] {
        let foreign = client_sdk::Plane::clone(plane);
        let attached = forger.attach_plane(foreign.id()).unwrap();
        let e = attached.restore(&good).unwrap_err().to_string();
        assert!(e.contains("only its owner may restore"), "{e}");
    }
    // Edited bodies with their checksum fixed up: refused, or accepted and possibly failing
    // the forger's own plane; the victim's plane steps on either way.
    let (header, start) = shm_layout::snapshot::header(good.bytes()).unwrap();
    let body = &good.bytes()[start..];
    let mut seed = 0x2545_f491_4f6c_dd1du64;
    for round in 0..40 {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        let mut edited = body.to_vec();
        for k in 0..3 {
            let i = ((seed >> (k * 16)) as usize) % edited.len();
            edited[i] ^= (seed >> 48) as u8 | 1;
        }
        let bytes = shm_layout::snapshot::encode(header.clone(), &edited);
        let forged = PlaneSnapshot::from_bytes(bytes).unwrap();
        if let Ok(plane) = forger.plane_from_snapshot(&forged, &[]) {
            for _ in 0..3 {
                if plane.step(DT).is_err() {
                    break;
                }
            }
        }
        let before = theirs.state_hash().unwrap();
        theirs
            .step(DT)
            .unwrap_or_else(|e| panic!("round {round}: the victim failed: {e}"));
        assert_ne!(
            theirs.state_hash().unwrap(),
            before,
            "the victim's ball falls"
        );
    }
}

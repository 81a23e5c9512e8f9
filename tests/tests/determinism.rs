//! Determinism through a real daemon: the same commands give bit-identical states on every
//! tick, whichever daemon runs them, with Threads = 1 or 2; the tick header's `state_hash`
//! shows it, and is exactly the hash of the published bodies.

use client_sdk::{Client, Object, PlaneOptions, StateHasher};
use integration_tests::TestDaemon;
use physics_scenes::determinism_scene;

const DT: f32 = 1.0 / 60.0;
const TICKS: u32 = 150;

/// One entry of a game's command log: what it sent before the step of tick `tick`.
#[derive(Clone, Copy)]
enum Command {
    Impulse {
        tick: u32,
        object: usize,
        j: [f32; 3],
    },
    Velocity {
        tick: u32,
        object: usize,
        v: [f32; 3],
    },
}

/// The command log replayed by every run: impulses and velocity writes while the balls are
/// still flying and after they hit the pyramid.
fn command_log() -> Vec<Command> {
    vec![
        Command::Impulse {
            tick: 20,
            object: 3,
            j: [0.0, 8.0, 1.5],
        },
        Command::Velocity {
            tick: 45,
            object: 25,
            v: [-4.0, 6.0, 0.0],
        },
        Command::Impulse {
            tick: 80,
            object: 20,
            j: [2.0, 0.0, -3.0],
        },
    ]
}

/// Builds the scene on a new manual plane of `client` with `threads`, replays `log` and
/// returns the state hash of every tick, checking each against the published bodies.
fn run(client: &Client, threads: u32, log: &[Command]) -> Vec<u64> {
    let plane = client
        .create_plane(&PlaneOptions {
            threads: Some(threads),
            ..PlaneOptions::manual()
        })
        .unwrap();
    let objects: Vec<Object> = determinism_scene(&mut &plane).unwrap();
    let mut hashes = Vec::new();
    for tick in 1..=TICKS {
        for c in log {
            match *c {
                Command::Impulse { tick: t, object, j } if t == tick => {
                    objects[object].apply_impulse(j).unwrap()
                }
                Command::Velocity { tick: t, object, v } if t == tick => {
                    objects[object].set_velocity(v).unwrap()
                }
                _ => {}
            }
        }
        plane.step(DT).unwrap();
        let snap = plane.snapshot().unwrap();
        assert_eq!(snap.tick(), tick as u64);
        let hash = plane.state_hash().unwrap();
        assert_eq!(
            hash,
            StateHasher::of(snap.bodies()),
            "tick {tick}: the header's hash is the hash of the published bodies"
        );
        hashes.push(hash);
    }
    hashes
}

/// The first tick at which two runs differ, if any.
fn first_difference(a: &[u64], b: &[u64]) -> Option<usize> {
    a.iter().zip(b).position(|(x, y)| x != y).map(|i| i + 1)
}

#[test]
fn same_commands_give_the_same_hash_every_tick_on_any_daemon_and_thread_count() {
    let log = command_log();
    let first = TestDaemon::start("determinism-a");
    let client = first.client();
    let reference = run(&client, 1, &log);
    // The hash follows the state: the scene moves, so consecutive ticks differ.
    let distinct: std::collections::HashSet<_> = reference.iter().collect();
    assert!(
        distinct.len() > TICKS as usize * 9 / 10,
        "only {} distinct hashes in {TICKS} ticks",
        distinct.len()
    );

    // The same scene again on the same daemon.
    let again = run(&client, 1, &log);
    assert_eq!(
        first_difference(&reference, &again),
        None,
        "second run diverged"
    );

    // Threads = 2: rapier's parallel solver gives the same bits.
    let threaded = run(&client, 2, &log);
    assert_eq!(
        first_difference(&reference, &threaded),
        None,
        "Threads = 2 diverged from Threads = 1"
    );

    // Another client replaying the log against a fresh daemon.
    let second = TestDaemon::start("determinism-b");
    let replayed = run(&second.client(), 1, &log);
    assert_eq!(
        first_difference(&reference, &replayed),
        None,
        "the replay diverged"
    );

    // A log that differs by one small upward impulse on a ball diverges from that tick on,
    // and the hash shows it on that very tick.
    let mut changed = log.clone();
    changed.push(Command::Impulse {
        tick: 100,
        object: 30,
        j: [0.0, 1e-2, 0.0],
    });
    let other = run(&client, 1, &changed);
    assert_eq!(first_difference(&reference, &other), Some(100));
}

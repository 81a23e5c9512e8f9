//! Held adds (`ConnectOptions::hold_adds_until_flush`, what the Lua runner uses): an object
//! added on a plane that ticks by itself stays exactly where it was put until the client's
//! next flush, or for at most `MAX_HELD_TICKS` ticks when no flush comes.

use std::time::Duration;

use client_sdk::{Client, ConnectOptions, PlaneOptions, Pose, Shape};
use integration_tests::{eventually, TestDaemon};
use shm_layout::settings::object::MAX_HELD_TICKS;

fn holding_client(daemon: &TestDaemon) -> Client {
    let mut options = ConnectOptions::new(&daemon.domain);
    options.hold_adds_until_flush = true;
    Client::connect_with(options).unwrap()
}

/// The published height of `slot` and the tick it is from (once a tick shows the slot).
fn height(plane: &client_sdk::Plane, slot: u32) -> Option<(u64, f32)> {
    let snap = plane.snapshot().unwrap();
    let y = snap.bodies().get(slot as usize)?.position[1];
    Some((snap.tick(), y))
}

#[test]
fn a_held_add_waits_for_the_next_flush_or_at_most_max_held_ticks() {
    let daemon = TestDaemon::start("held-adds");
    let client = holding_client(&daemon);
    let plane = client
        .create_plane(&PlaneOptions {
            tick_rate: Some(120.0),
            ..Default::default()
        })
        .unwrap();
    let ball = Shape::Sphere { radius: 0.5 };
    // No flush: the object waits MAX_HELD_TICKS ticks, then falls by itself.
    let held = plane
        .add(ball.clone(), Pose::at([0.0, 10.0, 0.0]), &[])
        .unwrap();
    let added_at = plane.snapshot().unwrap().tick();
    let slot = held.handle().slot;
    let late = u64::from(MAX_HELD_TICKS) - 3;
    let (tick, y) = eventually(Duration::from_secs(10), || {
        let (t, y) = height(&plane, slot)?;
        (t >= added_at + late).then_some((t, y))
    })
    .expect("the plane ticks");
    assert_eq!(
        y, 10.0,
        "still held at tick {tick} (added after {added_at})"
    );
    let fell = eventually(Duration::from_secs(10), || {
        let (t, y) = height(&plane, slot)?;
        (t >= added_at + u64::from(MAX_HELD_TICKS) + 10).then_some(y)
    })
    .expect("the plane ticks");
    assert!(
        fell < 9.99,
        "released after {MAX_HELD_TICKS} ticks: y = {fell}"
    );

    // A flush releases at once, with the writes queued since the add.
    let other = plane.add(ball, Pose::at([5.0, 10.0, 0.0]), &[]).unwrap();
    std::thread::sleep(Duration::from_millis(50));
    let (_, y) = height(&plane, other.handle().slot).expect("published");
    assert_eq!(y, 10.0, "held until the flush");
    other.set_velocity([0.0, 20.0, 0.0]).unwrap();
    client.flush().unwrap();
    let rose = eventually(Duration::from_secs(5), || {
        let (_, y) = height(&plane, other.handle().slot)?;
        (y > 10.05).then_some(y)
    });
    assert!(
        rose.is_some(),
        "the velocity written before the flush is its first motion"
    );
}

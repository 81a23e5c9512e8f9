//! A plane's object count comes from the tick header plus this process's own adds and
//! removals the header does not show yet: it equals the daemon's count after every change,
//! also while the plane ticks on its own, and it needs no request to the daemon.

use std::time::{Duration, Instant};

use client_sdk::{Client, ControllerProp, MapOptions, PlaneOptions, Pose, Shape};
use integration_tests::{assets, TestDaemon};

fn ball() -> Shape {
    Shape::Sphere { radius: 0.5 }
}

/// The daemon's own count (an info read: a round trip).
fn daemon_count(plane: &client_sdk::Plane) -> u32 {
    plane.info().unwrap().object_count
}

#[test]
fn the_count_follows_adds_and_removals_at_once_while_the_plane_ticks() {
    let daemon = TestDaemon::start("count-ticking");
    let client = daemon.client();
    let plane = client
        .create_plane(&PlaneOptions {
            tick_rate: Some(240.0),
            gravity: Some([0.0; 3]),
            ..Default::default()
        })
        .unwrap();
    let mut live = Vec::new();
    // A fixed pseudo-random walk of adds and removals, read back after every change (the
    // plane publishes every ~4 ms, so reads land before, between and after ticks).
    let mut seed = 12345u32;
    for step in 0..300u32 {
        seed = seed.wrapping_mul(1_103_515_245).wrapping_add(12_345);
        let remove = !live.is_empty() && (seed >> 16).is_multiple_of(3);
        if remove {
            let i = (seed >> 8) as usize % live.len();
            let o: client_sdk::Object = live.swap_remove(i);
            o.destroy();
        } else {
            let x = (step % 20) as f32 * 2.0;
            live.push(plane.add(ball(), Pose::at([x, 0.0, 0.0]), &[]).unwrap());
        }
        assert_eq!(
            plane.object_count().unwrap(),
            live.len() as u32,
            "step {step}: right after the change"
        );
        if step.is_multiple_of(25) {
            std::thread::sleep(Duration::from_millis(3));
            client.begin_frame();
            assert_eq!(plane.object_count().unwrap(), live.len() as u32);
            assert_eq!(daemon_count(&plane), live.len() as u32, "step {step}");
        }
    }
    // Once ticks show everything, the header alone carries it.
    std::thread::sleep(Duration::from_millis(50));
    client.begin_frame();
    assert_eq!(
        plane.snapshot().unwrap().header().body_count,
        live.len() as u32
    );
    assert_eq!(plane.object_count().unwrap(), live.len() as u32);
}

#[test]
fn refused_removals_controllers_and_maps_count_as_the_daemon_counts() {
    let daemon = TestDaemon::start("count-kinds");
    let client = daemon.client();
    let plane = client.create_plane(&PlaneOptions::manual()).unwrap();
    let a = plane.add(ball(), Pose::at([0.0; 3]), &[]).unwrap();
    let b = plane.add(ball(), Pose::at([3.0, 0.0, 0.0]), &[]).unwrap();
    assert_eq!(plane.object_count().unwrap(), 2, "before any tick");
    plane.step(1.0 / 60.0).unwrap();
    // A removal counts from the moment it is queued.
    a.destroy();
    assert_eq!(client.queued(), 1);
    assert_eq!(plane.object_count().unwrap(), 1);
    // The same object removed twice: the daemon refuses the second (stale handle), and the
    // count does not go down twice.
    client.flush().unwrap();
    a.destroy();
    assert_eq!(plane.object_count().unwrap(), 1);
    let _ = client.flush();
    assert_eq!(plane.object_count().unwrap(), 1);
    assert_eq!(daemon_count(&plane), 1);
    // Controllers are objects of the plane too.
    let c = plane
        .new_controller(
            Pose::at([6.0, 1.0, 0.0]),
            [1.0, 2.0, 1.0],
            false,
            &[ControllerProp::WalkSpeed(4.0)],
        )
        .unwrap();
    assert_eq!(plane.object_count().unwrap(), 2);
    assert_eq!(daemon_count(&plane), 2);
    // A map's body is counted after asking the daemon once.
    let map = plane
        .load_map_meshes(&assets::terrain(), &MapOptions::default())
        .unwrap();
    assert_eq!(plane.object_count().unwrap(), 3);
    plane.step(1.0 / 60.0).unwrap();
    assert_eq!(plane.object_count().unwrap(), 3);
    c.destroy();
    map.object.destroy();
    b.destroy();
    assert_eq!(plane.object_count().unwrap(), 0);
    plane.step(1.0 / 60.0).unwrap();
    assert_eq!(plane.object_count().unwrap(), 0);
    assert_eq!(daemon_count(&plane), 0);
}

#[test]
fn another_clients_adds_show_with_the_next_tick() {
    let daemon = TestDaemon::start("count-shared");
    let owner = daemon.client();
    let plane = owner
        .create_plane(&PlaneOptions {
            shared: Some(true),
            ..PlaneOptions::manual()
        })
        .unwrap();
    plane.add(ball(), Pose::at([0.0; 3]), &[]).unwrap();
    plane.step(1.0 / 60.0).unwrap();
    let other = Client::connect(&daemon.domain).unwrap();
    let theirs = other.attach_plane(plane.id()).unwrap();
    theirs.add(ball(), Pose::at([2.0, 0.0, 0.0]), &[]).unwrap();
    theirs.add(ball(), Pose::at([4.0, 0.0, 0.0]), &[]).unwrap();
    assert_eq!(theirs.object_count().unwrap(), 3);
    assert_eq!(plane.object_count().unwrap(), 1, "no tick since their adds");
    plane.step(1.0 / 60.0).unwrap();
    owner.begin_frame();
    assert_eq!(plane.object_count().unwrap(), 3);
}

#[test]
fn reading_the_count_sends_nothing_to_the_daemon() {
    let daemon = TestDaemon::start("count-local");
    let client = daemon.client();
    let plane = client.create_plane(&PlaneOptions::manual()).unwrap();
    let objects: Vec<_> = (0..4)
        .map(|i| {
            plane
                .add(ball(), Pose::at([i as f32 * 2.0, 0.0, 0.0]), &[])
                .unwrap()
        })
        .collect();
    plane.step(1.0 / 60.0).unwrap();
    objects[0].destroy();
    // A stopped daemon answers no request: a read that needed one would wait for the
    // client's request timeout instead of returning at once.
    daemon.signal(libc::SIGSTOP);
    let started = Instant::now();
    let counts: Vec<u32> = (0..1000).map(|_| plane.object_count().unwrap()).collect();
    let took = started.elapsed();
    daemon.signal(libc::SIGCONT);
    assert!(counts.iter().all(|&n| n == 3), "{:?}", &counts[..4]);
    assert!(
        took < Duration::from_secs(1),
        "1,000 reads took {took:?}: they waited on the daemon"
    );
    client.flush().unwrap();
    assert_eq!(daemon_count(&plane), 3);
}

#[test]
fn a_gui_planes_count_follows_its_adds_and_removals_while_it_ticks() {
    let daemon = TestDaemon::start("count-gui");
    let client = daemon.client();
    let plane = client
        .create_gui_plane(&client_sdk::GuiPlaneOptions {
            tick_rate: Some(240.0),
            ..Default::default()
        })
        .unwrap();
    let mut live = Vec::new();
    for step in 0..120u32 {
        if step % 3 == 2 {
            let o: client_sdk::GuiObject = live.remove(0);
            o.destroy();
        } else {
            let x = 40.0 * (step % 20) as f32;
            let shape = client_sdk::GuiShape::Circle;
            live.push(plane.add(shape, [20.0, 20.0], [x, 100.0], &[]).unwrap());
        }
        assert_eq!(
            plane.object_count().unwrap(),
            live.len() as u32,
            "step {step}"
        );
    }
    client.flush().unwrap();
    assert_eq!(plane.info().unwrap().object_count, live.len() as u32);
    std::thread::sleep(Duration::from_millis(50));
    client.begin_frame();
    assert_eq!(plane.object_count().unwrap(), live.len() as u32);
}

//! Snapshots taken between two ticks, through real daemons: after objects were added or
//! written and before the plane steps again, a snapshot restored (as a new plane, or into
//! the plane it was taken from) steps on to the bit as the original does. The restored
//! plane's first step treats the objects those ops touched as the original's does (with
//! the plane's damping: a new ball thrown at 14 units/s moves 14·dt less a damped share),
//! and its later steps follow. GUI planes alike.

use client_sdk::{
    Client, GuiPlane, GuiPlaneOptions, Object, ObjectProp, Plane, PlaneOptions, Pose, Shape,
};
use integration_tests::TestDaemon;
use shm_layout::settings::{GuiObjectProp, GuiShape};

const DT: f32 = 1.0 / 60.0;

fn manual_plane(client: &Client) -> Plane {
    client.create_plane(&PlaneOptions::manual()).unwrap()
}

/// Steps `a` and `b` `ticks` times; the first tick whose state hash differs, if any.
fn first_divergence(a: &Plane, b: &Plane, ticks: u32) -> Option<(u32, u64, u64)> {
    lockstep(&[a, b], ticks).map(|(tick, hashes)| (tick, hashes[0], hashes[1]))
}

/// Steps every plane `ticks` times; the first tick whose state hashes differ, if any,
/// with the hashes.
fn lockstep(planes: &[&Plane], ticks: u32) -> Option<(u32, Vec<u64>)> {
    for tick in 0..ticks {
        let hashes: Vec<u64> = planes
            .iter()
            .map(|p| {
                p.step(DT).unwrap();
                p.state_hash().unwrap()
            })
            .collect();
        if hashes.windows(2).any(|w| w[0] != w[1]) {
            return Some((tick, hashes));
        }
    }
    None
}

/// The smallest case: one ball added with a velocity, never stepped, snapshotted, and
/// restored as a new plane. Both planes' first steps damp it alike.
#[test]
fn a_ball_added_before_any_step_restores_bit_for_bit() {
    let daemon = TestDaemon::start("pend-ball");
    let client = daemon.client();
    let plane = manual_plane(&client);
    let ball = plane
        .add(
            Shape::Sphere { radius: 0.5 },
            Pose::at([-10.0, 5.0, 0.0]),
            &[ObjectProp::Velocity([14.0, 0.0, 0.0])],
        )
        .unwrap();
    let snapshot = plane.take_snapshot().unwrap();
    let copy = client.plane_from_snapshot(&snapshot, &[]).unwrap();
    let ball_copy = Object::from_handle(&copy, ball.handle());
    plane.step(DT).unwrap();
    copy.step(DT).unwrap();
    let (x, x_copy) = (
        ball.position().unwrap()[0],
        ball_copy.position().unwrap()[0],
    );
    // The plane's LinearDamping takes its share: short of the undamped -10 + 14·dt by more
    // than float rounding (the undamped step lands within 1e-6 of it).
    assert!(x < -10.0 + 14.0 * DT - 1e-4, "x = {x}: undamped");
    assert_eq!(
        x.to_bits(),
        x_copy.to_bits(),
        "original {x}, restored {x_copy}"
    );
    assert_eq!(plane.state_hash().unwrap(), copy.state_hash().unwrap());
    assert_eq!(first_divergence(&plane, &copy, 60), None);
}

/// A pile settled (partly asleep), then objects added with velocities, sleeping and awake
/// ones written, a force and an impulse: every kind of op a step lists its objects for.
fn settled_and_written(client: &Client) -> (Plane, Vec<Object>) {
    let plane = manual_plane(client);
    plane
        .add(
            Shape::Cube {
                size: [40.0, 1.0, 40.0],
            },
            Pose::at([0.0, -0.5, 0.0]),
            &[ObjectProp::Anchored(true)],
        )
        .unwrap();
    let mut objects: Vec<Object> = (0..16)
        .map(|i| {
            let at = [(i % 4) as f32 * 2.5 - 4.0, 0.5, (i / 4) as f32 * 2.5 - 4.0];
            let cube = Shape::Cube { size: [1.0; 3] };
            plane.add(cube, Pose::at(at), &[]).unwrap()
        })
        .collect();
    for _ in 0..150 {
        plane.step(DT).unwrap();
    }
    for i in 0..4 {
        let v = ObjectProp::Velocity([3.0 + i as f32, 2.0, -1.0]);
        let at = [i as f32 * 2.0 - 3.0, 4.0, 6.0];
        let ball = Shape::Sphere { radius: 0.4 };
        objects.push(plane.add(ball, Pose::at(at), &[v]).unwrap());
    }
    for (k, o) in objects.iter().enumerate().step_by(3) {
        o.set_velocity([0.3 * (k % 5) as f32, 0.5, -0.2]).unwrap();
    }
    objects[1]
        .set(ObjectProp::ConstantForce([0.0, 15.0, 0.0]))
        .unwrap();
    objects[2].apply_impulse([2.0, 3.0, 0.0]).unwrap();
    (plane, objects)
}

/// The same writes and an add on a plane after the restore, before its first step.
fn written_after(plane: &Plane, objects: &[Object]) {
    for (k, o) in objects.iter().enumerate().skip(1).step_by(4) {
        let o = Object::from_handle(plane, o.handle());
        o.set_velocity([0.2, 0.5 * (k % 4) as f32, 0.1]).unwrap();
    }
    plane
        .add(
            Shape::Sphere { radius: 0.5 },
            Pose::at([0.0, 6.0, 0.0]),
            &[ObjectProp::Velocity([0.0, -5.0, 2.0])],
        )
        .unwrap();
}

/// Writes and adds before the snapshot, the same writes on both planes after the restore:
/// the new plane (on the same daemon and on a second one) steps on to the bit.
#[test]
fn writes_and_adds_around_the_snapshot_step_on_to_the_bit() {
    let first = TestDaemon::start("pend-a");
    let second = TestDaemon::start("pend-b");
    let (client, other) = (first.client(), second.client());
    let (plane, objects) = settled_and_written(&client);
    let snapshot = plane.take_snapshot().unwrap();
    let here = client.plane_from_snapshot(&snapshot, &[]).unwrap();
    let carried = client_sdk::PlaneSnapshot::from_bytes(snapshot.bytes().to_vec()).unwrap();
    let there = other.plane_from_snapshot(&carried, &[]).unwrap();
    for p in [&plane, &here, &there] {
        written_after(p, &objects);
    }
    // A plane that never took a snapshot: taking one changes nothing either.
    let (reference, _) = settled_and_written(&client);
    written_after(&reference, &objects);
    assert_eq!(
        lockstep(&[&reference, &plane, &here, &there], 40),
        None,
        "(never snapshotted, snapshotted, restored here, restored on a second daemon)"
    );
}

/// A snapshot restored into the plane it was taken from, after that plane added and wrote
/// objects of its own it has not stepped over: it steps on as a plane that never did.
#[test]
fn a_snapshot_restored_into_its_own_plane_after_ops_of_its_own_steps_on_to_the_bit() {
    let daemon = TestDaemon::start("pend-own");
    let client = daemon.client();
    let (plane, objects) = settled_and_written(&client);
    let snapshot = plane.take_snapshot().unwrap();
    let (reference, _) = settled_and_written(&client);
    plane.step(DT).unwrap();
    for k in 0..10 {
        let at = [k as f32 - 5.0, 8.0, 0.0];
        let v = ObjectProp::Velocity([0.0, 0.0, 9.0]);
        plane
            .add(Shape::Sphere { radius: 0.3 }, Pose::at(at), &[v])
            .unwrap();
    }
    objects[5].set_velocity([0.0, 7.0, 0.0]).unwrap();
    plane.restore(&snapshot).unwrap();
    assert_eq!(first_divergence(&reference, &plane, 40), None);
}

/// A GUI plane alike: a square added with a velocity and never stepped (the GUI plane's
/// default LinearDamping), restored as a new plane.
#[test]
fn a_gui_square_added_before_any_step_restores_bit_for_bit() {
    let daemon = TestDaemon::start("pend-gui");
    let client = daemon.client();
    let gui = client.create_gui_plane(&GuiPlaneOptions::manual()).unwrap();
    let square = gui
        .add(
            GuiShape::Square,
            [30.0, 30.0],
            [100.0, 100.0],
            &[GuiObjectProp::Velocity([300.0, 0.0])],
        )
        .unwrap();
    let snapshot = gui.plane().take_snapshot().unwrap();
    let copy = GuiPlane::from_plane(client.plane_from_snapshot(&snapshot, &[]).unwrap());
    gui.step(DT).unwrap();
    copy.step(DT).unwrap();
    let x = square.position().unwrap()[0];
    assert!(x < 100.0 + 300.0 * DT - 1e-3, "x = {x}: undamped");
    assert_eq!(
        gui.plane().state_hash().unwrap(),
        copy.plane().state_hash().unwrap()
    );
    assert_eq!(first_divergence(gui.plane(), copy.plane(), 60), None);
}

//! Contact events and collision groups through a real daemon: one start and one end per
//! contact with its point, normal and impulse; removal ends contacts; a reader that falls
//! behind is told exactly how many events it lost; groups that do not collide pass through
//! each other and report nothing.

use client_sdk::{Contact, Events, Object, ObjectProp, PlaneOptions, Pose, Shape};
use integration_tests::Scene;

const G: f32 = 50.0;
const DT: f32 = 1.0 / 60.0;

fn contacts(events: &Events) -> Vec<Contact> {
    events
        .records
        .iter()
        .filter_map(Contact::from_record)
        .collect()
}

fn ball(scene: &Scene, at: [f32; 3], props: &[ObjectProp]) -> Object {
    scene
        .plane
        .add(Shape::Sphere { radius: 0.5 }, Pose::at(at), props)
        .expect("add ball")
}

fn no_damping() -> PlaneOptions {
    PlaneOptions {
        linear_damping: Some(0.0),
        angular_damping: Some(0.0),
        ..Default::default()
    }
}

#[test]
fn a_landing_starts_one_contact_with_point_normal_and_impulse_and_lifting_ends_it() {
    let s = Scene::new("ev-land", no_damping());
    let floor = s.floor();
    s.plane.subscribe_events().unwrap();
    let h = 5.0;
    let b = ball(&s, [0.0, 0.5 + h, 0.0], &[ObjectProp::ReportContacts(true)]);
    let mut seen = Vec::new();
    for _ in 0..90 {
        s.plane.step(DT).unwrap();
        seen.extend(contacts(&s.plane.events().unwrap()));
    }
    assert_eq!(seen.len(), 1, "exactly one start while resting: {seen:?}");
    let Contact::Started {
        a,
        b: other,
        position,
        normal,
        impulse,
        ..
    } = seen[0]
    else {
        panic!("{seen:?}")
    };
    // Either order; the normal points from a toward b.
    let (ball_first, n_from_ball) = if a == b.handle() {
        assert_eq!(other, floor.handle());
        (true, normal)
    } else {
        assert_eq!((a, other), (floor.handle(), b.handle()));
        (false, normal.map(|c| -c))
    };
    let _ = ball_first;
    assert!(
        (n_from_ball[1] + 1.0).abs() < 1e-3,
        "normal from the ball to the floor is -y: {normal:?}"
    );
    assert!(
        position[0].abs() < 1e-2 && position[1].abs() < 0.05 && position[2].abs() < 1e-2,
        "contact under the ball on the floor's top face: {position:?}"
    );
    // Bounciness 0: the contact removes the impact speed v = √(2gh) (plus gravity during
    // the step): the normal impulse of the first contact tick is about m·v, m = 1. Rapier's
    // soft contacts may spread it over two ticks, hence the wide band.
    let v = (2.0 * G * h).sqrt();
    assert!(
        impulse > 0.5 * v && impulse < 1.5 * (v + G * DT),
        "impulse {impulse} vs m·v = {v}"
    );
    // Lifting it away ends the contact, once.
    b.set_pose(Pose::at([0.0, 20.0, 0.0])).unwrap();
    let mut ended = Vec::new();
    for _ in 0..5 {
        s.plane.step(DT).unwrap();
        ended.extend(contacts(&s.plane.events().unwrap()));
    }
    assert_eq!(ended.len(), 1, "{ended:?}");
    assert!(matches!(ended[0], Contact::Ended { a, b: o, .. }
        if [a, o].contains(&b.handle()) && [a, o].contains(&floor.handle())));
}

#[test]
fn removing_a_touching_object_ends_its_contacts() {
    let s = Scene::new("ev-remove", PlaneOptions::default());
    let floor = s.floor();
    s.plane.subscribe_events().unwrap();
    let b = ball(&s, [0.0, 0.5, 0.0], &[ObjectProp::ReportContacts(true)]);
    s.plane.step(DT).unwrap();
    let started = contacts(&s.plane.events().unwrap());
    assert_eq!(started.len(), 1, "{started:?}");
    let handle = b.handle();
    b.destroy();
    s.plane.step(DT).unwrap();
    let ended = contacts(&s.plane.events().unwrap());
    assert!(
        matches!(ended.as_slice(), [Contact::Ended { a, b: o, .. }]
            if [*a, *o].contains(&handle) && [*a, *o].contains(&floor.handle())),
        "{ended:?}"
    );
}

#[test]
fn a_reader_that_falls_behind_is_told_exactly_how_many_events_it_lost() {
    let s = Scene::new("ev-lost", PlaneOptions::default());
    s.floor();
    s.plane.subscribe_events().unwrap();
    let b = ball(&s, [0.0, 10.0, 0.0], &[ObjectProp::ReportContacts(true)]);
    // Teleport onto the floor and away again: one event per tick.
    let ticks = 200;
    for i in 0..ticks {
        let y = if i % 2 == 0 { 0.5 } else { 10.0 };
        b.set_pose(Pose::at([0.0, y, 0.0])).unwrap();
        s.plane.step(DT).unwrap();
    }
    let events = s.plane.events().unwrap();
    let kept = client_sdk::EVENT_BUFFER_TICKS as u64;
    assert_eq!(
        events.records.len() as u64,
        kept,
        "the newest ticks are kept"
    );
    assert_eq!(events.lost, ticks - kept, "every dropped event is counted");
    // Kept events are the newest, in order, without gaps.
    let seqs: Vec<u64> = events.records.iter().map(|r| r.seq).collect();
    assert!(seqs.windows(2).all(|w| w[1] == w[0] + 1), "{seqs:?}");
    assert_eq!(*seqs.last().unwrap(), ticks - 1);
    // Keeping up again: nothing more is lost.
    b.set_pose(Pose::at([0.0, 0.5, 0.0])).unwrap();
    s.plane.step(DT).unwrap();
    let next = s.plane.events().unwrap();
    assert_eq!((next.records.len(), next.lost), (1, 0));
}

#[test]
fn groups_that_do_not_collide_pass_through_and_report_nothing() {
    let s = Scene::new("ev-groups", no_damping());
    s.client.register_collision_group("Players").unwrap();
    s.client.register_collision_group("Ghosts").unwrap();
    s.client
        .collision_group_set_collidable("Players", "Ghosts", false)
        .unwrap();
    assert!(!s
        .client
        .collision_groups_are_collidable("Ghosts", "Players")
        .unwrap());
    assert!(s
        .client
        .collision_groups_are_collidable("Ghosts", "Default")
        .unwrap());
    let floor = s.floor();
    floor.set_collision_group("Players").unwrap();
    s.plane.subscribe_events().unwrap();
    let ghost = ball(&s, [0.0, 2.0, 0.0], &[ObjectProp::ReportContacts(true)]);
    ghost.set_collision_group("Ghosts").unwrap();
    let solid = ball(&s, [5.0, 2.0, 0.0], &[ObjectProp::ReportContacts(true)]);
    let mut seen = Vec::new();
    for _ in 0..60 {
        s.plane.step(DT).unwrap();
        seen.extend(contacts(&s.plane.events().unwrap()));
    }
    // Free fall for 1 s from y = 2: y = 2 - g/2 ≈ -23 (the floor's top is y = 0).
    assert!(
        ghost.position().unwrap()[1] < -20.0,
        "the ghost fell through"
    );
    assert!(
        (solid.position().unwrap()[1] - 0.5).abs() < 0.05,
        "the Default ball rests on the Players floor"
    );
    assert!(
        seen.iter().all(|c| match c {
            Contact::Started { a, b, .. } | Contact::Ended { a, b, .. } =>
                ![*a, *b].contains(&ghost.handle()),
        }),
        "no contact for the ghost: {seen:?}"
    );
    assert_eq!(ghost.collision_group().unwrap(), "Ghosts");
    // Removing the group returns its objects to Default, which collides with Players.
    s.client.unregister_collision_group("Ghosts").unwrap();
    assert_eq!(ghost.collision_group().unwrap(), "Default");
    ghost.set_pose(Pose::at([0.0, 2.0, 0.0])).unwrap();
    ghost.set_velocity([0.0; 3]).unwrap();
    s.run(DT, 60);
    assert!((ghost.position().unwrap()[1] - 0.5).abs() < 0.05);
}

#[test]
fn the_group_table_has_roblox_limits_and_clear_errors() {
    let s = Scene::new("ev-limits", PlaneOptions::default());
    let c = &s.client;
    assert_eq!(c.max_collision_groups(), 32);
    for i in 1..32 {
        c.register_collision_group(&format!("G{i}")).unwrap();
    }
    let e = c.register_collision_group("G32").unwrap_err();
    assert!(e.to_string().contains("32"), "{e}");
    let names: Vec<String> = c
        .registered_collision_groups()
        .into_iter()
        .map(|g| g.name)
        .collect();
    assert_eq!(names.len(), 32);
    assert_eq!(names[0], "Default");
    let e = c.register_collision_group("").unwrap_err();
    assert!(e.to_string().contains("name"), "{e}");
    let b = ball(&s, [0.0; 3], &[]);
    let e = b.set_collision_group("Unknown").unwrap_err();
    assert!(e.to_string().contains("\"Unknown\""), "{e}");
    // A forged index is refused by the daemon, naming the property.
    let e = b.set(ObjectProp::CollisionGroup(200));
    let e = match e {
        Err(e) => e,
        Ok(()) => s.client.flush().unwrap_err(),
    };
    assert!(e.to_string().contains("CollisionGroup"), "{e}");
}

//! `JointOp::List` through a real daemon: a plane's joints in pages, in slot order, each as
//! `JointOp::Info` describes it; a destroyed joint is absent; any client may list (a read)
//! though only the owner may change; a bad limit is refused by the daemon too; a GUI plane
//! refuses the op as not its own.

use client_sdk::{
    Error, ErrorKind, Handle, Joint, JointInfo, JointKind, JointProp, Object, ObjectProp, Pose,
    Shape,
};
use integration_tests::{Scene, TestDaemon};
use shm_layout::codec::{decode_response, encode_request};
use shm_layout::joint_op::{JointOp, MAX_JOINT_PAGE};
use shm_layout::{Command, PlaneOp, Reply, Request, Response};

const DT: f32 = 1.0 / 60.0;

/// A chain of `n + 1` balls along +x, 1 apart, the first held to the world: `n` ball joints
/// (the first to the world, then each ball to the one before).
fn chain(s: &Scene, n: usize) -> (Vec<Object>, Vec<Joint>) {
    let balls: Vec<Object> = (0..n)
        .map(|i| {
            s.plane
                .add(
                    Shape::Sphere { radius: 0.2 },
                    Pose::at([i as f32, 10.0, 0.0]),
                    &[ObjectProp::Weight(1.0)],
                )
                .unwrap()
        })
        .collect();
    let joints = balls
        .iter()
        .enumerate()
        .map(|(i, ball)| {
            let (other, anchor_b) = if i == 0 {
                (None, [-0.5, 10.0, 0.0])
            } else {
                (Some(&balls[i - 1]), [0.5, 0.0, 0.0])
            };
            s.plane
                .joint(
                    JointKind::Ball,
                    ball,
                    other,
                    &[
                        JointProp::AnchorA([-0.5, 0.0, 0.0]),
                        JointProp::AnchorB(anchor_b),
                    ],
                )
                .unwrap()
        })
        .collect();
    (balls, joints)
}

fn raw_list(
    client: &client_sdk::Client,
    plane: client_sdk::PlaneId,
    after: u32,
    limit: u32,
) -> Reply {
    let request = Request {
        commands: vec![Command::plane(
            plane,
            PlaneOp::Joint(JointOp::List { after, limit }),
        )],
    };
    let bytes = client.raw_request(&encode_request(&request)).unwrap();
    match decode_response(&bytes).unwrap() {
        Response::Results(mut r) => r.remove(0).unwrap_or_else(|e| panic!("{e:?}")),
        other => panic!("expected results, got {other:?}"),
    }
}

/// Eleven joints, the fifth destroyed: pages of three walk the ten others in slot order
/// (3, 3, 3, then a short last page of 1), each entry equal to what `Info` answers; the
/// whole list and a raw request agree; past the last slot the page is empty.
#[test]
fn pages_of_three_walk_every_live_joint_in_slot_order() {
    let s = Scene::new("joints-list", Default::default());
    let (_balls, mut joints) = chain(&s, 11);
    let gone = joints.remove(4);
    let gone_handle = gone.handle();
    gone.destroy().unwrap();
    // The chain swings a little: the figures (error, force) are those of a step.
    s.run(DT, 5);
    let want: Vec<Handle> = joints.iter().map(Joint::handle).collect();
    assert_eq!(want.len(), 10);
    // Slots as the table hands them out: 0..=10, the destroyed one's (4) free.
    let mut slots: Vec<u32> = want.iter().map(|h| h.slot).collect();
    slots.sort_unstable();
    assert_eq!(slots, [0, 1, 2, 3, 5, 6, 7, 8, 9, 10]);
    assert_eq!(gone_handle.slot, 4);

    let mut pages = Vec::new();
    let mut after = 0;
    loop {
        let page = s.plane.joint_page(after, 3).unwrap();
        assert!(page.len() <= 3, "a page of {}", page.len());
        let short = page.len() < 3;
        if let Some(last) = page.last() {
            after = last.handle.slot + 1;
        }
        pages.push(page);
        assert!(pages.len() <= 5, "the pages never end: {pages:?}");
        if short {
            break;
        }
    }
    let sizes: Vec<usize> = pages.iter().map(Vec::len).collect();
    assert_eq!(sizes, [3, 3, 3, 1]);
    let listed: Vec<JointInfo> = pages.into_iter().flatten().collect();
    let mut in_order = want.clone();
    in_order.sort_by_key(|h| h.slot);
    assert_eq!(
        listed.iter().map(|j| j.handle).collect::<Vec<_>>(),
        in_order,
        "every live joint once, ascending slots"
    );
    assert!(listed.iter().all(|j| j.handle != gone_handle));
    for j in &joints {
        let info = j.info().unwrap();
        let entry = listed.iter().find(|l| l.handle == j.handle()).unwrap();
        assert_eq!(*entry, info, "the list describes a joint as Info does");
        assert_eq!(entry.kind, JointKind::Ball);
    }
    // The chain is loaded: its joints carry force (the list's figures are the step's).
    assert!(listed.iter().any(|j| j.force > 0.0), "{listed:?}");
    // The world joint (the first ball's) has no B; the others name the ball before.
    assert_eq!(listed[0].b, None);
    assert!(listed[1..].iter().all(|j| j.b.is_some()));

    assert_eq!(
        s.plane.joints().unwrap(),
        listed,
        "the SDK pages to the same list"
    );
    // From a slot inside the table, from the last slot, past the end.
    let from_six = s.plane.joint_page(6, 100).unwrap();
    assert_eq!(
        from_six.iter().map(|j| j.handle.slot).collect::<Vec<_>>(),
        [6, 7, 8, 9, 10]
    );
    assert_eq!(s.plane.joint_page(10, 100).unwrap().len(), 1);
    assert!(s.plane.joint_page(11, 100).unwrap().is_empty());
    assert!(s
        .plane
        .joint_page(u32::MAX, MAX_JOINT_PAGE)
        .unwrap()
        .is_empty());

    // The daemon cuts a large limit to a page and refuses 0 (a client bypassing the SDK).
    match raw_list(&s.client, s.plane.id(), 0, u32::MAX) {
        Reply::Joints(all) => assert_eq!(all, listed),
        other => panic!("{other:?}"),
    }
    let request = Request {
        commands: vec![Command::plane(
            s.plane.id(),
            PlaneOp::Joint(JointOp::List { after: 0, limit: 0 }),
        )],
    };
    let bytes = s.client.raw_request(&encode_request(&request)).unwrap();
    let Response::Results(r) = decode_response(&bytes).unwrap() else {
        panic!("expected results");
    };
    let e = r[0].as_ref().unwrap_err();
    assert_eq!(e.kind, ErrorKind::InvalidValue);
    assert_eq!(e.field.as_deref(), Some("limit"), "{e:?}");
    // The SDK refuses it before sending.
    match s.plane.joint_page(0, 0) {
        Err(Error::Invalid { field, .. }) => assert_eq!(field, "limit"),
        other => panic!("{other:?}"),
    }

    // A plane without joints lists none.
    let empty = s
        .client
        .create_plane(&client_sdk::PlaneOptions::manual())
        .unwrap();
    assert!(empty.joints().unwrap().is_empty());
}

/// Another client may list the plane's joints (a read) but not destroy one (a write).
#[test]
fn a_client_that_does_not_own_the_plane_may_list_its_joints() {
    let s = Scene::new("joints-list-other", Default::default());
    let (_balls, joints) = chain(&s, 4);
    s.run(DT, 2);
    let other_client = s.daemon.client();
    let theirs = other_client.attach_plane(s.plane.id()).unwrap();
    let listed = theirs.joints().unwrap();
    assert_eq!(listed, s.plane.joints().unwrap());
    assert_eq!(
        listed.iter().map(|j| j.handle).collect::<Vec<_>>(),
        joints.iter().map(Joint::handle).collect::<Vec<_>>()
    );
    // The ownership check is live: the same client's write is refused.
    let j = &joints[1];
    let err = Joint::from_handle(&theirs, j.handle(), j.kind())
        .destroy()
        .unwrap_err();
    assert!(matches!(err, Error::Command(_)), "{err:?}");
    assert_eq!(s.plane.joints().unwrap().len(), 4, "nothing was destroyed");
}

/// A GUI plane has no joints: it refuses the list as an op of 3D planes.
#[test]
fn a_gui_plane_refuses_the_list() {
    let daemon = TestDaemon::start("joints-list-gui");
    let client = daemon.client();
    let gui = client
        .create_gui_plane(&client_sdk::GuiPlaneOptions::manual())
        .unwrap();
    match gui.plane().joints() {
        Err(Error::Command(e)) => {
            assert_eq!(e.kind, ErrorKind::InvalidValue);
            assert!(e.message.contains("3D planes"), "{}", e.message);
        }
        other => panic!("{other:?}"),
    }
}

//! `--rebalance`: a daemon over its share of the tick budget moves planes to a member with
//! room. `a` runs with an artificially small share (`--rebalance 0.0001`: any ticking plane
//! puts it over), `b` idles. The largest plane that is not pinned moves to `b`; a pinned
//! plane and a smaller one stay (`b` has no room once it ticks the moved plane: no
//! ping-pong); the owner's handle follows the move and still owns the plane there.

use std::time::Duration;

use client_sdk::{Client, Object, Plane, PlaneOptions, Pose, Shape};
use integration_tests::cluster::{endpoint, free_port, member, unique_cluster};
use integration_tests::eventually;

fn ticking_plane(client: &Client, balls: usize) -> (Plane, Vec<Object>) {
    let plane = client
        .create_plane(&PlaneOptions {
            tick_rate: Some(60.0),
            gravity: Some([0.0, 0.0, 0.0]),
            ..integration_tests::no_damping()
        })
        .unwrap();
    let objects = (0..balls)
        .map(|i| {
            plane
                .add(
                    Shape::Sphere { radius: 0.5 },
                    Pose::at([(i % 20) as f32 * 2.0, (i / 20) as f32 * 2.0, 0.0]),
                    &[],
                )
                .unwrap()
        })
        .collect();
    (plane, objects)
}

/// The daemon `plane` lives on, as its handle learns it (asking the old daemon once: a
/// plane moved by `--rebalance` is switched over by the refusal).
fn where_now(plane: &Plane) -> Option<String> {
    let _ = plane.info();
    plane.daemon()
}

#[test]
fn an_overloaded_daemon_moves_its_largest_unpinned_plane_and_only_that() {
    let cluster = unique_cluster("rb");
    let (pa, pb) = (free_port(), free_port());
    let a = member(&cluster, "a", pa, &[], &["--rebalance", "0.0001"]);
    let _b = member(&cluster, "b", pb, &[pa], &[]);
    let view = client_sdk::cluster::Cluster::connect(&cluster, &[&endpoint(pa)]).unwrap();
    eventually(Duration::from_secs(10), || {
        (view.daemons().ok()?.len() == 2).then_some(())
    })
    .expect("both members joined");

    let owner = a.client();
    let (pinned, _) = ticking_plane(&owner, 300);
    pinned.pin().unwrap();
    let (large, large_balls) = ticking_plane(&owner, 200);
    let (small, _) = ticking_plane(&owner, 20);
    // The largest plane not pinned goes to b within a few load reports.
    let moved = eventually(Duration::from_secs(15), || {
        (where_now(&large).as_deref() == Some("b")).then_some(())
    });
    assert!(moved.is_some(), "the 200-ball plane moved to b");
    // It ticks on there, and its owner still owns it (the claim key came with the refusal).
    let tick = large.wait_tick(Duration::from_secs(2)).unwrap();
    assert!(large.wait_tick(Duration::from_secs(2)).unwrap() > tick);
    large_balls[0].set_velocity([1.0, 0.0, 0.0]).unwrap();
    owner.flush().expect("the owner writes to its moved plane");
    // Past the cooldown, nothing else moves: the pinned plane never, the small one because
    // b, ticking the moved plane, has no room under half the share.
    std::thread::sleep(super_cooldown());
    assert_eq!(where_now(&pinned), None, "the pinned plane stays on a");
    assert_eq!(
        where_now(&small),
        None,
        "no member has room for the small plane"
    );
    assert_eq!(where_now(&large).as_deref(), Some("b"), "no ping-pong");
}

/// A little longer than the daemon's cooldown between two moves.
fn super_cooldown() -> Duration {
    Duration::from_secs(7)
}

#[test]
fn a_bad_rebalance_share_is_refused_naming_the_flag() {
    let cluster = unique_cluster("rb-bad");
    let port = free_port();
    let out = std::process::Command::new(client_sdk::daemon_executable())
        .args([
            "--domain",
            &integration_tests::unique_domain("rb-bad"),
            "--cluster",
            &cluster,
            "--name",
            "a",
            "--listen",
            &endpoint(port),
            "--rebalance",
            "1.5",
        ])
        .env("PHYSICS_LOG", "warn")
        .stdin(std::process::Stdio::null())
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{text}");
    assert!(
        text.contains("--rebalance") && text.contains("1.5"),
        "{text}"
    );
}

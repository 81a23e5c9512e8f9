//! The contact, joint and shape rows of the reference, exercised from Luau: each script
//! under tests/lua runs through the real `physics-lua` runner against a real daemon and
//! asserts its numbers (closed forms) itself; these tests check its exit status and the
//! line it prints when every assertion held.

use std::time::{Duration, Instant};

use integration_tests::{physics_lua, TestDaemon};

/// Runs `script` against a daemon of its own; panics with both streams unless it exits 0
/// and prints `done`.
fn run_script(tag: &str, script: &str, done: &str) -> String {
    let daemon = TestDaemon::start(tag);
    let started = Instant::now();
    let mut child = physics_lua(&daemon.domain, script, &[])
        .spawn()
        .expect("spawn physics-lua");
    while child.try_wait().expect("wait physics-lua").is_none() {
        if started.elapsed() > Duration::from_secs(90) {
            let _ = child.kill();
            break;
        }
        std::thread::sleep(Duration::from_millis(10));
    }
    let out = child.wait_with_output().expect("collect output");
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(
        out.status.success() && stdout.contains(done),
        "{script}: status {:?}\nstdout:\n{stdout}\nstderr:\n{}",
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
    stdout
}

#[test]
fn a_resting_box_reports_four_corner_points_whose_impulses_carry_its_weight() {
    let out = run_script(
        "rows-contacts",
        "tests/lua/contact_points.luau",
        "contact points ok",
    );
    print!("{out}");
}

#[test]
fn sixdof_axis_springs_oscillate_at_their_period_and_motors_reach_their_velocity() {
    let out = run_script(
        "rows-motors",
        "tests/lua/axis_motors.luau",
        "axis motors ok",
    );
    print!("{out}");
}

#[test]
fn planes_and_brushes_meet_rays_contacts_and_controllers_where_their_equations_say() {
    let out = run_script(
        "rows-static",
        "tests/lua/static_shapes.luau",
        "static shapes ok",
    );
    print!("{out}");
}

#[test]
fn animated_ragdoll_bones_follow_their_cframes_and_hits_name_the_bone() {
    let out = run_script(
        "rows-ragdoll",
        "tests/lua/animated_ragdoll.luau",
        "animated ragdoll ok",
    );
    print!("{out}");
}

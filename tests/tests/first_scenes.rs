//! The scenes a user writes first, as Luau scripts under `tests/lua/` run by the real
//! `physics-lua` against a real daemon: each script asserts its own outcome and prints a
//! last line that these tests look for.

use integration_tests::{physics_lua, TestDaemon};

/// Runs `script` against a daemon of its own and checks it exits 0 printing `done`.
fn runs(tag: &str, script: &str, done: &str) {
    let daemon = TestDaemon::start(tag);
    let out = physics_lua(&daemon.domain, script, &[])
        .output()
        .expect("run physics-lua");
    let (stdout, stderr) = (
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr),
    );
    assert!(
        out.status.success() && stdout.contains(done),
        "{script}: {:?}\nstdout:\n{stdout}\nstderr:\n{stderr}",
        out.status
    );
}

#[test]
fn a_controller_walks_along_its_look_vector() {
    runs(
        "first-facing",
        "tests/lua/controller_facing.luau",
        "controller facing ok",
    );
}

#[test]
fn joints_swing_and_turn_default_parts() {
    runs(
        "first-joints",
        "tests/lua/joints_default_parts.luau",
        "joints on default parts ok",
    );
}

#[test]
fn ground_y_takes_nil_to_clear_it() {
    runs(
        "first-groundy",
        "tests/lua/ground_y_nil.luau",
        "GroundY nil ok",
    );
}

#[test]
fn values_read_back_as_written() {
    runs("first-readback", "tests/lua/read_back.luau", "read back ok");
}

#[test]
fn joints_have_a_lifecycle_like_objects() {
    runs(
        "first-joint-life",
        "tests/lua/joint_lifecycle.luau",
        "joint lifecycle ok",
    );
}

#[test]
fn gui_values_name_themselves_without_rust_internals() {
    runs(
        "first-gui-names",
        "tests/lua/gui_names.luau",
        "gui names ok",
    );
}

//! The Capsule, Cylinder and Wedge parts from Luau: tests/lua/shapes.luau runs through the
//! real `physics-lua` runner against a real daemon and asserts masses, the wedge's centre
//! of mass, the slope's direction and resting heights itself.

use std::time::{Duration, Instant};

use integration_tests::{physics_lua, TestDaemon};

#[test]
fn capsule_cylinder_and_wedge_parts_work_from_lua() {
    let daemon = TestDaemon::start("lua-shapes");
    let started = Instant::now();
    let mut child = physics_lua(&daemon.domain, "tests/lua/shapes.luau", &[])
        .spawn()
        .expect("spawn physics-lua");
    while child.try_wait().expect("wait physics-lua").is_none() {
        if started.elapsed() > Duration::from_secs(60) {
            let _ = child.kill();
            break;
        }
        std::thread::sleep(Duration::from_millis(10));
    }
    let out = child.wait_with_output().expect("collect output");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success() && stdout.contains("shapes ok"),
        "status {:?}\nstdout:\n{stdout}\nstderr:\n{}",
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
}

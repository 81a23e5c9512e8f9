//! What a script trips on, through the real `physics-lua` runner and a real daemon: a run
//! ends once nothing can fire its handlers again, Heart's dt after a quiet stretch, tostring
//! of destroyed things, `wait(math.huge)`, Size limits of a free part.

use std::process::Output;
use std::time::{Duration, Instant};

use integration_tests::{physics_lua, run_lua, TestDaemon};

/// Runs `script` with `--seconds 30` and asserts it succeeded; returns its output and how
/// long it ran, or panics after `limit` (the run did not end) with what it printed.
fn run(daemon: &TestDaemon, script: &str, limit: Duration) -> (Output, Duration) {
    let (out, took) = run_lua(&daemon.domain, script, &["--seconds", "30"], limit);
    assert!(
        out.status.success(),
        "{script} failed\nstdout:\n{}\nstderr:\n{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    (out, took)
}

fn stdout(out: &Output) -> String {
    String::from_utf8_lossy(&out.stdout).into_owned()
}

#[test]
fn a_run_ends_when_a_broke_handler_lost_its_joint_with_the_object() {
    let daemon = TestDaemon::start("trust-joint");
    let (out, _) = run(
        &daemon,
        "tests/lua/run_ends_joint.luau",
        Duration::from_secs(15),
    );
    assert!(stdout(&out).contains("run ends joint: destroyed"));
}

#[test]
fn a_run_ends_when_its_plane_went_under_broke_and_cframe_handlers() {
    let daemon = TestDaemon::start("trust-plane");
    let (out, _) = run(
        &daemon,
        "tests/lua/run_ends_plane.luau",
        Duration::from_secs(15),
    );
    assert!(stdout(&out).contains("run ends plane: destroyed"));
}

#[test]
fn a_live_cframe_handler_keeps_the_run_going() {
    let daemon = TestDaemon::start("trust-goes-on");
    let started = Instant::now();
    let out = physics_lua(
        &daemon.domain,
        "tests/lua/run_goes_on.luau",
        &["--seconds", "2"],
    )
    .output()
    .expect("run physics-lua");
    let took = started.elapsed();
    assert!(out.status.success(), "{out:?}");
    assert!(stdout(&out).contains("run goes on: listening"));
    assert!(
        took >= Duration::from_millis(1900),
        "the run ended after {took:?} while a live part's CFrame handler listened"
    );
}

#[test]
fn heart_dt_tostring_wait_forever_and_free_part_sizes() {
    let daemon = TestDaemon::start("trust-small");
    let (out, took) = run(
        &daemon,
        "tests/lua/trust_small.luau",
        Duration::from_secs(20),
    );
    assert!(stdout(&out).contains("trust small ok"), "{}", stdout(&out));
    // The thread parked in wait(math.huge) does not keep the run going.
    assert!(took < Duration::from_secs(15), "took {took:?}");
}

#[test]
fn dyn_mesh_welds_follow_every_step_of_a_loop() {
    let daemon = TestDaemon::start("trust-welds");
    let (out, _) = run(
        &daemon,
        "tests/lua/weld_steps.luau",
        Duration::from_secs(20),
    );
    assert!(stdout(&out).contains("weld steps ok"), "{}", stdout(&out));
}

#[test]
fn errors_speak_the_api_words_not_rust() {
    let daemon = TestDaemon::start("trust-words");
    let (out, _) = run(
        &daemon,
        "tests/lua/error_words.luau",
        Duration::from_secs(30),
    );
    assert!(stdout(&out).contains("error words ok"), "{}", stdout(&out));
}

/// Runs with a daemon the runner starts itself (and a GPU plane where there is an adapter):
/// stderr carries nothing, since the script prints nothing there (iceoryx2's notes and a
/// GPU driver's probe lines stay out of the run's output). Several runs, as the notes came
/// in a few runs of a hundred.
#[test]
fn an_ordinary_run_prints_nothing_on_stderr() {
    for i in 0..6 {
        let domain = integration_tests::unique_domain("trust-quiet");
        let out = physics_lua(&domain, "tests/lua/quiet_run.luau", &[])
            .output()
            .expect("run physics-lua");
        let _ =
            std::fs::remove_file(std::env::temp_dir().join(format!("physics-daemon-{domain}.log")));
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "run {i}: {out:?}");
        assert!(
            stdout(&out).contains("quiet ok"),
            "run {i}: {}",
            stdout(&out)
        );
        assert!(
            stderr.trim().is_empty(),
            "run {i} printed on stderr:\n{stderr}"
        );
    }
}

#[test]
fn nil_removes_joint_limits_and_motors() {
    let daemon = TestDaemon::start("trust-unset");
    let (out, _) = run(
        &daemon,
        "tests/lua/joint_unset.luau",
        Duration::from_secs(30),
    );
    assert!(stdout(&out).contains("joint unset ok"), "{}", stdout(&out));
}

#[test]
fn joint_coordinates_follow_the_one_documented_rule() {
    let daemon = TestDaemon::start("trust-conventions");
    let (out, _) = run(
        &daemon,
        "tests/lua/joint_conventions.luau",
        Duration::from_secs(30),
    );
    assert!(
        stdout(&out).contains("joint conventions ok"),
        "{}",
        stdout(&out)
    );
}

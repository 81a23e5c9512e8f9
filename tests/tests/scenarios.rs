//! Scenario games (`examples/scenarios/*.luau`): small games written the way a user writes
//! them, each asserting its own outcome and printing one summary line. Each runs here with
//! the built `physics-lua` against a fresh daemon; a test fails on a nonzero exit or a
//! missing summary line. The scripts step their planes once per frame (TickRate 0), so
//! `--fps 1000` only removes the real-time pace `--view` keeps, not a single step.

use std::time::{Duration, Instant};

use integration_tests::{physics_lua, TestDaemon};

/// Runs `examples/scenarios/NAME.luau` against a fresh daemon and checks its summary line
/// (`NAME: …`) and exit status; returns stdout.
fn scenario(name: &str, tag: &str) -> String {
    scenario_with(name, tag, &[])
}

fn scenario_with(name: &str, tag: &str, env: &[(&str, &str)]) -> String {
    let daemon = TestDaemon::start_with(tag, &[], env);
    let script = format!("examples/scenarios/{name}.luau");
    let started = Instant::now();
    let limit = Duration::from_secs(90);
    let mut child = physics_lua(&daemon.domain, &script, &["--fps", "1000"])
        .spawn()
        .expect("spawn physics-lua");
    while child.try_wait().expect("wait physics-lua").is_none() {
        if started.elapsed() > limit {
            let _ = child.kill();
            break;
        }
        std::thread::sleep(Duration::from_millis(10));
    }
    let out = child.wait_with_output().expect("collect output");
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    let stderr = String::from_utf8_lossy(&out.stderr);
    println!("{stdout}");
    // Never a silent skip: a machine without a GPU adapter fails here, saying so.
    assert!(
        !stderr.contains("no GPU adapter"),
        "{script} needs a GPU adapter and the daemon found none (on a machine without a GPU, \
         install Mesa's lavapipe: apt-get install mesa-vulkan-drivers libvulkan1)\nstderr:\n{stderr}"
    );
    assert_eq!(
        out.status.code(),
        Some(0),
        "{script} failed after {:?}\nstdout:\n{stdout}\nstderr:\n{stderr}",
        started.elapsed()
    );
    let prefix = format!("{name}: ");
    assert!(
        stdout.lines().any(|l| l.starts_with(&prefix)),
        "{script}: no summary line starting {prefix:?}\nstdout:\n{stdout}\nstderr:\n{stderr}"
    );
    stdout
}

#[test]
fn obby_player_reaches_the_goal() {
    let out = scenario("obby", "sc-obby");
    assert!(out.contains("obby: reached goal at t="), "{out}");
}

#[test]
fn vehicle_drives_over_the_hill_on_a_triangle_map() {
    scenario("vehicle", "sc-car");
}

#[test]
fn ragdoll_death_by_hitscan() {
    let out = scenario("ragdoll_death", "sc-ragdoll");
    assert!(out.contains("ragdoll_death: shot in the "), "{out}");
}

#[test]
fn destructible_wall_breaks_where_the_blast_is() {
    scenario("destructible_wall", "sc-wall");
}

#[test]
fn pinball_scores_on_a_gui_plane() {
    let out = scenario("pinball", "sc-pinball");
    assert!(out.contains("0 steps outside"), "{out}");
}

#[test]
fn fps_range_hits_every_target_once_and_spares_friendlies() {
    let out = scenario("fps_range", "sc-fps");
    assert!(out.contains("5/5 bullet hits (1/1/1/1/1)"), "{out}");
}

#[test]
fn rope_bridge_carries_a_heavy_cart_across() {
    let out = scenario("rope_bridge", "sc-bridge");
    assert!(out.contains("rope_bridge: cart crossed at t="), "{out}");
}

#[test]
fn gpu_debris_settles_beside_cpu_gameplay() {
    let out = scenario("gpu_debris", "sc-gpu");
    assert!(out.contains("0 still moving, 0 outside"), "{out}");
}

/// The GPU scenario without an adapter fails, and says why (the check above turns the
/// script's error into the test's message).
#[test]
fn gpu_debris_without_an_adapter_fails_loudly() {
    let result = std::panic::catch_unwind(|| {
        scenario_with("gpu_debris", "sc-gpu-off", &[("PHYSICS_GPU", "off")])
    });
    let message = match result {
        Ok(out) => panic!("gpu_debris passed without an adapter:\n{out}"),
        Err(e) => e.downcast_ref::<String>().cloned().unwrap_or_default(),
    };
    assert!(
        message.contains("needs a GPU adapter") && message.contains("mesa-vulkan-drivers"),
        "{message}"
    );
}

/// Every game in `examples/scenarios/` has its test above (a new game cannot be forgotten).
#[test]
fn every_scenario_file_is_tested() {
    let tested = [
        "destructible_wall",
        "fps_range",
        "gpu_debris",
        "obby",
        "pinball",
        "ragdoll_death",
        "rope_bridge",
        "vehicle",
    ];
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/scenarios");
    let mut found: Vec<String> = std::fs::read_dir(&dir)
        .expect("examples/scenarios")
        .filter_map(|e| {
            let name = e.ok()?.file_name().into_string().ok()?;
            name.strip_suffix(".luau").map(str::to_string)
        })
        .collect();
    found.sort();
    assert_eq!(found, tested, "scenario files vs. tests in scenarios.rs");
}

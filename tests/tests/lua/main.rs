//! The Luau API, exercised from Luau: scripts under tests/lua run through the real
//! `physics-lua` runner against a real daemon and assert behaviour themselves; these tests
//! check the runner's exit status and what the scripts printed.

// The Luau API's other subjects, one module each: the generated reference, the declarations, the runner, shapes, untrusted scripts.
mod api_doc;
mod definitions;
mod runner;
mod shapes;
mod trust;

use std::process::Output;
use std::time::Duration;

use integration_tests::{domain_files, run_lua, unique_domain, TestDaemon};

struct Run {
    output: Output,
    took: Duration,
}

impl Run {
    fn stdout(&self) -> String {
        String::from_utf8_lossy(&self.output.stdout).into_owned()
    }
    fn stderr(&self) -> String {
        String::from_utf8_lossy(&self.output.stderr).into_owned()
    }
    fn code(&self) -> Option<i32> {
        self.output.status.code()
    }
    /// Panics with both streams unless the run exited 0.
    fn assert_ok(&self) -> &Self {
        assert_eq!(
            self.code(),
            Some(0),
            "physics-lua failed\nstdout:\n{}\nstderr:\n{}",
            self.stdout(),
            self.stderr()
        );
        self
    }
}

/// Runs `physics-lua script --domain domain extra...`, killing it after `limit`.
fn run_in(domain: &str, script: &str, extra: &[&str], limit: Duration) -> Run {
    let (output, took) = run_lua(domain, script, extra, limit);
    Run { output, took }
}

fn run(daemon: &TestDaemon, script: &str) -> Run {
    run_in(&daemon.domain, script, &[], Duration::from_secs(60))
}

#[test]
fn values_written_from_lua_read_back() {
    let daemon = TestDaemon::start("lua-values");
    let r = run(&daemon, "tests/lua/values.luau");
    r.assert_ok();
    assert!(r.stdout().contains("values ok"), "{}", r.stdout());
}

#[test]
fn bad_input_errors_name_property_type_and_value() {
    let daemon = TestDaemon::start("lua-errors");
    let r = run(&daemon, "tests/lua/errors.luau");
    r.assert_ok();
    let count: usize = r
        .stdout()
        .trim()
        .strip_prefix("errors ok\t")
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("unexpected output {:?}", r.stdout()));
    assert!(count >= 40, "only {count} error cases ran");
}

#[test]
fn documented_properties_read_back() {
    let daemon = TestDaemon::start("lua-props");
    let r = run(&daemon, "tests/lua/properties.luau");
    r.assert_ok();
    // 21 properties read back what was written (DeferGpu included); none is missing.
    let fields: Vec<usize> = r
        .stdout()
        .trim()
        .split('\t')
        .skip(1)
        .map(|n| n.parse().expect("count"))
        .collect();
    assert_eq!(fields, vec![21, 0], "{}", r.stdout());
}

#[test]
fn speed_limits_are_plane_options_from_lua() {
    let daemon = TestDaemon::start("lua-speed");
    let r = run(&daemon, "tests/lua/speed_limits.luau");
    r.assert_ok();
    assert!(r.stdout().contains("speed limits ok"), "{}", r.stdout());
}

#[test]
fn signals_fire_only_while_listened_to() {
    let daemon = TestDaemon::start("lua-signals");
    let r = run(&daemon, "tests/lua/signals.luau");
    r.assert_ok();
    assert!(r.stdout().starts_with("signals ok\t5\t"), "{}", r.stdout());
}

#[test]
fn step_driven_free_fall_matches_the_substep_formula() {
    let daemon = TestDaemon::start("lua-fall");
    let r = run(&daemon, "tests/lua/free_fall.luau");
    r.assert_ok();
    let out = r.stdout();
    // The script asserts every step; check the last one here from the printed figures too.
    let field = |name: &str| -> f64 {
        out.split(|c: char| c.is_whitespace())
            .find_map(|w| w.strip_prefix(name))
            .and_then(|v| v.parse().ok())
            .unwrap_or_else(|| panic!("{name} missing in {out:?}"))
    };
    let (y, s) = (field("y120="), field("substeps="));
    let (g, dt, n) = (-50.0, 1.0 / 60.0, 120.0);
    let (m, h) = (s * n, dt / s);
    let expected = 100.0 + g * h * h * m * (m + 1.0) / 2.0;
    assert!((y - expected).abs() < 5e-3, "y120 {y} vs {expected}");
    let vz = field("vz=");
    let mass = field("mass=");
    assert!(
        (vz * mass - 12.0).abs() < 1e-2,
        "impulse: vz {vz} · mass {mass} != 12"
    );
}

#[test]
fn state_hash_from_luau_agrees_between_identical_planes() {
    let daemon = TestDaemon::start("lua-hash");
    let r = run(&daemon, "tests/lua/state_hash.luau");
    r.assert_ok();
    assert!(r.stdout().contains("state hashes agree"), "{}", r.stdout());
}

#[test]
fn uncaught_error_exits_1_with_message_and_traceback() {
    let daemon = TestDaemon::start("lua-fails");
    let r = run(&daemon, "tests/lua/fails.luau");
    assert_eq!(r.code(), Some(1), "stderr: {}", r.stderr());
    assert_eq!(r.stdout().trim(), "before the error");
    let err = r.stderr();
    for needle in [
        "PhysicsObject.Velocity expects a Vector",
        "string \"fast\"",
        "stack traceback",
        "fails.luau:10",
        "fails.luau:14",
    ] {
        assert!(
            err.contains(needle),
            "{needle:?} missing from stderr:\n{err}"
        );
    }

    // Errors in signal handlers are the handlers' own: printed, and the script goes on.
    let r = run(&daemon, "tests/lua/heart_fails.luau");
    r.assert_ok();
    assert!(
        r.stdout().contains("handlers isolated ok"),
        "{}",
        r.stdout()
    );
    let err = r.stderr();
    for needle in [
        "handler failed on frame 3",
        "heart_fails.luau:16",
        "error in a Heart handler (the function at",
        "heart_fails.luau:13",
        "touch handler failed",
        "Touched handler",
        "failed after a wait",
        "stack traceback",
    ] {
        assert!(
            err.contains(needle),
            "{needle:?} missing from stderr:\n{err}"
        );
    }
}

#[test]
fn seconds_ends_a_script_that_never_stops() {
    let daemon = TestDaemon::start("lua-seconds");
    let r = run_in(
        &daemon.domain,
        "tests/lua/forever.luau",
        &["--seconds", "0.5"],
        Duration::from_secs(30),
    );
    r.assert_ok();
    assert!(
        r.took >= Duration::from_millis(450),
        "stopped after {:?}",
        r.took
    );
    // At 60 frames/s, 0.5 s prints frames 10, 20, 30 (fewer on a loaded machine).
    let lines = r.stdout().lines().count();
    assert!((1..=3).contains(&lines), "{}", r.stdout());
}

#[test]
fn runner_starts_a_daemon_when_none_answers_and_stops_it() {
    let domain = unique_domain("lua-own");
    let r = run_in(
        &domain,
        "tests/lua/own_daemon.luau",
        &[],
        Duration::from_secs(60),
    );
    r.assert_ok();
    assert!(r.stdout().contains("own daemon ok\t60"), "{}", r.stdout());
    // The daemon it started is gone, and so are its shared-memory files.
    assert!(matches!(
        client_sdk::Client::connect(&domain),
        Err(client_sdk::Error::NoDaemon { .. })
    ));
    let left = domain_files(&domain);
    assert!(left.is_empty(), "left behind: {left:?}");
}

/// The numbers in a line, in order.
fn numbers(line: &str) -> Vec<f32> {
    line.split(|c: char| !(c.is_ascii_digit() || c == '.' || c == '-'))
        .filter_map(|t| t.parse().ok())
        .collect()
}

#[test]
fn reference_examples_run() {
    let daemon = TestDaemon::start("lua-examples");
    for (script, expect) in [
        ("examples/falling_ball.luau", "ball at"),
        ("examples/cframe_changes.luau", "ball at"),
        ("examples/mixed_mode.luau", "unlinked at"),
        ("examples/controllers.luau", "enemy 4 at"),
    ] {
        let r = run(&daemon, script);
        r.assert_ok();
        assert!(r.stdout().contains(expect), "{script}: {}", r.stdout());
    }
    // The ragdoll example: knocked over, the head (5.4 up when standing) lies low, and the
    // joints hold (error under 0.5: anchors part by ~0.5 only under a 1,000 u/s hit).
    let r = run(&daemon, "examples/ragdoll.luau");
    r.assert_ok();
    let nums = numbers(&r.stdout());
    assert!(
        nums.len() == 2 && nums[0] < 2.0 && nums[1] < 0.5,
        "{}",
        r.stdout()
    );
    // The map example: the shipped 12 × 12-quad terrain (288 triangles, 169 shared
    // vertices, no open edge inside, 48 boundary edges), the ground within the terrain's
    // ±0.5 amplitude, balls (radius 0.5) resting on it within the map, the welded prop
    // (half-height 0.5) on it.
    let r = run(&daemon, "examples/map.luau");
    r.assert_ok();
    let out = r.stdout();
    assert!(
        out.contains("1 mesh(es), 288 triangles, 169 vertices"),
        "{out}"
    );
    for line in out.lines() {
        let n = numbers(line);
        if line.starts_with("ground under") {
            assert!(n[2].abs() <= 0.5, "{line}");
        } else if line.starts_with("ball") {
            let (x, y, z) = (n[1], n[2], n[3]);
            assert!(x.abs() < 12.0 && z.abs() < 12.0, "{line}");
            assert!((-0.05..=1.05).contains(&y), "{line}");
        } else if line.starts_with("prop") {
            assert!((-0.05..=1.05).contains(&n[0]), "{line}");
        }
    }
    // The same shove of 100 on unit cubes: Δv = 100 / (density × 1), then about 0.1 s of the
    // default LinearDamping 0.10 (at most 1.5 % over the frames of `wait(0.1)`).
    let r = run(&daemon, "examples/density_crates.luau");
    r.assert_ok();
    let line = r.stdout();
    let vz: Vec<f32> = line
        .split(['=', ','])
        .filter_map(|t| t.trim().parse().ok())
        .collect();
    assert_eq!(vz.len(), 2, "{line}");
    for (v, density) in vz.iter().zip([7800.0f32, 30.0]) {
        let kick = 100.0 / density;
        assert!(*v <= kick && *v > 0.985 * kick, "density {density}: {line}");
    }
}

#[test]
fn sleeping_reads_the_published_flag_and_wake_wakes() {
    let daemon = TestDaemon::start("lua-sleeping");
    let r = run(&daemon, "tests/lua/sleeping.luau");
    r.assert_ok();
    let ticks: u32 = r
        .stdout()
        .trim()
        .strip_prefix("sleeping ok\t")
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("unexpected output {:?}", r.stdout()));
    // Rapier puts a body to sleep after 0.5 s below its thresholds (30 ticks at 60 Hz).
    assert!((30..360).contains(&ticks), "asleep after {ticks} ticks");
}

/// Runs `script` against `daemon` and checks it printed `expect` at the start of its output.
fn run_ok(daemon: &TestDaemon, script: &str, expect: &str) -> String {
    let r = run(daemon, script);
    r.assert_ok();
    let out = r.stdout();
    assert!(out.starts_with(expect), "{script}: {out}");
    out
}

#[test]
fn api_errors_reach_pcall_as_strings_with_the_position() {
    let daemon = TestDaemon::start("lua-error-strings");
    run_ok(
        &daemon,
        "tests/lua/error_strings.luau",
        "error strings ok\t6",
    );
}

#[test]
fn stale_objects_never_reach_the_parts_new_body() {
    let daemon = TestDaemon::start("lua-stale");
    run_ok(&daemon, "tests/lua/stale_objects.luau", "stale objects ok");
}

#[test]
fn pose_reads_reuse_a_value_only_while_the_pose_is_the_same() {
    let daemon = TestDaemon::start("lua-pose-reads");
    run_ok(&daemon, "tests/lua/pose_reads.luau", "pose reads ok");
}

#[test]
fn resizing_a_simulated_part_resizes_its_body() {
    let daemon = TestDaemon::start("lua-resize");
    run_ok(&daemon, "tests/lua/resize.luau", "resize ok");
}

#[test]
fn a_destroyed_plane_refuses_every_option_alike() {
    let daemon = TestDaemon::start("lua-destroyed");
    run_ok(
        &daemon,
        "tests/lua/destroyed_plane.luau",
        "destroyed plane ok\t13",
    );
}

#[test]
fn cframe_signals_fire_once_per_step() {
    let daemon = TestDaemon::start("lua-step-signals");
    run_ok(
        &daemon,
        "tests/lua/step_signals.luau",
        "step signals ok\t10",
    );
}

#[test]
fn scripts_run_sandboxed_with_the_api_globals() {
    let daemon = TestDaemon::start("lua-sandbox");
    run_ok(&daemon, "tests/lua/sandbox.luau", "sandbox ok");
}

#[test]
fn queries_touches_and_collision_groups_from_luau() {
    let daemon = TestDaemon::start("lua-queries");
    let r = run(&daemon, "tests/lua/queries.luau");
    r.assert_ok();
    assert!(r.stdout().contains("queries ok"), "{}", r.stdout());
}

#[test]
fn controllers_from_luau() {
    let daemon = TestDaemon::start("lua-kcc");
    let r = run(&daemon, "tests/lua/controllers.luau");
    r.assert_ok();
    assert!(r.stdout().contains("controllers ok"), "{}", r.stdout());
}

#[test]
fn gui_snippet_layers_runs_unmodified() {
    let daemon = TestDaemon::start("lua-gui-layers");
    let r = run(&daemon, "tests/lua/gui_layers.luau");
    r.assert_ok();
    assert!(r.stdout().contains("gui layers ok"), "{}", r.stdout());
}

#[test]
fn writes_right_after_an_add_apply_before_its_first_step() {
    let daemon = TestDaemon::start("lua-held-adds");
    let r = run(&daemon, "tests/lua/held_adds.luau");
    r.assert_ok();
    assert!(r.stdout().contains("held adds ok"), "{}", r.stdout());
}

#[test]
fn gui_snippet_cursor_drag_runs_with_a_stubbed_mouse() {
    let daemon = TestDaemon::start("lua-gui-drag");
    let r = run_in(
        &daemon.domain,
        "tests/lua/gui_drag.luau",
        &["--seconds", "3"],
        Duration::from_secs(60),
    );
    r.assert_ok();
    assert!(r.stdout().contains("gui drag ok"), "{}", r.stdout());
}

#[test]
fn gui_snippet_npc_waypoints_loops_in_order() {
    let daemon = TestDaemon::start("lua-gui-npc");
    let r = run(&daemon, "tests/lua/gui_npc.luau");
    r.assert_ok();
    assert!(r.stdout().contains("gui npc ok"), "{}", r.stdout());
}

#[test]
fn joints_from_lua_match_the_pendulum_period_and_check_options() {
    let daemon = TestDaemon::start("lua-joints");
    let r = run(&daemon, "tests/lua/joints.luau");
    r.assert_ok();
    assert!(r.stdout().contains("joints ok"), "{}", r.stdout());
}

#[test]
fn mesh_parts_and_props_from_lua_rest_where_their_meshes_say() {
    let daemon = TestDaemon::start("lua-meshes");
    let out = run_ok(&daemon, "tests/lua/meshes.luau", "meshes ok");
    println!("{out}");
}

#[test]
fn ragdolls_from_lua_keep_their_bones_joined_after_a_hit() {
    let daemon = TestDaemon::start("lua-ragdoll");
    let out = run_ok(&daemon, "tests/lua/ragdoll.luau", "ragdoll ok");
    println!("{out}");
}

#[test]
fn defer_gpu_from_lua_falls_flips_and_refuses() {
    let daemon = TestDaemon::start("lua-gpu");
    let r = run(&daemon, "tests/lua/gpu.luau");
    r.assert_ok();
    assert!(r.stdout().contains("gpu ok\t60"), "{}", r.stdout());
}

// The scenes a user writes first (defects a new user met), each script asserting its outcome.

#[test]
fn a_controller_walks_along_its_look_vector() {
    let daemon = TestDaemon::start("first-facing");
    let r = run(&daemon, "tests/lua/controller_facing.luau");
    r.assert_ok();
    assert!(
        r.stdout().contains("controller facing ok"),
        "{}",
        r.stdout()
    );
}

#[test]
fn joints_swing_and_turn_default_parts() {
    let daemon = TestDaemon::start("first-joints");
    let r = run(&daemon, "tests/lua/joints_default_parts.luau");
    r.assert_ok();
    assert!(
        r.stdout().contains("joints on default parts ok"),
        "{}",
        r.stdout()
    );
}

#[test]
fn ground_y_takes_nil_to_clear_it() {
    let daemon = TestDaemon::start("first-groundy");
    let r = run(&daemon, "tests/lua/ground_y_nil.luau");
    r.assert_ok();
    assert!(r.stdout().contains("GroundY nil ok"), "{}", r.stdout());
}

#[test]
fn values_read_back_as_written() {
    let daemon = TestDaemon::start("first-readback");
    let r = run(&daemon, "tests/lua/read_back.luau");
    r.assert_ok();
    assert!(r.stdout().contains("read back ok"), "{}", r.stdout());
}

#[test]
fn joints_have_a_lifecycle_like_objects() {
    let daemon = TestDaemon::start("first-joint-life");
    let r = run(&daemon, "tests/lua/joint_lifecycle.luau");
    r.assert_ok();
    assert!(r.stdout().contains("joint lifecycle ok"), "{}", r.stdout());
}

#[test]
fn gui_values_name_themselves_without_rust_internals() {
    let daemon = TestDaemon::start("first-gui-names");
    let r = run(&daemon, "tests/lua/gui_names.luau");
    r.assert_ok();
    assert!(r.stdout().contains("gui names ok"), "{}", r.stdout());
}

#[test]
fn refused_writes_raise_catchably_and_never_end_the_run() {
    let daemon = TestDaemon::start("first-refused");
    let r = run(&daemon, "tests/lua/refused_writes.luau");
    r.assert_ok();
    assert!(r.stdout().contains("refused writes ok"), "{}", r.stdout());
}

#[test]
fn defer_gpu_without_an_adapter_is_refused_where_it_is_written() {
    let daemon = TestDaemon::start_with("first-gpu-off", &[], &[("PHYSICS_GPU", "off")]);
    let r = run(&daemon, "tests/lua/defer_gpu_off.luau");
    r.assert_ok();
    assert!(r.stdout().contains("defer gpu off ok"), "{}", r.stdout());
}

#[test]
fn impulses_read_back_at_once_and_divide_by_the_mass_just_written() {
    let daemon = TestDaemon::start("first-impulse");
    let r = run(&daemon, "tests/lua/impulse_read_back.luau");
    r.assert_ok();
    assert!(
        r.stdout().contains("impulse read back ok"),
        "{}",
        r.stdout()
    );
}

#[test]
fn parts_follow_their_collision_groups_renaming_and_removal() {
    let daemon = TestDaemon::start("first-groups");
    let r = run(&daemon, "tests/lua/group_rename.luau");
    r.assert_ok();
    assert!(r.stdout().contains("group rename ok"), "{}", r.stdout());
}

#[test]
fn gui_object_count_drops_at_once_when_a_controller_is_destroyed() {
    let daemon = TestDaemon::start("first-gui-count");
    let r = run(&daemon, "tests/lua/gui_count.luau");
    r.assert_ok();
    assert!(r.stdout().contains("gui count ok"), "{}", r.stdout());
}

#[test]
fn apis_hand_back_the_values_the_script_holds() {
    let daemon = TestDaemon::start("first-identity");
    let r = run(&daemon, "tests/lua/identity.luau");
    r.assert_ok();
    assert!(r.stdout().contains("identity ok"), "{}", r.stdout());
}

#[test]
fn probes_and_explosions_from_luau() {
    let daemon = TestDaemon::start("lua-probes");
    let r = run(&daemon, "tests/lua/probes.luau");
    r.assert_ok();
    assert!(r.stdout().contains("probes ok"), "{}", r.stdout());
}

#[test]
fn overlap_queries_page_and_max_parts_from_luau() {
    let daemon = TestDaemon::start("lua-overlap-pages");
    run_ok(&daemon, "tests/lua/overlap_pages.luau", "overlap pages ok");
}

#[test]
fn modules_are_frozen_and_maps_load_only_under_the_asset_roots() {
    let daemon = TestDaemon::start("lua-assets");
    let r = run_in(
        &daemon.domain,
        "tests/lua/sandbox_assets.luau",
        &["--asset-root", "examples/assets"],
        Duration::from_secs(60),
    );
    r.assert_ok();
    assert!(r.stdout().contains("sandbox assets ok"), "{}", r.stdout());
}

#[test]
fn small_messages_say_what_to_do() {
    let daemon = TestDaemon::start("first-messages");
    let r = run(&daemon, "tests/lua/small_messages.luau");
    r.assert_ok();
    assert!(r.stdout().contains("small messages ok"), "{}", r.stdout());
}

#[test]
fn dyn_mesh_welds_ride_along_with_their_driver() {
    let daemon = TestDaemon::start("first-dyn-mesh");
    let r = run(&daemon, "tests/lua/dyn_mesh.luau");
    r.assert_ok();
    assert!(r.stdout().contains("dyn mesh ok"), "{}", r.stdout());
}

#[test]
fn planes_snapshot_restore_and_start_from_snapshots_in_luau() {
    let daemon = TestDaemon::start("lua-snapshot");
    let r = run(&daemon, "tests/lua/snapshot.luau");
    // physics-lua runs in the repository root.
    let file = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../lua-snapshot-test.snap");
    let _ = std::fs::remove_file(file);
    r.assert_ok();
    assert!(r.stdout().contains("snapshot lua ok"), "{}", r.stdout());
}

#[test]
fn a_loaded_map_is_a_handle_queries_filters_and_contacts_hand_back() {
    let daemon = TestDaemon::start("lua-map-handle");
    run_ok(&daemon, "tests/lua/map_handle.luau", "map handle ok");
}

#[test]
fn a_signal_property_is_one_value_per_signal() {
    let daemon = TestDaemon::start("lua-signal-ids");
    run_ok(
        &daemon,
        "tests/lua/signal_identity.luau",
        "signal identity ok",
    );
}

#[test]
fn rollback_rewinds_and_replays_bit_for_bit() {
    let daemon = TestDaemon::start("lua-rollback");
    run_ok(&daemon, "tests/lua/rollback.luau", "rollback ok");
}

#[test]
fn a_snapshot_planes_objects_come_to_luau() {
    let daemon = TestDaemon::start("lua-get-objects");
    run_ok(&daemon, "tests/lua/get_objects.luau", "get objects ok");
}

#[test]
fn gui_planes_are_named_opened_and_rewound_from_luau() {
    let daemon = TestDaemon::start("lua-gui-rollback");
    run_ok(&daemon, "tests/lua/gui_rollback.luau", "gui rollback ok");
}

#[test]
fn persistent_planes_come_back_to_luau_after_a_sigkill() {
    let state = std::env::temp_dir().join(unique_domain("lua-state"));
    std::fs::create_dir_all(&state).unwrap();
    let domain = unique_domain("lua-persist");
    let args = [
        "--state-dir",
        state.to_str().unwrap(),
        "--snapshot-every",
        "3600",
    ];
    // physics-lua runs in the repository root.
    let snap = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../lua-persist-test.snap");
    let script = "tests/lua/persistence.luau";
    let mut daemon = TestDaemon::start_with_in(&domain, &args, &[]);
    let first = run(&daemon, script);
    if first.code() != Some(0) {
        let _ = std::fs::remove_file(&snap);
    }
    first.assert_ok();
    assert!(
        first.stdout().contains("persistence run 1 ok"),
        "{}",
        first.stdout()
    );
    daemon.kill9();
    let daemon = TestDaemon::start_with_in(&domain, &args, &[]);
    let second = run(&daemon, script);
    drop(daemon);
    let _ = std::fs::remove_file(&snap);
    let _ = std::fs::remove_dir_all(&state);
    second.assert_ok();
    assert!(
        second.stdout().contains("persistence run 2 ok"),
        "{}",
        second.stdout()
    );
}

#[test]
fn physics_lua_starts_from_a_snapshot_file() {
    use client_sdk::{PlaneOptions, PlaneProp, Pose, Shape};
    let daemon = TestDaemon::start("lua-start-snap");
    let script = "tests/lua/start_plane.luau";
    // Without --snapshot there is no start plane.
    let plain = run(&daemon, script);
    plain.assert_ok();
    assert!(
        plain.stdout().contains("no start plane"),
        "{}",
        plain.stdout()
    );

    // A ball of radius 1 dropped from 20 under g = -10, 25 ticks, no damping.
    let (g, dt, y0, n) = (-10.0f64, 1.0f64 / 60.0, 20.0f64, 25u32);
    let client = daemon.client();
    let plane = client
        .create_plane(
            &PlaneOptions::manual()
                .with(PlaneProp::Gravity([0.0, g as f32, 0.0]))
                .with(PlaneProp::LinearDamping(0.0)),
        )
        .unwrap();
    let ball = plane
        .add(
            Shape::Sphere { radius: 1.0 },
            Pose::at([0.0, y0 as f32, 0.0]),
            &[],
        )
        .unwrap();
    for _ in 0..n {
        plane.step(dt as f32).unwrap();
    }
    let snapshot = plane.take_snapshot().unwrap();
    let y = ball.pose().unwrap().position[1] as f64;
    plane.step(dt as f32).unwrap();
    let next = plane.state_hash().unwrap();
    // Semi-implicit Euler in 4 substeps a tick (see free_fall.luau).
    let (h, m) = (dt / 4.0, 4.0 * n as f64);
    let closed = y0 + g * h * h * m * (m + 1.0) / 2.0;
    assert!((y - closed).abs() < 1e-3, "{y} vs {closed}");

    let dir = std::env::temp_dir().join(unique_domain("lua-start"));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("report.physnap");
    snapshot.save(&file).unwrap();
    let r = run_in(
        &daemon.domain,
        script,
        &["--snapshot", file.to_str().unwrap()],
        Duration::from_secs(60),
    );
    // A damaged file: the run refuses to start, naming the file.
    let bytes = snapshot.bytes();
    let cut = dir.join("cut.physnap");
    std::fs::write(&cut, &bytes[..bytes.len() / 2]).unwrap();
    let bad = run_in(
        &daemon.domain,
        script,
        &["--snapshot", cut.to_str().unwrap()],
        Duration::from_secs(60),
    );
    let _ = std::fs::remove_dir_all(&dir);
    r.assert_ok();
    let out = r.stdout();
    assert!(
        out.contains(&format!("start hash {:016x}", snapshot.state_hash())),
        "{out}"
    );
    let top: f64 = out
        .lines()
        .find_map(|l| l.strip_prefix("ball top "))
        .and_then(|v| v.trim().parse().ok())
        .unwrap_or_else(|| panic!("no ball top in {out}"));
    assert!(
        (top - (closed + 1.0)).abs() < 1e-3,
        "{top} vs {}",
        closed + 1.0
    );
    assert!(out.contains(&format!("next hash {next:016x}")), "{out}");
    assert_ne!(bad.code(), Some(0), "{}", bad.stdout());
    assert!(
        bad.stderr().contains("--snapshot") && bad.stderr().contains("cut.physnap"),
        "{}",
        bad.stderr()
    );
}

#[test]
fn cframe_values_are_tagged_userdata_that_refuse_forgeries() {
    let daemon = TestDaemon::start("lua-cframe-values");
    run_ok(&daemon, "tests/lua/cframe_values.luau", "cframe values ok");
}

/// A GUI plane's 2D settings, rows of its settings table: defaults, writes of each kind,
/// the documented clamp, refusals naming the property and the value, Bounds at creation.
#[test]
fn gui_plane_settings_come_from_their_table() {
    let daemon = TestDaemon::start("lua-gui-settings");
    run_ok(&daemon, "tests/lua/gui_settings.luau", "gui settings ok");
}

//! `physics-bench frame` as a user runs it (the built binary, its own daemon), in a tiny
//! configuration: the report's JSON has the four modes with their frame times, the world
//! the bench promises (half the bodies settled and asleep, half flying and awake), the goals
//! list with the daemon / no-physics verdicts, and no write refused (a frame-stepped plane
//! advanced one tick a frame).

// The recording row of `physics-bench snapshot`, run tiny.
mod recording;

use std::process::Command;

#[test]
fn frame_reports_four_modes_and_the_goals() {
    let bench = client_sdk::daemon_executable().with_file_name("physics-bench");
    assert!(bench.is_file(), "build the workspace's binaries first");
    let out = std::env::temp_dir().join(integration_tests::unique_domain("frame"));
    let output = Command::new(bench)
        .args(["frame", "--bodies", "200", "--writes", "10"])
        .args(["--frames", "20", "--blocks", "2", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&output.stdout).to_string()
        + &String::from_utf8_lossy(&output.stderr);
    assert!(output.status.success(), "{text}");
    let json = std::fs::read_to_string(out.join("frame.json")).unwrap();
    let _ = std::fs::remove_dir_all(&out);
    let report: serde_json::Value = serde_json::from_str(&json).unwrap();

    assert_eq!(report["bodies"], 200);
    let modes = report["modes"].as_array().expect("modes");
    let names: Vec<&str> = modes.iter().filter_map(|m| m["mode"].as_str()).collect();
    assert_eq!(
        names,
        ["no_physics", "daemon", "in_process", "daemon_frame_stepped"]
    );
    for m in modes {
        // Two blocks of 20 frames per mode.
        assert_eq!(m["frames"], 40, "{m}");
        let (p50, p99) = (
            m["frame_ms"]["p50"].as_f64().unwrap(),
            m["frame_ms"]["p99"].as_f64().unwrap(),
        );
        assert!(p50 > 0.0 && p50 <= p99, "{m}");
        assert!(m["ratio_p50"].as_f64().unwrap() > 0.0, "{m}");
    }
    assert_eq!(modes[0]["ratio_p50"].as_f64(), Some(1.0));
    // 100 cubes in a pile settled over 180 ticks (rapier sleeps a body after 2 s at rest);
    // 100 fly at 2 units/s with neither gravity nor damping and never sleep. The pile's
    // floor is anchored and not counted: asleep = 100 / 200.
    let asleep = report["asleep_fraction"].as_f64().unwrap();
    assert!((asleep - 0.5).abs() <= 0.05, "asleep fraction {asleep}");
    assert!(report["game_work_ms"].as_f64().unwrap() > 0.0);

    let goals = report["goals"].as_array().expect("goals");
    for (mode, words) in [(1, "60 Hz timer"), (3, "stepped after each frame")] {
        let main = goals
            .iter()
            .find(|g| {
                g["goal"].as_str().is_some_and(|s| {
                    s.contains("without physics") && s.contains("≤ 1.05") && s.contains(words)
                })
            })
            .unwrap_or_else(|| panic!("no daemon / no-physics goal ({words}) in {goals:?}"));
        assert!(main["met"].is_boolean(), "{main}");
        // The judged figure first, the other estimators' figures after it.
        let value: f64 = main["value"]
            .as_str()
            .and_then(|v| v.split_whitespace().next())
            .unwrap()
            .parse()
            .unwrap();
        let ratio = modes[mode]["ratio_p50"].as_f64().unwrap();
        assert!((value - ratio).abs() < 1e-3, "{value} against {ratio}");
        assert_eq!(main["met"].as_bool(), Some(ratio <= 1.05));
    }
    // The frame-stepped plane stepped: its step time was read off its own ticks.
    assert!(
        report["frame_stepped_step_ms"].as_f64().unwrap() >= 0.0,
        "{report}"
    );
}

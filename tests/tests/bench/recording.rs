//! `physics-bench snapshot` as a user runs it (the built binary, its own daemon), in a tiny
//! configuration: the report's recording row holds its ABBA blocks, the goal on what
//! recording adds to a tick's CPU with its estimator, and the stopped recording's bytes by
//! kind of entry, which add up to the file the daemon reported and count every tick and
//! every write the bench made; the rows that were there before keep their goals.

use std::process::Command;

#[test]
fn snapshot_reports_what_recording_costs() {
    let bench = client_sdk::daemon_executable().with_file_name("physics-bench");
    assert!(bench.is_file(), "build the workspace's binaries first");
    let out = std::env::temp_dir().join(integration_tests::unique_domain("bench-rec"));
    let output = Command::new(bench)
        .args(["snapshot", "--bodies", "100", "--rewind-bodies", "100"])
        .args([
            "--keep-bodies",
            "100",
            "--record-bodies",
            "50",
            "--repeats",
            "1",
        ])
        .args(["--cpu-blocks", "3", "--block-steps", "2"])
        .args(["--recording-bodies", "200", "--recording-writes", "20"])
        .args(["--recording-settle-ticks", "20"])
        .args([
            "--recording-blocks",
            "4",
            "--recording-block-ticks",
            "10",
            "--out",
        ])
        .arg(&out)
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&output.stdout).to_string()
        + &String::from_utf8_lossy(&output.stderr);
    assert!(output.status.success(), "{text}");
    let json = std::fs::read_to_string(out.join("snapshot.json")).unwrap();
    let page = std::fs::read_to_string(out.join("snapshot.md")).unwrap();
    let _ = std::fs::remove_dir_all(&out);
    let report: serde_json::Value = serde_json::from_str(&json).unwrap();

    // The goals: the six rows judged before, without an estimator, then the recording's.
    let goals = report["goals"].as_array().expect("goals");
    assert_eq!(goals.len(), 7, "{goals:?}");
    for g in &goals[..6] {
        assert!(g.get("estimator").is_none(), "{g}");
        assert!(g["met"].is_boolean(), "{g}");
    }
    let goal = &goals[6];
    assert_eq!(goal["estimator"], "cpu-median-of-blocks");
    let words = goal["goal"].as_str().unwrap();
    assert!(
        words.starts_with("recording adds <= 5 % to a tick's CPU (200 bodies, 20 writes a frame")
            && words.ends_with("[cpu-median-of-blocks]"),
        "{words}"
    );
    assert!(goal["met"].is_boolean(), "{goal}");
    assert!(goal["value"].as_str().unwrap().ends_with(" %)"), "{goal}");
    assert!(report["estimators"]["cpu-median-of-blocks"].is_string());

    let r = &report["recording"];
    assert_eq!(r["bodies"], 200);
    assert_eq!(r["writes_per_tick"], 20);
    assert_eq!(r["ticks_per_block"], 10);
    assert_eq!(r["settle_ticks"], 20);
    assert_eq!(r["blocks"]["order"], "abba");
    for side in ["a", "b"] {
        let blocks = r["blocks"][side]["blocks"].as_array().unwrap();
        assert_eq!(blocks.len(), 4, "{side}");
        for b in blocks {
            // An awake pile's tick takes some CPU of the daemon, and some wall.
            assert!(b["cpu_us"].as_f64().unwrap() > 0.0, "{b}");
            assert!(b["wall_us"].as_f64().unwrap() > 0.0, "{b}");
        }
    }
    let ratio = r["cpu_ratio"].as_f64().unwrap();
    assert!(ratio.is_finite() && ratio > 0.0, "{ratio}");

    // The cross-check: 8 stretches, each with 10 ticks of each plane.
    let threads = &r["threads"];
    assert_eq!(threads["ticks_per_stretch"], 10);
    assert_eq!(threads["ratios"].as_array().unwrap().len(), 8);
    for k in ["recording_worker_us", "plain_worker_us"] {
        assert!(threads[k].as_f64().unwrap() > 0.0, "{k}: {threads}");
    }
    // The writer wrote every tick's entries.
    assert!(threads["writer_us"].as_f64().unwrap() > 0.0, "{threads}");

    // The file: started after the 20 settling ticks, before the warm-up block; it holds
    // that block (10 ticks), the 4 measured ones (40) and the recording plane's ticks of
    // the cross-check (80): 130 ticks, each with a batch of the 20 writes before it; one
    // keyframe (the start one: 130 ticks is short of the 600 between periodic ones).
    let b = &r["bytes"];
    let n = |k: &str| b[k].as_u64().unwrap_or_else(|| panic!("{k}: {b}"));
    assert_eq!(n("ticks"), 130, "{b}");
    assert_eq!(n("tick_entries"), 130, "{b}");
    assert_eq!(n("batches"), 130, "{b}");
    assert_eq!(n("ops"), 2600, "{b}");
    assert_eq!(n("keyframes"), 1, "{b}");
    assert_eq!(n("keyframe_every"), 600, "{b}");
    // A tick entry: tick u64, dt f32, hash u64 and 13 bytes of framing.
    assert_eq!(n("tick_bytes"), 130 * 33, "{b}");
    // Every byte of the file is one kind's, and the file is what the daemon wrote.
    assert_eq!(
        n("keyframe_bytes") + n("batch_bytes") + n("tick_bytes") + n("other_bytes"),
        n("file_bytes"),
        "{b}"
    );
    assert_eq!(n("file_bytes"), n("bytes"), "{b}");
    // The preamble (16) and the start and end entries (13 bytes of framing each, a few
    // dozen of payload).
    assert!((16 + 26..=300).contains(&n("other_bytes")), "{b}");
    // A Velocity write holds three f32 (12 bytes) besides its handle and tags; a batch's
    // framing (25 bytes) is shared by its 20 writes.
    let per_op = b["per_op"].as_f64().unwrap();
    assert!((12.0..=40.0).contains(&per_op), "{per_op}");
    let without = b["per_tick_without_keyframes"].as_f64().unwrap();
    assert_eq!(
        without,
        (n("batch_bytes") + n("tick_bytes")) as f64 / 130.0,
        "{b}"
    );
    // With the keyframes: the start one's size (the only one) over 600 ticks on top.
    let with = b["per_tick_with_keyframes"].as_f64().unwrap();
    let expected = without + n("keyframe_bytes") as f64 / 600.0;
    assert!((with - expected).abs() < 1e-6, "{with} vs {expected}");

    assert!(page.contains("## What recording costs"), "{page}");
    assert!(
        page.contains("recording adds <= 5 % to a tick's CPU"),
        "{page}"
    );
}

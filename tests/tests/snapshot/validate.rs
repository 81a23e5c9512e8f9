//! `physics-bench snapshot --validate` as a user runs it (the built binary, its own daemon):
//! a restored plane's replay matches its first run bit for bit, and a one-bit difference
//! injected into the replay's input at tick 44 is reported as the first field that differs,
//! with the object, both values and the tick, and fails the run.

use std::process::Command;

fn validate(out: &std::path::Path, extra: &[&str]) -> (bool, String) {
    let bench = client_sdk::daemon_executable().with_file_name("physics-bench");
    assert!(bench.is_file(), "build the workspace's binaries first");
    let output = Command::new(bench)
        .args(["snapshot", "--validate", "--validate-bodies", "200"])
        .args(["--validate-ticks", "50", "--out"])
        .arg(out)
        .args(extra)
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&output.stdout).to_string()
        + &String::from_utf8_lossy(&output.stderr);
    (output.status.success(), text)
}

#[test]
fn validate_passes_an_exact_replay_and_names_an_injected_difference() {
    let out = std::env::temp_dir().join(integration_tests::unique_domain("validate"));
    let (ok, text) = validate(&out, &[]);
    assert!(ok, "{text}");
    assert!(
        text.contains("matched the first run on every tick"),
        "{text}"
    );

    let (ok, text) = validate(&out, &["--inject-tick", "44"]);
    assert!(!ok, "a diverged replay fails the run: {text}");
    // The ball (object 0) flies alone: the flipped bit of its velocity write shows on it
    // first, at the tick it entered.
    let line = text
        .lines()
        .find(|l| l.contains("the replay diverged"))
        .unwrap_or_else(|| panic!("{text}"));
    assert!(
        line.contains("object 0 linvel.x: ")
            && line.contains(" vs ")
            && line.ends_with("at tick 44"),
        "{line}"
    );
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("snapshot-validate.json")).unwrap())
            .unwrap();
    assert_eq!(json["diverged_at"], 44);
    let _ = std::fs::remove_dir_all(&out);
}

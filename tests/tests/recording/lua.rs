//! Record and replay from Luau and the runner: a scenario game recorded with
//! `PhysicsService.New{ Record = true }` replays through `physics-lua --replay FILE` with
//! every state hash equal; `--until TICK` hands the plane at that tick to a script, which
//! reads what the recording script read there bit for bit; a damaged file is refused naming
//! the byte offset, a forged tick hash stops the replay naming that tick; `StartRecording`
//! refuses a file that exists naming it; GUI planes record and replay too; the runner's
//! flags are checked. Real daemon, real `physics-lua`.

use crate::common::TempDir;
use integration_tests::recording_file::forge_tick_hash;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

use integration_tests::{physics_lua, run_lua, unique_domain, TestDaemon};

/// How long one run of the runner may take on a loaded 2-core machine.
const LIMIT: Duration = Duration::from_secs(120);

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// Files the daemon named (in its temporary `physics-recordings` folder), removed at the end.
struct Made(Vec<PathBuf>);

impl Drop for Made {
    fn drop(&mut self) {
        for p in &self.0 {
            let _ = std::fs::remove_file(p);
        }
    }
}

fn stdout(out: &Output) -> String {
    String::from_utf8_lossy(&out.stdout).into_owned()
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// Both streams, for a failure message.
fn shown(out: &Output) -> String {
    format!(
        "status {:?}\nstdout:\n{}\nstderr:\n{}",
        out.status,
        stdout(out),
        stderr(out)
    )
}

/// `physics-lua SCRIPT --domain DOMAIN EXTRA…` to its end.
fn lua(domain: &str, script: &str, extra: &[&str]) -> Output {
    run_lua(domain, script, extra, LIMIT).0
}

/// `physics-lua ARGS…` without a script (as `physics_lua` runs it: repository root, quiet
/// logs, no stdin), killed after [`LIMIT`].
fn runner(args: &[&str]) -> Output {
    // The same executable `physics_lua` runs: its program, without its script argument.
    let program = physics_lua("unused", "unused.luau", &[])
        .get_program()
        .to_owned();
    let mut child = Command::new(program)
        .current_dir(repo())
        .args(args)
        .env("PHYSICS_LOG", "warn")
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("spawn physics-lua");
    let started = Instant::now();
    while child.try_wait().expect("wait physics-lua").is_none() {
        if started.elapsed() > LIMIT {
            let _ = child.kill();
            break;
        }
        std::thread::sleep(Duration::from_millis(10));
    }
    child.wait_with_output().expect("collect output")
}

/// `physics-lua --replay FILE --domain DOMAIN EXTRA…` (no script).
fn replay_only(domain: &str, file: &Path, extra: &[&str]) -> Output {
    let mut args = vec!["--replay", file.to_str().unwrap(), "--domain", domain];
    args.extend_from_slice(extra);
    runner(&args)
}

/// The value after `prefix` on the first line that starts with it.
fn after<'a>(text: &'a str, prefix: &str) -> &'a str {
    text.lines()
        .find_map(|l| l.strip_prefix(prefix))
        .unwrap_or_else(|| panic!("no line {prefix:?} in:\n{text}"))
}

#[test]
fn a_recorded_scenario_game_replays_with_every_hash_and_hands_its_plane_over_at_a_tick() {
    let daemon = TestDaemon::start("lua-record");
    let dir = TempDir::new("lua-record");
    let rec = lua(&daemon.domain, "tests/lua/record_scenario.luau", &[]);
    let out = stdout(&rec);
    let file = PathBuf::from(after(&out, "recorded "));
    let _made = Made(vec![file.clone()]);
    assert!(rec.status.success(), "{}", shown(&rec));
    let (stepped, start) = after(&out, "stepped ")
        .split_once(" from tick ")
        .map(|(n, s)| (n.parse::<u64>().unwrap(), s.parse::<u64>().unwrap()))
        .unwrap();
    assert_eq!(stepped, 180);
    // What the recording script read after each tick: ball position and state hash.
    let at_tick = |t: u64| after(&out, &format!("tick {t} ")).to_string();
    assert!(file.is_file(), "{} was written", file.display());

    // (a) The whole recording, no script: every tick's hash equal.
    let whole = replay_only(&daemon.domain, &file, &[]);
    assert!(whole.status.success(), "{}", shown(&whole));
    let verdict = format!(
        "replayed ticks {start}..{} of {}: every state hash equal ({stepped} ticks)",
        start + stepped,
        file.display()
    );
    assert!(stderr(&whole).contains(&verdict), "{}", shown(&whole));

    // (b) Up to tick T, then the script gets the plane there: tick, ball and hash as recorded.
    let t = start + 97;
    let until = t.to_string();
    let inspect = lua(
        &daemon.domain,
        "tests/lua/record_inspect.luau",
        &["--replay", file.to_str().unwrap(), "--until", &until],
    );
    assert!(inspect.status.success(), "{}", shown(&inspect));
    let seen = stdout(&inspect);
    assert_eq!(after(&seen, "start tick "), until, "{seen}");
    // "ball X Y Z hash H" (%.9g: every bit of an f32) against the recording's line.
    let recorded = at_tick(t);
    assert_eq!(format!("ball {}", after(&seen, "ball ")), recorded);
    assert_eq!(after(&seen, "stepped on to "), (t + 1).to_string());
    assert!(
        stderr(&inspect).contains(&format!("replayed ticks {start}..{t} of ")),
        "{}",
        shown(&inspect)
    );
    assert!(
        stderr(&inspect).contains(&format!("({} ticks)", t - start)),
        "{}",
        shown(&inspect)
    );

    // --until past the last tick: to the end, saying so.
    let past = replay_only(&daemon.domain, &file, &["--until", "1000000"]);
    assert!(past.status.success(), "{}", shown(&past));
    assert!(
        stderr(&past).contains(&format!("({stepped} ticks)"))
            && stderr(&past).contains(&format!("past its last tick {}", start + stepped)),
        "{}",
        shown(&past)
    );

    // (c) A byte flipped in the middle: refused before anything replays, naming the offset.
    let bytes = std::fs::read(&file).unwrap();
    let mut damaged = bytes.clone();
    damaged[bytes.len() / 2] ^= 0x5a;
    let bad = dir.0.join("damaged.physrec");
    std::fs::write(&bad, &damaged).unwrap();
    let refused = replay_only(&daemon.domain, &bad, &[]);
    assert!(!refused.status.success(), "{}", shown(&refused));
    let message = stderr(&refused);
    assert!(
        message.contains("byte offset") && message.contains("damaged.physrec"),
        "{}",
        shown(&refused)
    );
    assert!(!message.contains("replayed ticks"), "{}", shown(&refused));

    // (e) A tick's hash forged (checksum and all): the replay stops at that tick, naming it and
    // the batch of writes before it.
    let forged_tick = start + 60;
    let forged = dir.0.join("forged.physrec");
    std::fs::write(&forged, forge_tick_hash(&bytes, forged_tick).0).unwrap();
    let diverged = replay_only(&daemon.domain, &forged, &[]);
    assert_eq!(diverged.status.code(), Some(1), "{}", shown(&diverged));
    let message = stderr(&diverged);
    assert!(
        message.contains(&format!("diverged at tick {forged_tick}:"))
            && message.contains("the batch before it")
            && message.contains(&format!(
                "({} tick(s) before it agreed)",
                forged_tick - start - 1
            )),
        "{}",
        shown(&diverged)
    );

    // A file that is not there.
    let missing = replay_only(&daemon.domain, &dir.0.join("none.physrec"), &[]);
    assert!(!missing.status.success(), "{}", shown(&missing));
    assert!(
        stderr(&missing).contains("none.physrec"),
        "{}",
        shown(&missing)
    );
    print!("{}{}", stderr(&whole), stderr(&diverged));
}

#[test]
fn recording_refusals_name_the_file_and_gui_planes_record_and_replay() {
    let daemon = TestDaemon::start("lua-record-edges");
    let dir = TempDir::new("lua-record-edges");
    let folder = dir.0.canonicalize().unwrap();
    let source = std::fs::read_to_string(repo().join("tests/lua/record_refusals.luau")).unwrap();
    assert!(source.contains("\"RECORD_DIR\""));
    let script = folder.join("record_refusals.luau");
    std::fs::write(
        &script,
        source.replace("\"RECORD_DIR\"", &format!("{:?}", folder.to_str().unwrap())),
    )
    .unwrap();
    let run = lua(
        &daemon.domain,
        script.to_str().unwrap(),
        &["--asset-root", folder.to_str().unwrap()],
    );
    let out = stdout(&run);
    let _made = Made(
        out.lines()
            .filter_map(|l| l.strip_prefix("made "))
            .map(PathBuf::from)
            .collect(),
    );
    assert!(
        run.status.success() && out.contains("record refusals ok"),
        "{}",
        shown(&run)
    );
    // (d) The daemon's refusal names the file that exists.
    let taken = folder.join("taken.physrec");
    assert!(
        after(&out, "exists refused: ").contains(taken.to_str().unwrap()),
        "{out}"
    );
    // The file is the snapshot saved there, untouched.
    assert!(!std::fs::read(&taken).unwrap().starts_with(b"PHYSREC1"));

    // The GUI recording replays (30 ticks), and its plane goes to a script as a GUI plane.
    let gui = PathBuf::from(after(&out, "gui recorded "));
    let whole = replay_only(&daemon.domain, &gui, &[]);
    assert!(
        whole.status.success() && stderr(&whole).contains("every state hash equal (30 ticks)"),
        "{}",
        shown(&whole)
    );
    let start = lua(
        &daemon.domain,
        "tests/lua/record_gui_start.luau",
        &["--replay", gui.to_str().unwrap(), "--until", "12"],
    );
    let seen = stdout(&start);
    assert!(start.status.success(), "{}", shown(&start));
    assert!(
        after(&seen, "start ").starts_with("GuiPhysicsPlane "),
        "{seen}"
    );
    assert_eq!(after(&seen, "gui start tick "), "12 objects 1", "{seen}");
}

#[test]
fn the_runners_replay_flags_are_checked() {
    // Parsed before any daemon is reached: clap's usage errors (status 2).
    let domain = unique_domain("lua-record-flags");
    let script = repo().join("tests/lua/record_inspect.luau");
    let script = script.to_str().unwrap();
    let cases: [(&[&str], &str); 3] = [
        (&[script, "--until", "5"], "--replay"),
        (
            &[script, "--replay", "a.physrec", "--snapshot", "b.physnap"],
            "--snapshot",
        ),
        (&[], "<SCRIPT>"),
    ];
    for (args, needle) in cases {
        let mut args = args.to_vec();
        args.extend_from_slice(&["--domain", &domain]);
        let out = runner(&args);
        assert_eq!(out.status.code(), Some(2), "{args:?}: {}", shown(&out));
        assert!(stderr(&out).contains(needle), "{args:?}: {}", shown(&out));
    }
}

//! `physics-lua` under stress: runaway scripts (busy loops, allocation loops), signals, and
//! a daemon that stalls or dies. Each test runs the real runner against a real daemon and
//! checks how, and how fast, the run ends.

use std::io::{BufRead, BufReader, Read};
use std::process::{Child, ExitStatus};
use std::sync::mpsc::{self, Receiver};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use integration_tests::{domain_files, eventually, physics_lua, unique_domain, TestDaemon};

/// A running `physics-lua`: its stdout lines as they come, stderr collected.
struct Runner {
    child: Child,
    started: Instant,
    lines: Receiver<String>,
    stdout: Vec<String>,
    stderr: JoinHandle<String>,
    peak_rss_kb: u64,
}

/// How a run ended.
struct Ended {
    status: ExitStatus,
    /// From the start of the runner, or from the last `mark`.
    took: Duration,
    stdout: String,
    stderr: String,
    peak_rss_kb: u64,
}

impl Runner {
    fn start(domain: &str, script: &str, extra: &[&str]) -> Runner {
        let mut child = physics_lua(domain, script, extra)
            .spawn()
            .expect("spawn physics-lua");
        let (tx, lines) = mpsc::channel();
        let out = child.stdout.take().expect("stdout");
        std::thread::spawn(move || {
            for line in BufReader::new(out).lines().map_while(Result::ok) {
                let _ = tx.send(line);
            }
        });
        let mut err = child.stderr.take().expect("stderr");
        let stderr = std::thread::spawn(move || {
            let mut s = String::new();
            let _ = err.read_to_string(&mut s);
            s
        });
        Runner {
            child,
            started: Instant::now(),
            lines,
            stdout: Vec::new(),
            stderr,
            peak_rss_kb: 0,
        }
    }

    fn pid(&self) -> i32 {
        self.child.id() as i32
    }

    fn sample_rss(&mut self) {
        let status = std::fs::read_to_string(format!("/proc/{}/status", self.pid()));
        let kb = status.ok().and_then(|s| {
            s.lines()
                .find_map(|l| l.strip_prefix("VmRSS:"))
                .and_then(|v| v.trim().trim_end_matches("kB").trim().parse().ok())
        });
        self.peak_rss_kb = self.peak_rss_kb.max(kb.unwrap_or(0));
    }

    /// Waits until the script printed `line`.
    fn wait_for(&mut self, line: &str, limit: Duration) {
        let deadline = Instant::now() + limit;
        while Instant::now() < deadline {
            if let Ok(l) = self.lines.recv_timeout(Duration::from_millis(20)) {
                let found = l == line;
                self.stdout.push(l);
                if found {
                    return;
                }
            }
        }
        let _ = self.child.kill();
        panic!(
            "no {line:?} within {limit:?}; stdout so far: {:?}",
            self.stdout
        );
    }

    /// Restarts the clock `Ended::took` counts from.
    fn mark(&mut self) {
        self.started = Instant::now();
    }

    fn signal(&self, sig: i32) {
        // SAFETY: kill(2) on our own child.
        unsafe { libc::kill(self.pid(), sig) };
    }

    /// Waits for the exit (killing the runner and failing after `limit`), sampling its RSS.
    fn wait(mut self, limit: Duration) -> Ended {
        let status = loop {
            if let Some(status) = self.child.try_wait().expect("wait physics-lua") {
                break status;
            }
            self.sample_rss();
            if self.started.elapsed() > limit {
                let _ = self.child.kill();
                let _ = self.child.wait();
                panic!(
                    "physics-lua still running after {limit:?}; stdout: {:?}\nstderr:\n{}",
                    self.stdout,
                    self.stderr.join().unwrap_or_default()
                );
            }
            std::thread::sleep(Duration::from_millis(5));
        };
        let took = self.started.elapsed();
        let stderr = self.stderr.join().unwrap_or_default();
        self.stdout.extend(self.lines.try_iter());
        Ended {
            status,
            took,
            stdout: self.stdout.join("\n"),
            stderr,
            peak_rss_kb: self.peak_rss_kb,
        }
    }
}

impl Ended {
    fn assert_stderr_has(&self, needles: &[&str]) {
        for needle in needles {
            assert!(
                self.stderr.contains(needle),
                "{needle:?} missing from stderr:\n{}",
                self.stderr
            );
        }
    }
}

fn stop_process(pid: u32, sig: i32) {
    // SAFETY: kill(2) on a daemon this test started.
    unsafe { libc::kill(pid as i32, sig) };
}

#[test]
fn max_run_ms_stops_a_script_that_never_yields() {
    let daemon = TestDaemon::start("lua-busy");
    let r = Runner::start(
        &daemon.domain,
        "tests/lua/spin.luau",
        &["--max-run-ms", "300"],
    )
    .wait(Duration::from_secs(20));
    assert_eq!(r.status.code(), Some(1), "stderr:\n{}", r.stderr);
    // Well before the default limit of 5 s.
    assert!(r.took < Duration::from_secs(4), "took {:?}", r.took);
    r.assert_stderr_has(&["without yielding", "--max-run-ms 300", "spin.luau:4"]);
}

#[test]
fn seconds_stops_a_script_that_never_yields() {
    let daemon = TestDaemon::start("lua-busy-seconds");
    let r = Runner::start(&daemon.domain, "tests/lua/spin.luau", &["--seconds", "1"])
        .wait(Duration::from_secs(20));
    assert_eq!(r.status.code(), Some(0), "stderr:\n{}", r.stderr);
    assert!(
        r.took >= Duration::from_millis(950) && r.took < Duration::from_secs(4),
        "took {:?}",
        r.took
    );
    r.assert_stderr_has(&["--seconds 1", "still running", "spin.luau:4"]);
}

#[test]
fn max_memory_mb_stops_an_allocation_loop() {
    let daemon = TestDaemon::start("lua-memory");
    let r = Runner::start(
        &daemon.domain,
        "tests/lua/hog_memory.luau",
        &["--max-memory-mb", "64"],
    )
    .wait(Duration::from_secs(30));
    assert_eq!(r.status.code(), Some(1), "stderr:\n{}", r.stderr);
    r.assert_stderr_has(&["out of memory", "--max-memory-mb 64"]);
    // 64 MiB of Lua plus the runner itself; without the limit it grows by 1 MB a loop.
    assert!(
        r.peak_rss_kb > 0 && r.peak_rss_kb < 400 * 1024,
        "peak RSS {} kB",
        r.peak_rss_kb
    );
}

#[test]
fn max_memory_mb_holds_for_cframes_that_pose_reads_make() {
    // Pose reads make their CFrame values outside mlua's per-value protected call (the limit
    // is lifted for that one allocation): the limit must still end a script that keeps them.
    let daemon = TestDaemon::start("lua-memory-cframes");
    let r = Runner::start(
        &daemon.domain,
        "tests/lua/hog_cframes.luau",
        &["--max-memory-mb", "32"],
    )
    .wait(Duration::from_secs(30));
    assert_eq!(r.status.code(), Some(1), "stderr:\n{}", r.stderr);
    r.assert_stderr_has(&["out of memory", "--max-memory-mb 32"]);
    // 32 MiB of Lua, the Rust side of each CFrame and the runner itself.
    assert!(
        r.peak_rss_kb > 0 && r.peak_rss_kb < 400 * 1024,
        "peak RSS {} kB",
        r.peak_rss_kb
    );
}

#[test]
fn the_first_signal_ends_a_busy_script_and_stops_the_daemon_it_started() {
    for (sig, name) in [(libc::SIGTERM, "term"), (libc::SIGINT, "int")] {
        let domain = unique_domain(&format!("lua-sig{name}"));
        let mut runner = Runner::start(&domain, "tests/lua/spin.luau", &[]);
        runner.wait_for("spinning", Duration::from_secs(30));
        std::thread::sleep(Duration::from_millis(200));
        runner.mark();
        runner.signal(sig);
        let r = runner.wait(Duration::from_secs(10));
        assert_eq!(r.status.code(), Some(130), "stderr:\n{}", r.stderr);
        assert!(r.took < Duration::from_secs(2), "took {:?}", r.took);
        r.assert_stderr_has(&["stopped by a signal"]);
        // The daemon the runner started is gone, and so are its shared-memory files.
        assert!(matches!(
            client_sdk::Client::connect(&domain),
            Err(client_sdk::Error::NoDaemon { .. })
        ));
        let left = eventually(Duration::from_secs(5), || {
            let left = domain_files(&domain);
            left.is_empty().then_some(())
        });
        assert!(left.is_some(), "left behind: {:?}", domain_files(&domain));
    }
}

#[test]
fn the_first_signal_ends_a_run_blocked_on_a_stalled_daemon() {
    let daemon = TestDaemon::start("lua-stalled-signal");
    let mut runner = Runner::start(&daemon.domain, "tests/lua/step_forever.luau", &[]);
    runner.wait_for("ready", Duration::from_secs(30));
    stop_process(daemon.pid(), libc::SIGSTOP);
    std::thread::sleep(Duration::from_millis(300));
    runner.mark();
    runner.signal(libc::SIGTERM);
    let r = runner.wait(Duration::from_secs(15));
    stop_process(daemon.pid(), libc::SIGCONT);
    assert_eq!(r.status.code(), Some(130), "stderr:\n{}", r.stderr);
    // The step in flight cannot be interrupted: the runner gives it 2 s, then exits.
    assert!(r.took < Duration::from_secs(4), "took {:?}", r.took);
}

#[test]
fn a_stalled_daemon_is_reported_within_seconds() {
    let daemon = TestDaemon::start("lua-stalled");
    // The default request timeout (30 s) is far away: the daemon's silent heartbeat tells.
    let mut runner = Runner::start(&daemon.domain, "tests/lua/step_forever.luau", &[]);
    runner.wait_for("ready", Duration::from_secs(30));
    stop_process(daemon.pid(), libc::SIGSTOP);
    runner.mark();
    let r = runner.wait(Duration::from_secs(20));
    stop_process(daemon.pid(), libc::SIGCONT);
    assert_eq!(r.status.code(), Some(1), "stderr:\n{}", r.stderr);
    r.assert_stderr_has(&["PhysicsPlane:Step", "is stalled", "step_forever.luau:10"]);
    assert!(r.took < Duration::from_secs(8), "took {:?}", r.took);
}

#[test]
fn a_killed_daemon_is_reported() {
    let mut daemon = TestDaemon::start("lua-killed");
    let mut runner = Runner::start(&daemon.domain, "tests/lua/step_forever.luau", &[]);
    runner.wait_for("ready", Duration::from_secs(30));
    daemon.kill9();
    runner.mark();
    let r = runner.wait(Duration::from_secs(20));
    assert_eq!(r.status.code(), Some(1), "stderr:\n{}", r.stderr);
    r.assert_stderr_has(&["PhysicsPlane:Step", "is gone"]);
    assert!(r.took < Duration::from_secs(10), "took {:?}", r.took);
    assert!(r.stdout.starts_with("ready"), "{}", r.stdout);
}

#[test]
fn a_script_that_only_reads_learns_of_a_stall_within_a_second() {
    let daemon = TestDaemon::start("lua-read-stall");
    let mut runner = Runner::start(&daemon.domain, "tests/lua/read_only_stall.luau", &[]);
    runner.wait_for("ready", Duration::from_secs(30));
    stop_process(daemon.pid(), libc::SIGSTOP);
    let stopped = Instant::now();
    // 0.6 s of silence counted from the last beat (before the stop) plus one watch period;
    // the required bound is 1 s; 1.5 s leaves room for a loaded machine's scheduling.
    runner.wait_for("stalled", Duration::from_secs(5));
    let noticed = stopped.elapsed();
    stop_process(daemon.pid(), libc::SIGCONT);
    runner.wait_for("resumed", Duration::from_secs(5));
    let r = runner.wait(Duration::from_secs(10));
    assert_eq!(r.status.code(), Some(0), "stderr:\n{}", r.stderr);
    assert!(
        noticed < Duration::from_millis(1500),
        "Stalled fired {noticed:?} after the stop"
    );
}

//! `physics-bench fuzz`: the fuzzer of `physics_fuzz` against a real daemon for a
//! given time: frames, commands and replies by kind, quota rounds, op coverage, and the
//! verdict (no crash, every request answered with a reply of the right shape).

mod fuzz_report;
mod markdown;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use physics_fuzz::{self as fuzz, FuzzConfig, FuzzStats, QUOTA_FLAGS};

use super::daemon::DaemonProcess;
use super::error::{BenchError, BenchResult};
use super::procfs;
use super::report::{self, Goal};
use fuzz_report::{FindingOut, FuzzReport};

/// Options of the `fuzz` subcommand.
#[derive(Debug, Clone, clap::Args)]
pub struct FuzzArgs {
    /// How long to send batches.
    #[arg(long, default_value_t = 60.0)]
    pub seconds: f64,
    /// Seeds every random choice (default: from the clock; printed either way).
    #[arg(long)]
    pub seed: Option<u64>,
    /// Clients sending frames, in turn from one thread.
    #[arg(long, default_value_t = 4)]
    pub clients: usize,
    /// Folder receiving fuzz.json, fuzz.md, fuzz-daemon.log and the frames of findings.
    #[arg(long, default_value = "bench-out")]
    pub out: PathBuf,
}

pub fn run(args: &FuzzArgs) -> BenchResult<()> {
    let seed = args.seed.unwrap_or_else(|| {
        std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| d.as_nanos() as u64)
    });
    eprintln!("fuzz seed {seed} (--seed {seed} replays the input)");
    std::fs::create_dir_all(&args.out).map_err(BenchError::io(format!(
        "create the output folder --out {}",
        args.out.display()
    )))?;
    let log = args.out.join("fuzz-daemon.log");
    std::fs::write(&log, b"").map_err(BenchError::io(format!("write {}", log.display())))?;

    let mut config = FuzzConfig::new(seed, Duration::from_secs_f64(args.seconds.max(0.0)));
    config.clients = args.clients.max(1);
    let flags = config.quotas.daemon_args();
    let mut daemon = DaemonProcess::start_with("fuzz", &flags, Some(&log))?;
    let pid = daemon.pid();
    let rss_start = procfs::rss_bytes(pid)?;
    let domain = daemon.domain.clone();
    let started = Instant::now();
    let mut last_note = Instant::now();
    let stats = {
        let mut alive = || daemon.is_running();
        let mut progress = |s: &FuzzStats| {
            if last_note.elapsed() >= Duration::from_secs(10) {
                eprintln!(
                    "{:>5.0} s: {} frames, {} commands, {} crashes",
                    s.seconds, s.frames, s.commands, s.crashes
                );
                last_note = Instant::now();
            }
        };
        fuzz::run(&domain, &config, &mut alive, &mut progress)?
    };
    let running = daemon.is_running();
    let rss_end = running.then(|| procfs::rss_bytes(pid).ok()).flatten();
    let served_after = running.then(|| served(&daemon));
    drop(daemon);
    let daemon_panics = panics_in_log(&log);

    let findings = stats
        .findings
        .iter()
        .enumerate()
        .map(|(i, f)| {
            let frame_file = (!f.frame.is_empty()).then(|| {
                let name = format!("fuzz-finding-{i}.bin");
                let _ = std::fs::write(args.out.join(&name), &f.frame);
                name
            });
            FindingOut {
                kind: f.kind,
                batch: f.batch,
                client: f.client,
                detail: f.detail.clone(),
                frame_file,
            }
        })
        .collect();
    let seconds = stats.seconds.max(1e-9);
    let mut report = FuzzReport {
        daemon_flags: flags,
        frames_per_s: stats.frames as f64 / seconds,
        commands_per_s: stats.commands as f64 / seconds,
        ok_fraction: stats.ok_fraction(),
        ops_not_sent: stats.ops_not_sent(),
        daemon_panics,
        findings,
        served_after,
        daemon_rss_start_bytes: rss_start,
        daemon_rss_end_bytes: rss_end,
        goals: Vec::new(),
        method: markdown::method(),
        stats: stats.clone(),
    };
    report.goals = goals(&report);
    let md = markdown::render(&report);
    let (json, md_path) = report::write(&args.out, "fuzz", &report, &md)?;
    report::print(&md_path);
    eprintln!(
        "wrote {} and {} in {:.0} s (daemon log: {})",
        json.display(),
        md_path.display(),
        started.elapsed().as_secs_f64(),
        log.display()
    );
    if stats.clean() && served_after == Some(true) {
        Ok(())
    } else {
        Err(BenchError::Failed(format!(
            "the daemon failed the fuzz run (seed {seed}): {} crashes, {} unanswered, {} \
             protocol errors, served a normal client afterwards: {}",
            stats.crashes,
            stats.unanswered,
            stats.protocol_errors,
            served_after.map_or("no (not running)".to_string(), |b| b.to_string())
        )))
    }
}

/// A normal client is served after the run: a plane, a ball, ten steps, the ball falls.
fn served(daemon: &DaemonProcess) -> bool {
    let check = || -> BenchResult<bool> {
        let client = daemon.connect()?;
        let plane = client.create_plane(&client_sdk::PlaneOptions::manual())?;
        let ball = physics_scenes::ball(&mut &plane, [0.0, 10.0, 0.0], &[])?;
        for _ in 0..10 {
            plane.step(1.0 / 60.0)?;
        }
        let y = ball.position()?[1];
        Ok(y < 10.0 && y > 8.0)
    };
    check().unwrap_or(false)
}

/// Panics the daemon logged (its panic hook writes `panicked at LOCATION:` then the
/// message), by location and message.
fn panics_in_log(log: &Path) -> BTreeMap<String, u64> {
    let text = std::fs::read_to_string(log).unwrap_or_default();
    let mut found = BTreeMap::new();
    let mut lines = text.lines();
    while let Some(line) = lines.next() {
        if let Some((_, at)) = line.split_once("panicked at ") {
            let location = at.trim_end_matches(':');
            // Keep the crate-relative part of registry paths.
            let location = location
                .rsplit_once("/registry/src/")
                .and_then(|(_, rest)| rest.split_once('/').map(|(_, p)| p))
                .unwrap_or(location);
            let message = lines.next().unwrap_or("").trim();
            *found.entry(format!("{location}: {message}")).or_default() += 1;
        }
    }
    found
}

fn goals(r: &FuzzReport) -> Vec<Goal> {
    let mut goals = vec![
        Goal::new(
            "no crash: the daemon process never exits, every reply decodes",
            format!("{} crashes in {} frames", r.crashes, r.frames),
            Some(r.crashes == 0),
        ),
        Goal::new(
            "every request answered (no timeout, stall or lost reply)",
            format!("{} unanswered", r.unanswered),
            Some(r.unanswered == 0),
        ),
        Goal::new(
            "every reply of the shape the frame calls for (one result per command, or the \
             predicted rejection, or the version-neutral reply)",
            format!("{} protocol errors", r.protocol_errors),
            Some(r.protocol_errors == 0),
        ),
        Goal::new(
            "a normal client is served after the run",
            match r.served_after {
                Some(true) => "yes".to_string(),
                Some(false) => "no".to_string(),
                None => "daemon not running".to_string(),
            },
            Some(r.served_after == Some(true)),
        ),
        Goal::new(
            "fuzzed commands reach past validation: ≥ 30 % succeed",
            format!("{:.0} %", r.ok_fraction * 100.0),
            Some(r.ok_fraction >= 0.3),
        ),
    ];
    let all = fuzz::stats::all_op_names().len();
    goals.push(Goal::new(
        "every Command / PlaneOp / ObjectOp / property / shape variant sent",
        if r.ops_not_sent.is_empty() {
            format!("{all} of {all}")
        } else {
            format!(
                "{} of {all}; missing {}",
                all - r.ops_not_sent.len(),
                r.ops_not_sent.join(", ")
            )
        },
        Some(r.ops_not_sent.is_empty()),
    ));
    for flag in QUOTA_FLAGS {
        let q = r.quota_rounds.get(flag);
        goals.push(Goal::new(
            format!("quota {flag} refused when exceeded"),
            q.map_or("no round ran".into(), |q| {
                format!("{} of {} rounds", q.hit, q.runs)
            }),
            q.map(|q| q.runs > 0 && q.hit == q.runs),
        ));
    }
    let log_panics: u64 = r.daemon_panics.values().sum();
    goals.push(Goal::new(
        "no plane fails inside the daemon (a caught panic removes the plane)",
        format!(
            "{} in replies, {} panics in the daemon log",
            r.plane_panics, log_panics
        ),
        Some(r.plane_panics == 0 && log_panics == 0),
    ));
    goals
}

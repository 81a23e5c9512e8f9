//! The fuzzer of `physics-bench fuzz` for a bounded time against a real daemon: structured
//! batches of every command with valid and wild values, raw and mutated frames, and rounds
//! that exceed every quota. The daemon must survive all of it, answer every frame with a
//! reply of the right shape, and still serve a normal client afterwards.

use std::time::Duration;

use client_sdk::{PlaneOptions, Pose, Shape};
use integration_tests::TestDaemon;
use physics_fuzz::{self as fuzz, FuzzConfig, QUOTA_FLAGS};

/// `PHYSICS_FUZZ_SEED` replays a run; otherwise a seed from the clock (printed).
fn seed() -> u64 {
    std::env::var("PHYSICS_FUZZ_SEED")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or_else(|| {
            std::time::SystemTime::now()
                .duration_since(std::time::UNIX_EPOCH)
                .unwrap()
                .as_nanos() as u64
        })
}

#[test]
fn the_daemon_survives_fuzzed_requests_and_serves_on() {
    let mut config = FuzzConfig::new(seed(), Duration::from_secs(12));
    // Short run: a quota round often enough that every quota comes round at least once.
    config.quota_every = 25;
    config.until_covered = true;
    println!("fuzz seed {} (PHYSICS_FUZZ_SEED replays it)", config.seed);
    let args = config.quotas.daemon_args();
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let mut daemon = TestDaemon::start_with("fuzz", &args, &[]);
    let domain = daemon.domain.clone();
    let stats = {
        let mut alive = || daemon.is_running();
        fuzz::run(&domain, &config, &mut alive, &mut |_| {}).expect("fuzz clients connect")
    };
    println!(
        "{} frames, {} commands, ok {:?}, errors {:?}, rejected {:?}",
        stats.frames, stats.commands, stats.ok, stats.errors, stats.rejected
    );

    for f in &stats.findings {
        eprintln!(
            "{} in batch {} (client {}): {}",
            f.kind, f.batch, f.client, f.detail
        );
        // What was asked, so a finding can be read without a replay.
        match shm_layout::codec::decode_request(&f.frame) {
            Ok(request) => eprintln!("  request: {:.4000}", format!("{request:?}")),
            Err(e) => eprintln!("  request ({} bytes) does not decode: {e}", f.frame.len()),
        }
    }
    assert_eq!(stats.crashes, 0, "seed {}", stats.seed);
    assert_eq!(stats.unanswered, 0, "seed {}", stats.seed);
    assert_eq!(stats.protocol_errors, 0, "seed {}", stats.seed);
    // A plane that panics is caught and removed, but no client input may make one panic.
    assert_eq!(
        stats.plane_panics, 0,
        "seed {}: planes panicked (see the findings above)",
        stats.seed
    );
    assert!(daemon.is_running());

    // It went well past validation: many commands, a good share of them applied, steps and
    // objects among them, every quota met.
    assert!(stats.frames > 200, "{} frames", stats.frames);
    assert!(stats.commands > 2_000, "{} commands", stats.commands);
    // Measured over 15 seeds with every op family (queries, groups, controllers, GUI,
    // joints, maps, most of them aimed at random planes and handles by design): 28–37 %
    // Ok. A generator that stopped producing valid commands would fall far below 25 %.
    println!("{:.1} % of results Ok", stats.ok_fraction() * 100.0);
    assert!(
        stats.ok_fraction() > 0.25,
        "seed {}: only {:.0} % of results were Ok",
        stats.seed,
        stats.ok_fraction() * 100.0
    );
    for reply in ["Stepped", "Object", "Applied", "Plane", "ObjectInfo"] {
        assert!(
            stats.ok.get(reply).copied().unwrap_or(0) > 0,
            "no {reply} reply"
        );
    }
    assert!(stats.raw_frames > 50 && stats.version_replies > 0);
    // Every command, op, property and shape variant went out (Goodbye, rare by design so
    // clients keep their planes, may miss a short run).
    let missing: Vec<String> = stats
        .ops_not_sent()
        .into_iter()
        .filter(|op| op != "Goodbye")
        .collect();
    assert!(missing.is_empty(), "never sent: {missing:?}");
    for flag in QUOTA_FLAGS {
        assert!(
            stats.quota_rounds.get(flag).is_some_and(|r| r.hit > 0),
            "quota {flag} never met: {:?}",
            stats.quota_rounds
        );
    }

    // A normal client is served as if nothing happened.
    let client = daemon.client();
    let plane = client.create_plane(&PlaneOptions::manual()).unwrap();
    let ball = plane
        .add(
            Shape::Sphere { radius: 0.5 },
            Pose::at([0.0, 10.0, 0.0]),
            &[],
        )
        .unwrap();
    for _ in 0..10 {
        plane.step(1.0 / 60.0).unwrap();
    }
    let y = ball.position().unwrap()[1];
    assert!(y < 10.0 && y > 8.0, "the ball fell normally: y = {y}");
}

//! The physics fuzzer (`physics-envelope`) at a fixed seed inside the documented envelope
//! (`physics_envelope::space::HOLDS`, the ranges where the defaults hold today): every case
//! drawn must pass every oracle of its family (values finite, nothing through its target,
//! resting heights / penetration / sleep / tilt / drift within the family's stated
//! tolerances, undamped energy kept within 1 %, momentum kept, the state-hash fold equal
//! across two runs). A failure is shrunk and printed as a runnable `physics-lua` repro.
//! In process, through the daemon's own plane code; the longer runs over the full ranges are
//! `physics-bench envelope --minutes N`.

use physics_envelope::{fuzz, space, FuzzConfig};

/// Cases per family: 720 cases in about 48 s on a 2-core machine (debug test profile).
const PER_FAMILY: usize = 120;

#[test]
fn every_case_inside_the_documented_envelope_holds() {
    physics_envelope::one_pool_thread();
    let cfg = FuzzConfig {
        seed: 42,
        cases: Some(PER_FAMILY * physics_envelope::FAMILIES.len()),
        time: None,
        space: space::HOLDS,
        determinism_every: 3,
        shrink_budget: 30,
        shrink_per_oracle: 1,
    };
    let report = fuzz(&cfg, |i, case, v| {
        if !v.is_empty() {
            eprintln!(
                "case {i} ({}) fails {v:?}: {}",
                case.family(),
                case.describe()
            );
        }
    });
    eprintln!(
        "envelope: {} cases in {:.1} s, {} failing",
        report.cases,
        report.wall_s,
        report.failing()
    );
    for f in &report.findings {
        eprintln!(
            "\n=== {} / {}: shrunk in {} runs to {}\n{:?}\n--- Luau repro (physics-lua FILE) ---\n{}",
            f.family,
            f.oracle,
            f.shrink_runs,
            f.shrunk.describe(),
            f.violations,
            f.luau
        );
    }
    assert_eq!(
        report.failing(),
        0,
        "cases inside the documented envelope failed (shrunk repros above): {:?}",
        report
            .families
            .iter()
            .filter(|(_, s)| s.failing > 0)
            .map(|(f, s)| (f, &s.by_oracle))
            .collect::<Vec<_>>()
    );
}

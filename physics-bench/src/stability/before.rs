//! The figures the stability scenes had before articulations (issue "Stability III"), so
//! that stability.md shows each scene's figure before and after. Scenes not listed here
//! were not changed by that work; their "before" is the previous report's figure.

/// What scene `name` measured before, in words (`None`: unchanged since).
pub fn before(name: &str) -> Option<&'static str> {
    Some(match name {
        "chain-1000" => "~50 at the defaults (impulse joints); 0.98 at SolverIterations 16",
        "ragdoll-1000-limits" => "1.23 rad (impulse joints, SolverIterations 16)",
        "ragdoll-1000-anchors" => "0.49 (impulse joints, SolverIterations 16)",
        "ragdoll-1000-pass-through" => "the ball passed through, even with CCD",
        "card-house-q4" => "falls at the defaults",
        "mass-ratio-1000-stack" | "mass-ratio-1000-column" => {
            "holds only at 30 Hz × 8 or 120 Hz × 16"
        }
        "pyramid-100" => "never finished: stopped after 10 minutes (single-threaded)",
        _ => return None,
    })
}

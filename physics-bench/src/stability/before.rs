//! The figures the stability scenes had before articulations and adaptive solving (issue
//! "Stability III"; the card house before thin objects' contacts were recomputed every step), so
//! that stability.md shows each scene's figure before and after. Scenes not listed here
//! were not changed by that work; their "before" is the previous report's figure.

/// What scene `name` measured before, in words (`None`: unchanged since).
pub fn before(name: &str) -> Option<&'static str> {
    Some(match name {
        "chain-1000" => "~50 at the defaults (impulse joints); 0.98 at SolverIterations 16",
        "ragdoll-1000-limits" => "1.23 rad (impulse joints, SolverIterations 16)",
        "ragdoll-1000-anchors" => "0.49 (impulse joints, SolverIterations 16)",
        "ragdoll-1000-pass-through" => "the ball passed through, even with CCD",
        "card-house-q4" => {
            "2.1 at the defaults (the top pair slid apart within 1.5 s: thin cards' contacts \
             recycled); only rotation locked (q1) held it"
        }
        "mass-ratio-1000-stack" => "0.73 at the defaults (holds only at 30 Hz × 8 or 120 Hz × 16)",
        "mass-ratio-1000-column" => "1.98 at the defaults (holds only at 60 Hz × 32)",
        "pyramid-100" => {
            "0.76 over 2 s at the defaults; the run never finished (the remedy search over the \
             whole grid on 5,050 boxes)"
        }
        _ => return None,
    })
}

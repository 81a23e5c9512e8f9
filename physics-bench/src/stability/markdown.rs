//! stability.md: per scene pass / fail with the figure against its bound, then the sweeps'
//! critical values at the defaults and at the strongest configuration.

use std::fmt::Write as _;

use super::entry::Entry;
use crate::accuracy::markdown::sci;
use crate::report::Table;
use crate::sim::Config;

pub fn render(entries: &[Entry]) -> String {
    let mut md = String::from("# Stability: stiff and extreme scenes\n\n");
    let _ = writeln!(
        md,
        "In process, through the daemon's own plane code. Every scene also fails if any body \
         turns non-finite on any tick. `cost` is wall seconds of step calls per simulated \
         second. Defaults: {}; strongest: {}. A failing scene is retried under every \
         configuration of the accuracy grid (TickRate 30–480 × SolverIterations 1–64 × \
         HitBoxQuality 1, 4, 32; a tick-rate scene keeps its rate); the cheapest that passes is \
         listed.\n",
        Config::DEFAULT.label(),
        Config::STRONGEST.label()
    );
    let passed = entries.iter().filter(|e| e.pass).count();
    let _ = writeln!(md, "**{passed} of {} pass.**\n", entries.len());
    let mut t = Table::new(&[
        "scene",
        "config",
        "result",
        "figure",
        "bound",
        "unit",
        "cost",
        "passes with (cost)",
        "before",
        "wall s",
    ]);
    for e in entries.iter().filter(|e| e.points.is_empty()) {
        t.row(&[
            e.scene.to_string(),
            e.config.label(),
            verdict(e),
            sci(e.figure),
            sci(e.bound),
            e.unit.to_string(),
            sci(e.cost),
            remedy(e),
            e.before.unwrap_or("—").to_string(),
            format!("{:.1}", e.wall_s),
        ]);
    }
    md.push_str(&t.finish());
    md.push_str("\nCriteria:\n\n");
    for e in entries.iter().filter(|e| e.points.is_empty()) {
        let _ = writeln!(md, "- `{}`: {}", e.scene, e.criterion);
    }
    md.push_str(NOTES);
    md.push_str("\n## Critical values\n\n");
    let mut t = Table::new(&[
        "sweep",
        "at defaults",
        "at strongest",
        "required",
        "result",
        "values tried",
    ]);
    for e in entries.iter().filter(|e| !e.points.is_empty()) {
        let mut values: Vec<String> = e.points.iter().map(|p| p.value.to_string()).collect();
        values.dedup();
        values.truncate(e.points.len() / 2);
        t.row(&[
            e.scene.to_string(),
            e.critical_default
                .map_or("none passes".into(), |v| v.to_string()),
            e.critical_strongest
                .map_or("none passes".into(), |v| v.to_string()),
            format!("{} ({})", e.bound, judged(e)),
            verdict(e),
            values.join(", "),
        ]);
    }
    md.push_str(&t.finish());
    md.push('\n');
    for e in entries.iter().filter(|e| !e.points.is_empty()) {
        let _ = writeln!(md, "- `{}`: {}", e.scene, e.criterion);
    }
    md.push_str("\n### Sweep points\n");
    for e in entries.iter().filter(|e| !e.points.is_empty()) {
        let _ = write!(md, "\n`{}`\n\n", e.scene);
        let mut t = Table::new(&["config", "value", "result", "figure", "bound", "cost"]);
        for p in &e.points {
            t.row(&[
                p.config.label(),
                p.value.to_string(),
                if p.check.pass { "pass" } else { "**fail**" }.into(),
                sci(p.check.figure),
                sci(p.check.bound),
                sci(p.check.cost),
            ]);
        }
        md.push_str(&t.finish());
    }
    md
}

fn judged(e: &Entry) -> &'static str {
    if e.config == Config::DEFAULT {
        "at defaults"
    } else {
        "at strongest"
    }
}

fn verdict(e: &Entry) -> String {
    match (e.pass, e.finite) {
        (true, _) => "pass".into(),
        (false, true) => "**FAIL**".into(),
        (false, false) => "**FAIL** (non-finite)".into(),
    }
}

fn remedy(e: &Entry) -> String {
    match (&e.remedy, e.remedy_candidates) {
        (Some(r), _) => format!("{} ({})", r.config.label(), sci(r.cost)),
        (None, 0) => String::new(),
        (None, n) => format!("**none of {n} configurations**"),
    }
}

/// What the service's settings imply for reading the figures.
const NOTES: &str = "
Reading the figures:

- At HitBoxQuality 1 a box's rotation is locked against contacts, so a quality-1 stack cannot
  topple; the q4 variants (rotation free) are the demanding ones.
- Contacts are soft springs (rapier's natural frequency: 30 Hz between bodies, 60 Hz against
  anchored ones, raised up to 2.5× by HitBoxQuality). Under a heavy body the steady sink grows
  with the mass ratio; more iterations or a higher tick rate do not remove it.
- Speeds are capped at the plane's MaxLinearSpeed (default 10,000 units/s, applied per
  substep through rapier's `normalized_max_linear_velocity`), far above the speed sweep, so
  every launch of the sweep really flies at its speed.
";

//! accuracy.md: what was run, a summary at the defaults, and a table per scene with the
//! Pareto-optimal configurations and the defaults marked.

use std::fmt::Write as _;

use super::point::{scene_info, Point};
use crate::report::Table;

/// Three significant digits, scientific: errors and costs span many decades.
pub fn sci(v: f64) -> String {
    if v.is_nan() {
        "non-finite".into()
    } else if v == 0.0 {
        "0".into()
    } else {
        format!("{v:.2e}")
    }
}

pub fn render(points: &[Point], quick: bool, repeats: usize) -> String {
    let mut md = String::from("# Accuracy: error against run time\n\n");
    let _ = writeln!(
        md,
        "Each scene runs in process through the daemon's own plane code \
         (`physics_daemon::rapier3d::Plane`, what the daemon steps), so `cost` is wall seconds of \
         step calls per simulated second, without IPC: median of {repeats} repeats{}. A cost \
         below 1 runs faster than real time on one core. `error` is deterministic; its \
         meaning and unit are given per scene. Configurations: {}. **P** marks the \
         Pareto-optimal configurations of a scene (nothing else is both at least as accurate \
         and as cheap); _default_ marks TickRate 60, SolverIterations 4, HitBoxQuality 1.\n",
        if quick { ", `--quick`" } else { "" },
        if quick {
            "the three families (one knob varied, the others at the defaults)"
        } else {
            "the full TickRate × SolverIterations × HitBoxQuality cross product"
        }
    );
    md.push_str("## At the defaults\n\n");
    let mut summary = Table::new(&[
        "scene",
        "error at default",
        "cost at default",
        "default Pareto-optimal",
        "default dominated by (config: error, cost)",
        "most accurate (config: error, cost)",
    ]);
    let mut names: Vec<&str> = points.iter().map(|p| p.scene).collect();
    names.dedup();
    for name in &names {
        let these: Vec<&Point> = points.iter().filter(|p| p.scene == *name).collect();
        let Some(d) = these.iter().find(|p| p.is_default) else {
            continue;
        };
        let best = these
            .iter()
            .filter(|p| !p.error.is_nan())
            .min_by(|a, b| a.error.total_cmp(&b.error).then(a.cost.total_cmp(&b.cost)));
        summary.row(&[
            name.to_string(),
            format!("{} {}", sci(d.error), d.error_unit),
            sci(d.cost),
            if d.pareto { "yes" } else { "no" }.into(),
            // The cheapest configuration at least as accurate and as cheap as the defaults.
            these
                .iter()
                .filter(|q| {
                    !q.error.is_nan()
                        && q.error <= d.error
                        && q.cost <= d.cost
                        && (q.error < d.error || q.cost < d.cost)
                })
                .min_by(|a, b| a.cost.total_cmp(&b.cost))
                .map_or("—".into(), |q| {
                    format!("{}: {}, {}", q.config.label(), sci(q.error), sci(q.cost))
                }),
            best.map_or("—".into(), |b| {
                format!("{}: {}, {}", b.config.label(), sci(b.error), sci(b.cost))
            }),
        ]);
    }
    md.push_str(&summary.finish());
    let on_front = names
        .iter()
        .filter(|n| {
            points
                .iter()
                .any(|p| p.scene == **n && p.is_default && p.pareto)
        })
        .count();
    let _ = writeln!(
        md,
        "\nThe defaults are on the Pareto front of {on_front} of {} scenes; where they are \
         not, the column above names the cheapest configuration that dominates them. Step \
         costs of these small scenes are microseconds and noisy on a shared machine, so a \
         domination by cost alone is within noise, and one in error (another TickRate or \
         iteration count doing better on one scene) is measured on that scene alone. \
         The defaults stay: 60 Hz is the rate games tick at, 4 iterations is rapier's \
         default, and the stability suite (`physics-bench stability`) passes at them except \
         for the 1,000:1 mass ratios.",
        names.len()
    );
    for name in &names {
        let mut these: Vec<&Point> = points.iter().filter(|p| p.scene == *name).collect();
        these.sort_by(|a, b| a.cost.total_cmp(&b.cost));
        let unit = these.first().map_or("", |p| p.error_unit);
        let _ = write!(md, "\n## {name}\n\n");
        if let Some(s) = scene_info(name) {
            let _ = writeln!(
                md,
                "error: {} ({unit}). Chart: [accuracy-{name}.svg](accuracy-{name}.svg).\n",
                s.measures
            );
        }
        let mut t = Table::new(&[
            "TickRate",
            "SolverIterations",
            "HitBoxQuality",
            &format!("error ({unit})"),
            "cost",
            "",
        ]);
        for p in these {
            let mut marks = Vec::new();
            if p.pareto {
                marks.push("**P**");
            }
            if p.is_default {
                marks.push("_default_");
            }
            t.row(&[
                p.config.tick_rate.to_string(),
                p.config.iterations_label(),
                p.config.hit_box_quality.to_string(),
                sci(p.error),
                sci(p.cost),
                marks.join(" "),
            ]);
        }
        md.push_str(&t.finish());
    }
    md
}

//! Critical values and goals. A [`Probe`] fixes a family's other parameters and walks one
//! parameter along a grid from easy to hard (mass ratio up, speed up, thickness down,
//! stiffness up, ...); the critical value at a setting is the last grid value at which every
//! case of the probe still passes every oracle (so every easier value passed too). The
//! issue's goals are judged from those values, a few dedicated runs and the fuzz run.

use std::time::Instant;

use crate::case::{judge, Case};
use crate::families::chain::{Chain, Kind, Solver, StartPose};
use crate::families::drop::{Drop, ALL_SHAPES};
use crate::families::pile::Pile;
use crate::families::projectile::{Projectile, Target};
use crate::families::spring::{Spring, SpringKind};
use crate::families::stack::{Order, Stack};
use crate::fuzz::FuzzReport;
use crate::setting::Setting;

/// One parameter walked along a grid with the rest fixed.
pub struct Probe {
    pub name: &'static str,
    pub parameter: &'static str,
    /// Easiest first.
    pub grid: &'static [f64],
    /// Settings beyond [`Setting::DEFAULT`] and [`Setting::STRONG`] this probe is run at.
    pub extra: &'static [Setting],
    /// The cases at a setting and grid value (all must pass).
    pub cases: fn(Setting, f64) -> Vec<Case>,
}

const RATIOS: &[f64] = &[1.0, 10.0, 30.0, 100.0, 300.0, 1000.0, 3000.0, 10000.0];
const SPEEDS: &[f64] = &[
    100.0, 300.0, 1000.0, 2000.0, 3200.0, 5000.0, 7000.0, 10000.0,
];
const THICKNESSES: &[f64] = &[10.0, 3.0, 1.0, 0.3, 0.1, 0.05, 0.02, 0.01];

/// 60 Hz, 4 iterations at HitBoxQuality 2: the lowest quality above the default.
pub const Q2: Setting = Setting {
    tick_rate: 60.0,
    iterations: 4,
    quality: 2,
};

/// 60 Hz, 4 iterations at HitBoxQuality 32.
pub const Q32: Setting = Setting {
    tick_rate: 60.0,
    iterations: 4,
    quality: 32,
};

fn stack(s: Setting, ratio: f64, count: u32, order: Order) -> Case {
    Case::Stack(Stack {
        setting: s,
        count,
        ratio,
        size: 1.0,
        order,
    })
}

fn chain(s: Setting, ratio: f64, pose: StartPose) -> Case {
    Case::Chain(Chain {
        setting: s,
        links: 20,
        ratio,
        link: 1.0,
        pose,
        kind: Kind::Ball,
        solver: Solver::Articulation,
    })
}

fn projectile(s: Setting, target: Target, speed: f64, thickness: f64) -> Case {
    Case::Projectile(Projectile {
        setting: s,
        target,
        speed,
        radius: 0.1,
        thickness,
        target_quality: s.quality,
        angle: 0.0,
        mass_ratio: 1.0,
    })
}

fn spring(s: Setting, kind: SpringKind, stiffness: f64) -> Case {
    Case::Spring(Spring {
        setting: s,
        kind,
        stiffness,
        mass: 1.0,
        amplitude: 0.5,
    })
}

/// Every probe of the report.
pub const PROBES: &[Probe] = &[
    Probe {
        name: "stack: a heavy box on a light one",
        parameter: "mass ratio",
        grid: RATIOS,
        extra: &[],
        cases: |s, v| vec![stack(s, v, 2, Order::HeavyTop)],
    },
    Probe {
        name: "column: 1 / R / 1 / R",
        parameter: "mass ratio",
        grid: RATIOS,
        extra: &[],
        cases: |s, v| vec![stack(s, v, 4, Order::Alternating)],
    },
    Probe {
        name: "chain of 20, heavy end, hanging",
        parameter: "mass ratio",
        grid: RATIOS,
        extra: &[],
        cases: |s, v| vec![chain(s, v, StartPose::Hanging)],
    },
    Probe {
        name: "chain of 20, heavy end, horizontal",
        parameter: "mass ratio",
        grid: RATIOS,
        extra: &[],
        cases: |s, v| vec![chain(s, v, StartPose::Horizontal)],
    },
    Probe {
        name: "chain of 20, heavy end, coiled",
        parameter: "mass ratio",
        grid: RATIOS,
        extra: &[],
        cases: |s, v| vec![chain(s, v, StartPose::Coiled)],
    },
    Probe {
        name: "ball 0.1 at an anchored wall 0.05 thick",
        parameter: "speed (u/s)",
        grid: SPEEDS,
        extra: &[],
        cases: |s, v| vec![projectile(s, Target::Wall, v, 0.05)],
    },
    Probe {
        name: "ball 0.1 at 3,200 u/s at an anchored wall",
        parameter: "thickness (thinnest holding)",
        grid: THICKNESSES,
        extra: &[],
        cases: |s, v| vec![projectile(s, Target::Wall, 3200.0, v)],
    },
    Probe {
        name: "ball 0.1 at a free 1 × 2 × 2 body (both at the setting's quality)",
        parameter: "speed (u/s)",
        grid: SPEEDS,
        extra: &[Q2, Q32],
        cases: |s, v| vec![projectile(s, Target::Body, v, 1.0)],
    },
    Probe {
        name: "SixDof axis spring, m 1, undamped",
        parameter: "stiffness",
        grid: &[1.0, 10.0, 100.0, 1e3, 1e4, 1e5],
        extra: &[],
        cases: |s, v| vec![spring(s, SpringKind::AxisSpring, v)],
    },
    Probe {
        name: "Spring joint, m 1, undamped",
        parameter: "stiffness",
        grid: &[1.0, 10.0, 100.0, 1e3, 1e4, 1e5],
        extra: &[],
        cases: |s, v| vec![spring(s, SpringKind::Spring, v)],
    },
    Probe {
        name: "every drop shape (2 wide, 3 tall) dropped flat",
        parameter: "drop height",
        grid: &[0.1, 1.0, 5.0, 20.0],
        extra: &[],
        cases: |s, v| {
            ALL_SHAPES
                .iter()
                .map(|&shape| {
                    Case::Drop(Drop {
                        setting: s,
                        shape,
                        size: 2.0,
                        aspect: 1.5,
                        height: v,
                    })
                })
                .collect()
        },
    },
    Probe {
        name: "pile of 20 unit parts",
        parameter: "distance from the origin",
        grid: &[0.0, 100.0, 1e3, 1e4, 3e4, 1e5],
        extra: &[],
        cases: |s, v| {
            vec![Case::Pile(Pile {
                setting: s,
                count: 20,
                size: 1.0,
                offset: v,
                round: false,
            })]
        },
    },
];

/// A probe's result at one setting.
#[derive(Debug, Clone, serde::Serialize)]
pub struct CriticalValue {
    pub probe: &'static str,
    pub parameter: &'static str,
    pub setting: Setting,
    /// The last grid value at which every case passed (None: the easiest failed).
    pub value: Option<f64>,
    /// The first grid value that failed, and the oracles that failed there.
    pub first_failure: Option<(f64, Vec<&'static str>)>,
    /// Whether the whole grid passed.
    pub whole_grid: bool,
    pub grid: Vec<f64>,
    pub wall_s: f64,
}

/// Walks `probe`'s grid at `setting`.
pub fn search(probe: &Probe, setting: Setting) -> CriticalValue {
    let started = Instant::now();
    let mut value = None;
    let mut first_failure = None;
    for &g in probe.grid {
        let mut failed: Vec<&'static str> = Vec::new();
        for case in (probe.cases)(setting, g) {
            for v in judge(&case, false) {
                if !failed.contains(&v.oracle) {
                    failed.push(v.oracle);
                }
            }
        }
        if failed.is_empty() {
            value = Some(g);
        } else {
            first_failure = Some((g, failed));
            break;
        }
    }
    CriticalValue {
        probe: probe.name,
        parameter: probe.parameter,
        setting,
        value,
        whole_grid: first_failure.is_none(),
        first_failure,
        grid: probe.grid.to_vec(),
        wall_s: started.elapsed().as_secs_f64(),
    }
}

/// Every probe at the defaults, the strong setting and its extra settings; `progress`
/// hears each before it runs.
pub fn search_all(mut progress: impl FnMut(&str, Setting)) -> Vec<CriticalValue> {
    let mut out = Vec::new();
    for p in PROBES {
        for s in [Setting::DEFAULT, Setting::STRONG]
            .iter()
            .chain(p.extra.iter())
        {
            progress(p.name, *s);
            out.push(search(p, *s));
        }
    }
    out
}

/// One goal of the issue: what was measured, and whether it was met.
#[derive(Debug, Clone, serde::Serialize)]
pub struct GoalResult {
    pub goal: String,
    pub value: String,
    pub met: Option<bool>,
}

fn crit<'a>(c: &'a [CriticalValue], probe: &str, s: Setting) -> Option<&'a CriticalValue> {
    c.iter()
        .find(|v| v.probe.starts_with(probe) && v.setting == s)
}

fn show(v: Option<&CriticalValue>) -> String {
    match v {
        None => "not run".into(),
        Some(v) => match (v.value, &v.first_failure) {
            (_, None) => format!("≥ {} (whole grid)", v.value.unwrap_or(f64::NAN)),
            (Some(x), Some((f, o))) => format!("{x} (fails at {f}: {})", o.join(", ")),
            (None, Some((f, o))) => format!("none (fails at {f}: {})", o.join(", ")),
        },
    }
}

fn at_least(v: Option<&CriticalValue>, need: f64) -> bool {
    v.is_some_and(|v| v.value.is_some_and(|x| x >= need))
}

/// The goals, judged from the critical values, dedicated runs and the fuzz run.
pub fn goals(c: &[CriticalValue], fuzz: Option<&FuzzReport>) -> Vec<GoalResult> {
    let d = Setting::DEFAULT;
    let mut out = Vec::new();
    let ratio_probes = [
        "stack",
        "column",
        "chain of 20, heavy end, hanging",
        "chain of 20, heavy end, horizontal",
        "chain of 20, heavy end, coiled",
    ];
    let ratio: Vec<String> = ratio_probes
        .iter()
        .map(|p| format!("{p}: {}", show(crit(c, p, d))))
        .collect();
    out.push(GoalResult {
        goal: "mass ratio ≥ 1,000:1 holds at the defaults for stacks, columns and chains from any start pose".into(),
        value: ratio.join("; "),
        met: Some(ratio_probes.iter().all(|p| at_least(crit(c, p, d), 1000.0))),
    });
    let wall = crit(c, "ball 0.1 at an anchored wall 0.05", d);
    out.push(GoalResult {
        goal: "no projectile up to MaxLinearSpeed (10,000 u/s) passes an anchored wall ≥ 0.05 thick, at the defaults".into(),
        value: show(wall),
        met: Some(at_least(wall, 10_000.0)),
    });
    let body = "ball 0.1 at a free";
    out.push(GoalResult {
        goal: "no projectile up to MaxLinearSpeed passes a body when both have HitBoxQuality > 1 (2 and 32 tried)".into(),
        value: format!(
            "q2: {}; q32: {}",
            show(crit(c, body, Q2)),
            show(crit(c, body, Q32))
        ),
        met: Some(at_least(crit(c, body, Q2), 10_000.0) && at_least(crit(c, body, Q32), 10_000.0)),
    });
    out.push(GoalResult {
        goal: "at the default quality no projectile up to 1,000 u/s passes a body".into(),
        value: show(crit(c, body, d)),
        met: Some(at_least(crit(c, body, d), 1000.0)),
    });
    // The docs' spring: m 2, k 50, released 0.5 from rest, 60 Hz, both kinds.
    let mut kept = Vec::new();
    let mut met = true;
    for kind in [SpringKind::AxisSpring, SpringKind::Spring] {
        let case = Spring {
            setting: d,
            kind,
            stiffness: 50.0,
            mass: 2.0,
            amplitude: 0.5,
        };
        match case.measure() {
            Ok((_, k, _)) => {
                met &= k >= 0.99;
                kept.push(format!("{kind:?} {:.2} %", 100.0 * k));
            }
            Err(e) => {
                met = false;
                kept.push(format!("{kind:?}: {e}"));
            }
        }
    }
    out.push(GoalResult {
        goal: "undamped springs (m 2, k 50) keep ≥ 99 % of their energy over 10 s at 60 Hz".into(),
        value: kept.join(", "),
        met: Some(met),
    });
    let mut failing = Vec::new();
    let mut n = 0;
    for shape in ALL_SHAPES {
        for q in [1, 2, 4, 8, 16, 32] {
            n += 1;
            let case = Case::Drop(Drop {
                setting: Setting { quality: q, ..d },
                shape,
                size: 2.0,
                aspect: 1.5,
                height: 3.0,
            });
            let v = judge(&case, false);
            if !v.is_empty() {
                failing.push(format!("{shape:?} q{q}"));
            }
        }
    }
    out.push(GoalResult {
        goal: "symmetric drops stay upright and in place for every shape at every quality (1–32, dropped 3 onto a floor, defaults otherwise)".into(),
        value: if failing.is_empty() {
            format!("{n} of {n} hold")
        } else {
            format!(
                "{} of {n} hold; failing: {}",
                n - failing.len(),
                failing.join(", ")
            )
        },
        met: Some(failing.is_empty()),
    });
    if let Some(f) = fuzz {
        out.push(GoalResult {
            goal: "zero non-finite values across a 30-minute run".into(),
            value: format!(
                "{} of {} cases non-finite in {:.1} min (seed {})",
                f.non_finite_cases,
                f.cases,
                f.wall_s / 60.0,
                f.seed
            ),
            // A shorter clean run is not judged; any non-finite case fails the goal.
            met: if f.non_finite_cases > 0 {
                Some(false)
            } else if f.wall_s >= 1800.0 {
                Some(true)
            } else {
                None
            },
        });
    }
    out
}

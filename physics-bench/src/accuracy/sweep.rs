//! Which configurations run: families that vary one knob with the others at their defaults,
//! and (outside `--quick`) the full cross product.

use crate::sim::Config;

pub const TICK_RATES: [u32; 5] = [30, 60, 120, 240, 480];
/// 64 is LoopSolver (which pins 64 iterations).
pub const ITERATIONS: [u32; 6] = [1, 2, 4, 8, 16, 64];
pub const QUALITIES: [u32; 3] = [1, 4, 32];

/// A family: one knob swept, the others at the defaults.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Family {
    TickRate,
    SolverIterations,
    HitBoxQuality,
}

impl Family {
    pub const ALL: [Family; 3] = [
        Family::TickRate,
        Family::SolverIterations,
        Family::HitBoxQuality,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Family::TickRate => "TickRate",
            Family::SolverIterations => "SolverIterations",
            Family::HitBoxQuality => "HitBoxQuality",
        }
    }

    /// The family's configurations in the order of its knob.
    pub fn configs(self) -> Vec<Config> {
        let d = Config::DEFAULT;
        match self {
            Family::TickRate => TICK_RATES
                .iter()
                .map(|&tick_rate| Config { tick_rate, ..d })
                .collect(),
            Family::SolverIterations => ITERATIONS.iter().map(|&n| iterations(d, n)).collect(),
            Family::HitBoxQuality => QUALITIES
                .iter()
                .map(|&hit_box_quality| Config {
                    hit_box_quality,
                    ..d
                })
                .collect(),
        }
    }
}

fn iterations(base: Config, n: u32) -> Config {
    Config {
        solver_iterations: n,
        loop_solver: n == 64,
        ..base
    }
}

/// Every configuration to run, each once: the families, plus the cross product when `full`.
pub fn configs(full: bool) -> Vec<Config> {
    let mut all: Vec<Config> = Family::ALL.iter().flat_map(|f| f.configs()).collect();
    if full {
        for &tick_rate in &TICK_RATES {
            for &n in &ITERATIONS {
                for &hit_box_quality in &QUALITIES {
                    all.push(iterations(
                        Config {
                            tick_rate,
                            hit_box_quality,
                            ..Config::DEFAULT
                        },
                        n,
                    ));
                }
            }
        }
    }
    let mut seen = std::collections::HashSet::new();
    all.retain(|c| seen.insert(*c));
    all
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn families_share_only_the_default() {
        let quick = configs(false);
        // 5 + 6 + 3 points, the default counted once.
        assert_eq!(quick.len(), 12);
        assert_eq!(quick.iter().filter(|c| **c == Config::DEFAULT).count(), 1);
        for f in Family::ALL {
            assert!(f.configs().contains(&Config::DEFAULT), "{}", f.name());
        }
        assert_eq!(configs(true).len(), 5 * 6 * 3);
        let lp = configs(false).into_iter().filter(|c| c.loop_solver).count();
        assert_eq!(lp, 1);
    }
}

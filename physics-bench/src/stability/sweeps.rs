//! Sweeps for critical values: the tallest stack, the largest mass ratio, the highest speed
//! that still pass, at the defaults and at the strongest configuration.

use super::check::Check;
use super::scenes::{fast_box, heavy_on_light, stack};
use crate::error::BenchResult;
use crate::sim::Config;

pub struct Sweep {
    pub name: &'static str,
    pub what: &'static str,
    pub values: &'static [f64],
    /// The value the criterion asks for, and at which configuration it is judged.
    pub required: f64,
    pub judged_at_default: bool,
    pub run: fn(Config, f64) -> BenchResult<Check>,
}

pub const SWEEPS: &[Sweep] = &[
    Sweep {
        name: "tallest-stack",
        what: "boxes in a stack that stands 10 s (top drift ≤ 0.05)",
        values: &[5.0, 10.0, 15.0, 20.0, 30.0, 40.0, 60.0],
        required: 15.0,
        judged_at_default: true,
        run: |c, n| stack(c, n as usize, 10.0),
    },
    Sweep {
        name: "largest-mass-ratio-stack",
        what: "heavy:light mass ratio, heavy box on one light box (sinks ≤ 0.05)",
        values: &[1.0, 10.0, 100.0, 1e3, 1e4, 1e5],
        required: 1e3,
        judged_at_default: true,
        run: |c, r| heavy_on_light(c, r, 1),
    },
    Sweep {
        name: "largest-mass-ratio-column",
        what: "heavy:light mass ratio, heavy box on a column of 4 light boxes (sinks ≤ 0.05)",
        values: &[1.0, 10.0, 100.0, 1e3, 1e4, 1e5],
        required: 1e3,
        judged_at_default: true,
        run: |c, r| heavy_on_light(c, r, 4),
    },
    Sweep {
        name: "highest-speed",
        what: "launch speed (units/s) of a 0.5 box that does not tunnel through a 0.1 wall",
        values: &[25.0, 50.0, 100.0, 200.0, 400.0, 800.0, 1600.0],
        required: 400.0,
        judged_at_default: false,
        run: fast_box,
    },
];

/// One value of a sweep at one configuration.
#[derive(Debug, Clone, serde::Serialize)]
pub struct SweepPoint {
    #[serde(flatten)]
    pub config: Config,
    pub value: f64,
    #[serde(flatten)]
    pub check: Check,
}

/// The largest value such that it and every smaller value pass (None if the first fails).
pub fn critical(points: &[SweepPoint]) -> Option<f64> {
    let mut best = None;
    for p in points {
        if !p.check.pass {
            break;
        }
        best = Some(p.value);
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    fn point(value: f64, pass: bool) -> SweepPoint {
        SweepPoint {
            config: Config::DEFAULT,
            value,
            check: Check {
                figure: 0.0,
                bound: 0.0,
                pass,
                finite: true,
                cost: 0.0,
            },
        }
    }

    #[test]
    fn critical_value_stops_at_the_first_failure() {
        let v = [
            point(1.0, true),
            point(2.0, true),
            point(3.0, false),
            point(4.0, true),
        ];
        assert_eq!(critical(&v), Some(2.0));
        assert_eq!(critical(&v[2..]), None);
        assert_eq!(critical(&[]), None);
    }
}

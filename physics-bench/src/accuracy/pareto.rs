//! Pareto-optimal points: no other point of the scene is at least as accurate and as cheap
//! and strictly better in one of the two.

use super::point::Point;

pub fn mark(points: &mut [Point]) {
    let flags: Vec<bool> = points
        .iter()
        .map(|p| {
            !p.error.is_nan()
                && !points.iter().any(|q| {
                    !q.error.is_nan()
                        && q.error <= p.error
                        && q.cost <= p.cost
                        && (q.error < p.error || q.cost < p.cost)
                })
        })
        .collect();
    for (p, f) in points.iter_mut().zip(flags) {
        p.pareto = f;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::Config;

    fn point(error: f64, cost: f64) -> Point {
        Point {
            scene: "s",
            config: Config::DEFAULT,
            dt: 1.0 / 60.0,
            error,
            error_unit: "units",
            cost,
            pareto: false,
            is_default: false,
        }
    }

    #[test]
    fn dominated_and_broken_points_are_not_optimal() {
        let mut v = vec![
            point(1.0, 1.0),
            point(0.5, 2.0),
            point(1.0, 3.0), // dominated by the first
            point(f64::NAN, 0.1),
            point(0.5, 2.0), // ties the second: neither dominates
        ];
        mark(&mut v);
        let flags: Vec<bool> = v.iter().map(|p| p.pareto).collect();
        assert_eq!(flags, [true, true, false, false, true]);
    }
}

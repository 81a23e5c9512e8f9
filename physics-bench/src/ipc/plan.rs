//! How much `ipc` measures: sizes, repeats and durations, full or `--quick`.

use std::time::Duration;

/// The size at which the goals are judged (and the only size of `--quick`).
pub const GOAL_BODIES: usize = 10_000;

/// How much to measure.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Plan {
    pub sizes: Vec<usize>,
    /// Timed blocks per scene and side of the overhead figure (ABBA; judged on the minimum
    /// of each side's blocks, so enough of them that some fall in quiet stretches).
    pub repeats: usize,
    pub delivery_ticks: usize,
    #[serde(skip)]
    pub delivery_time_cap: Duration,
    pub round_trips: usize,
    pub batch_size: usize,
    pub batches: usize,
    pub idle_window_s: u64,
    /// Round trips per side of the head-of-line figure.
    pub head_of_line_round_trips: usize,
    /// Seconds per side of the multi-plane figure.
    pub multi_plane_s: f64,
    /// Seconds of ticking per side of the many-planes figure.
    pub many_planes_s: f64,
}

impl Plan {
    pub fn new(quick: bool) -> Plan {
        if quick {
            Plan {
                sizes: vec![GOAL_BODIES],
                repeats: 8,
                delivery_ticks: 30,
                delivery_time_cap: Duration::from_secs(4),
                round_trips: 1_000,
                batch_size: 1_000,
                batches: 10,
                idle_window_s: 10,
                head_of_line_round_trips: 1_000,
                multi_plane_s: 3.0,
                many_planes_s: 5.0,
            }
        } else {
            Plan {
                sizes: vec![100, 1_000, GOAL_BODIES, 50_000],
                repeats: 12,
                delivery_ticks: 60,
                delivery_time_cap: Duration::from_secs(8),
                round_trips: 5_000,
                batch_size: 1_000,
                batches: 30,
                idle_window_s: 60,
                head_of_line_round_trips: 3_000,
                multi_plane_s: 6.0,
                many_planes_s: 10.0,
            }
        }
    }
}

//! What `fuzz` reports (fuzz.json), which the markdown renders.

use std::collections::BTreeMap;

use physics_fuzz::FuzzStats;

use crate::report::Goal;

/// One failure, its frame written next to the report.
#[derive(Debug, Clone, serde::Serialize)]
pub struct FindingOut {
    pub kind: &'static str,
    pub batch: u64,
    pub client: usize,
    pub detail: String,
    /// File (in the output folder) holding the request frame.
    pub frame_file: Option<String>,
}

/// The report of one run: the engine's counters (flattened into the JSON, read through
/// `Deref`) and what the bench adds around them.
#[derive(Debug, Clone, serde::Serialize)]
pub struct FuzzReport {
    #[serde(flatten)]
    pub stats: FuzzStats,
    pub daemon_flags: Vec<String>,
    pub frames_per_s: f64,
    pub commands_per_s: f64,
    /// Share of fuzzed commands (not quota rounds) that succeeded.
    pub ok_fraction: f64,
    pub ops_not_sent: Vec<String>,
    /// Panics in the daemon's log, by location and message (automatic ticks included).
    pub daemon_panics: BTreeMap<String, u64>,
    pub findings: Vec<FindingOut>,
    /// A normal client created a plane, dropped a ball and saw it fall after the run.
    pub served_after: Option<bool>,
    pub daemon_rss_start_bytes: u64,
    pub daemon_rss_end_bytes: Option<u64>,
    pub goals: Vec<Goal>,
    pub method: BTreeMap<&'static str, &'static str>,
}

impl std::ops::Deref for FuzzReport {
    type Target = FuzzStats;
    fn deref(&self) -> &FuzzStats {
        &self.stats
    }
}

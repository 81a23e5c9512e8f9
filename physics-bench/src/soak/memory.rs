//! The soak's memory readings: one [`Sample`] of the daemon (RSS and its anonymous, file
//! and shared parts, threads, open files) and of the domain's shared memory, and the
//! figures the goals judge: the rise over the window's first sample and the least-squares
//! slope.

use crate::error::{BenchError, BenchResult};
use crate::procfs;

/// The daemon and its domain at one moment.
#[derive(Debug, Clone, Copy, Default, serde::Serialize)]
pub struct Sample {
    /// Seconds since the load started (setup excluded).
    pub t_s: f64,
    /// VmRSS: every resident page (anonymous, file-backed, shared memory touched).
    pub rss_bytes: u64,
    /// RssAnon: the heap, stacks and other private memory.
    pub rss_anon_bytes: u64,
    /// RssFile: mapped files (the executable, libraries).
    pub rss_file_bytes: u64,
    /// RssShmem: shared-memory pages the daemon touched.
    pub rss_shmem_bytes: u64,
    /// Threads of the daemon.
    pub threads: u64,
    /// Open file descriptors of the daemon.
    pub fds: u64,
    /// Mapped size of the domain's /dev/shm files.
    pub shm_bytes: u64,
    /// Bytes of them backed by pages.
    pub shm_backed_bytes: u64,
}

impl Sample {
    /// Reads the daemon `pid` and the shared memory of `domain`, stamped `t_s`.
    pub fn read(pid: u32, domain: &str, t_s: f64) -> BenchResult<Sample> {
        let path = format!("/proc/{pid}/status");
        let status =
            std::fs::read_to_string(&path).map_err(BenchError::io(format!("read {path}")))?;
        let field = |name: &str| -> BenchResult<u64> {
            status
                .lines()
                .find_map(|l| l.strip_prefix(name))
                .and_then(|v| v.trim().trim_end_matches("kB").trim().parse::<u64>().ok())
                .ok_or_else(|| BenchError::Failed(format!("{path}: no readable {name} line")))
        };
        let fds = std::fs::read_dir(format!("/proc/{pid}/fd"))
            .map(|d| d.count() as u64)
            .unwrap_or(0);
        let (shm, backed) = procfs::shm_bytes(domain)?;
        Ok(Sample {
            t_s,
            rss_bytes: field("VmRSS:")? * 1024,
            rss_anon_bytes: field("RssAnon:")? * 1024,
            rss_file_bytes: field("RssFile:")? * 1024,
            rss_shmem_bytes: field("RssShmem:")? * 1024,
            threads: field("Threads:")?,
            fds,
            shm_bytes: shm,
            shm_backed_bytes: backed,
        })
    }
}

/// How one quantity moved over the window.
#[derive(Debug, Clone, Copy, Default, serde::Serialize)]
pub struct Drift {
    /// At the window's first sample (the warm-up's end).
    pub start: f64,
    /// Largest and last value in the window.
    pub max: f64,
    pub end: f64,
    /// max - start: what the flatness goal judges.
    pub rise: f64,
    /// The least value of the window's last minute (what a count settles back to).
    pub settled: f64,
    /// Least-squares slope over the window, per minute.
    pub slope_per_min: f64,
    /// The slope carried over 60 minutes.
    pub projected_per_hour: f64,
}

impl Drift {
    /// The drift of `value` over `window` (samples in time order).
    pub fn of(window: &[Sample], value: impl Fn(&Sample) -> u64) -> Drift {
        let Some(first) = window.first() else {
            return Drift::default();
        };
        let start = value(first) as f64;
        let max = window.iter().map(|s| value(s) as f64).fold(start, f64::max);
        let end = window.last().map_or(start, |s| value(s) as f64);
        let last_t = window.last().map_or(0.0, |s| s.t_s);
        let settled = window
            .iter()
            .filter(|s| s.t_s >= last_t - 60.0)
            .map(|s| value(s) as f64)
            .fold(end, f64::min);
        let points: Vec<(f64, f64)> = window.iter().map(|s| (s.t_s, value(s) as f64)).collect();
        let slope_per_min = slope(&points) * 60.0;
        Drift {
            start,
            max,
            end,
            rise: max - start,
            settled,
            slope_per_min,
            projected_per_hour: slope_per_min * 60.0,
        }
    }
}

/// Least-squares slope of y over x (0 with fewer than two distinct x).
pub fn slope(points: &[(f64, f64)]) -> f64 {
    let n = points.len() as f64;
    if n < 2.0 {
        return 0.0;
    }
    let mx = points.iter().map(|p| p.0).sum::<f64>() / n;
    let my = points.iter().map(|p| p.1).sum::<f64>() / n;
    let (mut num, mut den) = (0.0, 0.0);
    for (x, y) in points {
        num += (x - mx) * (y - my);
        den += (x - mx).powi(2);
    }
    if den > 0.0 {
        num / den
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(t_s: f64, rss: u64) -> Sample {
        Sample {
            t_s,
            rss_bytes: rss,
            ..Sample::default()
        }
    }

    #[test]
    fn slope_of_a_line_is_exact_and_of_a_flat_series_is_zero() {
        // y = 3x + 7: slope 3 whatever the intercept.
        let line: Vec<(f64, f64)> = (0..10).map(|i| (i as f64, 3.0 * i as f64 + 7.0)).collect();
        assert!((slope(&line) - 3.0).abs() < 1e-12);
        let flat: Vec<(f64, f64)> = (0..10).map(|i| (i as f64, 5.0)).collect();
        assert_eq!(slope(&flat), 0.0);
        assert_eq!(slope(&[(1.0, 2.0)]), 0.0);
    }

    #[test]
    fn drift_reports_the_rise_over_the_first_sample_and_the_hourly_projection() {
        // 1 KiB per second for 60 s, one dip: rise = max - first, slope 60 KiB/min.
        let mut window: Vec<Sample> = (0..=60).map(|i| at(i as f64, 1024 * i)).collect();
        window[30].rss_bytes = 0;
        let d = Drift::of(&window, |s| s.rss_bytes);
        assert_eq!(d.start, 0.0);
        assert_eq!(d.max, 60.0 * 1024.0);
        assert_eq!(d.rise, 60.0 * 1024.0);
        // The least value of the last minute (the whole window here): the dip.
        assert_eq!(d.settled, 0.0);
        // The dip at the midpoint has no leverage on the fitted slope (x - mean = 0).
        assert!((d.slope_per_min - 60.0 * 1024.0).abs() < 1e-6, "{d:?}");
        assert!((d.projected_per_hour - 3600.0 * 1024.0).abs() < 1e-3);
    }
}

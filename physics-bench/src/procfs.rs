//! What a process costs, read from /proc and /dev/shm.

use std::time::Duration;

use super::error::{BenchError, BenchResult};

/// User + system CPU time of `pid` (all threads), from /proc/PID/stat.
pub fn cpu_time(pid: u32) -> BenchResult<Duration> {
    let path = format!("/proc/{pid}/stat");
    let stat = std::fs::read_to_string(&path).map_err(BenchError::io(format!("read {path}")))?;
    // The command name may contain spaces: fields are counted after its closing parenthesis.
    let after_name = stat.rsplit_once(')').map_or("", |(_, rest)| rest);
    let fields: Vec<&str> = after_name.split_whitespace().collect();
    let field = |i: usize, name: &str| -> BenchResult<u64> {
        fields
            .get(i)
            .and_then(|v| v.parse().ok())
            .ok_or_else(|| BenchError::Failed(format!("{path}: field {name} unreadable: {stat:?}")))
    };
    // utime and stime are fields 14 and 15 of the line, 12 and 13 after the name.
    let ticks = field(11, "utime")? + field(12, "stime")?;
    Ok(Duration::from_secs_f64(
        ticks as f64 / clock_ticks_per_second(),
    ))
}

fn clock_ticks_per_second() -> f64 {
    // SAFETY: sysconf only reads a system constant.
    let hz = unsafe { libc::sysconf(libc::_SC_CLK_TCK) };
    if hz > 0 {
        hz as f64
    } else {
        100.0
    }
}

/// CPU use of `pid` over `window`, in percent of one core. Counted in nanoseconds from
/// every thread's scheduler statistics (`/proc/PID/task/*/schedstat`): `stat`'s clock
/// ticks (10 ms) would make 0.1 % of a 10 s window a single tick. A thread that ends within
/// the window takes its time with it, so this is for windows in which threads stay (an
/// idle daemon).
pub fn cpu_percent_over(pid: u32, window: Duration) -> BenchResult<f64> {
    let before = thread_cpu_ns(pid)?;
    std::thread::sleep(window);
    let after = thread_cpu_ns(pid)?;
    let used: u64 = after
        .iter()
        .map(|(tid, ns)| ns.saturating_sub(before.get(tid).copied().unwrap_or(0)))
        .sum();
    Ok(used as f64 / 1e9 / window.as_secs_f64() * 100.0)
}

/// Nanoseconds on a CPU so far of each thread of `pid`, by thread id.
fn thread_cpu_ns(pid: u32) -> BenchResult<std::collections::HashMap<u32, u64>> {
    let dir = format!("/proc/{pid}/task");
    let entries = std::fs::read_dir(&dir).map_err(BenchError::io(format!("list {dir}")))?;
    let mut out = std::collections::HashMap::new();
    for entry in entries.flatten() {
        let Some(tid) = entry.file_name().to_str().and_then(|t| t.parse().ok()) else {
            continue;
        };
        // A thread may end between the listing and the read: it is simply not counted.
        let Ok(stat) = std::fs::read_to_string(entry.path().join("schedstat")) else {
            continue;
        };
        if let Some(ns) = stat.split_whitespace().next().and_then(|v| v.parse().ok()) {
            out.insert(tid, ns);
        }
    }
    Ok(out)
}

/// Resident set size of `pid` in bytes (VmRSS, which includes the shared memory it touched).
pub fn rss_bytes(pid: u32) -> BenchResult<u64> {
    let path = format!("/proc/{pid}/status");
    let status = std::fs::read_to_string(&path).map_err(BenchError::io(format!("read {path}")))?;
    status
        .lines()
        .find_map(|l| l.strip_prefix("VmRSS:"))
        .and_then(|v| v.trim().trim_end_matches("kB").trim().parse::<u64>().ok())
        .map(|kb| kb * 1024)
        .ok_or_else(|| BenchError::Failed(format!("{path}: no readable VmRSS line")))
}

/// Shared memory of one domain: (mapped size, bytes actually backed by pages).
pub fn shm_bytes(domain: &str) -> BenchResult<(u64, u64)> {
    use std::os::unix::fs::MetadataExt;
    let prefix = shm_layout::names::prefix(domain);
    let entries = std::fs::read_dir("/dev/shm").map_err(BenchError::io("list /dev/shm"))?;
    let (mut size, mut backed) = (0, 0);
    for entry in entries.flatten() {
        if !entry.file_name().to_string_lossy().starts_with(&prefix) {
            continue;
        }
        if let Ok(meta) = entry.metadata() {
            size += meta.size();
            backed += meta.blocks() * 512;
        }
    }
    Ok((size, backed))
}

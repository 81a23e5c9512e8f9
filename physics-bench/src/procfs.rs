//! What a process costs, read from /proc and /dev/shm.

use std::time::Duration;

use super::error::{BenchError, BenchResult};

/// CPU use of `pid` over `window`, in percent of one core. Counted in nanoseconds from
/// every thread's scheduler statistics (`/proc/PID/task/*/schedstat`): `stat`'s clock
/// ticks (10 ms) would make 0.1 % of a 10 s window a single tick. A thread that ends within
/// the window takes its time with it, so this is for windows in which threads stay (an
/// idle daemon).
pub fn cpu_percent_over(pid: u32, window: Duration) -> BenchResult<f64> {
    let before = ThreadsCpu::of(pid)?;
    std::thread::sleep(window);
    let used = ThreadsCpu::of(pid)?.used_since(&before);
    Ok(used as f64 / 1e9 / window.as_secs_f64() * 100.0)
}

/// CPU time of this process so far, all its threads (those that ended included), in
/// nanoseconds: `CLOCK_PROCESS_CPUTIME_ID`.
pub fn own_cpu_ns() -> u64 {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: clock_gettime writes one timespec, which lives for the call.
    let rc = unsafe { libc::clock_gettime(libc::CLOCK_PROCESS_CPUTIME_ID, &mut ts) };
    if rc != 0 {
        return 0;
    }
    (ts.tv_sec.max(0) as u64) * 1_000_000_000 + ts.tv_nsec.max(0) as u64
}

/// Nanoseconds on a CPU so far of every thread of a process, by thread id (scheduler
/// statistics: exact to the nanosecond, unlike `stat`'s 10 ms clock ticks).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ThreadsCpu(std::collections::HashMap<u32, u64>);

impl ThreadsCpu {
    /// The threads of `pid` now.
    pub fn of(pid: u32) -> BenchResult<ThreadsCpu> {
        thread_cpu_ns(pid).map(ThreadsCpu)
    }

    /// Nanoseconds used since `before`: every thread's growth, a thread started since then
    /// counted from zero. A thread that ended in between takes its time with it (the
    /// daemons' threads live as long as their planes, so windows over a steady plane lose
    /// nothing).
    pub fn used_since(&self, before: &ThreadsCpu) -> u64 {
        self.0
            .iter()
            .map(|(tid, ns)| ns.saturating_sub(before.0.get(tid).copied().unwrap_or(0)))
            .sum()
    }
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

/// Spins until the calling thread has used `ns` more of CPU (its own thread clock).
#[cfg(test)]
pub(crate) fn burn(ns: u64) {
    let thread_ns = || {
        let mut ts = libc::timespec {
            tv_sec: 0,
            tv_nsec: 0,
        };
        // SAFETY: clock_gettime writes one timespec, which lives for the call.
        unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut ts) };
        ts.tv_sec as u64 * 1_000_000_000 + ts.tv_nsec as u64
    };
    let start = thread_ns();
    let mut x = 0u64;
    while thread_ns() - start < ns {
        x = std::hint::black_box(x.wrapping_mul(31).wrapping_add(7));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn own_cpu_time_grows_by_the_work_done() {
        let before = own_cpu_ns();
        assert!(before > 0, "the process clock is readable");
        burn(20_000_000);
        let used = own_cpu_ns() - before;
        // At least the 20 ms this thread burnt (the process clock counts every thread); other
        // test threads running beside stay far below 10 s.
        assert!((20_000_000..10_000_000_000).contains(&used), "{used} ns");
    }

    #[test]
    fn threads_cpu_of_this_process_sees_the_work_done() {
        let pid = std::process::id();
        let before = ThreadsCpu::of(pid).unwrap();
        burn(30_000_000);
        let after = ThreadsCpu::of(pid).unwrap();
        let used = after.used_since(&before);
        // This thread, alive at both readings, burnt 30 ms; other test threads may add some.
        assert!((30_000_000..10_000_000_000).contains(&used), "{used} ns");
        assert_eq!(before.used_since(&before), 0);
        // A thread unknown before counts from zero, one gone is not counted.
        let mut later = before.clone();
        later.0.insert(u32::MAX, 5);
        assert_eq!(later.used_since(&before), 5);
        assert_eq!(before.used_since(&later), 0);
    }
}

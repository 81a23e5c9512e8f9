//! Giving freed heap memory back to the system. Under a steady load the daemon's live heap
//! is flat (planes, objects, joints and clients come and go, and what they held is freed),
//! yet glibc's malloc keeps the pages of freed chunks inside its per-thread arenas: each
//! plane worker allocates in an arena of its own, and a chunk freed in the middle of an
//! arena's heap is not returned to the system until the heap's top is free. Over an hour
//! of churn that shows as a resident size that creeps up (fragmentation, not a leak:
//! heaptrack sees no growth of what is allocated). `malloc_trim(0)` walks every arena and
//! releases the whole free pages inside free chunks.
//!
//! A trim takes 1 to 8 ms on a daemon of ~100 MB (measured under the soak's load), so it
//! runs on a thread of its own, never on the request loop: the loop asks for one every
//! [`PERIOD`] while clients are connected, and at once when it finds that a plane's worker
//! has ended (a plane frees megabytes: its world and its ports' bookkeeping). An idle
//! daemon asks for nothing more, and the thread sleeps. Elsewhere (other allocators, other
//! C libraries) a trim does nothing.

use std::sync::{Condvar, Mutex};
use std::time::{Duration, Instant};

/// Time between two trims while clients are connected.
pub const PERIOD: Duration = Duration::from_secs(10);

/// When the loop next asks for a periodic trim.
#[derive(Debug)]
pub struct Schedule {
    next: Instant,
}

impl Default for Schedule {
    fn default() -> Self {
        Schedule {
            next: Instant::now() + PERIOD,
        }
    }
}

impl Schedule {
    /// Whether a trim is due: [`PERIOD`] has passed since the last one, or `now` is true
    /// (a plane is gone); either way the next periodic one is a period away.
    pub fn due(&mut self, now: bool) -> bool {
        let at = Instant::now();
        if !now && at < self.next {
            return false;
        }
        self.next = at + PERIOD;
        true
    }
}

/// Requests from the loop to the trimming thread.
#[derive(Debug, Default)]
pub struct Trims {
    /// (a trim is asked for, stop)
    state: Mutex<(bool, bool)>,
    changed: Condvar,
}

impl Trims {
    /// Asks for a trim (it runs soon on the trimming thread; the caller does not wait).
    pub fn request(&self) {
        if let Ok(mut state) = self.state.lock() {
            state.0 = true;
            self.changed.notify_all();
        }
    }

    /// Ends the trimming thread.
    pub fn stop(&self) {
        if let Ok(mut state) = self.state.lock() {
            state.1 = true;
            self.changed.notify_all();
        }
    }

    /// Waits for a request; false once stopped.
    fn wait(&self) -> bool {
        let Ok(mut state) = self.state.lock() else {
            return false;
        };
        while !state.0 && !state.1 {
            state = match self.changed.wait(state) {
                Ok(s) => s,
                Err(_) => return false,
            };
        }
        state.0 = false;
        !state.1
    }
}

/// The trimming thread: one trim per request until stopped.
pub fn run(trims: &Trims) {
    while trims.wait() {
        let started = Instant::now();
        let released = trim();
        tracing::debug!(
            released,
            took_us = started.elapsed().as_secs_f64() * 1e6,
            "heap trimmed"
        );
    }
}

/// Malloc arenas the daemon uses (`M_ARENA_MAX`), unless `GLIBC_TUNABLES` names
/// `glibc.malloc.arena_max`. glibc's default, 8 a core, gives every plane worker an arena of
/// its own; freed memory then lingers in partly used pages of many arenas, which no trim
/// returns. Measured under the soak's load: 165 KiB a minute with the default, 38 (one
/// step, then flat) with one arena. Each thread's cache of small blocks (tcache) still
/// serves most allocations without the arena's lock.
pub const ARENAS: i32 = 1;

/// Caps the malloc arenas at [`ARENAS`] (call first thing in `main`, before any thread).
pub fn limit_arenas() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    {
        let tuned = std::env::var("GLIBC_TUNABLES").is_ok_and(|t| t.contains("arena_max"));
        if !tuned {
            // SAFETY: mallopt only changes a malloc setting; called before other threads.
            unsafe { libc::mallopt(libc::M_ARENA_MAX, ARENAS) };
        }
    }
}

/// Returns free heap pages of every malloc arena to the system; whether any were returned.
pub fn trim() -> bool {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    {
        // SAFETY: malloc_trim only rearranges the allocator's own free memory; it is
        // thread-safe (it takes each arena's lock in turn).
        unsafe { libc::malloc_trim(0) != 0 }
    }
    #[cfg(not(all(target_os = "linux", target_env = "gnu")))]
    {
        false
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Reads RssAnon of this process (KiB).
    fn rss_anon_kib() -> Option<u64> {
        std::fs::read_to_string("/proc/self/status")
            .ok()?
            .lines()
            .find_map(|l| l.strip_prefix("RssAnon:"))?
            .trim()
            .trim_end_matches("kB")
            .trim()
            .parse()
            .ok()
    }

    #[test]
    fn a_trim_is_due_once_a_period_or_at_once_when_asked() {
        let mut s = Schedule::default();
        assert!(!s.due(false), "not before a period has passed");
        s.next = Instant::now();
        assert!(s.due(false));
        assert!(!s.due(false), "the next one is a period away");
        assert!(s.due(true), "a plane gone: at once");
        assert!(!s.due(false), "and a new period starts");
    }

    #[test]
    fn the_thread_trims_on_request_and_stops() {
        let trims = Trims::default();
        std::thread::scope(|scope| {
            let t = scope.spawn(|| run(&trims));
            trims.request();
            trims.request();
            trims.stop();
            t.join().unwrap();
        });
        assert!(!trims.wait(), "stopped stays stopped");
    }

    /// Freed memory held in an arena's middle is given back by a trim: 64 MiB allocated in
    /// 4 KiB blocks on another thread (its own arena), three blocks of every four freed
    /// (each run coalesces into a free chunk of ~12 KiB, two or more whole pages), and the
    /// last block kept so the arena's top stays in use. Without the trim those 48 MiB of
    /// touched free memory stay resident.
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    #[test]
    fn a_trim_returns_the_free_pages_inside_an_arena() {
        const BLOCK: usize = 4096;
        const BLOCKS: usize = 16 * 1024;
        let kept = std::thread::spawn(|| {
            let mut blocks: Vec<Vec<u8>> = (0..BLOCKS).map(|i| vec![i as u8; BLOCK]).collect();
            let mut kept = Vec::with_capacity(BLOCKS / 4 + 1);
            for (i, b) in blocks.drain(..).enumerate() {
                if i % 4 == 3 || i + 1 == BLOCKS {
                    kept.push(b);
                }
            }
            kept
        })
        .join()
        .unwrap();
        let Some(before) = rss_anon_kib() else {
            return; // no /proc: nothing to measure
        };
        trim();
        let after = rss_anon_kib().unwrap();
        // Of each ~12 KiB free run at least two pages are whole: 32 MiB of the 48 MiB
        // freed. Expect at least 16 MiB back, a margin for what the test harness
        // allocates meanwhile.
        assert!(
            before.saturating_sub(after) >= 16 * 1024,
            "RssAnon {before} KiB before the trim, {after} KiB after"
        );
        drop(kept);
    }
}

//! Giving freed heap memory back to the system. Under a steady load the daemon's live heap
//! is flat (planes, objects, joints and clients come and go, and what they held is freed),
//! yet glibc's malloc keeps the pages of freed chunks inside its per-thread arenas: each
//! plane worker allocates in an arena of its own, and a chunk freed in the middle of an
//! arena's heap is not returned to the system until the heap's top is free. Over an hour
//! of churn that shows as a resident size that creeps up (fragmentation, not a leak:
//! heaptrack sees no growth of what is allocated). `malloc_trim(0)` walks every arena and
//! releases the whole free pages inside free chunks; the loop calls it now and then, off
//! the hot path. Elsewhere (other allocators, other C libraries) it does nothing.

use std::time::{Duration, Instant};

/// Time between two trims.
pub const PERIOD: Duration = Duration::from_secs(10);

/// When the heap was last trimmed.
#[derive(Debug)]
pub struct Trimmer {
    next: Instant,
}

impl Default for Trimmer {
    fn default() -> Self {
        Trimmer {
            next: Instant::now() + PERIOD,
        }
    }
}

impl Trimmer {
    /// Trims the heap if [`PERIOD`] has passed since the last trim; returns whether it did.
    pub fn maybe_trim(&mut self) -> bool {
        let now = Instant::now();
        if now < self.next {
            return false;
        }
        self.next = now + PERIOD;
        let released = trim();
        tracing::debug!(
            released,
            took_us = now.elapsed().as_secs_f64() * 1e6,
            "heap trimmed"
        );
        true
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
    fn a_trim_is_due_once_a_period() {
        let mut t = Trimmer::default();
        assert!(!t.maybe_trim(), "not before a period has passed");
        t.next = Instant::now();
        assert!(t.maybe_trim());
        assert!(!t.maybe_trim(), "the next one is a period away");
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

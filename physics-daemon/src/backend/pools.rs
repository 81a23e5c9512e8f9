//! The thread pools of planes that ask for `Threads` > 1, shared by size and capped by the
//! machine's cores. A pool per plane let 64 planes × `Threads = 64` start 4,164 daemon
//! threads on a 2-core machine; now a plane uses at most as many threads as the machine has
//! cores, and planes asking for the same number share one pool (rapier's results are
//! bitwise identical for any pool size, so sharing changes no number). The plane reads back
//! the `Threads` it uses.
//!
//! Each worker of a pool is pinned to a core of its own (among the cores the daemon may run
//! on, pools taking turns, each daemon process starting at a core of its own), as game
//! engines pin their job threads. Unpinned, a worker woken for a parallel phase is placed
//! by Linux on the core of the thread that woke it (which then goes on working), and waits
//! there for a millisecond or more until the scheduler moves it: measured with 1,000
//! controllers on a 2-core machine, the second worker of a Threads = 2 plane started its
//! first task 0.85–1.2 ms into a 1.5 ms phase or not at all, against 15–80 µs pinned. A pool
//! with more threads than those cores is not pinned.

use std::collections::HashMap;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex, OnceLock, Weak};

/// The cores the daemon may use (`available_parallelism`, at least 1).
pub fn cores() -> u32 {
    static CORES: OnceLock<u32> = OnceLock::new();
    *CORES.get_or_init(|| {
        std::thread::available_parallelism().map_or(1, |n| n.get().min(u32::MAX as usize) as u32)
    })
}

/// The `Threads` a plane asking for `n` gets: `n` capped by [`cores`] (at least 1).
pub fn capped(n: u32) -> u32 {
    n.clamp(1, cores())
}

/// The shared pool of `n` threads (`n` as [`capped`] gives it), made on first use and
/// dropped with the last plane using it.
pub fn shared(n: u32) -> Result<Arc<rayon::ThreadPool>, rayon::ThreadPoolBuildError> {
    static POOLS: OnceLock<Mutex<HashMap<u32, Weak<rayon::ThreadPool>>>> = OnceLock::new();
    let mut pools = POOLS
        .get_or_init(Default::default)
        .lock()
        .unwrap_or_else(|p| p.into_inner());
    if let Some(pool) = pools.get(&n).and_then(Weak::upgrade) {
        return Ok(pool);
    }
    let allowed = allowed_cores();
    // Pools take turns over the cores: the next pool's first worker goes where this one's
    // last did not. Daemons of other domains on the machine start elsewhere (by process id),
    // so their pools do not all crowd the first cores.
    static NEXT: AtomicUsize = AtomicUsize::new(0);
    let first = NEXT.fetch_add(n as usize, Ordering::Relaxed) + std::process::id() as usize;
    let pin = (n > 1 && n as usize <= allowed.len()).then_some((allowed, first));
    let pool = Arc::new(
        rayon::ThreadPoolBuilder::new()
            .num_threads(n as usize)
            .thread_name(move |i| format!("planes-{n}-{i}"))
            .start_handler(move |i| {
                if let Some((allowed, first)) = &pin {
                    pin_to(allowed[(first + i) % allowed.len()]);
                }
            })
            .build()?,
    );
    pools.retain(|_, p| p.strong_count() > 0);
    pools.insert(n, Arc::downgrade(&pool));
    Ok(pool)
}

/// The lock the planes of a shared pool take turns with in rapier's step.
///
/// Rapier's step hands its broad phase's tree optimisation to another thread of the pool
/// (`rayon::spawn`) and later waits for it on a channel, outside rayon. Two planes stepping
/// in one pool at once could each hold a pool thread in that wait with their optimisations
/// queued behind them, and stall for good (every request to them unanswered): `n` planes
/// on a pool of `n` threads can. One step at a time leaves at most one thread of the pool
/// waiting, and the others free to run the optimisation. What the pool runs besides (the
/// plane's own passes, controllers) waits the rayon way, taking work while it waits, and
/// needs no turn. Keyed by the pool's size, as [`shared`] keys the pools.
pub fn turn(pool: &rayon::ThreadPool) -> &'static Mutex<()> {
    static TURNS: OnceLock<Mutex<HashMap<usize, &'static Mutex<()>>>> = OnceLock::new();
    let mut turns = TURNS
        .get_or_init(Default::default)
        .lock()
        .unwrap_or_else(|p| p.into_inner());
    // One small lock per pool size ever used (at most the machine's cores), kept for the
    // life of the process.
    turns
        .entry(pool.current_num_threads())
        .or_insert_with(|| Box::leak(Box::new(Mutex::new(()))))
}

/// The cores this thread may run on (its affinity mask), in order; empty when unknown.
fn allowed_cores() -> Vec<usize> {
    // SAFETY: a zeroed cpu_set_t is a valid empty set, and sched_getaffinity writes at most
    // the size it is given.
    unsafe {
        let mut set: libc::cpu_set_t = std::mem::zeroed();
        if libc::sched_getaffinity(0, std::mem::size_of::<libc::cpu_set_t>(), &mut set) != 0 {
            return Vec::new();
        }
        (0..libc::CPU_SETSIZE as usize)
            .filter(|&c| libc::CPU_ISSET(c, &set))
            .collect()
    }
}

/// Pins the calling thread to `core` (left as it is when that fails).
fn pin_to(core: usize) {
    // SAFETY: as in `allowed_cores`; CPU_SET is given a core below CPU_SETSIZE (one from
    // the affinity mask).
    unsafe {
        let mut set: libc::cpu_set_t = std::mem::zeroed();
        libc::CPU_SET(core, &mut set);
        if libc::sched_setaffinity(0, std::mem::size_of::<libc::cpu_set_t>(), &set) != 0 {
            tracing::debug!(core, "could not pin a pool worker");
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn threads_are_capped_by_cores_and_pools_are_shared() {
        assert_eq!(capped(0), 1);
        assert_eq!(capped(1), 1);
        assert_eq!(capped(10_000), cores());
        let n = capped(2);
        let a = shared(n).unwrap();
        let b = shared(n).unwrap();
        assert!(
            Arc::ptr_eq(&a, &b),
            "planes of the same Threads share one pool"
        );
        assert_eq!(a.current_num_threads(), n as usize);
    }

    #[test]
    fn the_workers_of_a_pool_run_on_cores_of_their_own() {
        let allowed = allowed_cores();
        assert!(!allowed.is_empty(), "the affinity mask is readable");
        let n = capped(2);
        if n < 2 {
            return; // one core: no pool to pin
        }
        let pool = shared(n).unwrap();
        let cores: Vec<Vec<usize>> = pool.broadcast(|_| allowed_cores());
        for c in &cores {
            assert_eq!(c.len(), 1, "each worker is pinned to one core: {cores:?}");
            assert!(allowed.contains(&c[0]));
        }
        let mut distinct: Vec<usize> = cores.iter().map(|c| c[0]).collect();
        distinct.sort_unstable();
        distinct.dedup();
        assert_eq!(distinct.len(), n as usize, "distinct cores: {cores:?}");
    }
}

//! The thread pools of planes that ask for `Threads` > 1, shared by size and capped by the
//! machine's cores. A pool per plane let 64 planes × `Threads = 64` start 4,164 daemon
//! threads on a 2-core machine; now a plane uses at most as many threads as the machine has
//! cores, and planes asking for the same number share one pool (rapier's results are
//! bitwise identical for any pool size, so sharing changes no number). The plane reads back
//! the `Threads` it uses.

use std::collections::HashMap;
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
    let pool = Arc::new(
        rayon::ThreadPoolBuilder::new()
            .num_threads(n as usize)
            .thread_name(move |i| format!("planes-{n}-{i}"))
            .build()?,
    );
    pools.retain(|_, p| p.strong_count() > 0);
    pools.insert(n, Arc::downgrade(&pool));
    Ok(pool)
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
}

//! What the server tells a cluster's load report (`cluster::load`): its planes' usage
//! records and the time spent stepping them. Kept on the server's side so the server never
//! imports the cluster (the cluster reads this).

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};

pub use crate::server::quotas::fair::stepped_nanos;
use crate::server::quotas::quota::PlaneUsage;

/// What the server loop tells the reporter: the usage records of its planes.
#[derive(Debug, Default)]
pub struct Gauge {
    planes: Mutex<Vec<Arc<PlaneUsage>>>,
    /// The (plane count, next plane id) the list was taken at.
    seen: AtomicU64,
}

impl Gauge {
    /// Called by the server loop after each round: refreshes the list through `planes` only
    /// when the set of planes changed (a new id was handed out or the count moved).
    pub fn track<F>(&self, count: usize, next_id: u32, planes: F)
    where
        F: FnOnce() -> Vec<Arc<PlaneUsage>>,
    {
        let key = ((count as u64) << 32) | u64::from(next_id);
        if self.seen.swap(key, Ordering::Relaxed) != key {
            *self.planes.lock().unwrap_or_else(|p| p.into_inner()) = planes();
        }
    }

    /// Planes and the objects in them.
    pub fn counts(&self) -> (u32, u64) {
        let planes = self.planes.lock().unwrap_or_else(|p| p.into_inner());
        (
            planes.len() as u32,
            planes.iter().map(|p| p.objects()).sum(),
        )
    }
}

//! Per-process quota counters, checked and reserved atomically. Every plane of a client
//! process adds what it holds to one [`OwnerUsage`] of that process; an op that adds objects
//! or mesh vertices first reserves its cost there with a compare-and-swap, and only then
//! runs. Planes step and apply runs on their own workers in parallel, so a check against a
//! snapshot of the other planes (taken when a run was handed out) let eight connections of
//! one process each add a full quota at once; a reservation cannot be overtaken.

use std::collections::HashMap;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;

use shm_layout::{CommandError, OpCost};

use super::limits::{exceeded, Limits};
use crate::backend::Usage;

/// What the planes of one client process hold, all together, plus what ops in flight have
/// reserved.
#[derive(Debug, Default)]
pub struct OwnerUsage {
    objects: AtomicU64,
    mesh_vertices: AtomicU64,
    state_bytes: AtomicU64,
}

/// A reservation: released when dropped (by then the plane's own count holds what the op
/// added).
pub struct Reserved<'a> {
    owner: &'a OwnerUsage,
    objects: u64,
    mesh_vertices: u64,
    state_bytes: u64,
}

impl Drop for Reserved<'_> {
    fn drop(&mut self) {
        self.owner
            .state_bytes
            .fetch_sub(self.state_bytes, Ordering::SeqCst);
        self.owner.objects.fetch_sub(self.objects, Ordering::SeqCst);
        self.owner
            .mesh_vertices
            .fetch_sub(self.mesh_vertices, Ordering::SeqCst);
    }
}

/// Adds `n` to `counter` unless the sum would pass `limit`; the error carries the sum.
fn take(counter: &AtomicU64, n: u64, limit: u64) -> Result<(), u64> {
    counter
        .fetch_update(Ordering::SeqCst, Ordering::SeqCst, |now| {
            now.checked_add(n).filter(|sum| *sum <= limit)
        })
        .map(|_| ())
        .map_err(|now| now.saturating_add(n))
}

impl OwnerUsage {
    /// What the process holds (and has reserved) now.
    #[cfg(test)]
    pub fn get(&self) -> Usage {
        Usage {
            objects: self.objects.load(Ordering::SeqCst),
            mesh_vertices: self.mesh_vertices.load(Ordering::SeqCst),
            state_bytes: self.state_bytes.load(Ordering::SeqCst),
        }
    }

    /// Reserves `cost` against `limits`, or the `Quota` error naming the quota, its flag and
    /// the total the op would have made.
    pub fn reserve(&self, limits: &Limits, cost: OpCost) -> Result<Reserved<'_>, CommandError> {
        let objects = cost.objects as u64;
        let vertices = cost.mesh_vertices;
        if vertices > limits.mesh_vertices_per_object {
            return Err(exceeded(
                "mesh vertices per object",
                limits.mesh_vertices_per_object,
                "max-mesh-vertices",
                vertices,
            ));
        }
        take(&self.objects, objects, limits.objects_per_client).map_err(|sum| {
            exceeded(
                "objects per client",
                limits.objects_per_client,
                "max-objects-per-client",
                sum,
            )
        })?;
        if let Err(sum) = take(
            &self.mesh_vertices,
            vertices,
            limits.mesh_vertices_per_client,
        ) {
            self.objects.fetch_sub(objects, Ordering::SeqCst);
            return Err(exceeded(
                "mesh vertices per client",
                limits.mesh_vertices_per_client,
                "max-mesh-vertices-per-client",
                sum,
            ));
        }
        let bytes = cost.state_bytes;
        if let Err(sum) = take(&self.state_bytes, bytes, limits.state_bytes_per_client) {
            self.objects.fetch_sub(objects, Ordering::SeqCst);
            self.mesh_vertices.fetch_sub(vertices, Ordering::SeqCst);
            return Err(exceeded(
                "state bytes per client (controller paths)",
                limits.state_bytes_per_client,
                "max-state-bytes-per-client",
                sum,
            ));
        }
        Ok(Reserved {
            owner: self,
            objects,
            mesh_vertices: vertices,
            state_bytes: bytes,
        })
    }

    /// Moves the count from `old` to `new` (one plane's usage changed).
    fn change(&self, old: Usage, new: Usage) {
        // Add first, then take away: the count never dips below what is held.
        self.objects.fetch_add(new.objects, Ordering::SeqCst);
        self.objects.fetch_sub(old.objects, Ordering::SeqCst);
        self.mesh_vertices
            .fetch_add(new.mesh_vertices, Ordering::SeqCst);
        self.mesh_vertices
            .fetch_sub(old.mesh_vertices, Ordering::SeqCst);
        self.state_bytes
            .fetch_add(new.state_bytes, Ordering::SeqCst);
        self.state_bytes
            .fetch_sub(old.state_bytes, Ordering::SeqCst);
    }
}

/// A plane's [`Usage`] as it last was, kept in its owner's [`OwnerUsage`] total.
#[derive(Debug)]
pub struct PlaneUsage {
    now: std::sync::Mutex<Usage>,
    owner: Arc<OwnerUsage>,
}

impl PlaneUsage {
    /// A plane that holds nothing yet, counted for `owner`.
    pub fn new(owner: Arc<OwnerUsage>) -> PlaneUsage {
        PlaneUsage {
            now: std::sync::Mutex::new(Usage::default()),
            owner,
        }
    }

    /// The owner's total.
    pub fn owner(&self) -> &OwnerUsage {
        &self.owner
    }

    /// The plane now holds `usage`.
    pub fn set(&self, usage: Usage) {
        let mut now = self.now.lock().unwrap_or_else(|p| p.into_inner());
        if *now != usage {
            self.owner.change(*now, usage);
            *now = usage;
        }
    }

    /// The plane is gone: it holds nothing.
    pub fn release(&self) {
        self.set(Usage::default());
    }
}

impl Drop for PlaneUsage {
    fn drop(&mut self) {
        self.release();
    }
}

/// The [`OwnerUsage`] of every client process, by process id.
#[derive(Default)]
pub struct Owners {
    by_pid: HashMap<u32, Arc<OwnerUsage>>,
}

impl Owners {
    /// The counter of process `pid` (made on first use).
    pub fn of(&mut self, pid: u32) -> Arc<OwnerUsage> {
        self.by_pid.entry(pid).or_default().clone()
    }

    /// Forgets the counters no plane uses any more (they hold zero).
    pub fn prune(&mut self) {
        self.by_pid.retain(|_, o| Arc::strong_count(o) > 1);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cost(objects: u32) -> OpCost {
        OpCost {
            objects,
            ..OpCost::default()
        }
    }

    #[test]
    fn reservations_from_many_threads_never_pass_the_limit() {
        let limits = Limits {
            objects_per_client: 1_000,
            ..Limits::DEFAULT
        };
        let owner = OwnerUsage::default();
        let accepted = AtomicU64::new(0);
        std::thread::scope(|s| {
            for _ in 0..8 {
                s.spawn(|| {
                    for _ in 0..500 {
                        if let Ok(r) = owner.reserve(&limits, cost(1)) {
                            // The op "adds" its object: the plane's count takes it over.
                            owner.change(
                                Usage::default(),
                                Usage {
                                    objects: 1,
                                    ..Usage::default()
                                },
                            );
                            drop(r);
                            accepted.fetch_add(1, Ordering::SeqCst);
                        }
                    }
                });
            }
        });
        assert_eq!(accepted.load(Ordering::SeqCst), 1_000);
        assert_eq!(owner.get().objects, 1_000);
    }

    #[test]
    fn a_plane_that_goes_gives_its_count_back() {
        let owner = Arc::new(OwnerUsage::default());
        let plane = PlaneUsage::new(owner.clone());
        plane.set(Usage {
            objects: 7,
            mesh_vertices: 30,
            state_bytes: 1_000,
        });
        assert_eq!(owner.get().objects, 7);
        drop(plane);
        assert_eq!(owner.get(), Usage::default());
    }

    #[test]
    fn a_refused_reservation_names_the_flag_and_keeps_nothing() {
        let limits = Limits {
            objects_per_client: 10,
            ..Limits::DEFAULT
        };
        let owner = OwnerUsage::default();
        let e = owner
            .reserve(&limits, cost(11))
            .err()
            .expect("over the quota");
        assert!(
            e.message.contains("--max-objects-per-client"),
            "{}",
            e.message
        );
        assert!(e.message.contains("11"), "{}", e.message);
        assert_eq!(owner.get(), Usage::default());
    }
}

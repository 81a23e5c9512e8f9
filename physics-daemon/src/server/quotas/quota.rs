//! Per-process quota counters, checked and reserved atomically. Every plane of a client
//! process adds what it holds to one [`OwnerUsage`] of that process; an op that adds objects
//! or mesh vertices first reserves its cost there with a compare-and-swap, and only then
//! runs. Planes step and apply runs on their own workers in parallel, so a check against a
//! snapshot of the other planes (taken when a run was handed out) let eight connections of
//! one process each add a full quota at once; a reservation cannot be overtaken.

use std::collections::HashMap;
use std::sync::atomic::{AtomicU32, AtomicU64, Ordering};
use std::sync::{Arc, Mutex};

use shm_layout::settings::plane::NO_SHARED_OBJECT_LIMIT;
use shm_layout::{CommandError, ErrorKind, Handle, OpCost, PlaneId};

use super::fair;
use crate::backend::{Backend, Usage};
use crate::server::quotas::limits::{exceeded, Limits};

/// Memory one empty plane costs the daemon, measured: 1.8 MiB in a debug build (its worker
/// thread, engine, node and output ports). It was 10.2 MiB while iceoryx2 kept a reference
/// counter per chunk for each of the 255 segments the output's data may grow to, written at
/// creation (`vendor/iceoryx2-0.10.0/PATCHED.md`, change 3).
pub const PLANE_BYTES: u64 = 3 << 20;
/// Memory one object costs, measured (~2.8 KB for a lone cube) plus room for its contacts.
pub const OBJECT_BYTES: u64 = 4 << 10;
/// Memory one mesh vertex (or triangle) costs: positions, indices and the BVH.
pub const VERTEX_BYTES: u64 = 32;

/// What the daemon admits, all clients together, against `--max-memory-mb`: planes and what
/// they hold, counted as [`PLANE_BYTES`], [`OBJECT_BYTES`] and so on.
#[derive(Debug)]
pub struct DaemonMemory {
    bytes: AtomicU64,
    limit: u64,
}

impl DaemonMemory {
    /// A budget of `limit` bytes.
    pub fn new(limit: u64) -> DaemonMemory {
        DaemonMemory {
            bytes: AtomicU64::new(0),
            limit,
        }
    }

    fn take(&self, n: u64) -> Result<(), CommandError> {
        take(&self.bytes, n, self.limit).map_err(|sum| {
            exceeded(
                "memory of the daemon (planes and what they hold)",
                format!("{} MiB", self.limit >> 20),
                "max-memory-mb",
                format!("{} MiB", sum.div_ceil(1 << 20)),
            )
        })
    }

    fn give(&self, n: u64) {
        self.bytes.fetch_sub(n, Ordering::SeqCst);
    }
}

impl Default for DaemonMemory {
    fn default() -> Self {
        DaemonMemory::new(u64::MAX)
    }
}

/// The bytes `usage` costs the daemon.
fn bytes_of(usage: Usage) -> u64 {
    usage
        .objects
        .saturating_mul(OBJECT_BYTES)
        .saturating_add(usage.mesh_vertices.saturating_mul(VERTEX_BYTES))
        .saturating_add(usage.state_bytes)
}

/// What the planes of one client process hold, all together, plus what ops in flight have
/// reserved.
#[derive(Debug, Default)]
pub struct OwnerUsage {
    objects: AtomicU64,
    mesh_vertices: AtomicU64,
    state_bytes: AtomicU64,
    /// The daemon's total, which every change of this one also moves.
    memory: Arc<DaemonMemory>,
    /// The process's CPU account (fair shares between processes).
    pub cpu: fair::CpuAccount,
}

/// A reservation: released when dropped (by then the plane's own count holds what the op
/// added).
pub struct Reserved<'a> {
    owner: &'a OwnerUsage,
    objects: u64,
    mesh_vertices: u64,
    state_bytes: u64,
}

impl Reserved<'_> {
    /// Keeps the reservation as a lasting charge (an object another process added to a
    /// shared plane stays counted for it; [`PlaneUsage`] gives it back).
    pub fn keep(self) {
        std::mem::forget(self);
    }
}

impl Drop for Reserved<'_> {
    fn drop(&mut self) {
        self.owner.memory.give(bytes_of(Usage {
            objects: self.objects,
            mesh_vertices: self.mesh_vertices,
            state_bytes: self.state_bytes,
        }));
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
                "state bytes per client (controller paths, ticks kept for Rewind)",
                limits.state_bytes_per_client,
                "max-state-bytes-per-client",
                sum,
            ));
        }
        let memory = bytes_of(Usage {
            objects,
            mesh_vertices: vertices,
            state_bytes: bytes,
        });
        if let Err(e) = self.memory.take(memory) {
            self.objects.fetch_sub(objects, Ordering::SeqCst);
            self.mesh_vertices.fetch_sub(vertices, Ordering::SeqCst);
            self.state_bytes.fetch_sub(bytes, Ordering::SeqCst);
            return Err(e);
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
        self.memory.bytes.fetch_add(bytes_of(new), Ordering::SeqCst);
        self.memory.give(bytes_of(old));
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

/// A plane's [`Usage`]: the owner's share kept in its owner's [`OwnerUsage`] total, and the
/// objects other processes added to it (a `Shared` plane), each kept in its adder's total
/// until it is destroyed or the plane goes.
#[derive(Debug)]
pub struct PlaneUsage {
    state: Mutex<UsageCounts>,
    owner: Arc<OwnerUsage>,
    /// `SharedObjectLimit`: most objects other processes may have added at once.
    guest_limit: AtomicU32,
}

#[derive(Debug, Default)]
struct UsageCounts {
    /// The owner's share as counted in its total.
    share: Usage,
    /// Objects other processes added, by handle: who pays, and what.
    guests: HashMap<Handle, (Arc<OwnerUsage>, Usage)>,
    /// The sum of `guests`.
    guest_total: Usage,
    /// The plane's objects at the last update (fewer now: some were destroyed).
    objects: u64,
}

impl PlaneUsage {
    /// A plane that holds nothing yet, counted for `owner`; its own [`PLANE_BYTES`] are
    /// admitted against the daemon's memory budget until it is dropped.
    pub fn admit(owner: Arc<OwnerUsage>) -> Result<PlaneUsage, CommandError> {
        owner.memory.take(PLANE_BYTES)?;
        Ok(PlaneUsage {
            state: Mutex::default(),
            owner,
            guest_limit: AtomicU32::new(NO_SHARED_OBJECT_LIMIT),
        })
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, UsageCounts> {
        self.state.lock().unwrap_or_else(|p| p.into_inner())
    }

    /// The owner's total.
    pub fn owner(&self) -> &OwnerUsage {
        &self.owner
    }

    /// Sets `SharedObjectLimit`.
    pub fn set_guest_limit(&self, limit: u32) {
        self.guest_limit.store(limit, Ordering::SeqCst);
    }

    /// Whether other processes may add `objects` more objects (`SharedObjectLimit`).
    pub fn check_guest_room(&self, plane: PlaneId, objects: u64) -> Result<(), CommandError> {
        let limit = self.guest_limit.load(Ordering::SeqCst);
        let now = self.lock().guest_total.objects;
        if now + objects > limit as u64 {
            return Err(CommandError::new(
                ErrorKind::Quota,
                format!(
                    "quota exceeded: objects other clients may add to plane {plane} are limited \
                     to {limit} (its owner's SharedObjectLimit), this would make {}",
                    now + objects
                ),
            ));
        }
        Ok(())
    }

    /// Another process added the object `handle` and keeps paying `cost` for it (its
    /// reservation was kept).
    pub fn add_guest(&self, handle: Handle, who: Arc<OwnerUsage>, cost: Usage) {
        let mut st = self.lock();
        st.guest_total = sum(st.guest_total, cost);
        if let Some((old, old_cost)) = st.guests.insert(handle, (who, cost)) {
            // A slot reused under the same handle cannot happen; stay exact if it did.
            old.change(old_cost, Usage::default());
            st.guest_total = less(st.guest_total, old_cost);
        }
    }

    /// The plane now holds what `plane` reports: the owner pays for what no other process
    /// pays for. Objects other processes added that are gone stop counting for them.
    pub fn update(&self, plane: &dyn Backend) {
        let usage = plane.usage();
        let mut st = self.lock();
        if usage.objects < st.objects && !st.guests.is_empty() {
            let slots = plane.slot_count();
            let mut gone = Usage::default();
            st.guests.retain(|h, (who, cost)| {
                let alive =
                    (h.slot as usize) < slots && plane.body_state(h.slot as usize).matches(*h);
                if !alive {
                    who.change(*cost, Usage::default());
                    gone = sum(gone, *cost);
                }
                alive
            });
            st.guest_total = less(st.guest_total, gone);
        }
        st.objects = usage.objects;
        let share = less(usage, st.guest_total);
        if st.share != share {
            self.owner.change(st.share, share);
            st.share = share;
        }
    }

    /// The plane's objects at its last update (the cluster's load report counts them).
    pub fn objects(&self) -> u64 {
        self.lock().objects
    }

    /// The plane is gone: it holds nothing, and nobody pays for it any more.
    pub fn release(&self) {
        let mut st = self.lock();
        self.owner.change(st.share, Usage::default());
        for (_, (who, cost)) in st.guests.drain() {
            who.change(cost, Usage::default());
        }
        *st = UsageCounts::default();
    }
}

fn sum(a: Usage, b: Usage) -> Usage {
    Usage {
        objects: a.objects + b.objects,
        mesh_vertices: a.mesh_vertices + b.mesh_vertices,
        state_bytes: a.state_bytes + b.state_bytes,
    }
}

fn less(a: Usage, b: Usage) -> Usage {
    Usage {
        objects: a.objects.saturating_sub(b.objects),
        mesh_vertices: a.mesh_vertices.saturating_sub(b.mesh_vertices),
        state_bytes: a.state_bytes.saturating_sub(b.state_bytes),
    }
}

impl Drop for PlaneUsage {
    fn drop(&mut self) {
        self.release();
        self.owner.memory.give(PLANE_BYTES);
    }
}

/// The [`OwnerUsage`] of every client process, by process id, and the daemon's memory.
#[derive(Default)]
pub struct Owners {
    by_pid: HashMap<u128, Arc<OwnerUsage>>,
    memory: Arc<DaemonMemory>,
    shares: Arc<fair::CpuShares>,
}

impl Owners {
    /// No owner yet; the daemon admits at most `memory_limit` bytes.
    pub fn new(memory_limit: u64) -> Owners {
        Owners {
            by_pid: HashMap::new(),
            memory: Arc::new(DaemonMemory::new(memory_limit)),
            shares: Arc::default(),
        }
    }

    /// The counter of process `pid` (made on first use).
    pub fn of(&mut self, pid: u128) -> Arc<OwnerUsage> {
        let (memory, shares) = (&self.memory, &self.shares);
        let owner = self
            .by_pid
            .entry(pid)
            .or_insert_with(|| {
                Arc::new(OwnerUsage {
                    memory: memory.clone(),
                    cpu: fair::CpuAccount::new(shares.clone()),
                    ..OwnerUsage::default()
                })
            })
            .clone();
        self.shares.set_processes(self.by_pid.len());
        owner
    }

    /// Forgets the counters no plane uses any more (they hold zero).
    pub fn prune(&mut self) {
        self.by_pid.retain(|_, o| Arc::strong_count(o) > 1);
        self.shares.set_processes(self.by_pid.len());
    }
}

/// State bytes held for as long as this value lives (a snapshot transfer's buffer), counted
/// in a process's total like a plane's; given back when dropped.
#[derive(Debug)]
pub struct HeldBytes {
    owner: Arc<OwnerUsage>,
    bytes: u64,
}

impl HeldBytes {
    /// Reserves `bytes` of state against `owner`'s quota (and the daemon's memory), or the
    /// `Quota` error naming the quota and its flag.
    pub fn reserve(
        owner: &Arc<OwnerUsage>,
        limits: &Limits,
        bytes: u64,
    ) -> Result<HeldBytes, CommandError> {
        owner
            .reserve(
                limits,
                OpCost {
                    state_bytes: bytes,
                    ..OpCost::default()
                },
            )?
            .keep();
        Ok(HeldBytes {
            owner: owner.clone(),
            bytes,
        })
    }
}

impl Drop for HeldBytes {
    fn drop(&mut self) {
        drop(Reserved {
            owner: &self.owner,
            objects: 0,
            mesh_vertices: 0,
            state_bytes: self.bytes,
        });
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
    fn a_plane_that_goes_gives_back_what_its_adders_pay() {
        let owner = Arc::new(OwnerUsage::default());
        let guest = Arc::new(OwnerUsage::default());
        let plane = PlaneUsage::admit(owner.clone()).unwrap();
        let limits = Limits::DEFAULT;
        guest.reserve(&limits, cost(1)).unwrap().keep();
        let one = Usage {
            objects: 1,
            ..Usage::default()
        };
        plane.add_guest(
            Handle {
                slot: 3,
                generation: 1,
            },
            guest.clone(),
            one,
        );
        assert_eq!(guest.get().objects, 1);
        assert_eq!(owner.get().objects, 0);
        plane.set_guest_limit(1);
        assert!(plane.check_guest_room(7, 1).is_err());
        drop(plane);
        assert_eq!(guest.get(), Usage::default());
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

    #[test]
    fn the_daemon_memory_budget_admits_planes_and_objects_within_it() {
        let mut owners = Owners::new(2 * PLANE_BYTES + 10 * OBJECT_BYTES);
        let (a, b) = (owners.of(1), owners.of(2));
        let pa = PlaneUsage::admit(a.clone()).unwrap();
        let pb = PlaneUsage::admit(b.clone()).unwrap();
        let e = PlaneUsage::admit(a.clone()).expect_err("a third plane does not fit");
        assert!(e.message.contains("--max-memory-mb"), "{}", e.message);
        let limits = Limits::DEFAULT;
        for _ in 0..10 {
            b.reserve(&limits, cost(1)).unwrap().keep();
        }
        assert!(a.reserve(&limits, cost(1)).is_err(), "objects count too");
        drop(pa);
        assert!(
            PlaneUsage::admit(a).is_ok(),
            "a dropped plane gives its bytes back"
        );
        drop(pb);
    }
}

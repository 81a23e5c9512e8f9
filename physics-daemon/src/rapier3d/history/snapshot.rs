//! A 3D plane's whole state as bytes, and back: rapier's world (bodies, colliders, joints,
//! islands, the broad and narrow phases with their contact cache and warm starts) and the
//! plane's own tables (parts, controllers, joints, held objects, collision groups, tick
//! counters), so that a restored plane continues bit for bit.
//!
//! What is not state stays with the plane being restored: its id, its event channels, its
//! thread pool (rapier's pipeline is a per-step workspace) and its quota counter. A restore
//! decodes and checks everything before it touches the plane: a refused snapshot leaves the
//! plane as it was.

use rapier3d::prelude::*;
use shm_layout::{snapshot, CommandError, ErrorKind, PlaneKind, PlaneProp, SnapshotHeader};

use crate::rapier3d::controllers;
use crate::rapier3d::history::gpu_saved::GpuSaved;
use crate::rapier3d::objects::object::MAX_SLOTS;
use crate::rapier3d::plane::{Plane, State, StateRef};

/// The engine named in the snapshot header: only a daemon of the same engine reads it.
pub const ENGINE: &str = "rapier3d 0.36 / physics-daemon state 4";

/// A snapshot body: the state, then the GPU world of a DeferGpu plane.
#[derive(serde::Serialize)]
struct Encoded<'a> {
    state: StateRef<'a>,
    gpu: Option<GpuSaved>,
}

/// [`Encoded`], decoded.
#[derive(serde::Deserialize)]
struct Decoded {
    state: State,
    gpu: Option<GpuSaved>,
}

/// [`check`], and GPU bodies in whole slots, one per object slot at most.
fn check_decoded(d: &Decoded) -> Result<(), CommandError> {
    check(&d.state)?;
    if let Some(g) = &d.gpu {
        if !g.states.len().is_multiple_of(64)
            || g.states.len() != g.params.len()
            || g.states.len() / 64 > d.state.bodies.slot_count()
        {
            return Err(refused(format!(
                "GPU bodies of {} and {} bytes for {} object slots",
                g.states.len(),
                g.params.len(),
                d.state.bodies.slot_count()
            )));
        }
    }
    Ok(())
}

fn refused(what: String) -> CommandError {
    CommandError::new(ErrorKind::InvalidValue, format!("snapshot refused: {what}"))
}

/// A restore's GPU world where there is no GPU path: a DeferGpu snapshot is refused by name.
fn no_gpu_world(saved: Option<GpuSaved>, defer_gpu: bool) -> Result<(), CommandError> {
    match saved.is_some() || defer_gpu {
        true => Err(CommandError::invalid_field(
            "DeferGpu",
            "the snapshot is of a DeferGpu plane and this daemon was built without the GPU \
             path (feature \"gpu\")",
        )),
        false => Ok(()),
    }
}

impl Plane {
    /// The plane's whole state as snapshot bytes (see `shm_layout::snapshot`).
    pub fn snapshot(&self) -> Result<Vec<u8>, CommandError> {
        self.snapshot_with(None)
    }

    /// [`Plane::snapshot`] with the GPU world of a DeferGpu plane (`gpu`).
    pub fn snapshot_with(&self, gpu: Option<GpuSaved>) -> Result<Vec<u8>, CommandError> {
        let body = postcard::to_allocvec(&Encoded {
            state: self.state_ref(),
            gpu,
        })
        .map_err(|e| CommandError::new(ErrorKind::Internal, format!("snapshot failed: {e}")))?;
        Ok(snapshot::encode(self.snapshot_header(), &body))
    }

    fn snapshot_header(&self) -> SnapshotHeader {
        let usage = crate::backend::Backend::usage(self);
        SnapshotHeader {
            engine: ENGINE.to_string(),
            kind: PlaneKind::Rapier3d,
            tick: self.clock.tick,
            state_hash: self.history.state_hash,
            objects: usage.objects,
            mesh_vertices: usage.mesh_vertices,
            state_bytes: usage.state_bytes,
            ..SnapshotHeader::default()
        }
    }

    /// [`Plane::snapshot`] split in two: the state copied now (what Rewind keeps, cheaper
    /// than the encode) and encoded by the returned job, on any thread, to the same bytes a
    /// snapshot of this tick gives.
    pub fn snapshot_later(&self) -> Result<crate::backend::SnapshotJob, CommandError> {
        self.snapshot_later_with(None)
    }

    /// [`Plane::snapshot_later`] with the GPU world of a DeferGpu plane (`gpu`).
    pub fn snapshot_later_with(
        &self,
        gpu: Option<GpuSaved>,
    ) -> Result<crate::backend::SnapshotJob, CommandError> {
        let header = self.snapshot_header();
        let state = self.clone_state();
        Ok(Box::new(move || {
            let encoded = Encoded {
                state: state.as_ref(),
                gpu,
            };
            let body = postcard::to_allocvec(&encoded).map_err(|e| {
                CommandError::new(ErrorKind::Internal, format!("snapshot failed: {e}"))
            })?;
            Ok(snapshot::encode(header, &body))
        }))
    }

    /// Becomes exactly the state of `bytes` (same objects under the same handles). The
    /// plane keeps its id. Nothing changes when the snapshot is refused (a snapshot of a
    /// DeferGpu plane is: see [`Plane::restore_with`]).
    pub fn restore(&mut self, bytes: &[u8], overrides: &[PlaneProp]) -> Result<(), CommandError> {
        self.restore_with(bytes, overrides, no_gpu_world)
    }

    /// [`Plane::restore`] where `gpu_world` makes what the snapshot's GPU bodies (and its
    /// DeferGpu setting) call for, before anything changes: its error refuses the restore;
    /// what it made is returned once the plane is restored.
    pub fn restore_with<T>(
        &mut self,
        bytes: &[u8],
        overrides: &[PlaneProp],
        gpu_world: impl FnOnce(Option<GpuSaved>, bool) -> Result<T, CommandError>,
    ) -> Result<T, CommandError> {
        let (header, body) = snapshot::decode(bytes, PlaneKind::Rapier3d, ENGINE)?;
        let Decoded { mut state, gpu } =
            crate::backend::snapshot_decode::decode(body, refused, check_decoded)?;
        // A DeferGpu plane's GPU world, made before anything changes (no adapter: refused).
        let gpu = gpu_world(gpu, state.settings.defer_gpu)?;
        take_map_meshes(&mut state)?;
        // The overrides are checked on the decoded settings before anything changes.
        for prop in overrides {
            if let PlaneProp::DeferGpu(_) = prop {
                return Err(CommandError::invalid_field(
                    "DeferGpu",
                    "DeferGpu cannot be set by a restore: set it on the restored plane",
                ));
            }
            if let PlaneProp::Name(_) | PlaneProp::Persistent(_) = prop {
                return Err(CommandError::invalid_field(
                    prop.name(),
                    format!(
                        "{} cannot be set by a restore (it belongs to the plane, like its id: \
                         give it at creation)",
                        prop.name()
                    ),
                ));
            }
            state.settings.apply(*prop, true)?;
        }
        // The name and persistence belong to the plane being restored, like its id: a
        // snapshot of a named plane restored into another plane does not take the name.
        state.settings.name = self.settings.name;
        state.settings.persistent = self.settings.persistent;
        state.bodies.adopt_limits(self.objects.table())?;
        state.joints.adopt_limits(&self.joints)?;
        // What is not state stays: the pipeline (the thread pool), the CCD workspace, the
        // table limits, the quota counter.
        state.world.physics_pipeline = std::mem::take(&mut self.world.physics_pipeline);
        // The quota reserved what the header claims: the body may not hold more.
        let paths = crate::backend::counted::Counter::default();
        controllers::count_paths_in(&mut state.controllers, &paths);
        let held = [
            state.bodies.live() as u64 + state.joints.live() as u64,
            state.tally.mesh_vertices(),
            paths.get(),
        ];
        let claimed = [header.objects, header.mesh_vertices, header.state_bytes];
        if held.iter().zip(claimed).any(|(h, c)| *h > c) {
            return Err(refused(format!(
                "it holds {held:?} (objects, mesh vertices, state bytes), its header claims \
                 {claimed:?}"
            )));
        }
        self.adopt(state, overrides)?;
        // Another timeline: the ticks kept for Rewind no longer lead here.
        self.history.rollback.clear();
        Ok(gpu)
    }

    /// Becomes `state` (a copy this plane made with [`Plane::clone_state`]).
    pub(in crate::rapier3d) fn adopt_copy(&mut self, mut state: State) -> Result<(), CommandError> {
        state.bodies.adopt_limits(self.objects.table())?;
        state.joints.adopt_limits(&self.joints)?;
        state.world.physics_pipeline = std::mem::take(&mut self.world.physics_pipeline);
        self.adopt(state, &[])
    }

    /// Takes a decoded and checked `state`, then `overrides` (checked already).
    fn adopt(&mut self, mut state: State, overrides: &[PlaneProp]) -> Result<(), CommandError> {
        controllers::count_paths_in(&mut state.controllers, &self.state_bytes);
        let threads = state.settings.threads;
        self.objects.hand_marks_to(&mut state.bodies);
        self.take_state(state);
        self.events.reset();
        self.objects.take_pending_map();
        // Derived from the parts (rebuilt, not stored).
        self.objects.recount_qualities();
        self.set_threads(threads)?;
        // Their mapping onto the engine (Gravity, NeverSleep; Threads is set above; DeferGpu
        // was refused as an override).
        for prop in overrides {
            self.apply_prop(*prop, true, &mut crate::rapier3d::offload::no_other_engine)?;
        }
        self.objects.mark_all();
        Ok(())
    }
}

/// Gives each decoded map object the mesh its collider carries (a snapshot writes it once),
/// checked against the content hash the object names, and tells the daemon's map store
/// about it (a later build of the same mesh shares it).
fn take_map_meshes(state: &mut State) -> Result<(), CommandError> {
    let w = &state.world;
    for (handle, body) in state.bodies.iter_mut() {
        let Some(map) = body.part.map.as_mut() else {
            continue;
        };
        let shape = w
            .bodies
            .get(body.handle)
            .and_then(|b| b.colliders().first())
            .and_then(|c| w.colliders.get(*c))
            .map(|c| c.shared_shape().clone())
            .ok_or_else(|| refused(format!("map object {} has no collider", handle.slot)))?;
        let Some(mesh) = shape.as_trimesh() else {
            return Err(refused(format!(
                "map object {}'s collider is not a triangle mesh",
                handle.slot
            )));
        };
        let hash = crate::rapier3d::objects::map_store::content_hash(mesh);
        if hash != map.hash {
            return Err(refused(format!(
                "map object {}'s mesh has content hash {hash:016x}, the object names {:016x}",
                handle.slot, map.hash
            )));
        }
        crate::rapier3d::objects::map_store::register(&shape);
        map.shape = shape;
    }
    Ok(())
}

/// Cross-references a decoded state must satisfy before the plane takes it: every object's
/// body, every collider's parent, every controller's and joint's bodies exist. A state that
/// decodes but does not hold together (edited bytes with a fixed checksum) is refused here
/// instead of failing inside the engine later.
fn check(state: &State) -> Result<(), CommandError> {
    let w = &state.world;
    crate::backend::snapshot_decode::check_broad_phase::<_, 3>(&w.broad_phase).map_err(refused)?;
    if state.bodies.slot_count() > MAX_SLOTS {
        return Err(refused(format!(
            "{} object slots (at most {MAX_SLOTS})",
            state.bodies.slot_count()
        )));
    }
    for (slot, body) in state.bodies.iter() {
        if w.bodies.get(body.handle).is_none() {
            return Err(refused(format!("object {slot} has no engine body")));
        }
        if body.part.hit_box_quality > shm_layout::validate::MAX_HIT_BOX_QUALITY {
            return Err(refused(format!(
                "object {slot} has HitBoxQuality {}",
                body.part.hit_box_quality
            )));
        }
    }
    for (_, c) in w.colliders.iter() {
        if c.parent().is_some_and(|p| w.bodies.get(p).is_none()) {
            return Err(refused("a collider's body is missing".into()));
        }
    }
    for (_, j) in w.impulse_joints.iter() {
        if w.bodies.get(j.body1()).is_none() || w.bodies.get(j.body2()).is_none() {
            return Err(refused("a joint's body is missing".into()));
        }
    }
    for slot in state.controllers.keys() {
        if state.bodies.at(*slot as usize).is_none() {
            return Err(refused(format!("controller #{slot} has no object")));
        }
    }
    if !crate::rapier3d::joints::articulations::hold_together(
        &state.joints.articulations,
        &w.bodies,
        &w.multibody_joints,
    ) {
        return Err(refused("an articulation's body is missing".into()));
    }
    if !state.settings.gravity.iter().all(|g| g.is_finite()) {
        return Err(refused("its Gravity is not finite".into()));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::backend::Backend;
    use shm_layout::{JointKind, JointOp, ObjectProp, PlaneOp, Pose, Reply, Shape};

    /// A small plane with the kinds of state a snapshot carries.
    fn scene() -> Plane {
        let mut plane = Plane::new(1, &[]).unwrap();
        let add = |plane: &mut Plane, shape: Shape, p: [f32; 3], props: Vec<ObjectProp>| match plane
            .apply(PlaneOp::AddObject {
                shape,
                pose: Pose::at(p),
                props,
            })
            .unwrap()
        {
            Reply::Object { handle, .. } => handle,
            other => panic!("{other:?}"),
        };
        add(
            &mut plane,
            Shape::Cube {
                size: [20.0, 1.0, 20.0],
            },
            [0.0, -0.5, 0.0],
            vec![ObjectProp::Anchored(true)],
        );
        let a = add(
            &mut plane,
            Shape::Sphere { radius: 0.5 },
            [0.0, 3.0, 0.0],
            vec![],
        );
        let b = add(
            &mut plane,
            Shape::Cube { size: [1.0; 3] },
            [1.5, 3.0, 0.0],
            vec![],
        );
        add(
            &mut plane,
            Shape::Capsule {
                size: [0.6, 1.5, 0.6],
            },
            [-2.0, 2.0, 1.0],
            vec![],
        );
        plane
            .apply(PlaneOp::Joint(JointOp::Create {
                kind: JointKind::Ball,
                a,
                b: Some(b),
                props: vec![],
            }))
            .unwrap();
        for _ in 0..20 {
            plane.step(1.0 / 60.0).unwrap();
        }
        plane
    }

    /// The split snapshot (copy now, encode on another thread) gives the bytes of a
    /// snapshot of the same tick, and they restore to a plane that steps on identically.
    #[test]
    fn a_snapshot_encoded_later_is_the_snapshot() {
        let mut plane = scene();
        let now = plane.snapshot().unwrap();
        let job = plane.snapshot_later().unwrap();
        // The plane moves on before the job runs: the copy holds the tick it was taken at.
        plane.step(1.0 / 60.0).unwrap();
        let later = std::thread::spawn(job).join().unwrap().unwrap();
        assert_eq!(later, now);
        let mut copy = Plane::new(2, &[]).unwrap();
        copy.restore(&later, &[]).unwrap();
        copy.step(1.0 / 60.0).unwrap();
        assert_eq!(copy.history.state_hash, plane.history.state_hash);
    }

    /// The restore of edited bytes whose checksum was fixed up (what a forger sends): the
    /// restore itself never panics (refused, or accepted when it decodes and holds together
    /// as far as the checks see). The engine's own structures (its BVH, islands) are not
    /// all checkable from outside: a step of an accepted forgery may panic inside rapier,
    /// which the plane's worker contains (the forger's plane fails, the daemon serves on:
    /// `tests/tests/snapshot/`). Counted here so a change that makes that worse shows.
    #[test]
    fn edited_snapshots_never_panic_in_restore_and_rarely_in_a_step() {
        let good = scene().snapshot().unwrap();
        let (header, start) = snapshot::header(&good).unwrap();
        let body = &good[start..];
        let mut seed: u64 = 0x9e37_79b9_7f4a_7c15;
        let mut next = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            seed
        };
        let (mut refused, mut accepted, mut panicked) = (0, 0, Vec::new());
        for round in 0..1000 {
            let mut edited = body.to_vec();
            match round % 3 {
                // A few bytes changed.
                0 | 1 => {
                    for _ in 0..1 + next() % 4 {
                        let i = (next() as usize) % edited.len();
                        edited[i] = next() as u8;
                    }
                }
                // Cut short.
                _ => edited.truncate((next() as usize) % edited.len()),
            }
            let bytes = snapshot::encode(header.clone(), &edited);
            let mut plane = Plane::new(2, &[]).unwrap();
            if plane.restore(&bytes, &[]).is_err() {
                refused += 1;
                continue;
            }
            accepted += 1;
            let stepped = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                for _ in 0..3 {
                    let _ = plane.step(1.0 / 60.0);
                }
            }));
            if stepped.is_err() {
                panicked.push(round);
            }
        }
        eprintln!(
            "edited snapshots: {refused} refused, {accepted} accepted, {} of those panicked \
             in a step",
            panicked.len()
        );
        assert!(refused > 0);
        // Most edits land in floats (poses, velocities) and step fine; a panic needs an edit
        // of the engine's bookkeeping that the checks cannot see.
        assert!(
            panicked.len() * 10 <= accepted.max(1),
            "{} of {accepted} accepted forgeries panicked in a step",
            panicked.len()
        );
    }

    #[test]
    fn a_fresh_plane_restored_from_a_snapshot_hashes_the_same_every_tick() {
        let mut a = scene();
        let bytes = a.snapshot().unwrap();
        let mut b = Plane::new(9, &[]).unwrap();
        b.restore(&bytes, &[]).unwrap();
        for tick in 0..60 {
            a.step(1.0 / 60.0).unwrap();
            b.step(1.0 / 60.0).unwrap();
            assert_eq!(a.header().state_hash, b.header().state_hash, "tick {tick}");
        }
    }
}

/// A snapshot taken between two ticks, after ops the plane has not stepped over yet: the
/// restored plane's next step lists the bodies those ops touched as the original's does
/// (the marks no step has seen are state), and clears the forces the original's would (the
/// bodies the last pass left a force on are state).
#[cfg(test)]
mod between_ticks {
    use shm_layout::{
        Handle, ObjectOp, ObjectProp, PlaneKind, PlaneOp, PlaneProp, Pose, Reply, Shape,
    };

    use shm_layout::snapshot::header;

    use crate::backend::Backend;
    use crate::rapier3d::Plane;

    const DT: f32 = 1.0 / 60.0;

    fn add(p: &mut dyn Backend, shape: Shape, at: [f32; 3], props: Vec<ObjectProp>) -> Handle {
        match p
            .apply(PlaneOp::AddObject {
                shape,
                pose: Pose::at(at),
                props,
            })
            .unwrap()
        {
            Reply::Object { handle, .. } => handle,
            other => panic!("{other:?}"),
        }
    }

    fn set(p: &mut dyn Backend, handle: Handle, prop: ObjectProp) {
        p.apply(PlaneOp::Object {
            handle,
            op: ObjectOp::Set(prop),
        })
        .unwrap();
    }

    fn snapshot(p: &mut dyn Backend) -> Vec<u8> {
        match p.apply(PlaneOp::Snapshot).unwrap() {
            Reply::Snapshot(bytes) => bytes,
            other => panic!("{other:?}"),
        }
    }

    /// `bytes` restored into `p`, then published as the daemon's worker does at once (a
    /// publish drains the plane's marks).
    fn restore(p: &mut dyn Backend, bytes: &[u8]) {
        p.apply(PlaneOp::Restore {
            bytes: bytes.to_vec(),
            overrides: vec![],
        })
        .unwrap();
        p.drain_dirty(&mut Vec::new());
    }

    /// A fresh plane restored from `bytes` (published at once).
    fn restored(bytes: &[u8]) -> Plane {
        let mut p = Plane::new(2, &[]).unwrap();
        restore(&mut p, bytes);
        p
    }

    /// Every slot's published state, as bits.
    fn states(p: &dyn Backend) -> Vec<[u32; 13]> {
        (0..p.slot_count())
            .map(|i| {
                let s = p.body_state(i);
                let mut bits = [s.generation ^ s.flags.rotate_left(16); 13];
                let values = s
                    .position
                    .iter()
                    .chain(&s.rotation)
                    .chain(&s.linear_velocity)
                    .chain(&s.angular_velocity);
                for (b, v) in bits.iter_mut().zip(values) {
                    *b = v.to_bits();
                }
                bits
            })
            .collect()
    }

    /// `a` and `b` hold the same state to the bit: the same published states and hash, and
    /// the same snapshot body (the engine's whole world: forces, contact cache, islands, the
    /// bodies rapier records as changed), the last step's wall time aside; the headers
    /// differ at most in the state bytes counted (kept ticks are not state).
    fn same(a: &mut Plane, b: &mut Plane, what: &str) {
        assert_eq!(states(a), states(b), "{what}");
        assert_eq!(a.header().state_hash, b.header().state_hash, "{what}");
        a.clock.last_step_us = 0.0;
        b.clock.last_step_us = 0.0;
        let (x, y) = (a.snapshot().unwrap(), b.snapshot().unwrap());
        let ((mut hx, ix), (mut hy, iy)) = (header(&x).unwrap(), header(&y).unwrap());
        (hx.state_bytes, hy.state_bytes) = (0, 0);
        assert_eq!(hx, hy, "{what}");
        let (x, y) = (&x[ix..], &y[iy..]);
        let at = x.iter().zip(y).position(|(p, q)| p != q);
        assert!(
            x == y,
            "{what}: the states differ at byte {at:?} ({} and {} bytes)",
            x.len(),
            y.len()
        );
    }

    /// The minimal case: a lone ball added with a velocity (default damping) and never
    /// stepped, restored into a plane made by `crate::kinds::create`.
    #[test]
    fn a_ball_added_and_not_stepped_restores_bit_for_bit() {
        let mut a = crate::kinds::create(PlaneKind::Rapier3d, 1, &[]).unwrap();
        let ball = add(
            a.as_mut(),
            Shape::Sphere { radius: 0.5 },
            [-10.0, 5.0, 0.0],
            vec![ObjectProp::Velocity([14.0, 0.0, 0.0])],
        );
        let bytes = snapshot(a.as_mut());
        let mut b = crate::kinds::create(PlaneKind::Rapier3d, 2, &[]).unwrap();
        restore(b.as_mut(), &bytes);
        a.step(DT).unwrap();
        b.step(DT).unwrap();
        let slot = ball.slot as usize;
        let (x_a, x_b) = (
            a.body_state(slot).position[0],
            b.body_state(slot).position[0],
        );
        // Damped (the plane's default LinearDamping): short of the undamped -10 + 14·dt.
        assert!(x_a < -10.0 + 14.0 * DT - 1e-4, "x = {x_a}");
        assert_eq!(
            x_a.to_bits(),
            x_b.to_bits(),
            "original {x_a}, restored {x_b}"
        );
        assert_eq!(states(a.as_ref()), states(b.as_ref()));
        assert_eq!(a.header().state_hash, b.header().state_hash);
    }

    /// A pile settled and partly asleep, then: objects added (some with velocities), sleeping
    /// and awake ones written many times over (past the count at which the marks fold), a
    /// force, an impulse, a destroy.
    fn written_scene(p: &mut Plane) -> Vec<Handle> {
        p.set(PlaneProp::Drag(0.05)).unwrap();
        add(
            p,
            Shape::Cube {
                size: [40.0, 1.0, 40.0],
            },
            [0.0, -0.5, 0.0],
            vec![ObjectProp::Anchored(true)],
        );
        let mut bodies: Vec<Handle> = (0..24)
            .map(|i| {
                let at = [(i % 6) as f32 * 2.5 - 6.0, 0.5, (i / 6) as f32 * 2.5 - 4.0];
                add(p, Shape::Cube { size: [1.0; 3] }, at, vec![])
            })
            .collect();
        for _ in 0..150 {
            p.step(DT).unwrap();
        }
        assert!(p.awake_count() < bodies.len(), "some sleep");
        for i in 0..6 {
            let v = ObjectProp::Velocity([3.0 + i as f32, 2.0, -1.0]);
            let at = [i as f32 * 2.0 - 6.0, 4.0, 6.0];
            bodies.push(add(p, Shape::Sphere { radius: 0.4 }, at, vec![v]));
        }
        // More writes than the marks hold unfolded.
        for k in 0..1_500usize {
            let h = bodies[(k * 7) % bodies.len()];
            let v = [(k % 5) as f32 * 0.3, 0.5, -((k % 3) as f32) * 0.2];
            set(p, h, ObjectProp::Velocity(v));
        }
        set(p, bodies[3], ObjectProp::ConstantForce([0.0, 15.0, 0.0]));
        set(p, bodies[5], ObjectProp::AngularVelocity([0.0, 4.0, 0.0]));
        p.apply(PlaneOp::Object {
            handle: bodies[8],
            op: ObjectOp::ApplyImpulse([2.0, 3.0, 0.0]),
        })
        .unwrap();
        p.apply(PlaneOp::Object {
            handle: bodies[9],
            op: ObjectOp::Destroy,
        })
        .unwrap();
        bodies.remove(9);
        bodies
    }

    /// The same writes and adds on both planes after the restore, before their first step.
    fn written_after(p: &mut Plane, bodies: &[Handle]) {
        add(
            p,
            Shape::Sphere { radius: 0.5 },
            [0.0, 6.0, 0.0],
            vec![ObjectProp::Velocity([0.0, -5.0, 2.0])],
        );
        for k in 0..800usize {
            let h = bodies[(k * 5 + 1) % bodies.len()];
            set(p, h, ObjectProp::Velocity([0.2, (k % 4) as f32 * 0.5, 0.1]));
        }
    }

    /// Many writes and adds mixed, some folded, before the snapshot and after the restore:
    /// the restored plane and the original step on to the bit, tick after tick.
    #[test]
    fn writes_and_adds_before_the_snapshot_and_after_the_restore_step_on_to_the_bit() {
        let mut a = Plane::new(1, &[]).unwrap();
        let bodies = written_scene(&mut a);
        assert!(
            a.objects.since_step().len() < 1_000,
            "the marks folded: {}",
            a.objects.since_step().len()
        );
        let bytes = a.snapshot().unwrap();
        let mut b = restored(&bytes);
        written_after(&mut a, &bodies);
        written_after(&mut b, &bodies);
        assert_eq!(a.objects.since_step(), b.objects.since_step());
        for tick in 0..40 {
            a.step(DT).unwrap();
            b.step(DT).unwrap();
            assert_eq!(states(&a), states(&b), "tick {tick}");
        }
        same(&mut a, &mut b, "after 40 ticks");
    }

    /// A snapshot restored into the plane it was taken from, after that plane went on
    /// (ops of its own not stepped over yet, and no publish between): it steps on as a
    /// plane that never went on.
    #[test]
    fn a_snapshot_restored_into_its_own_plane_forgets_the_ops_since() {
        let mut a = Plane::new(1, &[]).unwrap();
        written_scene(&mut a);
        let bytes = a.snapshot().unwrap();
        let mut reference = Plane::new(1, &[]).unwrap();
        written_scene(&mut reference);
        for _ in 0..3 {
            a.step(DT).unwrap();
        }
        for k in 0..20 {
            add(
                &mut a,
                Shape::Sphere { radius: 0.3 },
                [k as f32 - 10.0, 8.0, 0.0],
                vec![ObjectProp::Velocity([0.0, 0.0, 9.0])],
            );
        }
        a.apply(PlaneOp::Restore {
            bytes,
            overrides: vec![],
        })
        .unwrap();
        for tick in 0..30 {
            a.step(DT).unwrap();
            reference.step(DT).unwrap();
            assert_eq!(states(&a), states(&reference), "tick {tick}");
        }
        same(&mut a, &mut reference, "after 30 ticks");
    }

    /// A ball rolling to rest on the ground (damped: each pass leaves it a force) that fell
    /// asleep in the last step, that pass's force still in rapier's accumulator.
    fn rolled_to_sleep(p: &mut Plane) {
        add(
            p,
            Shape::Cube {
                size: [20.0, 1.0, 20.0],
            },
            [0.0, -0.5, 0.0],
            vec![ObjectProp::Anchored(true)],
        );
        let v = ObjectProp::Velocity([0.3, 0.0, 0.0]);
        add(p, Shape::Sphere { radius: 0.5 }, [0.0, 0.5, 0.0], vec![v]);
        p.step(DT).unwrap();
        let mut ticks = 0;
        while p.awake_count() > 0 {
            p.step(DT).unwrap();
            ticks += 1;
            assert!(ticks < 2_000, "the ball never sleeps");
        }
        let zero = rapier3d::prelude::Vector::ZERO;
        let forced = p.world.bodies.iter().any(|(_, b)| b.user_force() != zero);
        assert!(forced, "a force stays");
    }

    /// The next pass clears the force the last one left on a body that fell asleep since.
    /// A plane restored from a snapshot of that tick clears it too, and the ball, woken by
    /// another landing on it, moves as the original's.
    #[test]
    fn a_force_left_on_a_body_that_fell_asleep_is_cleared_after_a_restore() {
        let mut a = Plane::new(1, &[]).unwrap();
        rolled_to_sleep(&mut a);
        let mut b = restored(&a.snapshot().unwrap());
        for p in [&mut a, &mut b] {
            add(p, Shape::Sphere { radius: 0.5 }, [0.2, 3.0, 0.0], vec![]);
        }
        for tick in 0..90 {
            a.step(DT).unwrap();
            b.step(DT).unwrap();
            assert_eq!(states(&a), states(&b), "tick {tick}");
        }
        same(&mut a, &mut b, "after 90 ticks");
    }

    /// The same through Rewind: the tick kept when the ball fell asleep steps on as it did.
    #[test]
    fn a_rewind_clears_the_forces_the_kept_tick_would() {
        let mut a = Plane::new(1, &[PlaneProp::RollbackTicks(2)]).unwrap();
        rolled_to_sleep(&mut a);
        a.step(DT).unwrap();
        let mut once = Plane::new(1, &[]).unwrap();
        once.restore(&a.snapshot().unwrap(), &[]).unwrap();
        a.apply(PlaneOp::Rewind(1)).unwrap();
        a.step(DT).unwrap();
        same(&mut a, &mut once, "stepped again after the rewind");
    }
}

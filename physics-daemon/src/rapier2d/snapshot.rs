//! A GUI plane's whole state as bytes, and back (see `rapier3d/history/snapshot.rs`, which this
//! follows): its `State` (rapier2d's world and the plane's own tables), so that a restored
//! plane continues bit for bit. The id, the quota counter and the scratch stay with the
//! plane.

use shm_layout::settings::GuiPlaneProp;
use shm_layout::{snapshot, CommandError, ErrorKind, PlaneKind, PlaneProp, SnapshotHeader};

use super::object::MAX_SLOTS;
use super::plane::Plane;
use super::state::{State, StateRef};
use crate::backend::counted::Counter;
use crate::backend::Backend;

/// The engine named in the snapshot header.
pub const ENGINE: &str = "rapier2d 0.36 / physics-daemon gui state 3";

impl Plane {
    /// The state borrowed (to encode).
    fn state_ref(&self) -> StateRef<'_> {
        StateRef {
            world: &self.world,
            settings: &self.settings,
            bodies: &self.bodies,
            controlled: &self.controlled,
            driven: &self.driven,
            query_stale: &self.query_stale,
            held: &self.held,
            clock: &self.clock,
            event_seq: &self.event_seq,
            rollback_ticks: &self.rollback_ticks,
        }
    }

    /// Becomes `state` (decoded and checked, or a copy).
    fn take_state(&mut self, state: State) {
        let State {
            world,
            settings,
            bodies,
            controlled,
            driven,
            query_stale,
            held,
            clock,
            event_seq,
            rollback_ticks,
        } = state;
        self.world = world;
        self.settings = settings;
        self.bodies = bodies;
        self.controlled = controlled;
        self.driven = driven;
        self.query_stale = query_stale;
        self.held = held;
        self.clock = clock;
        self.event_seq = event_seq;
        self.rollback_ticks = rollback_ticks;
    }

    /// The state as an owned copy (what Rewind keeps): the engine's sets cloned, its
    /// per-step workspaces fresh.
    pub(super) fn clone_state(&self) -> State {
        self.state_ref().to_state()
    }
}

fn refused(what: String) -> CommandError {
    CommandError::new(ErrorKind::InvalidValue, format!("snapshot refused: {what}"))
}

impl Plane {
    /// The plane's whole state as snapshot bytes.
    pub fn snapshot(&self) -> Result<Vec<u8>, CommandError> {
        let body = postcard::to_allocvec(&self.state_ref())
            .map_err(|e| CommandError::new(ErrorKind::Internal, format!("snapshot failed: {e}")))?;
        let usage = self.usage();
        let header = SnapshotHeader {
            engine: ENGINE.to_string(),
            kind: PlaneKind::Gui2d,
            tick: self.clock.tick,
            state_hash: self.header().state_hash,
            objects: usage.objects,
            mesh_vertices: usage.mesh_vertices,
            state_bytes: usage.state_bytes,
            ..SnapshotHeader::default()
        };
        Ok(snapshot::encode(header, &body))
    }

    /// Becomes exactly the state of `bytes`; nothing changes when it is refused.
    pub fn restore(&mut self, bytes: &[u8], overrides: &[PlaneProp]) -> Result<(), CommandError> {
        let (header, body) = snapshot::decode(bytes, PlaneKind::Gui2d, ENGINE)?;
        let mut state = crate::backend::snapshot_decode::decode(body, refused, check)?;
        // The overrides are checked on a copy of the decoded plane's settings first.
        let mut checked = state.settings;
        for prop in overrides {
            match prop.checked()? {
                PlaneProp::TickRate(_) | PlaneProp::Enabled(_) | PlaneProp::RollbackTicks(_) => {}
                PlaneProp::Gui(GuiPlaneProp::Bounds { .. }) | PlaneProp::Shared(_) => {
                    return Err(refused(format!(
                        "{} cannot be set by a restore (it is the snapshot's)",
                        prop.name()
                    )))
                }
                PlaneProp::Gui(g) => {
                    checked.apply(g, true)?;
                }
                other => {
                    return Err(refused(format!(
                        "{} is not an option of GUI planes",
                        other.name()
                    )))
                }
            }
        }
        state.bodies.adopt_limits(&self.bodies)?;
        let paths = Counter::default();
        for (_, b) in state.bodies.iter_mut() {
            if let Some(c) = &mut b.controller {
                c.count_in(&paths);
            }
        }
        let held = [state.bodies.live() as u64, paths.get()];
        let claimed = [header.objects, header.state_bytes];
        if held.iter().zip(claimed).any(|(h, c)| *h > c) {
            return Err(refused(format!(
                "it holds {held:?} (objects, state bytes), its header claims {claimed:?}"
            )));
        }
        for (_, b) in state.bodies.iter_mut() {
            if let Some(c) = &mut b.controller {
                c.count_in(&self.state_bytes);
            }
        }
        state.world.physics_pipeline = std::mem::take(&mut self.world.physics_pipeline);
        state.bodies.take_marks_of(&mut self.bodies);
        self.take_state(state);
        self.events.clear();
        self.bodies.mark_all();
        // Another timeline: the ticks kept for Rewind no longer lead here.
        self.rollback.clear();
        for prop in overrides {
            self.apply_prop(*prop, true)?;
        }
        Ok(())
    }

    /// Becomes `state` (a copy this plane made with [`Plane::clone_state`]).
    pub(super) fn adopt_copy(&mut self, mut state: State) -> Result<(), CommandError> {
        state.bodies.adopt_limits(&self.bodies)?;
        for (_, b) in state.bodies.iter_mut() {
            if let Some(c) = &mut b.controller {
                c.count_in(&self.state_bytes);
            }
        }
        state.world.physics_pipeline = std::mem::take(&mut self.world.physics_pipeline);
        state.bodies.take_marks_of(&mut self.bodies);
        self.take_state(state);
        self.events.clear();
        self.bodies.mark_all();
        Ok(())
    }
}

/// Cross-references a decoded state must satisfy (see the 3D plane's `check`).
fn check(state: &State) -> Result<(), CommandError> {
    let w = &state.world;
    crate::backend::snapshot_decode::check_broad_phase::<_, 2>(&w.broad_phase).map_err(refused)?;
    if state.bodies.slot_count() > MAX_SLOTS {
        return Err(refused(format!(
            "{} object slots (at most {MAX_SLOTS})",
            state.bodies.slot_count()
        )));
    }
    for (h, body) in state.bodies.iter() {
        if w.bodies.get(body.handle).is_none() || w.colliders.get(body.collider).is_none() {
            return Err(refused(format!("object {h} has no engine body")));
        }
    }
    for (_, c) in w.colliders.iter() {
        if c.parent().is_some_and(|p| w.bodies.get(p).is_none()) {
            return Err(refused("a collider's body is missing".into()));
        }
    }
    for slot in &state.controlled {
        if state.bodies.at(*slot as usize).is_none() {
            return Err(refused(format!("controller slot {slot} has no object")));
        }
    }
    Ok(())
}

/// A snapshot taken between two ticks, after ops the plane has not stepped over yet: the
/// restored plane's next force pass visits the bodies those ops touched, as the original's.
#[cfg(test)]
mod between_ticks {
    use shm_layout::{GuiObjectOp, GuiObjectProp, GuiOp, GuiShape, Handle, PlaneOp, Reply};

    use super::Plane;
    use crate::backend::Backend;

    const DT: f32 = 1.0 / 60.0;

    fn add(p: &mut dyn Backend, at: [f32; 2], props: Vec<GuiObjectProp>) -> Handle {
        let op = GuiOp::Add {
            shape: GuiShape::Square,
            size: [40.0, 40.0],
            position: at,
            props,
        };
        match p.apply(PlaneOp::Gui(op)).unwrap() {
            Reply::Object { handle, .. } => handle,
            other => panic!("{other:?}"),
        }
    }

    fn object(p: &mut dyn Backend, handle: Handle, op: GuiObjectOp) {
        p.apply(PlaneOp::Gui(GuiOp::Object { handle, op })).unwrap();
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

    /// A lone square added with a velocity (the GUI plane's default LinearDamping) and
    /// never stepped, restored into a fresh plane.
    #[test]
    fn a_square_added_and_not_stepped_restores_bit_for_bit() {
        let mut a: Box<dyn Backend> = Box::new(Plane::new(1, &[]).unwrap());
        let square = add(
            a.as_mut(),
            [100.0, 100.0],
            vec![GuiObjectProp::Velocity([300.0, 0.0])],
        );
        let bytes = snapshot(a.as_mut());
        let mut b: Box<dyn Backend> = Box::new(Plane::new(2, &[]).unwrap());
        restore(b.as_mut(), &bytes);
        a.step(DT).unwrap();
        b.step(DT).unwrap();
        let slot = square.slot as usize;
        let (x_a, x_b) = (
            a.body_state(slot).position[0],
            b.body_state(slot).position[0],
        );
        // Damped: short of the undamped 100 + 300·dt.
        assert!(x_a < 100.0 + 300.0 * DT - 1e-3, "x = {x_a}");
        assert_eq!(
            x_a.to_bits(),
            x_b.to_bits(),
            "original {x_a}, restored {x_b}"
        );
        assert_eq!(a.header().state_hash, b.header().state_hash);
    }

    /// Squares resting on a floor (some asleep), then added and written many times over
    /// (past the count at which the marks fold) before the snapshot, and written alike on
    /// both planes after the restore: they step on to the bit, the whole state included.
    #[test]
    fn writes_and_adds_around_a_snapshot_step_on_to_the_bit() {
        let mut a = Plane::new(1, &[]).unwrap();
        add(
            &mut a,
            [400.0, 600.0],
            vec![
                GuiObjectProp::Size([800.0, 40.0]),
                GuiObjectProp::Anchored(true),
            ],
        );
        let mut squares: Vec<Handle> = (0..12)
            .map(|i| add(&mut a, [60.0 + 60.0 * i as f32, 560.0], vec![]))
            .collect();
        for _ in 0..120 {
            a.step(DT).unwrap();
        }
        assert!(a.awake_count() < squares.len(), "some sleep");
        for i in 0..4 {
            let v = GuiObjectProp::Velocity([50.0 * i as f32, -200.0]);
            squares.push(add(&mut a, [100.0 + 150.0 * i as f32, 300.0], vec![v]));
        }
        for k in 0..1_500usize {
            let h = squares[(k * 7) % squares.len()];
            let v = [(k % 5) as f32 * 10.0, -((k % 3) as f32) * 20.0];
            object(&mut a, h, GuiObjectOp::Set(GuiObjectProp::Velocity(v)));
        }
        let up = GuiObjectProp::ConstantForce([0.0, -500.0]);
        object(&mut a, squares[2], GuiObjectOp::Set(up));
        object(&mut a, squares[4], GuiObjectOp::ApplyImpulse([30.0, -60.0]));
        object(&mut a, squares[6], GuiObjectOp::Destroy);
        squares.remove(6);
        let mut b = Plane::new(2, &[]).unwrap();
        restore(&mut b, &snapshot(&mut a));
        for p in [&mut a, &mut b] {
            add(
                p,
                [420.0, 200.0],
                vec![GuiObjectProp::Velocity([0.0, 100.0])],
            );
            for k in 0..300usize {
                let h = squares[(k * 5 + 1) % squares.len()];
                let v = GuiObjectProp::Velocity([5.0, (k % 4) as f32 * -15.0]);
                object(p, h, GuiObjectOp::Set(v));
            }
        }
        for tick in 0..40 {
            a.step(DT).unwrap();
            b.step(DT).unwrap();
            assert_eq!(states(&a), states(&b), "tick {tick}");
        }
        a.clock.last_step_us = 0.0;
        b.clock.last_step_us = 0.0;
        let (x, y) = (snapshot(&mut a), snapshot(&mut b));
        assert!(x == y, "the whole states differ after 40 ticks");
    }
}

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
pub const ENGINE: &str = "rapier2d 0.36 / physics-daemon gui state 2";

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

//! The rapier3d plane behind the backend seam: routes each op to the plane's methods.

use shm_layout::{
    BodyState, CommandError, CommandResult, ErrorKind, EventRecord, Handle, ObjectOp, ObjectProp,
    PlaneKind, PlaneOp, Reply, TickHeader, Vec3,
};

use super::Plane;
use crate::backend::{Backend, ObjectPlane, Usage};

impl Plane {
    /// Applies one op to the rapier world (the GPU path, `crate::gpu::GpuPlane`, wraps this).
    pub(super) fn apply_on_cpu(&mut self, op: PlaneOp) -> CommandResult {
        let applied = |plane: &Plane| Reply::Applied {
            tick: plane.clock.tick,
        };
        match op {
            PlaneOp::Info => Ok(Reply::Plane(self.info())),
            PlaneOp::Set(prop) => self.set(prop).map(|_| Reply::Done),
            PlaneOp::AddObject { shape, pose, props } => {
                let handle = self.add_object(&shape, pose, &props)?;
                Ok(Reply::Object {
                    handle,
                    tick: self.clock.tick,
                })
            }
            PlaneOp::Object { handle, op } => match op.into_common() {
                Ok(common) => crate::backend::object_op(self, handle, common),
                Err(ObjectOp::RecalculateCenterOfMass) => self
                    .recalculate_center_of_mass(handle)
                    .map(Reply::CenterOfMass),
                Err(ObjectOp::Contacts) => self.object_contacts(handle).map(Reply::Contacts),
                Err(other) => Err(CommandError::new(
                    ErrorKind::Internal,
                    format!("ObjectOp::{other:?} is a shared object op"),
                )),
            },
            PlaneOp::Query(query) => self.query(query),
            PlaneOp::Controller(op) => self.controller_op(op),
            PlaneOp::CollisionGroups(table) => {
                self.set_collision_groups(table).map(|_| Reply::Done)
            }
            PlaneOp::Gui(_) => Err(CommandError::new(
                ErrorKind::InvalidValue,
                "GUI ops (PlaneOp::Gui) need a GUI plane; this is a 3D plane",
            )),
            PlaneOp::Joint(op) => self.joint_op(op),
            PlaneOp::Map(op) => self.map_op(op),
            PlaneOp::Step { .. }
            | PlaneOp::Destroy
            | PlaneOp::Save
            | PlaneOp::RestoreUploaded { .. }
            | PlaneOp::MoveTo { .. }
            | PlaneOp::ClaimMoved { .. }
            | PlaneOp::Pin
            | PlaneOp::Record(_) => Err(CommandError::new(
                ErrorKind::Internal,
                format!("{op:?} is handled by the server, not the plane"),
            )),
            PlaneOp::Explode(explosion) => self.explode(explosion),
            PlaneOp::Snapshot => self.snapshot().map(Reply::Snapshot),
            PlaneOp::Rewind(n) => self.rewind(n),
            PlaneOp::Restore { bytes, overrides } => {
                self.restore(&bytes, &overrides).map(|_| applied(self))
            }
        }
    }
}

impl Backend for Plane {
    fn kind(&self) -> PlaneKind {
        PlaneKind::Rapier3d
    }

    fn snapshot_later(&self) -> Option<Result<crate::backend::SnapshotJob, CommandError>> {
        Some(Plane::snapshot_later(self))
    }

    fn idle_work(&mut self) -> Result<(), CommandError> {
        self.finish_keep()
    }

    fn has_idle_work(&self) -> bool {
        self.keep_pending()
    }

    fn apply(&mut self, op: PlaneOp) -> CommandResult {
        // The last tick is kept for Rewind before an op changes anything (see `rollback`).
        self.finish_keep()?;
        self.apply_on_cpu(op)
    }

    fn step(&mut self, dt: f32) -> Result<bool, CommandError> {
        Plane::step(self, dt)
    }

    fn tick_rate(&self) -> f32 {
        Plane::tick_rate(self)
    }

    fn enabled(&self) -> bool {
        Plane::enabled(self)
    }

    fn tick(&self) -> u64 {
        self.clock.tick
    }

    fn header(&self) -> TickHeader {
        Plane::header(self)
    }

    fn slot_count(&self) -> usize {
        Plane::slot_count(self)
    }

    fn awake_count(&self) -> usize {
        Plane::awake_count(self)
    }

    fn for_each_awake(&self, f: &mut dyn FnMut(usize)) {
        for slot in self.awake_slots() {
            f(slot);
        }
    }

    fn drain_dirty(&mut self, into: &mut Vec<u32>) -> bool {
        self.objects.drain_marks(into)
    }

    fn body_state(&self, i: usize) -> BodyState {
        Plane::body_state(self, i)
    }

    fn write_states(
        &self,
        out: &mut [std::mem::MaybeUninit<BodyState>],
        filter: crate::backend::SlotFilter<'_>,
    ) {
        self.write_sample(out, filter)
    }

    fn events(&self) -> &[EventRecord] {
        Plane::events(self)
    }

    fn usage(&self) -> Usage {
        Usage {
            objects: self.objects.live() as u64 + self.joints.live() as u64,
            mesh_vertices: self.objects.tally().mesh_vertices() + self.objects.pending_map().cost(),
            state_bytes: self.state_bytes.get(),
        }
    }
}

impl ObjectPlane for Plane {
    type Prop = ObjectProp;
    type Impulse = Vec3;

    fn tick_now(&self) -> u64 {
        self.clock.tick
    }

    fn set_prop(&mut self, handle: Handle, prop: ObjectProp) -> Result<(), CommandError> {
        Plane::set_object(self, handle, prop)
    }

    fn impulse(&mut self, handle: Handle, impulse: Vec3) -> Result<Vec3, CommandError> {
        Plane::apply_impulse(self, handle, impulse)
    }

    fn wake_object(&mut self, handle: Handle) -> Result<(), CommandError> {
        Plane::wake(self, handle)
    }

    fn info_reply(&self, handle: Handle) -> CommandResult {
        Ok(Reply::ObjectInfo(Box::new(self.object_info(handle)?)))
    }

    fn destroy(&mut self, handle: Handle) -> Result<(), CommandError> {
        Plane::destroy_object(self, handle)
    }
}

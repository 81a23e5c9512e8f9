//! The GUI plane behind the backend seam: routes each op to the plane's methods.

use shm_layout::{
    BodyState, CommandError, CommandResult, ErrorKind, EventRecord, GuiObjectOp, GuiObjectProp,
    GuiOp, GuiReply, Handle, ObjectOp, PlaneKind, PlaneOp, Reply, TickHeader, Vec2, Vec3,
};

use super::plane::Plane;
use crate::backend::{Backend, ObjectPlane, Usage};

impl Plane {
    fn gui(&mut self, op: GuiOp) -> CommandResult {
        match op {
            GuiOp::Info => Ok(Reply::Gui(GuiReply::Plane(self.gui_info()))),
            GuiOp::Add {
                shape,
                size,
                position,
                props,
            } => {
                let handle = self.add_object(shape, size, position, &props)?;
                Ok(Reply::Object {
                    handle,
                    tick: self.clock.tick,
                })
            }
            GuiOp::Object { handle, op } => crate::backend::object_op(self, handle, op),
            GuiOp::Controller { handle, op } => self.controller_op(handle, op),
            GuiOp::Raycast {
                from,
                dir,
                max_distance,
            } => Ok(Reply::Gui(GuiReply::Hit(self.raycast(
                from,
                dir,
                max_distance,
            )?))),
        }
    }
}

fn not_for_gui(what: &str) -> CommandError {
    CommandError::new(
        ErrorKind::InvalidValue,
        format!("{what} is an op of 3D planes; GUI planes take PlaneOp::Gui"),
    )
}

impl Backend for Plane {
    fn kind(&self) -> PlaneKind {
        PlaneKind::Gui2d
    }

    fn apply(&mut self, op: PlaneOp) -> CommandResult {
        match op {
            PlaneOp::Info => Ok(Reply::Plane(self.info())),
            PlaneOp::Set(prop) => self.set(prop).map(|_| Reply::Done),
            PlaneOp::Gui(op) => self.gui(op),
            PlaneOp::Snapshot => self.snapshot().map(Reply::Snapshot),
            PlaneOp::Rewind(n) => self.rewind(n),
            PlaneOp::Restore { bytes, overrides } => {
                self.restore(&bytes, &overrides).map(|_| Reply::Applied {
                    tick: self.clock.tick,
                })
            }
            PlaneOp::Object { handle, op } => match op {
                ObjectOp::Wake => self.gui(GuiOp::Object {
                    handle,
                    op: GuiObjectOp::Wake,
                }),
                ObjectOp::Destroy => self.gui(GuiOp::Object {
                    handle,
                    op: GuiObjectOp::Destroy,
                }),
                ObjectOp::ApplyImpulse(j) => self.gui(GuiOp::Object {
                    handle,
                    op: GuiObjectOp::ApplyImpulse([j[0], j[1]]),
                }),
                other => Err(not_for_gui(&format!("ObjectOp::{other:?}"))),
            },
            PlaneOp::AddObject { .. } => Err(not_for_gui("AddObject")),
            PlaneOp::Query(_) => Err(not_for_gui("Query")),
            PlaneOp::Controller(_) => Err(not_for_gui("Controller")),
            PlaneOp::Joint(_) => Err(not_for_gui("Joint")),
            PlaneOp::Map(_) => Err(not_for_gui("Map")),
            // Collision groups do not apply (ZIndex is the layer); a client sends its table to
            // every plane it owns, so a GUI plane takes it and ignores it.
            PlaneOp::CollisionGroups(_) => Ok(Reply::Done),
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
            PlaneOp::Explode(_) => Err(not_for_gui("Explode")),
        }
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
        self.bodies.drain_marks(into)
    }

    fn body_state(&self, i: usize) -> BodyState {
        Plane::body_state(self, i)
    }

    fn events(&self) -> &[EventRecord] {
        Plane::events(self)
    }

    fn usage(&self) -> Usage {
        Usage {
            objects: self.bodies.live() as u64,
            mesh_vertices: 0,
            state_bytes: self.state_bytes.get(),
        }
    }
}

impl ObjectPlane for Plane {
    type Prop = GuiObjectProp;
    type Impulse = Vec2;

    fn tick_now(&self) -> u64 {
        self.clock.tick
    }

    fn set_prop(&mut self, handle: Handle, prop: GuiObjectProp) -> Result<(), CommandError> {
        Plane::set_object(self, handle, prop)
    }

    fn impulse(&mut self, handle: Handle, impulse: Vec2) -> Result<Vec3, CommandError> {
        Plane::apply_impulse(self, handle, impulse).map(|v| [v[0], v[1], 0.0])
    }

    fn wake_object(&mut self, handle: Handle) -> Result<(), CommandError> {
        Plane::wake(self, handle)
    }

    fn info_reply(&self, handle: Handle) -> CommandResult {
        Ok(Reply::Gui(GuiReply::Object(Box::new(
            self.object_info(handle)?,
        ))))
    }

    fn destroy(&mut self, handle: Handle) -> Result<(), CommandError> {
        Plane::destroy_object(self, handle)
    }
}

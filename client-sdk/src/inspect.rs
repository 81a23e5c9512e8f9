//! Read-only views for tools that watch a daemon they did not fill (viewers, debuggers):
//! the ids of every plane of the domain, and the descriptions of objects, controllers and
//! GUI objects known only by handle. Every call here only reads, so it works on planes of
//! other clients.

use shm_layout::{
    Command, ControllerInfo, ControllerOp, GuiControllerOp, GuiObjectOp, GuiOp, GuiReply, Handle,
    ObjectInfo, ObjectOp, PlaneId, PlaneOp, Reply,
};

use shm_layout::gui_op::{GuiControllerInfo, GuiObjectInfo};

use crate::{client::Client, error::Error, plane::Plane};

fn unexpected(reply: Reply) -> Error {
    Error::Protocol(format!("unexpected reply {reply:?}"))
}

impl Client {
    /// The ids of every plane of the daemon (any client's), ascending. Attach to one with
    /// [`Client::attach_plane`].
    pub fn plane_ids(&self) -> Result<Vec<PlaneId>, Error> {
        match self.call(Command::ListPlanes)? {
            Reply::PlaneIds(ids) => Ok(ids),
            other => Err(unexpected(other)),
        }
    }

    /// Forgets plane `id` (destroyed, or no longer watched): its subscribers are closed, so
    /// the daemon's services of a destroyed plane are not kept alive by this client.
    pub fn detach_plane(&self, id: PlaneId) {
        self.forget_plane(id);
    }
}

impl Plane {
    /// Every property of the 3D object `handle` (one round trip).
    pub fn object_info(&self, handle: Handle) -> Result<ObjectInfo, Error> {
        match self
            .client()
            .call(Command::object(self.id(), handle, ObjectOp::Info))?
        {
            Reply::ObjectInfo(info) => Ok(*info),
            other => Err(unexpected(other)),
        }
    }

    /// The description of the character controller whose body is `handle`.
    pub fn controller_info(&self, handle: Handle) -> Result<ControllerInfo, Error> {
        let op = PlaneOp::Controller(ControllerOp::Info { handle });
        match self.client().call(Command::plane(self.id(), op))? {
            Reply::Controller(info) => Ok(*info),
            other => Err(unexpected(other)),
        }
    }

    /// Every property of the object `handle` of a GUI plane.
    pub fn gui_object_info(&self, handle: Handle) -> Result<GuiObjectInfo, Error> {
        let op = PlaneOp::Gui(GuiOp::Object {
            handle,
            op: GuiObjectOp::Info,
        });
        match self.client().call(Command::plane(self.id(), op))? {
            Reply::Gui(GuiReply::Object(info)) => Ok(*info),
            other => Err(unexpected(other)),
        }
    }

    /// The description of the GUI controller bound to the object `handle` of a GUI plane.
    pub fn gui_controller_info(&self, handle: Handle) -> Result<GuiControllerInfo, Error> {
        let op = PlaneOp::Gui(GuiOp::Controller {
            handle,
            op: GuiControllerOp::Info,
        });
        match self.client().call(Command::plane(self.id(), op))? {
            Reply::Gui(GuiReply::Controller(info)) => Ok(*info),
            other => Err(unexpected(other)),
        }
    }
}

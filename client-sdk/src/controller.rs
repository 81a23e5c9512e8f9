//! Character controllers: a kinematic capsule the daemon moves every tick (walk speed with
//! acceleration and friction, jumps, slopes, steps, platforms, paths). Its pose and
//! velocity read zero-copy like any object's; settings read back with one round trip.

use shm_layout::{
    Command, ControllerInfo, ControllerOp, ControllerProp, Handle, PlaneOp, Pose, Reply, Vec3,
    FLAG_ON_GROUND,
};

use crate::{error::Error, object::Object, plane::Plane};

/// One controller of a plane. Cheap to clone.
#[derive(Clone, Debug)]
pub struct Controller {
    object: Object,
}

impl Plane {
    /// Makes a controller for a part of full `size` at `pose` (only its yaw is kept; the
    /// capsule stays upright). `controlled`: the reference's NewControlledController
    /// (LookWhereMoving off by default). Sends the queue and waits for the handle.
    pub fn new_controller(
        &self,
        pose: Pose,
        size: Vec3,
        controlled: bool,
        props: &[ControllerProp],
    ) -> Result<Controller, Error> {
        let op = ControllerOp::Create {
            pose,
            size,
            controlled,
            props: props.to_vec(),
        }
        .checked()
        .map_err(Error::invalid_value)?;
        match self
            .client()
            .call(Command::plane(self.id(), PlaneOp::Controller(op)))?
        {
            Reply::Object { handle, tick } => {
                let object = Object::from_handle(self, handle);
                self.overlay_write(handle, |e| {
                    e.pose = Some(pose);
                    e.velocity = Some([0.0; 3]);
                });
                self.shared.confirm(handle, tick);
                self.shared.members.borrow_mut().added(tick);
                Ok(Controller { object })
            }
            other => Err(Error::Protocol(format!("unexpected reply {other:?}"))),
        }
    }
}

impl Controller {
    /// The controller whose object is `handle` on `plane` (a controller of a plane restored
    /// from a snapshot).
    pub fn from_handle(plane: &Plane, handle: Handle) -> Controller {
        Controller {
            object: Object::from_handle(plane, handle),
        }
    }

    /// The controller's body (pose, velocity, alive: zero-copy reads).
    pub fn object(&self) -> &Object {
        &self.object
    }

    /// Its object handle.
    pub fn handle(&self) -> Handle {
        self.object.handle()
    }

    fn command(&self, op: ControllerOp) -> Command {
        Command::plane(self.object.plane().id(), PlaneOp::Controller(op))
    }

    /// Queues `op` (sent with the next flush); `pose`: what reads show at once.
    fn queue(&self, op: ControllerOp, pose: Option<Pose>) -> Result<(), Error> {
        let op = op.checked().map_err(Error::invalid_value)?;
        let plane = self.object.plane();
        let confirms = pose.map(|p| {
            plane.overlay_write(self.handle(), |e| {
                e.pose = Some(p);
                e.velocity = Some([0.0; 3]);
            });
            (plane.id(), self.handle())
        });
        plane.client().queue(self.command(op), confirms);
        Ok(())
    }

    /// Sets a property or option (checked now, sent with the next flush).
    pub fn set(&self, prop: ControllerProp) -> Result<(), Error> {
        let pose = match prop {
            ControllerProp::Position(p) => Some(Pose {
                position: p,
                rotation: self.object.pose()?.rotation,
            }),
            _ => None,
        };
        self.queue(
            ControllerOp::Set {
                handle: self.handle(),
                prop,
            },
            pose,
        )
    }

    /// Every setting and the controller's own state (one round trip).
    pub fn info(&self) -> Result<ControllerInfo, Error> {
        match self
            .object
            .plane()
            .client()
            .call(self.command(ControllerOp::Info {
                handle: self.handle(),
            }))? {
            Reply::Controller(info) => Ok(*info),
            other => Err(Error::Protocol(format!("unexpected reply {other:?}"))),
        }
    }

    /// Whether it stood on the ground after the newest tick (zero-copy).
    pub fn on_ground(&self) -> Result<bool, Error> {
        Ok(self.object.state()?.flags & FLAG_ON_GROUND != 0)
    }

    /// Walks to one point (replaces the path).
    pub fn walk_to(&self, target: Vec3) -> Result<(), Error> {
        self.compute_path(&[target]).map(|_| ())
    }

    /// Replaces the path; returns the number of waypoints stored.
    pub fn compute_path(&self, waypoints: &[Vec3]) -> Result<usize, Error> {
        self.queue(
            ControllerOp::SetPath {
                handle: self.handle(),
                waypoints: waypoints.to_vec(),
            },
            None,
        )?;
        Ok(waypoints.len())
    }

    /// Adds a waypoint at the end of the path.
    pub fn append_waypoint(&self, point: Vec3) -> Result<(), Error> {
        self.queue(
            ControllerOp::AppendWaypoint {
                handle: self.handle(),
                point,
            },
            None,
        )
    }

    /// Clears the path and the motion intent.
    pub fn stop_walking(&self) -> Result<(), Error> {
        self.queue(
            ControllerOp::StopWalking {
                handle: self.handle(),
            },
            None,
        )
    }

    /// Jumps when on the ground (one round trip); returns whether it launched.
    pub fn jump(&self) -> Result<bool, Error> {
        match self
            .object
            .plane()
            .client()
            .call(self.command(ControllerOp::Jump {
                handle: self.handle(),
            }))? {
            Reply::Flag(launched) => Ok(launched),
            other => Err(Error::Protocol(format!("unexpected reply {other:?}"))),
        }
    }

    /// Sets position and facing, clears velocity and path.
    pub fn teleport(&self, pose: Pose) -> Result<(), Error> {
        self.queue(
            ControllerOp::Teleport {
                handle: self.handle(),
                pose,
            },
            Some(pose),
        )
    }

    /// Motion intent in local space (+z forward, +x right), each in [-1, 1]; it persists
    /// until changed or cleared.
    pub fn set_move_vector(&self, x: f32, z: f32) -> Result<(), Error> {
        self.set(ControllerProp::MoveVector([x, z]))
    }

    /// Removes the controller and its body (sent with the next flush).
    pub fn destroy(&self) {
        self.object.destroy();
    }
}

//! The 2D GUI plane (`PhysicsService.NewGUI`): [`GuiPlane`], its [`GuiObject`]s and
//! [`GuiController`]s, rays, and the controller signals ([`GuiEvent`]). Pixels, degrees and
//! seconds, +Y down. Reads come zero-copy from shared memory like 3D objects (the record's
//! `x, y` and the rotation about Z); writes join the client's batch.

use shm_layout::gui_op::{
    GuiControllerInfo, GuiObjectInfo, GuiPlaneInfo, EVENT_GUI_GROUND_CHANGED, EVENT_GUI_MOVED,
    EVENT_GUI_PATH_FINISHED, EVENT_GUI_WAYPOINT_REACHED,
};
use shm_layout::settings::gui_plane::finite2;
use shm_layout::{
    BodyState, Command, EventRecord, GuiControllerOp, GuiControllerProp, GuiHit, GuiObjectOp,
    GuiObjectProp, GuiOp, GuiPlaneProp, GuiReply, GuiShape, Handle, PlaneKind, PlaneOp, PlaneProp,
    Pose, Reply, Vec2,
};

use crate::{client::Client, error::Error, plane::Plane};

/// Options of a new GUI plane; `None` keeps the default.
#[derive(Debug, Clone, Default)]
pub struct GuiPlaneOptions {
    /// Ticks per second of wall time; 0 = manual.
    pub tick_rate: Option<f32>,
    /// `Enabled`.
    pub enabled: Option<bool>,
    /// `Shared` (creation only).
    pub shared: Option<bool>,
    /// `Gravity` (px/s², default (0, 980)).
    pub gravity: Option<Vec2>,
    /// `LinearDamping` (default 0.05).
    pub linear_damping: Option<f32>,
    /// `AngularDamping` (default 0.10).
    pub angular_damping: Option<f32>,
    /// `Drag`.
    pub drag: Option<f32>,
    /// `ConstantForce`.
    pub constant_force: Option<Vec2>,
    /// `RestThreshold` (default 0.25 px/s; 0 disables sleeping).
    pub rest_threshold: Option<f32>,
    /// `SolverIterations` (default 4, clamped to [1, 32]).
    pub solver_iterations: Option<u32>,
    /// `NeverSleep`.
    pub never_sleep: Option<bool>,
    /// `BoundsMin` / `BoundsMax` (creation only).
    pub bounds: Option<(Vec2, Vec2)>,
    /// `Name`: unique in the domain, for `Open` (creation only).
    pub name: Option<shm_layout::PlaneName>,
    /// `Persistent`: written to the daemon's state directory (creation only; needs a name).
    pub persistent: Option<bool>,
    /// `RollbackTicks`: ticks kept for [`Plane::rewind`].
    pub rollback_ticks: Option<u32>,
}

impl GuiPlaneOptions {
    /// A manual GUI plane: it advances only on [`GuiPlane::step`].
    pub fn manual() -> Self {
        GuiPlaneOptions {
            tick_rate: Some(0.0),
            ..Default::default()
        }
    }

    /// The creation request's options.
    pub fn props(&self) -> Vec<PlaneProp> {
        let o = self;
        let gui = [
            o.gravity.map(GuiPlaneProp::Gravity),
            o.linear_damping.map(GuiPlaneProp::LinearDamping),
            o.angular_damping.map(GuiPlaneProp::AngularDamping),
            o.drag.map(GuiPlaneProp::Drag),
            o.constant_force.map(GuiPlaneProp::ConstantForce),
            o.rest_threshold.map(GuiPlaneProp::RestThreshold),
            o.solver_iterations.map(GuiPlaneProp::SolverIterations),
            o.never_sleep.map(GuiPlaneProp::NeverSleep),
            o.bounds.map(|(min, max)| GuiPlaneProp::Bounds { min, max }),
        ];
        [
            o.tick_rate.map(PlaneProp::TickRate),
            o.enabled.map(PlaneProp::Enabled),
            o.shared.map(PlaneProp::Shared),
            o.name.map(PlaneProp::Name),
            o.persistent.map(PlaneProp::Persistent),
            o.rollback_ticks.map(PlaneProp::RollbackTicks),
        ]
        .into_iter()
        .flatten()
        .chain(gui.into_iter().flatten().map(PlaneProp::Gui))
        .collect()
    }
}

impl Client {
    /// Creates a GUI plane owned by this client.
    pub fn create_gui_plane(&self, options: &GuiPlaneOptions) -> Result<GuiPlane, Error> {
        let props = options
            .props()
            .into_iter()
            .map(|p| p.checked())
            .collect::<Result<Vec<_>, _>>()
            .map_err(Error::invalid_value)?;
        let id = match self.call(Command::CreatePlane {
            kind: PlaneKind::Gui2d,
            props,
        })? {
            Reply::Plane(info) => info.id,
            other => return Err(Error::Protocol(format!("unexpected reply {other:?}"))),
        };
        self.note_owned(id);
        Ok(GuiPlane {
            plane: self.attach_plane(id)?,
        })
    }
}

/// A GUI plane of the daemon. Cheap to clone.
#[derive(Clone, Debug)]
pub struct GuiPlane {
    plane: Plane,
}

fn unexpected(reply: Reply) -> Error {
    Error::Protocol(format!("unexpected reply {reply:?}"))
}

impl GuiPlane {
    /// A GUI plane known by its generic handle (e.g. attached by id).
    pub fn from_plane(plane: Plane) -> GuiPlane {
        GuiPlane { plane }
    }

    /// The generic plane: snapshots, `step`, `events`, `destroy`, `id`.
    pub fn plane(&self) -> &Plane {
        &self.plane
    }

    fn call(&self, op: GuiOp) -> Result<Reply, Error> {
        self.plane
            .client()
            .call(Command::plane(self.plane.id(), PlaneOp::Gui(op)))
    }

    fn queue(&self, op: GuiOp, confirms: Option<Handle>) {
        self.plane.client().queue(
            Command::plane(self.plane.id(), PlaneOp::Gui(op)),
            confirms.map(|h| (self.plane.id(), h)),
        );
    }

    /// Every option and count (one round trip, after the queue).
    pub fn info(&self) -> Result<GuiPlaneInfo, Error> {
        match self.call(GuiOp::Info)? {
            Reply::Gui(GuiReply::Plane(info)) => Ok(info),
            other => Err(unexpected(other)),
        }
    }

    /// Live bodies of the plane without a round trip (see [`Plane::object_count`]).
    pub fn object_count(&self) -> Result<u32, Error> {
        if let Some(n) = self.plane.published_object_count()? {
            return Ok(n);
        }
        let info = self.info()?;
        self.plane.shared.members.borrow_mut().asked(info.tick);
        Ok(info.object_count)
    }

    /// Changes a GUI option (checked now, sent with the next flush).
    pub fn set(&self, prop: GuiPlaneProp) -> Result<(), Error> {
        self.plane.set(PlaneProp::Gui(prop))
    }

    /// Changes an option every plane has (`TickRate`, `Enabled`).
    pub fn set_common(&self, prop: PlaneProp) -> Result<(), Error> {
        self.plane.set(prop)
    }

    /// Adds a body for a primitive; sends the queue and waits for the handle.
    pub fn add(
        &self,
        shape: GuiShape,
        size: Vec2,
        position: Vec2,
        props: &[GuiObjectProp],
    ) -> Result<GuiObject, Error> {
        let props = props
            .iter()
            .map(|p| p.checked())
            .collect::<Result<Vec<_>, _>>()
            .map_err(Error::invalid_value)?;
        GuiObjectProp::Size(size)
            .checked()
            .map_err(Error::invalid_value)?;
        finite2("Position", position).map_err(Error::invalid_value)?;
        let hold = self.plane.client().holds_adds();
        let mut sent = props.clone();
        if hold {
            sent.push(GuiObjectProp::Held(true));
        }
        let reply = self.call(GuiOp::Add {
            shape,
            size,
            position,
            props: sent,
        })?;
        let Reply::Object { handle, tick } = reply else {
            return Err(unexpected(reply));
        };
        if hold {
            // Released by the next flush, together with what the caller writes until then.
            let release = GuiOp::Object {
                handle,
                op: GuiObjectOp::Set(GuiObjectProp::Held(false)),
            };
            self.queue(release, None);
        }
        let mut pose = Pose::at([position[0], position[1], 0.0]);
        let mut velocity = [0.0; 3];
        for p in &props {
            match *p {
                GuiObjectProp::Position(q) => pose.position = [q[0], q[1], 0.0],
                GuiObjectProp::Rotation(deg) => pose.rotation = rotation_z(deg),
                GuiObjectProp::Velocity(v) => velocity = [v[0], v[1], 0.0],
                _ => {}
            }
        }
        self.plane.overlay_write(handle, |e| {
            e.pose = Some(pose);
            e.velocity = Some(velocity);
            e.angular_velocity = Some([0.0; 3]);
        });
        self.plane.shared.confirm(handle, tick);
        self.plane.shared.members.borrow_mut().added(tick);
        Ok(GuiObject {
            plane: self.clone(),
            handle,
        })
    }

    /// The first collidable body (any ZIndex) on the ray from `from` along `dir` within
    /// `max_distance` px (`None`: unbounded). Sees every op sent before it.
    pub fn raycast(
        &self,
        from: Vec2,
        dir: Vec2,
        max_distance: Option<f32>,
    ) -> Result<Option<GuiHit>, Error> {
        shm_layout::gui_op::check_ray(from, dir, max_distance).map_err(Error::invalid_value)?;
        match self.call(GuiOp::Raycast {
            from,
            dir,
            max_distance,
        })? {
            Reply::Gui(GuiReply::Hit(hit)) => Ok(hit),
            other => Err(unexpected(other)),
        }
    }

    /// Binds a controller to `object` (`uncontrolled`: `NewUncontrolled`); locks its
    /// rotation. Sent with the next flush.
    pub fn new_controller(
        &self,
        object: &GuiObject,
        uncontrolled: bool,
        props: &[GuiControllerProp],
    ) -> Result<GuiController, Error> {
        let controller = GuiController {
            object: object.clone(),
        };
        controller.op(GuiControllerOp::Create {
            uncontrolled,
            props: props.to_vec(),
        })?;
        Ok(controller)
    }

    /// Advances the plane (see [`Plane::step`]).
    pub fn step(&self, dt: f32) -> Result<u64, Error> {
        self.plane.step(dt)
    }

    /// Controller signals published since the last call, in order (the first call
    /// subscribes), with the count of events lost by falling behind.
    pub fn events(&self) -> Result<(Vec<GuiEvent>, u64), Error> {
        let events = self.plane.events()?;
        Ok((
            events
                .records
                .iter()
                .filter_map(GuiEvent::from_record)
                .collect(),
            events.lost,
        ))
    }

    /// Destroys the plane; objects keep reading their last state.
    pub fn destroy(&self) -> Result<(), Error> {
        self.plane.destroy()
    }
}

/// The quaternion of a rotation by `deg` degrees about +Z.
pub fn rotation_z(deg: f32) -> [f32; 4] {
    let half = deg.to_radians() * 0.5;
    [0.0, 0.0, half.sin(), half.cos()]
}

/// The rotation about +Z (degrees) of a published quaternion.
pub fn degrees_of(q: [f32; 4]) -> f32 {
    (2.0 * q[2].atan2(q[3])).to_degrees()
}

/// One body of a GUI plane. Cheap to clone.
#[derive(Clone, Debug)]
pub struct GuiObject {
    plane: GuiPlane,
    handle: Handle,
}

impl GuiObject {
    /// The object `handle` of `plane` (one a snapshot, a restore or an opened named plane
    /// holds); stale handles are reported when used.
    pub fn from_handle(plane: &GuiPlane, handle: Handle) -> GuiObject {
        GuiObject {
            plane: plane.clone(),
            handle,
        }
    }

    /// The object's handle.
    pub fn handle(&self) -> Handle {
        self.handle
    }

    /// Its plane.
    pub fn plane(&self) -> &GuiPlane {
        &self.plane
    }

    /// The published state with this process's pending writes on top.
    pub fn state(&self) -> Result<BodyState, Error> {
        self.plane.plane.body(self.handle)?.ok_or_else(|| {
            Error::Command(shm_layout::CommandError::new(
                shm_layout::ErrorKind::StaleHandle,
                format!(
                    "GUI object {} of plane {} no longer exists",
                    self.handle,
                    self.plane.plane.id()
                ),
            ))
        })
    }

    /// Whether it still exists.
    pub fn is_alive(&self) -> Result<bool, Error> {
        Ok(self.plane.plane.body(self.handle)?.is_some())
    }

    /// Position (px).
    pub fn position(&self) -> Result<Vec2, Error> {
        let p = self.state()?.position;
        Ok([p[0], p[1]])
    }

    /// Velocity (px/s).
    pub fn velocity(&self) -> Result<Vec2, Error> {
        let v = self.state()?.linear_velocity;
        Ok([v[0], v[1]])
    }

    /// Rotation (degrees).
    pub fn rotation(&self) -> Result<f32, Error> {
        Ok(degrees_of(self.state()?.rotation))
    }

    /// Angular velocity (degrees/s).
    pub fn angular_velocity(&self) -> Result<f32, Error> {
        Ok(self.state()?.angular_velocity[2].to_degrees())
    }

    /// Asleep at the newest tick.
    pub fn is_sleeping(&self) -> Result<bool, Error> {
        Ok(self.state()?.is_sleeping())
    }

    /// Anchored.
    pub fn is_anchored(&self) -> Result<bool, Error> {
        Ok(self.state()?.is_anchored())
    }

    fn op(&self, op: GuiObjectOp) -> GuiOp {
        GuiOp::Object {
            handle: self.handle,
            op,
        }
    }

    /// Sets a property (checked now, sent with the next flush); Position, Velocity,
    /// Rotation, AngularVelocity and Anchored read back at once.
    pub fn set(&self, prop: GuiObjectProp) -> Result<(), Error> {
        let prop = prop.checked().map_err(Error::invalid_value)?;
        let state = self.state()?;
        let plane = &self.plane.plane;
        let published = matches!(
            prop,
            GuiObjectProp::Position(_)
                | GuiObjectProp::Rotation(_)
                | GuiObjectProp::Velocity(_)
                | GuiObjectProp::AngularVelocity(_)
                | GuiObjectProp::Anchored(_)
        );
        if published {
            plane.overlay_write(self.handle, |e| match prop {
                GuiObjectProp::Position(p) => {
                    e.pose = Some(Pose {
                        position: [p[0], p[1], 0.0],
                        rotation: e.pose.map_or(state.rotation, |q| q.rotation),
                    })
                }
                GuiObjectProp::Rotation(deg) => {
                    e.pose = Some(Pose {
                        position: e.pose.map_or(state.position, |q| q.position),
                        rotation: rotation_z(deg),
                    })
                }
                GuiObjectProp::Velocity(v) => {
                    e.record(&shm_layout::ObjectProp::Velocity([v[0], v[1], 0.0]))
                }
                GuiObjectProp::AngularVelocity(w) => {
                    e.angular_velocity = Some([0.0, 0.0, w.to_radians()])
                }
                GuiObjectProp::Anchored(a) => e.record(&shm_layout::ObjectProp::Anchored(a)),
                _ => {}
            });
        }
        self.plane.queue(
            self.op(GuiObjectOp::Set(prop)),
            published.then_some(self.handle),
        );
        Ok(())
    }

    /// `Δv = impulse / Mass`, sent with the next flush.
    pub fn apply_impulse(&self, impulse: Vec2) -> Result<(), Error> {
        let j = finite2("impulse", impulse).map_err(Error::invalid_value)?;
        let plane = &self.plane.plane;
        let ticket = plane.impulse_queued(self.handle);
        plane.client().queue_impulse(
            Command::plane(
                plane.id(),
                PlaneOp::Gui(self.op(GuiObjectOp::ApplyImpulse(j))),
            ),
            plane.id(),
            self.handle,
            ticket,
        );
        Ok(())
    }

    /// Wakes the body, sent with the next flush.
    pub fn wake(&self) -> Result<(), Error> {
        self.state()?;
        self.plane.queue(self.op(GuiObjectOp::Wake), None);
        Ok(())
    }

    /// Every property (one round trip).
    pub fn info(&self) -> Result<GuiObjectInfo, Error> {
        match self.plane.call(self.op(GuiObjectOp::Info))? {
            Reply::Gui(GuiReply::Object(info)) => Ok(*info),
            other => Err(unexpected(other)),
        }
    }

    /// Removes the body (sent with the next flush; reads see it gone at once).
    pub fn destroy(&self) {
        self.plane
            .plane
            .overlay_write(self.handle, |e| e.destroyed = true);
        self.plane
            .plane
            .shared
            .members
            .borrow_mut()
            .removal_queued(self.handle);
        self.plane
            .queue(self.op(GuiObjectOp::Destroy), Some(self.handle));
    }
}

/// A `GUIController`: the body it drives plus movement, jumps and waypoints.
#[derive(Clone, Debug)]
pub struct GuiController {
    object: GuiObject,
}

impl GuiController {
    /// The controller of `object` (which must have one for ops to succeed).
    pub fn of(object: &GuiObject) -> GuiController {
        GuiController {
            object: object.clone(),
        }
    }

    /// The body it drives.
    pub fn object(&self) -> &GuiObject {
        &self.object
    }

    fn op(&self, op: GuiControllerOp) -> Result<(), Error> {
        let op = op.checked().map_err(Error::invalid_value)?;
        self.object.plane.queue(
            GuiOp::Controller {
                handle: self.object.handle,
                op,
            },
            None,
        );
        Ok(())
    }

    /// Changes a tunable.
    pub fn set(&self, prop: GuiControllerProp) -> Result<(), Error> {
        self.op(GuiControllerOp::Set(prop))
    }

    /// The desired direction (components clamped to [-1, 1] when used).
    pub fn move_direction(&self, direction: Vec2) -> Result<(), Error> {
        self.op(GuiControllerOp::Move(direction))
    }

    /// Jumps at the next tick if on the ground.
    pub fn jump(&self) -> Result<(), Error> {
        self.op(GuiControllerOp::Jump)
    }

    /// Replaces the path.
    pub fn set_waypoints(&self, points: &[Vec2]) -> Result<(), Error> {
        self.op(GuiControllerOp::SetWaypoints(points.to_vec()))
    }

    /// Drops the path.
    pub fn clear_waypoints(&self) -> Result<(), Error> {
        self.op(GuiControllerOp::ClearWaypoints)
    }

    /// Everything about the controller (one round trip).
    pub fn info(&self) -> Result<GuiControllerInfo, Error> {
        match self.object.plane.call(GuiOp::Controller {
            handle: self.object.handle,
            op: GuiControllerOp::Info,
        })? {
            Reply::Gui(GuiReply::Controller(info)) => Ok(*info),
            other => Err(unexpected(other)),
        }
    }

    /// Removes the controller and its body.
    pub fn destroy(&self) -> Result<(), Error> {
        self.object
            .plane
            .plane
            .overlay_write(self.object.handle, |e| e.destroyed = true);
        // Like an object's removal: the plane's object count drops at once.
        self.object
            .plane
            .plane
            .shared
            .members
            .borrow_mut()
            .removal_queued(self.object.handle);
        self.op(GuiControllerOp::Destroy)
    }
}

/// A controller signal from the plane's event stream.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum GuiEvent {
    /// `GroundChanged(onGround)`.
    GroundChanged {
        /// The controller's body.
        handle: Handle,
        /// OnGround now.
        on_ground: bool,
    },
    /// `Moved(dx, dy)` (px in one tick).
    Moved {
        /// The controller's body.
        handle: Handle,
        /// Pixels moved along X.
        dx: f32,
        /// Pixels moved along Y.
        dy: f32,
    },
    /// `WaypointReached(index)` (1-based).
    WaypointReached {
        /// The controller's body.
        handle: Handle,
        /// 1-based index of the waypoint.
        index: u32,
    },
    /// `PathFinished()`.
    PathFinished {
        /// The controller's body.
        handle: Handle,
    },
}

impl GuiEvent {
    /// The signal a record stands for (`None` for other kinds).
    pub fn from_record(r: &EventRecord) -> Option<GuiEvent> {
        let handle = r.a();
        Some(match r.kind {
            EVENT_GUI_GROUND_CHANGED => GuiEvent::GroundChanged {
                handle,
                on_ground: r.b_slot != 0,
            },
            EVENT_GUI_MOVED => GuiEvent::Moved {
                handle,
                dx: r.position[0],
                dy: r.position[1],
            },
            EVENT_GUI_WAYPOINT_REACHED => GuiEvent::WaypointReached {
                handle,
                index: r.b_slot,
            },
            EVENT_GUI_PATH_FINISHED => GuiEvent::PathFinished { handle },
            _ => return None,
        })
    }

    /// The controller's body.
    pub fn handle(&self) -> Handle {
        match *self {
            GuiEvent::GroundChanged { handle, .. }
            | GuiEvent::Moved { handle, .. }
            | GuiEvent::WaypointReached { handle, .. }
            | GuiEvent::PathFinished { handle } => handle,
        }
    }
}

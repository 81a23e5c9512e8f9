//! Objects: reads index into the newest sample, writes join the client's batch.

use shm_layout::{
    BodyState, Command, Handle, ObjectInfo, ObjectOp, ObjectProp, Pin, PlaneOp, Pose, Reply,
    Restraint, RotateTo, Shape, Vec3,
};

use crate::{error::Error, plane::Plane};

/// One body of a plane. Cheap to clone.
#[derive(Clone)]
pub struct Object {
    plane: Plane,
    handle: Handle,
}

impl Object {
    pub(crate) fn new(plane: Plane, handle: Handle) -> Object {
        Object { plane, handle }
    }

    /// An object of `plane` known only by its handle (e.g. one created by another process).
    pub fn from_handle(plane: &Plane, handle: Handle) -> Object {
        Object::new(plane.clone(), handle)
    }

    /// The object's handle.
    pub fn handle(&self) -> Handle {
        self.handle
    }

    /// The plane the object belongs to.
    pub fn plane(&self) -> &Plane {
        &self.plane
    }

    /// The current state (newest tick, with this process's pending writes on top).
    pub fn state(&self) -> Result<BodyState, Error> {
        self.plane.body(self.handle)?.ok_or_else(|| {
            Error::Command(shm_layout::CommandError::new(
                shm_layout::ErrorKind::StaleHandle,
                format!(
                    "object {} of plane {} no longer exists",
                    self.handle,
                    self.plane.id()
                ),
            ))
        })
    }

    /// Whether the object still exists (newest tick, with pending writes on top).
    pub fn is_alive(&self) -> Result<bool, Error> {
        Ok(self.plane.body(self.handle)?.is_some())
    }

    /// The current position and rotation.
    pub fn pose(&self) -> Result<Pose, Error> {
        match self.plane.pose(self.handle)? {
            Some(pose) => Ok(pose),
            // The same error `state` gives.
            None => self.state().map(|s| s.pose()),
        }
    }

    /// The current position.
    pub fn position(&self) -> Result<Vec3, Error> {
        Ok(self.state()?.position)
    }

    /// The current linear velocity.
    pub fn velocity(&self) -> Result<Vec3, Error> {
        Ok(self.state()?.linear_velocity)
    }

    /// The current angular velocity (rad/s).
    pub fn angular_velocity(&self) -> Result<Vec3, Error> {
        Ok(self.state()?.angular_velocity)
    }

    /// Whether the object is anchored.
    pub fn is_anchored(&self) -> Result<bool, Error> {
        Ok(self.state()?.is_anchored())
    }

    /// Sets any property: checked now (errors name the property and the value), sent with
    /// the next flush. Pose, velocities and Anchored read back at once.
    pub fn set(&self, prop: ObjectProp) -> Result<(), Error> {
        let prop = prop.checked().map_err(Error::invalid_value)?;
        self.plane
            .shared
            .mirror
            .borrow_mut()
            .object_written(self.handle, &prop);
        let plane = self.plane.id();
        let published = prop.is_published();
        if published {
            self.plane.overlay_write(self.handle, |e| e.record(&prop));
        }
        self.plane.client().queue(
            Command::object(plane, self.handle, ObjectOp::Set(prop)),
            published.then_some((plane, self.handle)),
        );
        Ok(())
    }

    /// Teleports the object.
    pub fn set_pose(&self, pose: Pose) -> Result<(), Error> {
        self.set(ObjectProp::Pose(pose))
    }

    /// Sets the linear velocity.
    pub fn set_velocity(&self, v: Vec3) -> Result<(), Error> {
        self.set(ObjectProp::Velocity(v))
    }

    /// Sets the angular velocity (rad/s).
    pub fn set_angular_velocity(&self, w: Vec3) -> Result<(), Error> {
        self.set(ObjectProp::AngularVelocity(w))
    }

    /// Anchored objects do not move; setting it zeroes both velocities.
    pub fn set_anchored(&self, anchored: bool) -> Result<(), Error> {
        self.set(ObjectProp::Anchored(anchored))
    }

    /// Ask the daemon to publish contact started / stopped events for this object.
    pub fn set_report_contacts(&self, on: bool) -> Result<(), Error> {
        self.set(ObjectProp::ReportContacts(on))
    }

    /// Mass for impulses when Density is 0 (free fall does not depend on it).
    pub fn set_weight(&self, weight: f32) -> Result<(), Error> {
        self.set(ObjectProp::Weight(weight))
    }

    /// Mass = density × volume when > 0 (wins over Weight); 0 returns to Weight.
    pub fn set_density(&self, density: f32) -> Result<(), Error> {
        self.set(ObjectProp::Density(density))
    }

    /// Restitution, clamped to [0, 1]; a pair uses the higher value.
    pub fn set_bounciness(&self, e: f32) -> Result<(), Error> {
        self.set(ObjectProp::Bounciness(e))
    }

    /// Coulomb friction in [0, 1]; a pair uses `sqrt(a·b)`.
    pub fn set_friction(&self, mu: f32) -> Result<(), Error> {
        self.set(ObjectProp::Friction(mu))
    }

    /// When false the object passes through everything.
    pub fn set_can_collide(&self, on: bool) -> Result<(), Error> {
        self.set(ObjectProp::CanCollide(on))
    }

    /// Fidelity dial, clamped to [1, 32].
    pub fn set_hit_box_quality(&self, quality: u32) -> Result<(), Error> {
        self.set(ObjectProp::HitBoxQuality(quality))
    }

    /// Full size of the object's box (a sphere takes the smallest half-extent as radius;
    /// a mesh is scaled to it).
    pub fn set_size(&self, size: Vec3) -> Result<(), Error> {
        self.set(ObjectProp::Size(size))
    }

    /// Body-local centre of mass; non-zero switches to the real inertia of the shape.
    pub fn set_center_of_mass(&self, com: Vec3) -> Result<(), Error> {
        self.set(ObjectProp::CenterOfMass(com))
    }

    /// Persistent per-tick acceleration.
    pub fn set_impulse_direction(&self, a: Vec3) -> Result<(), Error> {
        self.set(ObjectProp::ImpulseDirection(a))
    }

    /// Persistent world-space force.
    pub fn set_constant_force(&self, f: Vec3) -> Result<(), Error> {
        self.set(ObjectProp::ConstantForce(f))
    }

    /// Locks or frees axes; flags left `None` keep their value.
    pub fn field_restraint(&self, restraint: Restraint) -> Result<(), Error> {
        self.set(ObjectProp::FieldRestraint(restraint))
    }

    /// Drives the angular velocity toward the orientation `target` (quaternion).
    pub fn rotate_to(&self, target: [f32; 4], strength: f32) -> Result<(), Error> {
        self.set(ObjectProp::RotateTo(Some(RotateTo { target, strength })))
    }

    /// Stops the [`rotate_to`](Object::rotate_to) controller (angular velocity is left as
    /// it is).
    pub fn stop_rotate_to(&self) -> Result<(), Error> {
        self.set(ObjectProp::RotateTo(None))
    }

    /// Pins a body-local point to `target` with a force capped at `force`; `None` releases.
    pub fn set_pin(&self, pin: Option<Pin>) -> Result<(), Error> {
        self.set(ObjectProp::Pin(pin))
    }

    /// Every property as the daemon holds it (sends the queue first).
    pub fn info(&self) -> Result<ObjectInfo, Error> {
        match self.plane.client().call(self.op(ObjectOp::Info))? {
            Reply::ObjectInfo(info) => {
                self.plane.shared.mirror.borrow_mut().store_object(&info);
                Ok(*info)
            }
            other => Err(Error::Protocol(format!("unexpected reply {other:?}"))),
        }
    }

    /// Every property without a round trip where this process mirrors them (objects of a
    /// plane it created and did not share: after one [`Object::info`], kept current by its
    /// own writes); otherwise [`Object::info`]. `anchored` and `sleeping` come from the
    /// newest tick (with this process's writes on top).
    pub fn properties(&self) -> Result<ObjectInfo, Error> {
        let mirrored = self
            .plane
            .shared
            .mirror
            .borrow()
            .object(self.handle)
            .cloned();
        match mirrored {
            Some(mut info) => {
                let state = self.state()?;
                info.anchored = state.is_anchored();
                info.sleeping = state.is_sleeping();
                Ok(info)
            }
            None => self.info(),
        }
    }

    /// CenterOfMass := vertex centroid of the object's mesh, or a wedge's centroid (no-op for
    /// the other primitives).
    /// Returns the centre of mass in effect.
    pub fn recalculate_center_of_mass(&self) -> Result<Vec3, Error> {
        match self
            .plane
            .client()
            .call(self.op(ObjectOp::RecalculateCenterOfMass))?
        {
            Reply::CenterOfMass(c) => {
                self.plane
                    .shared
                    .mirror
                    .borrow_mut()
                    .forget_object(self.handle);
                Ok(c)
            }
            other => Err(Error::Protocol(format!("unexpected reply {other:?}"))),
        }
    }

    /// Takes the object out of the simulation and returns the pose it stays at.
    pub fn unlink(&self) -> Result<Pose, Error> {
        let pose = self.pose()?;
        self.destroy();
        Ok(pose)
    }

    /// Velocity-space impulse (`Δv = impulse / mass`), sent with the next flush.
    pub fn apply_impulse(&self, impulse: Vec3) -> Result<(), Error> {
        let impulse =
            shm_layout::validate::finite3("impulse", impulse).map_err(Error::invalid_value)?;
        let ticket = self.plane.impulse_queued(self.handle);
        self.plane.client().queue_impulse(
            self.op(ObjectOp::ApplyImpulse(impulse)),
            self.plane.id(),
            self.handle,
            ticket,
        );
        Ok(())
    }

    /// Whether the object is asleep at the newest tick (read from shared memory, no
    /// request). A sleeping body does not move until something wakes it.
    pub fn is_sleeping(&self) -> Result<bool, Error> {
        Ok(self.state()?.is_sleeping())
    }

    /// Wakes the object (and, at the next step, what rests on it); sent with the next flush.
    pub fn wake(&self) -> Result<(), Error> {
        self.state()?;
        self.plane.client().queue(self.op(ObjectOp::Wake), None);
        Ok(())
    }

    fn op(&self, op: ObjectOp) -> Command {
        Command::object(self.plane.id(), self.handle, op)
    }

    /// Removes the object (sent with the next flush; reads see it gone at once).
    pub fn destroy(&self) {
        self.plane
            .shared
            .mirror
            .borrow_mut()
            .forget_object(self.handle);
        self.plane
            .shared
            .members
            .borrow_mut()
            .removal_queued(self.handle);
        self.plane
            .overlay_write(self.handle, |e| e.destroyed = true);
        let plane = self.plane.id();
        self.plane
            .client()
            .queue(self.op(ObjectOp::Destroy), Some((plane, self.handle)));
    }
}

impl std::fmt::Debug for Object {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Object")
            .field("plane", &self.plane.id())
            .field("handle", &self.handle)
            .finish()
    }
}

impl Plane {
    /// Adds an object; sends the queue and waits for the new handle.
    pub fn add(&self, shape: Shape, pose: Pose, props: &[ObjectProp]) -> Result<Object, Error> {
        shape.check().map_err(Error::invalid_value)?;
        let pose = shm_layout::validate::pose("CFrame", pose).map_err(Error::invalid_value)?;
        let props = props
            .iter()
            .map(|p| p.checked())
            .collect::<Result<Vec<_>, _>>()
            .map_err(Error::invalid_value)?;
        let hold = self.client().holds_adds();
        let mut sent = props.clone();
        if hold {
            sent.push(ObjectProp::Held(true));
        }
        let reply = self.client().call(Command::plane(
            self.id(),
            PlaneOp::AddObject {
                shape,
                pose,
                props: sent,
            },
        ))?;
        let Reply::Object { handle, tick } = reply else {
            return Err(Error::Protocol(format!("unexpected reply {reply:?}")));
        };
        if hold {
            // Released by the next flush, together with what the caller writes until then.
            let release = PlaneOp::Object {
                handle,
                op: ObjectOp::Set(ObjectProp::Held(false)),
            };
            self.client()
                .queue(Command::plane(self.id(), release), None);
        }
        // Until a sample shows it, the object reads back as created.
        let mut overlay = self.shared.overlay.borrow_mut();
        overlay.write(handle, |e| {
            e.pose = Some(pose);
            e.velocity = Some([0.0; 3]);
            e.angular_velocity = Some([0.0; 3]);
            for p in &props {
                e.record(p);
            }
        });
        overlay.confirm(handle, tick);
        self.shared.members.borrow_mut().added(tick);
        Ok(Object::new(self.clone(), handle))
    }
}

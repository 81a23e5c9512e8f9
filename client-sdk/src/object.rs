//! Objects: reads index into the newest sample, writes join the client's batch.

use shm_layout::{BodyState, Command, Handle, ObjectProp, Pose, Vec3};

use crate::{Error, Plane};

/// One body of a plane. Cheap to clone.
#[derive(Clone)]
pub struct Object {
    plane: Plane,
    handle: Handle,
}

fn check3(field: &str, v: Vec3) -> Result<Vec3, Error> {
    if v.iter().all(|c| c.is_finite()) {
        Ok(v)
    } else {
        Err(Error::Invalid {
            field: field.into(),
            message: format!("must be finite, got {v:?}"),
        })
    }
}

impl Object {
    pub(crate) fn new(plane: Plane, handle: Handle) -> Object {
        Object { plane, handle }
    }

    /// An object of `plane` known only by its handle (e.g. one created by another process).
    pub fn from_handle(plane: &Plane, handle: Handle) -> Object {
        Object::new(plane.clone(), handle)
    }

    pub fn handle(&self) -> Handle {
        self.handle
    }

    pub fn plane(&self) -> &Plane {
        &self.plane
    }

    /// The current state (newest tick, with this process's pending writes on top).
    pub fn state(&self) -> Result<BodyState, Error> {
        self.plane.body(self.handle)?.ok_or_else(|| {
            Error::Command(shm_layout::CommandError::new(
                shm_layout::ErrorKind::StaleHandle,
                format!(
                    "object {:?} of plane {} no longer exists",
                    self.handle,
                    self.plane.id()
                ),
            ))
        })
    }

    pub fn is_alive(&self) -> Result<bool, Error> {
        Ok(self.plane.body(self.handle)?.is_some())
    }

    pub fn pose(&self) -> Result<Pose, Error> {
        let s = self.state()?;
        Ok(Pose {
            position: s.position,
            rotation: s.rotation,
        })
    }

    pub fn position(&self) -> Result<Vec3, Error> {
        Ok(self.state()?.position)
    }

    pub fn velocity(&self) -> Result<Vec3, Error> {
        Ok(self.state()?.linear_velocity)
    }

    pub fn angular_velocity(&self) -> Result<Vec3, Error> {
        Ok(self.state()?.angular_velocity)
    }

    pub fn is_anchored(&self) -> Result<bool, Error> {
        Ok(self.state()?.is_anchored())
    }

    fn write(&self, prop: ObjectProp, f: impl FnOnce(&mut crate::overlay::Entry)) {
        self.plane.shared.overlay.borrow_mut().write(self.handle, f);
        let plane = self.plane.id();
        self.plane.client().queue(
            Command::SetObject {
                plane,
                object: self.handle,
                prop,
            },
            Some((plane, self.handle)),
        );
    }

    /// Teleports the object (sent with the next flush; reads see it at once).
    pub fn set_pose(&self, pose: Pose) -> Result<(), Error> {
        check3("CFrame.position", pose.position)?;
        let n = pose.rotation.iter().map(|c| c * c).sum::<f32>().sqrt();
        if !n.is_finite() || n < 1e-6 {
            return Err(Error::Invalid {
                field: "CFrame.rotation".into(),
                message: format!(
                    "must be a finite non-zero quaternion, got {:?}",
                    pose.rotation
                ),
            });
        }
        let pose = Pose {
            rotation: pose.rotation.map(|c| c / n),
            ..pose
        };
        self.write(ObjectProp::Pose(pose), |e| e.pose = Some(pose));
        Ok(())
    }

    pub fn set_velocity(&self, v: Vec3) -> Result<(), Error> {
        let v = check3("Velocity", v)?;
        self.write(ObjectProp::Velocity(v), |e| e.velocity = Some(v));
        Ok(())
    }

    pub fn set_angular_velocity(&self, w: Vec3) -> Result<(), Error> {
        let w = check3("AngularVelocity", w)?;
        self.write(ObjectProp::AngularVelocity(w), |e| {
            e.angular_velocity = Some(w)
        });
        Ok(())
    }

    pub fn set_anchored(&self, anchored: bool) {
        self.write(ObjectProp::Anchored(anchored), |e| {
            e.anchored = Some(anchored);
            e.velocity = Some([0.0; 3]);
            e.angular_velocity = Some([0.0; 3]);
        });
    }

    /// Ask the daemon to publish contact started / stopped events for this object.
    pub fn set_report_contacts(&self, on: bool) {
        let plane = self.plane.id();
        self.plane.client().queue(
            Command::SetObject {
                plane,
                object: self.handle,
                prop: ObjectProp::ReportContacts(on),
            },
            None,
        );
    }

    /// Velocity-space impulse (`Δv = impulse / mass`), sent with the next flush.
    pub fn apply_impulse(&self, impulse: Vec3) -> Result<(), Error> {
        let impulse = check3("impulse", impulse)?;
        let plane = self.plane.id();
        self.plane.client().queue(
            Command::ApplyImpulse {
                plane,
                object: self.handle,
                impulse,
            },
            None,
        );
        Ok(())
    }

    /// Removes the object (sent with the next flush; reads see it gone at once).
    pub fn destroy(&self) {
        self.plane
            .shared
            .overlay
            .borrow_mut()
            .write(self.handle, |e| e.destroyed = true);
        let plane = self.plane.id();
        self.plane.client().queue(
            Command::DestroyObject {
                plane,
                object: self.handle,
            },
            Some((plane, self.handle)),
        );
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

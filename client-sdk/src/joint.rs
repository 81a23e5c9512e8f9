//! Joints between two objects of a plane (or an object and the world): creation, live
//! options, the error figures, breaking. Every call is one round trip (the queue goes with
//! it), so a bad option is reported where it was given.

use shm_layout::joint_op::MAX_JOINT_PAGE;
use shm_layout::{
    Command, EventRecord, Handle, JointInfo, JointKind, JointOp, JointProp, PlaneOp, Reply, Vec3,
    EVENT_JOINT_BROKE,
};

use crate::{error::Error, object::Object, plane::Plane};

/// One joint. Cheap to clone.
#[derive(Clone)]
pub struct Joint {
    plane: Plane,
    handle: Handle,
    kind: JointKind,
}

/// A joint-broke event (`EVENT_JOINT_BROKE`) as the API names it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JointBroke {
    /// The joint.
    pub joint: Handle,
    /// Its object A.
    pub object: Handle,
    /// The constraint force that broke it.
    pub force: f32,
    /// World-space anchor on A when it broke.
    pub position: Vec3,
    /// The tick.
    pub tick: u64,
}

impl JointBroke {
    /// The joint-broke event a record carries, if it is one.
    pub fn from_record(r: &EventRecord) -> Option<JointBroke> {
        (r.kind == EVENT_JOINT_BROKE).then(|| JointBroke {
            joint: r.a(),
            object: r.b(),
            force: r.impulse,
            position: r.position,
            tick: r.tick,
        })
    }
}

impl Plane {
    /// Creates a joint of `kind` between `a` and `b` (`None`: the world, `AnchorB` then a
    /// world point), `props` applied over the kind's defaults.
    pub fn joint(
        &self,
        kind: JointKind,
        a: &Object,
        b: Option<&Object>,
        props: &[JointProp],
    ) -> Result<Joint, Error> {
        let op = JointOp::Create {
            kind,
            a: a.handle(),
            b: b.map(Object::handle),
            props: props.to_vec(),
        }
        .checked()
        .map_err(Error::invalid_value)?;
        match self
            .client()
            .call(Command::plane(self.id(), PlaneOp::Joint(op)))?
        {
            Reply::Joint { handle, .. } => Ok(Joint {
                plane: self.clone(),
                handle,
                kind,
            }),
            other => Err(Error::Protocol(format!("expected a joint, got {other:?}"))),
        }
    }

    /// Every live joint of the plane, described as [`Joint::info`] describes one, in
    /// ascending slot order (asked a page of [`MAX_JOINT_PAGE`] at a time until a short
    /// page). Read-only: any client may list any plane's joints.
    pub fn joints(&self) -> Result<Vec<JointInfo>, Error> {
        let mut all = Vec::new();
        let mut after = 0u32;
        loop {
            let page = self.joint_page(after, MAX_JOINT_PAGE)?;
            let full = page.len() >= MAX_JOINT_PAGE as usize;
            let next = match page.last() {
                Some(last) if last.handle.slot < after => {
                    return Err(Error::Protocol(format!(
                        "a joint page from slot {after} listed slot {}",
                        last.handle.slot
                    )))
                }
                Some(last) => last.handle.slot.checked_add(1),
                None => None,
            };
            all.extend(page);
            match next {
                Some(n) if full => after = n,
                _ => return Ok(all),
            }
        }
    }

    /// One page of the plane's joints: those in slots from `after` on, ascending, at most
    /// `limit` (1 to [`MAX_JOINT_PAGE`]; more is cut to a page). The next page starts at
    /// the last joint's slot + 1; a page shorter than `limit` is the last.
    pub fn joint_page(&self, after: u32, limit: u32) -> Result<Vec<JointInfo>, Error> {
        let op = JointOp::List { after, limit }
            .checked()
            .map_err(Error::invalid_value)?;
        match self
            .client()
            .call(Command::plane(self.id(), PlaneOp::Joint(op)))?
        {
            Reply::Joints(joints) => Ok(joints),
            other => Err(Error::Protocol(format!(
                "expected a joint list, got {other:?}"
            ))),
        }
    }
}

impl Joint {
    /// The joint `handle` of `plane` (a joint of a plane restored from a snapshot, or
    /// another process's joint).
    pub fn from_handle(plane: &Plane, handle: Handle, kind: JointKind) -> Joint {
        Joint {
            plane: plane.clone(),
            handle,
            kind,
        }
    }

    /// The joint's handle.
    pub fn handle(&self) -> Handle {
        self.handle
    }

    /// Its kind.
    pub fn kind(&self) -> JointKind {
        self.kind
    }

    /// The plane it belongs to.
    pub fn plane(&self) -> &Plane {
        &self.plane
    }

    fn call(&self, op: JointOp) -> Result<Reply, Error> {
        self.plane
            .client()
            .call(Command::plane(self.plane.id(), PlaneOp::Joint(op)))
    }

    /// Changes one option (checked here and by the daemon against the others).
    pub fn set(&self, prop: JointProp) -> Result<(), Error> {
        let prop = prop.checked().map_err(Error::invalid_value)?;
        self.call(JointOp::Set {
            joint: self.handle,
            prop,
        })
        .map(|_| ())
    }

    /// Every option and figure (error, force, broken, position).
    pub fn info(&self) -> Result<JointInfo, Error> {
        match self.call(JointOp::Info { joint: self.handle })? {
            Reply::JointInfo(info) => Ok(*info),
            other => Err(Error::Protocol(format!(
                "expected joint info, got {other:?}"
            ))),
        }
    }

    /// Positional error after the last step (units).
    pub fn error(&self) -> Result<f32, Error> {
        Ok(self.info()?.error)
    }

    /// Whether the joint broke.
    pub fn is_broken(&self) -> Result<bool, Error> {
        Ok(self.info()?.broken)
    }

    /// Removes the joint.
    pub fn destroy(&self) -> Result<(), Error> {
        self.call(JointOp::Destroy { joint: self.handle })
            .map(|_| ())
    }
}

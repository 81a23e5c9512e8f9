//! [`SceneTarget`]: the one operation a scene builder needs, adding an object, implemented
//! by the daemon's plane code in process, by client-sdk's plane and by a plain list, so each
//! builder is written once for all of them.

use shm_layout::{CommandError, Handle, ObjectProp, Pose, Shape};

/// The daemon's plane code, stepped in process: exactly what the daemon steps (its 3D plane
/// kind, with the GPU path when the daemon has it).
///
/// The single place this crate, and `physics-bench` through it, names the daemon's plane
/// type.
pub type LocalPlane = physics_daemon::kinds::Plane3d;

/// Somewhere a scene builder can add objects.
pub trait SceneTarget {
    /// What addresses an added object.
    type Handle;
    /// Why adding an object failed.
    type Error;

    /// Adds an object of `shape` at `pose`, then applies `props` in order.
    fn add(
        &mut self,
        shape: Shape,
        pose: Pose,
        props: &[ObjectProp],
    ) -> Result<Self::Handle, Self::Error>;
}

impl SceneTarget for LocalPlane {
    type Handle = Handle;
    type Error = CommandError;

    fn add(
        &mut self,
        shape: Shape,
        pose: Pose,
        props: &[ObjectProp],
    ) -> Result<Handle, Self::Error> {
        self.add_object(&shape, pose, props)
    }
}

/// client-sdk's plane adds through a shared reference, so the target is a shared reference
/// to one: `floor(&mut &plane, ...)`.
impl SceneTarget for &client_sdk::Plane {
    type Handle = client_sdk::Object;
    type Error = client_sdk::Error;

    fn add(
        &mut self,
        shape: Shape,
        pose: Pose,
        props: &[ObjectProp],
    ) -> Result<client_sdk::Object, client_sdk::Error> {
        client_sdk::Plane::add(self, shape, pose, props)
    }
}

/// One object of a scene as a builder asked for it.
#[derive(Debug, Clone, PartialEq)]
pub struct Spawn {
    /// The object's shape.
    pub shape: Shape,
    /// Where it starts.
    pub pose: Pose,
    /// Its properties, in the order they are applied.
    pub props: Vec<ObjectProp>,
}

/// Records a scene instead of building it; an object's handle is its index in the list.
impl SceneTarget for Vec<Spawn> {
    type Handle = usize;
    type Error = std::convert::Infallible;

    fn add(
        &mut self,
        shape: Shape,
        pose: Pose,
        props: &[ObjectProp],
    ) -> Result<usize, Self::Error> {
        self.push(Spawn {
            shape,
            pose,
            props: props.to_vec(),
        });
        Ok(self.len() - 1)
    }
}

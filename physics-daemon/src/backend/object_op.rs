//! The object op every plane kind shares ([`ObjectOpOf`]: set a property, apply an impulse,
//! wake, describe, destroy), routed once here for every kind: a kind implements
//! [`ObjectPlane`] over its own property enum and impulse vector and hands its object ops to
//! [`object_op`], which also gives every kind the same replies.

use shm_layout::{CommandError, CommandResult, Handle, ObjectOpOf, Reply, Vec3};

/// A plane kind's objects as the shared object op reaches them.
pub trait ObjectPlane {
    /// The kind's object properties (`ObjectProp`, `GuiObjectProp`).
    type Prop;
    /// The kind's impulse vector (`Vec3`, `Vec2`).
    type Impulse;

    /// Ticks stepped so far (stamped into the replies).
    fn tick_now(&self) -> u64;

    /// Sets one property of `handle` (checked; errors name the property and the value).
    fn set_prop(&mut self, handle: Handle, prop: Self::Prop) -> Result<(), CommandError>;

    /// `Δv = impulse / mass` now; returns the linear velocity right after it, as published.
    fn impulse(&mut self, handle: Handle, impulse: Self::Impulse) -> Result<Vec3, CommandError>;

    /// Wakes the object.
    fn wake_object(&mut self, handle: Handle) -> Result<(), CommandError>;

    /// Every property of the object, as the kind replies it.
    fn info_reply(&self, handle: Handle) -> CommandResult;

    /// Removes the object; its handle becomes stale.
    fn destroy(&mut self, handle: Handle) -> Result<(), CommandError>;
}

/// Applies the shared object op `op` to the object `handle` of `plane`.
pub fn object_op<T: ObjectPlane>(
    plane: &mut T,
    handle: Handle,
    op: ObjectOpOf<T::Prop, T::Impulse>,
) -> CommandResult {
    let applied = |plane: &T| Reply::Applied {
        tick: plane.tick_now(),
    };
    match op {
        ObjectOpOf::Set(prop) => plane.set_prop(handle, prop).map(|_| applied(plane)),
        ObjectOpOf::ApplyImpulse(j) => plane.impulse(handle, j).map(|linear| Reply::Velocity {
            tick: plane.tick_now(),
            linear,
        }),
        ObjectOpOf::Wake => plane.wake_object(handle).map(|_| applied(plane)),
        ObjectOpOf::Info => plane.info_reply(handle),
        ObjectOpOf::Destroy => plane.destroy(handle).map(|_| applied(plane)),
    }
}

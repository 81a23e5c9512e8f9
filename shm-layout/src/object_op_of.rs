//! The object op every plane kind shares, generic over the kind's property enum and its
//! impulse vector: set a property, apply an impulse, wake, describe, destroy. The GUI
//! plane's object op is this op over its own properties (`GuiObjectOp`); the 3D object op
//! keeps its own wire order and hands over the shared part ([`ObjectOp::into_common`]), so
//! the daemon routes both through one function (`physics_daemon::backend::object_op`).

use serde::{Deserialize, Serialize};

use crate::geometry::Vec3;
use crate::object_op::ObjectOp;
use crate::settings::ObjectProp;

/// An op on one object of a plane whose properties are `P` and whose impulses are `V`
/// (`Vec3` in 3D, `Vec2` on GUI planes). The variant order is the wire order.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum ObjectOpOf<P, V> {
    /// Sets one property. Replies `Reply::Applied`.
    Set(P),
    /// `Δv = impulse / mass` now; wakes the body. Replies `Reply::Velocity`.
    ApplyImpulse(V),
    /// Wakes the body (and what rests on it). Replies `Reply::Applied`.
    Wake,
    /// Every property of the object (the kind's info reply).
    Info,
    /// Removes the object; its handle becomes stale. Replies `Reply::Applied`.
    Destroy,
}

impl ObjectOp {
    /// The op as the shared object op, or itself when it is one of the 3D plane's own
    /// (`RecalculateCenterOfMass`, `Contacts`).
    pub fn into_common(self) -> Result<ObjectOpOf<ObjectProp, Vec3>, ObjectOp> {
        Ok(match self {
            ObjectOp::Set(p) => ObjectOpOf::Set(p),
            ObjectOp::ApplyImpulse(j) => ObjectOpOf::ApplyImpulse(j),
            ObjectOp::Wake => ObjectOpOf::Wake,
            ObjectOp::Info => ObjectOpOf::Info,
            ObjectOp::Destroy => ObjectOpOf::Destroy,
            own @ (ObjectOp::RecalculateCenterOfMass | ObjectOp::Contacts) => return Err(own),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{GuiObjectOp, GuiObjectProp};

    /// The GUI object op is the shared op: its wire (variant indices and payloads) is what
    /// it was as an enum of its own (Set, ApplyImpulse, Wake, Info, Destroy).
    #[test]
    fn the_gui_object_op_keeps_its_wire() {
        let ops = [
            GuiObjectOp::Set(GuiObjectProp::Anchored(true)),
            GuiObjectOp::ApplyImpulse([1.5, -2.0]),
            GuiObjectOp::Wake,
            GuiObjectOp::Info,
            GuiObjectOp::Destroy,
        ];
        for (i, op) in ops.iter().enumerate() {
            let bytes = postcard::to_allocvec(op).unwrap();
            assert_eq!(bytes[0] as usize, i, "{op:?}");
            assert_eq!(postcard::from_bytes::<GuiObjectOp>(&bytes).unwrap(), *op);
        }
        let impulse = postcard::to_allocvec(&ops[1]).unwrap();
        assert_eq!(
            impulse,
            postcard::to_allocvec(&(1u8, [1.5f32, -2.0])).unwrap()
        );
    }

    #[test]
    fn the_3d_op_splits_into_the_shared_op_and_its_own() {
        assert_eq!(
            ObjectOp::ApplyImpulse([0.0, 1.0, 0.0]).into_common(),
            Ok(ObjectOpOf::ApplyImpulse([0.0, 1.0, 0.0]))
        );
        assert_eq!(ObjectOp::Info.into_common(), Ok(ObjectOpOf::Info));
        assert_eq!(ObjectOp::Contacts.into_common(), Err(ObjectOp::Contacts));
        assert_eq!(
            ObjectOp::RecalculateCenterOfMass.into_common(),
            Err(ObjectOp::RecalculateCenterOfMass)
        );
    }
}

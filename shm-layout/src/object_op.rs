//! What a command does to one object of a plane.

use serde::{Deserialize, Serialize};

use crate::geometry::Vec3;
use crate::settings::ObjectProp;

/// An op on one object.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum ObjectOp {
    /// Sets one property.
    Set(ObjectProp),
    /// Velocity-space impulse (`Δv = impulse / mass`).
    ApplyImpulse(Vec3),
    /// Every property of the object.
    Info,
    /// Sets the centre of mass to the vertex centroid of the object's mesh (no-op for a cube
    /// or sphere); replies with the centre of mass in effect.
    RecalculateCenterOfMass,
    /// Wakes a sleeping object (and what rests on it) up.
    Wake,
    /// Removes the object.
    Destroy,
    /// Every object it touches now, with the contact points of each pair
    /// ([`crate::Reply::Contacts`]).
    Contacts,
}

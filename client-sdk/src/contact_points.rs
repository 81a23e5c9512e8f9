//! Contact manifolds for game code: [`Object::contacts`] lists every object one touches now
//! with up to four contact points per pair (a box resting flat on a floor: its four bottom
//! corners, their impulses summing to what holds it up). Contact-started events carry the
//! same points ([`shm_layout::EventRecord::contact_points`]).

use shm_layout::{Command, ContactInfo, ObjectOp, Reply};

use crate::{error::Error, object::Object};

impl Object {
    /// Every object this one touches now (after the newest tick; one round trip, the queue
    /// goes first): the deepest point, its normal (from this object toward the other), the
    /// pair's total normal impulse of the last step and up to four contact points.
    pub fn contacts(&self) -> Result<Vec<ContactInfo>, Error> {
        let op = Command::object(self.plane().id(), self.handle(), ObjectOp::Contacts);
        match self.plane().client().call(op)? {
            Reply::Contacts(list) => Ok(list),
            other => Err(Error::Protocol(format!("expected contacts, got {other:?}"))),
        }
    }
}

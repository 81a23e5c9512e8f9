//! `PhysicsObject`: what `plane:Add(part)` returns. Property reads index into the newest
//! tick in shared memory; writes join the client's per-frame batch.

use std::rc::Rc;

use client_sdk::Object;
use mlua::{AnyUserData, MetaMethod, UserData, UserDataMethods, Value};

use crate::part::PartState;
use crate::props::object::{NOT_YET_METHODS, OBJECT};
use crate::props::{not_yet_methods, Kind};

pub struct PhysicsObject {
    pub object: Object,
    pub part: Rc<PartState>,
    /// The wrapped part's own userdata, so `obj:BasePart() == part`.
    pub part_ud: AnyUserData,
}

impl PhysicsObject {
    /// The body, while this object still wraps its part in a plane.
    pub fn live(&self, what: &str) -> mlua::Result<&Object> {
        if self.part.is_linked_to(&self.object) {
            Ok(&self.object)
        } else {
            Err(mlua::Error::runtime(format!(
                "PhysicsObject.{what}: the object was destroyed or unlinked"
            )))
        }
    }

    pub fn alive(&self) -> bool {
        self.part.is_linked_to(&self.object) && self.object.is_alive().unwrap_or(false)
    }
}

impl UserData for PhysicsObject {
    fn add_methods<M: UserDataMethods<Self>>(methods: &mut M) {
        methods.add_method("ApplyImpulse", |_, o, v: Value| {
            let j = Kind::Vector
                .convert("PhysicsObject:ApplyImpulse", &v)?
                .vector()?;
            o.live("ApplyImpulse")?
                .apply_impulse(j)
                .map_err(|e| crate::convert::sdk_error("PhysicsObject:ApplyImpulse", e))
        });
        methods.add_method("BasePart", |_, o, ()| Ok(o.part_ud.clone()));
        // The body leaves the plane; the part stays where the simulation left it.
        methods.add_method("Unlink", |_, o, ()| {
            if o.part.is_linked_to(&o.object) {
                o.part.detach();
            }
            Ok(())
        });
        methods.add_method("Destroy", |_, o, ()| {
            o.part.destroy();
            Ok(())
        });
        not_yet_methods(methods, "PhysicsObject", NOT_YET_METHODS);
        methods.add_meta_method(MetaMethod::Index, |lua, o, key: Value| {
            OBJECT.get(lua, o, &key)
        });
        methods.add_meta_method(
            MetaMethod::NewIndex,
            |lua, o, (key, value): (Value, Value)| OBJECT.set(lua, o, &key, &value),
        );
        methods.add_meta_method(MetaMethod::ToString, |_, o, ()| {
            Ok(format!("PhysicsObject \"{}\"", o.part.name()))
        });
    }
}

//! `PhysicsObject`: what `plane:Add(part)` returns. Property reads index into the newest
//! tick in shared memory; writes join the client's per-frame batch.

use std::rc::Rc;

use client_sdk::Object;
use mlua::{AnyUserData, Lua, MetaMethod, MultiValue, Table, UserData, UserDataMethods, Value};

use crate::convert::{expected, sdk_error};

use crate::part::PartState;
use crate::props::object::{NOT_YET_METHODS, OBJECT};
use crate::props::Kind;

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

/// `self` of a method called on a PhysicsObject.
fn this(what: &str, v: &Value) -> mlua::Result<mlua::UserDataRef<PhysicsObject>> {
    match v {
        Value::UserData(ud) => ud.borrow::<PhysicsObject>().ok(),
        _ => None,
    }
    .ok_or_else(|| expected(what, "a PhysicsObject as self (call it with ':')", v))
}

/// PhysicsObject's methods, looked up by `__index` after its properties.
pub fn methods(lua: &Lua) -> mlua::Result<Table> {
    let t = lua.create_table()?;
    t.set(
        "ApplyImpulse",
        lua.create_function(|_, (o, v): (Value, Value)| {
            let o = this("PhysicsObject:ApplyImpulse", &o)?;
            let j = Kind::Vector
                .convert("PhysicsObject:ApplyImpulse", &v)?
                .vector()?;
            o.live("ApplyImpulse")?
                .apply_impulse(j)
                .map_err(|e| sdk_error("PhysicsObject:ApplyImpulse", e))
        })?,
    )?;
    t.set(
        "BasePart",
        lua.create_function(|_, o: Value| Ok(this("PhysicsObject:BasePart", &o)?.part_ud.clone()))?,
    )?;
    // The body leaves the plane; the part stays where the simulation left it.
    t.set(
        "Unlink",
        lua.create_function(|_, o: Value| {
            let o = this("PhysicsObject:Unlink", &o)?;
            if o.part.is_linked_to(&o.object) {
                o.part.detach();
            }
            Ok(())
        })?,
    )?;
    t.set(
        "Destroy",
        lua.create_function(|_, o: Value| {
            this("PhysicsObject:Destroy", &o)?.part.destroy();
            Ok(())
        })?,
    )?;
    for &name in NOT_YET_METHODS {
        t.set(
            name,
            lua.create_function(move |_, _: MultiValue| -> mlua::Result<()> {
                Err(mlua::Error::runtime(format!(
                    "PhysicsObject:{name} is not supported yet"
                )))
            })?,
        )?;
    }
    Ok(t)
}

impl UserData for PhysicsObject {
    // Methods come from `__index` after the properties (see BasePart for why).
    fn add_methods<M: UserDataMethods<Self>>(methods: &mut M) {
        methods.add_meta_method(MetaMethod::Index, |lua, o, key: Value| {
            match OBJECT.row(&key) {
                Some(_) => OBJECT.get(lua, o, &key),
                None => crate::method_tables(lua)
                    .object
                    .raw_get::<Option<mlua::Function>>(key.clone())?
                    .map(Value::Function)
                    .ok_or_else(|| OBJECT.unknown(&key)),
            }
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

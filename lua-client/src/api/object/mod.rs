//! `PhysicsObject`: what `plane:Add(part)` returns. Property reads index into the newest
//! tick in shared memory; writes join the client's per-frame batch.

pub(crate) mod props;
pub(crate) mod state;

use std::rc::Rc;

use client_sdk::{Pin, Restraint};
use mlua::{AnyUserData, Lua, MetaMethod, Table, UserData, UserDataMethods, Value};

use super::method_tables::index;
use super::part::state::Ended;
use crate::props::Kind;
use crate::values::{describe, expected, new_vector, rotation, sdk_error, DESCRIBE};
use props::OBJECT;
use state::PhysicsObject;

/// RotateTo's documented default strength.
const DEFAULT_STRENGTH: f64 = 8.0;
const LOCK_FLAGS: [&str; 6] = [
    "LockX", "LockY", "LockZ", "LockRotX", "LockRotY", "LockRotZ",
];

/// `FieldRestraint{...}`: a table of the six lock flags; unknown keys and non-booleans fail.
fn restraint(opts: &Value) -> mlua::Result<Restraint> {
    let what = "PhysicsObject:FieldRestraint";
    let Value::Table(t) = opts else {
        return Err(expected(what, "a table of lock flags", opts));
    };
    let mut flags = [None; 6];
    for pair in t.pairs::<Value, Value>() {
        let (key, value) = pair?;
        let name = match &key {
            Value::String(s) => s.to_string_lossy(),
            other => describe(other),
        };
        let Some(i) = LOCK_FLAGS.iter().position(|f| *f == name) else {
            return Err(mlua::Error::runtime(format!(
                "{what}: unknown flag \"{name}\" (expected one of {})",
                LOCK_FLAGS.join(", ")
            )));
        };
        let Value::Boolean(on) = value else {
            return Err(expected(&format!("{what} {name}"), "a boolean", &value));
        };
        flags[i] = Some(on);
    }
    let [lock_x, lock_y, lock_z, lock_rot_x, lock_rot_y, lock_rot_z] = flags;
    Ok(Restraint {
        lock_x,
        lock_y,
        lock_z,
        lock_rot_x,
        lock_rot_y,
        lock_rot_z,
    })
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
            o.live("PhysicsObject:ApplyImpulse")?
                .apply_impulse(j)
                .map_err(|e| sdk_error("PhysicsObject:ApplyImpulse", e))
        })?,
    )?;
    t.set(
        "BasePart",
        lua.create_function(|_, o: Value| Ok(this("PhysicsObject:BasePart", &o)?.part_ud.clone()))?,
    )?;
    // The body leaves the plane; the part stays where the simulation left it. On an object
    // that is no longer its part's body (unlinked, destroyed, its plane destroyed) Unlink
    // and Destroy do nothing: the part may be in a plane again, with another body.
    t.set(
        "Unlink",
        lua.create_function(|_, o: Value| {
            let o = this("PhysicsObject:Unlink", &o)?;
            if o.body.ended().is_none() {
                o.part.detach(Ended::Unlinked);
            }
            Ok(())
        })?,
    )?;
    t.set(
        "Destroy",
        lua.create_function(|_, o: Value| {
            let o = this("PhysicsObject:Destroy", &o)?;
            if o.body.ended().is_none() {
                o.part.destroy();
            }
            Ok(())
        })?,
    )?;
    t.set(
        "FieldRestraint",
        lua.create_function(|_, (o, opts): (Value, Value)| {
            let o = this("PhysicsObject:FieldRestraint", &o)?;
            let r = restraint(&opts)?;
            o.live("PhysicsObject:FieldRestraint")?
                .field_restraint(r)
                .map_err(|e| sdk_error("PhysicsObject:FieldRestraint", e))
        })?,
    )?;
    t.set(
        "RotateTo",
        lua.create_function(|_, (o, target, strength): (Value, Value, Value)| {
            let what = "PhysicsObject:RotateTo";
            let o = this(what, &o)?;
            let euler = Kind::Vector
                .convert(&format!("{what} target"), &target)?
                .vector()?;
            let strength = match strength {
                Value::Nil => DEFAULT_STRENGTH,
                v => Kind::NON_NEGATIVE
                    .convert(&format!("{what} strength"), &v)?
                    .number()?,
            };
            o.live(what)?
                .rotate_to(rotation::from_euler(euler), strength as f32)
                .map_err(|e| sdk_error(what, e))
        })?,
    )?;
    t.set(
        "StopRotateTo",
        lua.create_function(|_, o: Value| {
            let o = this("PhysicsObject:StopRotateTo", &o)?;
            o.live("PhysicsObject:StopRotateTo")?
                .stop_rotate_to()
                .map_err(|e| sdk_error("PhysicsObject:StopRotateTo", e))
        })?,
    )?;
    t.set(
        "SetPin",
        lua.create_function(
            |_, (o, force, relative, target): (Value, Value, Value, Value)| {
                let what = "PhysicsObject:SetPin";
                let o = this(what, &o)?;
                let pin = match force {
                    Value::Nil => None,
                    force => Some(Pin {
                        force: Kind::NON_NEGATIVE
                            .convert(&format!("{what} force"), &force)?
                            .number()? as f32,
                        relative: Kind::Vector
                            .convert(&format!("{what} relative"), &relative)?
                            .vector()?,
                        target: Kind::CFrame
                            .convert(&format!("{what} target"), &target)?
                            .cframe()?
                            .pose(),
                    }),
                };
                o.live(what)?.set_pin(pin).map_err(|e| sdk_error(what, e))
            },
        )?,
    )?;
    t.set(
        "Wake",
        lua.create_function(|_, o: Value| {
            let what = "PhysicsObject:Wake";
            let o = this(what, &o)?;
            o.live(what)?.wake().map_err(|e| sdk_error(what, e))
        })?,
    )?;
    // Lua parts carry no mesh: a Wedge gets its centroid back, other shapes keep theirs.
    t.set(
        "RecalculateCenterOfMass",
        lua.create_function(|_, o: Value| {
            let what = "PhysicsObject:RecalculateCenterOfMass";
            let o = this(what, &o)?;
            let com = o
                .live(what)?
                .recalculate_center_of_mass()
                .map_err(|e| sdk_error(what, e))?;
            Ok(new_vector(com))
        })?,
    )?;
    t.set(
        "GetContacts",
        lua.create_function(super::contact_points::get_contacts)?,
    )?;
    Ok(t)
}

impl UserData for PhysicsObject {
    // Methods come from `__index` after the properties (see `method_tables::index`).
    fn add_methods<M: UserDataMethods<Self>>(methods: &mut M) {
        methods.add_meta_method(MetaMethod::Index, |lua, o, key: Value| {
            index(lua, &OBJECT, |m| &m.object, o, key)
        });
        methods.add_meta_method(
            MetaMethod::NewIndex,
            |lua, o, (key, value): (Value, Value)| OBJECT.set(lua, o, &key, &value),
        );
        methods.add_meta_method(MetaMethod::ToString, |_, o, ()| Ok(o.tostring()));
        methods.add_meta_method(DESCRIBE, |_, o, ()| Ok(o.describe()));
        // Two handles on the same body (e.g. `plane:Add`'s and a raycast's) are equal.
        methods.add_meta_method(MetaMethod::Eq, |_, o, other: Value| {
            Ok(match other {
                Value::UserData(ud) => ud
                    .borrow::<PhysicsObject>()
                    .is_ok_and(|p| Rc::ptr_eq(&p.body, &o.body)),
                _ => false,
            })
        });
    }
}

/// The script's `PhysicsObject` value of `o`'s body (one per body: see `identity.rs`).
pub(crate) fn object_ud(lua: &Lua, o: PhysicsObject) -> mlua::Result<AnyUserData> {
    let address = Rc::as_ptr(&o.body).cast();
    crate::host::identity::userdata(lua, address, crate::host::identity::tag::OBJECT, || o)
}

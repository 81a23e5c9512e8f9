//! `PhysicsGuiObject`: the body `GuiPhysicsPlane:Add(primitive)` returns (its handle lives
//! with the GUI plane's state, `gui_plane/state.rs`). Its properties are the rows in
//! `props.rs`; its methods are `ApplyImpulse`, `ApplyForce`, `Wake` and `Destroy` (the
//! primitive stays at its last simulated position).

pub(crate) mod props;

use std::rc::Rc;

use client_sdk::GuiObjectProp;
use mlua::{MetaMethod, UserData, UserDataMethods, Value};

use super::gui_basic::GuiPrimitive;
use super::gui_plane::state::PhysicsGuiObject;
use crate::values::dim_arg;
use crate::values::sdk_error;

impl UserData for PhysicsGuiObject {
    fn add_methods<M: UserDataMethods<Self>>(methods: &mut M) {
        methods.add_method("ApplyImpulse", |_, o, j: Value| {
            const WHAT: &str = "PhysicsGuiObject:ApplyImpulse";
            o.check_alive(WHAT)?;
            let j = dim_arg(WHAT, &j)?;
            o.object.apply_impulse(j).map_err(|e| sdk_error(WHAT, e))
        });
        methods.add_method("ApplyForce", |_, o, f: Value| {
            const WHAT: &str = "PhysicsGuiObject:ApplyForce";
            o.check_alive(WHAT)?;
            let f = dim_arg(WHAT, &f)?;
            o.object
                .set(GuiObjectProp::ConstantForce(f))
                .map_err(|e| sdk_error(WHAT, e))
        });
        methods.add_method("Wake", |_, o, ()| {
            const WHAT: &str = "PhysicsGuiObject:Wake";
            o.check_alive(WHAT)?;
            o.object.wake().map_err(|e| sdk_error(WHAT, e))
        });
        methods.add_method("Destroy", |_, o, ()| {
            if !o.alive() {
                return Ok(());
            }
            o.object.destroy();
            o.prim.unlink();
            if let Some(p) = o.plane.upgrade() {
                p.forget(&o.prim, o.object.handle());
            }
            Ok(())
        });
        methods.add_method("Primitive", |_, o, ()| Ok(GuiPrimitive(o.prim.clone())));
        methods.add_meta_method(MetaMethod::Index, |lua, o, key: Value| {
            props::GUI_OBJECT.get(lua, o, &key)
        });
        methods.add_meta_method(
            MetaMethod::NewIndex,
            |lua, o, (key, value): (Value, Value)| props::GUI_OBJECT.set(lua, o, &key, &value),
        );
        methods.add_meta_method(MetaMethod::ToString, |_, o, ()| {
            Ok(if o.alive() {
                "PhysicsGuiObject"
            } else {
                "PhysicsGuiObject (destroyed)"
            })
        });
    }
}

/// The script's `PhysicsGuiObject` value of `o` (one per body: see `identity.rs`).
pub(crate) fn gui_object_ud(
    lua: &mlua::Lua,
    o: PhysicsGuiObject,
) -> mlua::Result<mlua::AnyUserData> {
    let handle = o.object.handle();
    crate::host::identity::userdata_if(
        lua,
        Rc::as_ptr(&o.prim).cast(),
        crate::host::identity::tag::GUI_OBJECT,
        |held: &PhysicsGuiObject| held.object.handle() == handle,
        || o,
    )
}

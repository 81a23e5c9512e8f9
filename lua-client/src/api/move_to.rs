//! `plane:MoveTo(daemon)` in Luau: moves a 3D plane to another daemon of the cluster in a
//! `--cluster` run (docs/cluster.md "Migration"). The plane keeps its tick, objects and
//! handles; the script's `PhysicsPlane` and `PhysicsObject` values stay valid, and
//! `plane.Daemon` names the new daemon.

use mlua::{UserDataMethods, Value};

use super::plane::state::PhysicsPlane;
use crate::values::sdk_error;

/// `MoveTo` on `PhysicsPlane`.
pub fn add_methods<M: UserDataMethods<PhysicsPlane>>(methods: &mut M) {
    methods.add_method("MoveTo", |_, p, daemon: Value| {
        const WHAT: &str = "PhysicsPlane:MoveTo";
        let Value::String(name) = &daemon else {
            return Err(mlua::Error::runtime(format!(
                "{WHAT}: daemon must be a string (a daemon's --name), got {}",
                daemon.type_name()
            )));
        };
        let name = name.to_str()?.to_string();
        if !p.0.alive() {
            return Err(mlua::Error::runtime(format!(
                "{WHAT}: the plane was destroyed"
            )));
        }
        p.0.plane.move_to(&name).map_err(|e| sdk_error(WHAT, e))
    });
}

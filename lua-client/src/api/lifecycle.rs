//! The lifecycle every Lua plane shares (`PhysicsPlane`, `GuiPhysicsPlane`): `Step(dt)`,
//! `Destroy()`, `StateHash()` and `tostring`, written once over [`LuaPlane`]. A plane kind
//! says what it is, how to reach its SDK plane, what it does after a tick (fire its change
//! signals) and how it is destroyed; the methods are the same for every kind.

use mlua::{Lua, MetaMethod, UserData, UserDataMethods, Value};

use client_sdk::validate::MAX_DT;

use crate::values::{expected, finite_number, sdk_error};

/// A Lua plane type: what the shared lifecycle methods need of it.
pub(crate) trait LuaPlane: UserData + 'static {
    /// The Lua type's name, as messages spell it (`"PhysicsPlane"`).
    const TYPE: &'static str;
    /// False once destroyed (by the script, or with its client).
    fn alive(&self) -> bool;
    /// The SDK plane it drives.
    fn sdk_plane(&self) -> &client_sdk::Plane;
    /// Runs after each tick the script steps: fires the change signals of what moved.
    fn after_tick(&self, lua: &Lua) -> mlua::Result<()>;
    /// Forgets the plane in the script's lists and destroys it in the daemon.
    fn destroy(&self, lua: &Lua) -> mlua::Result<()>;
}

/// Adds `Step`, `Destroy`, `StateHash` and `tostring` to a plane type's methods.
pub(crate) fn add_methods<P: LuaPlane, M: UserDataMethods<P>>(methods: &mut M) {
    methods.add_method("Step", |lua, p, dt: Value| {
        let what = format!("{}:Step", P::TYPE);
        let dt = match finite_number(&what, &dt) {
            Ok(dt) if dt > 0.0 && dt <= MAX_DT as f64 => dt,
            _ => return Err(expected(&what, "a number of seconds in (0, 1]", &dt)),
        };
        // Documented as a no-op on a destroyed plane (the daemon skips disabled ones).
        if !p.alive() {
            return Ok(());
        }
        p.sdk_plane()
            .step(dt as f32)
            .map_err(|e| sdk_error(&what, e))?;
        // Welds ride along before the step's CFrame signals fire, so handlers see them.
        super::dyn_mesh::follow_all(lua)?;
        p.after_tick(lua)
    });
    methods.add_method("Destroy", |lua, p, ()| p.destroy(lua));
    // The newest tick's determinism hash as 16 hex digits (a u64 does not fit a Luau
    // number): equal strings on the same tick of two runs mean bit-identical states.
    methods.add_method("StateHash", |_, p, ()| {
        p.sdk_plane()
            .state_hash()
            .map(|h| format!("{h:016x}"))
            .map_err(|e| sdk_error(&format!("{}:StateHash", P::TYPE), e))
    });
    methods.add_meta_method(MetaMethod::ToString, |_, p, ()| {
        let id = p.sdk_plane().id();
        Ok(match p.alive() {
            true => format!("{} {id}", P::TYPE),
            false => format!("{} {id} (destroyed)", P::TYPE),
        })
    });
}

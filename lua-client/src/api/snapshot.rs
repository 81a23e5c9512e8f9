//! Plane snapshots in Luau: `plane:Snapshot()` → `PlaneSnapshot` (`Tick`, `Bytes`,
//! `StateHash`, `Kind`, `:Save(path)`), `plane:Restore(snapshot)`,
//! `PhysicsService.FromSnapshot(snapshot, options?)` and
//! `PhysicsService.LoadSnapshot(path)`, for 3D and GUI planes. Files are read and written
//! only under the asset roots (`--asset-root`), like maps.
//!
//! A restore keeps the script's handles: parts, objects and controllers that exist in the
//! snapshot read its state; what the script added after the snapshot no longer exists
//! (reads and writes name it stale).

use client_sdk::{GuiPlane, PlaneKind, PlaneProp, PlaneSnapshot};
use mlua::{Lua, MetaMethod, Table, UserData, UserDataFields, UserDataMethods, Value};

use super::gui_plane::state::{wrap_gui_plane, GuiPhysicsPlane};
use super::plane::context::{context, wrap_plane};
use super::plane::state::PhysicsPlane;
use crate::api::plane::props::PLANE;
use crate::values::{describe, expected, sdk_error};

/// A plane's whole state at one tick (`PlaneSnapshot`).
#[derive(Clone)]
pub struct LuaSnapshot(pub PlaneSnapshot);

fn kind_name(kind: PlaneKind) -> &'static str {
    match kind {
        PlaneKind::Rapier3d => "3D",
        PlaneKind::Gui2d => "GUI",
    }
}

impl UserData for LuaSnapshot {
    fn add_fields<F: UserDataFields<Self>>(fields: &mut F) {
        fields.add_field_method_get("Tick", |_, s| Ok(s.0.tick()));
        fields.add_field_method_get("Bytes", |_, s| Ok(s.0.len()));
        // 16 hex digits, as `plane:StateHash()` (a u64 does not fit a Luau number).
        fields.add_field_method_get("StateHash", |_, s| Ok(format!("{:016x}", s.0.state_hash())));
        fields.add_field_method_get("Kind", |_, s| Ok(kind_name(s.0.kind())));
    }

    fn add_methods<M: UserDataMethods<Self>>(methods: &mut M) {
        methods.add_method("Save", |lua, s, path: Value| {
            const WHAT: &str = "PlaneSnapshot:Save";
            let Value::String(path) = &path else {
                return Err(expected(WHAT, "a file path", &path));
            };
            let path = path.to_str()?.to_string();
            let target = crate::host::assets::resolve_for_write(lua, WHAT, &path)?;
            s.0.save(&target)
                .map_err(|e| mlua::Error::runtime(format!("{WHAT}: cannot write {path:?}: {e}")))
        });
        methods.add_meta_method(MetaMethod::ToString, |_, s, ()| {
            Ok(format!(
                "PlaneSnapshot ({} plane, tick {}, {} bytes)",
                kind_name(s.0.kind()),
                s.0.tick(),
                s.0.len()
            ))
        });
    }
}

fn snapshot_arg(what: &str, v: &Value) -> mlua::Result<PlaneSnapshot> {
    match v {
        Value::UserData(ud) => match ud.borrow::<LuaSnapshot>() {
            Ok(s) => Ok(s.0.clone()),
            Err(_) => Err(expected(what, "a PlaneSnapshot", v)),
        },
        _ => Err(expected(what, "a PlaneSnapshot", v)),
    }
}

fn alive(p: &PhysicsPlane, what: &str) -> mlua::Result<()> {
    match p.0.alive() {
        true => Ok(()),
        false => Err(mlua::Error::runtime(format!(
            "{what}: the plane was destroyed"
        ))),
    }
}

/// `Snapshot` and `Restore` on `PhysicsPlane`.
pub fn add_plane_methods<M: UserDataMethods<PhysicsPlane>>(methods: &mut M) {
    methods.add_method("Snapshot", |_, p, ()| {
        const WHAT: &str = "PhysicsPlane:Snapshot";
        alive(p, WHAT)?;
        p.0.plane
            .take_snapshot()
            .map(LuaSnapshot)
            .map_err(|e| sdk_error(WHAT, e))
    });
    add_rewind(methods);
    methods.add_method("Restore", |_, p, snapshot: Value| {
        const WHAT: &str = "PhysicsPlane:Restore";
        alive(p, WHAT)?;
        let snapshot = snapshot_arg(WHAT, &snapshot)?;
        p.0.plane
            .restore(&snapshot)
            .map(|_| ())
            .map_err(|e| sdk_error(WHAT, e))
    });
}

/// `Rewind(ticks)` on `PhysicsPlane` (RollbackTicks).
pub fn add_rewind<M: UserDataMethods<PhysicsPlane>>(methods: &mut M) {
    methods.add_method("Rewind", |_, p, ticks: Value| {
        const WHAT: &str = "PhysicsPlane:Rewind";
        alive(p, WHAT)?;
        let n = match ticks {
            Value::Integer(n) if (0..=u32::MAX as i64).contains(&n) => n as u32,
            Value::Number(n) if n.fract() == 0.0 && (0.0..=u32::MAX as f64).contains(&n) => {
                n as u32
            }
            other => return Err(expected(WHAT, "a whole number of ticks >= 0", &other)),
        };
        p.0.plane
            .rewind(n)
            .map(|_| ())
            .map_err(|e| sdk_error(WHAT, e))
    });
}

/// `Snapshot` and `Restore` on `GuiPhysicsPlane`.
pub fn add_gui_plane_methods<M: UserDataMethods<GuiPhysicsPlane>>(methods: &mut M) {
    methods.add_method("Snapshot", |_, p, ()| {
        const WHAT: &str = "GuiPhysicsPlane:Snapshot";
        p.0.check_alive(WHAT)?;
        p.0.plane
            .plane()
            .take_snapshot()
            .map(LuaSnapshot)
            .map_err(|e| sdk_error(WHAT, e))
    });
    methods.add_method("Restore", |_, p, snapshot: Value| {
        const WHAT: &str = "GuiPhysicsPlane:Restore";
        p.0.check_alive(WHAT)?;
        let snapshot = snapshot_arg(WHAT, &snapshot)?;
        p.0.plane
            .plane()
            .restore(&snapshot)
            .map(|_| ())
            .map_err(|e| sdk_error(WHAT, e))
    });
}

/// `PhysicsService.FromSnapshot(snapshot, options?)`: a new plane of the snapshot's kind and
/// state, then `options` (any option of `New` / `NewGUI`, e.g. TickRate, Enabled, Threads).
fn from_snapshot(lua: &Lua, (snapshot, opts): (Value, Value)) -> mlua::Result<Value> {
    const WHAT: &str = "PhysicsService.FromSnapshot";
    let snapshot = snapshot_arg(WHAT, &snapshot)?;
    let opts = match opts {
        Value::Nil => None,
        Value::Table(t) => Some(t),
        other => return Err(expected(WHAT, "a table of options or nil", &other)),
    };
    let mut overrides: Vec<PlaneProp> = Vec::new();
    for pair in opts.iter().flat_map(|t| t.pairs::<Value, Value>()) {
        let (key, value) = pair?;
        overrides.push(match snapshot.kind() {
            PlaneKind::Rapier3d => PLANE.option(WHAT, &key, &value)?,
            PlaneKind::Gui2d => {
                crate::api::gui_plane::props::GUI_PLANE.option(WHAT, &key, &value)?
            }
        });
    }
    let client = context(lua).client.clone();
    let plane = client
        .plane_from_snapshot(&snapshot, &overrides)
        .map_err(|e| sdk_error(WHAT, e))?;
    match snapshot.kind() {
        PlaneKind::Rapier3d => wrap_plane(lua, plane).map(Value::UserData),
        PlaneKind::Gui2d => lua
            .create_userdata(wrap_gui_plane(lua, GuiPlane::from_plane(plane)))
            .map(Value::UserData),
    }
}

/// `PhysicsService.LoadSnapshot(path)`.
fn load_snapshot(lua: &Lua, path: Value) -> mlua::Result<LuaSnapshot> {
    const WHAT: &str = "PhysicsService.LoadSnapshot";
    let Value::String(s) = &path else {
        return Err(expected(WHAT, "a file path", &path));
    };
    let resolved = crate::host::assets::resolve(lua, WHAT, &s.to_str()?)?;
    PlaneSnapshot::load(&resolved)
        .map(LuaSnapshot)
        .map_err(|e| mlua::Error::runtime(format!("{WHAT}({}): {e}", describe(&path))))
}

/// Adds `FromSnapshot` and `LoadSnapshot` to the `PhysicsService` module.
pub fn install(lua: &Lua, module: &Table) -> mlua::Result<()> {
    module.set("FromSnapshot", lua.create_function(from_snapshot)?)?;
    module.set("LoadSnapshot", lua.create_function(load_snapshot)?)?;
    Ok(())
}

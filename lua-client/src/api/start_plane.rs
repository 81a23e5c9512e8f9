//! The plane a run starts from: `physics-lua SCRIPT --snapshot FILE` restores FILE into a new
//! plane of this client before the script runs, and `physics-lua --replay FILE --until TICK
//! SCRIPT` hands over the plane its replay reached; the script gets it with
//! `PhysicsService.GetStartPlane()` (nil when the run has neither). A user's bug report
//! (`plane:Snapshot():Save(path)`, a persistent plane's `.physnap`, a recording) becomes a
//! file anyone can replay with their own script.

use std::path::Path;

use client_sdk::{GuiPlane, Plane, PlaneKind, PlaneSnapshot};
use mlua::{AnyUserData, Lua, Table, Value};

use super::gui_plane::state::wrap_gui_plane;
use super::plane::context::{context, wrap_plane};

/// The start plane's script value, once made.
struct StartPlane(AnyUserData);

/// Loads the snapshot file `path` (checked: format, checksum, engine) and makes it a new
/// plane of this script's client, with the snapshot's settings (a ticking plane ticks on).
/// An error names the file and what is wrong.
pub fn start_from_snapshot(lua: &Lua, path: &Path) -> Result<(), String> {
    let shown = path.display();
    let snapshot = PlaneSnapshot::load(path).map_err(|e| format!("--snapshot {shown}: {e}"))?;
    let client = context(lua).client.clone();
    let plane = client
        .plane_from_snapshot(&snapshot, &[])
        .map_err(|e| format!("--snapshot {shown}: the daemon refused its state: {e}"))?;
    start_from_plane(lua, plane, snapshot.kind()).map_err(|e| format!("--snapshot {shown}: {e}"))
}

/// Makes `plane`, a plane of this script's client of kind `kind` (a replayed recording's),
/// the start plane: the script's `PhysicsPlane`, or `GuiPhysicsPlane` for a GUI plane.
pub fn start_from_plane(lua: &Lua, plane: Plane, kind: PlaneKind) -> mlua::Result<()> {
    let value = match kind {
        PlaneKind::Rapier3d => wrap_plane(lua, plane),
        PlaneKind::Gui2d => lua.create_userdata(wrap_gui_plane(lua, GuiPlane::from_plane(plane))),
    }?;
    lua.set_app_data(StartPlane(value));
    Ok(())
}

/// `PhysicsService.GetStartPlane()`.
fn get_start_plane(lua: &Lua, (): ()) -> mlua::Result<Value> {
    Ok(match lua.app_data_ref::<StartPlane>() {
        Some(p) => Value::UserData(p.0.clone()),
        None => Value::Nil,
    })
}

/// Adds `GetStartPlane` to the `PhysicsService` module.
pub fn install(lua: &Lua, module: &Table) -> mlua::Result<()> {
    module.set("GetStartPlane", lua.create_function(get_start_plane)?)?;
    Ok(())
}

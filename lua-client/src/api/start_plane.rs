//! The plane a run starts from: `physics-lua SCRIPT --snapshot FILE` restores FILE into a new
//! plane of this client before the script runs, and the script gets it with
//! `PhysicsService.GetStartPlane()` (nil when the run has no `--snapshot`). A user's bug
//! report (`plane:Snapshot():Save(path)`, or a persistent plane's `.physnap`) becomes a
//! file anyone can replay with their own script.

use std::path::Path;

use client_sdk::{GuiPlane, PlaneKind, PlaneSnapshot};
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
    let value = match snapshot.kind() {
        PlaneKind::Rapier3d => wrap_plane(lua, plane),
        PlaneKind::Gui2d => lua.create_userdata(wrap_gui_plane(lua, GuiPlane::from_plane(plane))),
    }
    .map_err(|e| format!("--snapshot {shown}: {e}"))?;
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

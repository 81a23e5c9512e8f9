//! Recording a plane from Luau: `plane:StartRecording(path?)` and `plane:StopRecording()` on
//! 3D and GUI planes, and the `Record` option of `PhysicsService.New` / `NewGUI`. The daemon
//! writes the file (a keyframe at the start, every batch of writes with the tick it was
//! applied at, each tick's state hash); `physics-lua --replay FILE` plays it back.
//!
//! A path the script names must be a file in a directory under the asset roots
//! (`--asset-root`), like `PlaneSnapshot:Save`; without one the daemon names the file (in
//! its `--record` folder, or `physics-recordings` under the temporary folder).

use std::path::Path;

use mlua::{UserDataMethods, Value};

use super::lifecycle::LuaPlane;
use crate::values::{expected, sdk_error};

/// The `Record` option's name in `New` / `NewGUI` tables.
pub(crate) const OPTION: &str = "Record";

/// Whether `key` is the `Record` option.
pub(crate) fn is_record_option(key: &Value) -> bool {
    matches!(key, Value::String(k) if k.as_bytes() == OPTION.as_bytes())
}

/// The `Record` option's value: a boolean, or an error naming the option and the value.
pub(crate) fn record_option(what: &str, value: &Value) -> mlua::Result<bool> {
    match value {
        Value::Boolean(on) => Ok(*on),
        other => Err(expected(
            &format!("{what} option {OPTION}"),
            "a boolean",
            other,
        )),
    }
}

/// `Record = true` of a plane just created by `what`: starts recording it into a file the
/// daemon names. When the daemon refuses, the plane is destroyed again (the script never
/// got it) and the error names the option.
pub(crate) fn record_new_plane(what: &str, plane: &client_sdk::Plane) -> mlua::Result<()> {
    if let Err(e) = plane.start_recording(None) {
        let _ = plane.destroy();
        return Err(sdk_error(&format!("{what} option {OPTION}"), e));
    }
    Ok(())
}

fn check_alive<P: LuaPlane>(p: &P, what: &str) -> mlua::Result<()> {
    match p.alive() {
        true => Ok(()),
        false => Err(mlua::Error::runtime(format!(
            "{what}: the plane was destroyed"
        ))),
    }
}

/// Adds `StartRecording` and `StopRecording` to a plane type's methods.
pub(crate) fn add_methods<P: LuaPlane, M: UserDataMethods<P>>(methods: &mut M) {
    methods.add_method("StartRecording", |lua, p, path: Value| {
        let what = format!("{}:StartRecording", P::TYPE);
        check_alive(p, &what)?;
        let target = match &path {
            Value::Nil => None,
            Value::String(s) => {
                let s = s.to_str()?.to_string();
                Some(crate::host::assets::resolve_for_write(lua, &what, &s)?)
            }
            other => return Err(expected(&what, "a file path or nil", other)),
        };
        p.sdk_plane()
            .start_recording(target.as_deref().map(Path::new))
            .map(|file| file.to_string_lossy().into_owned())
            .map_err(|e| sdk_error(&what, e))
    });
    methods.add_method("StopRecording", |_, p, ()| {
        let what = format!("{}:StopRecording", P::TYPE);
        check_alive(p, &what)?;
        p.sdk_plane()
            .stop_recording()
            .map(|info| info.map(|i| i.path))
            .map_err(|e| sdk_error(&what, e))
    });
}

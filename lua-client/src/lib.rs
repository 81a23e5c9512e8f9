#![deny(missing_docs)]
//! The documented Luau `PhysicsService` API on top of client-sdk.
//!
//! [`install`] puts the API into a host's Lua state: the global `import(name)` (modules
//! `PhysicsService`, `Renderable`, `Primitives`), the `Heart` signal and `wait`. The host
//! then drives frames through the returned [`Host`]: each frame resumes due waits, fires
//! `Heart` with the frame's dt, fires the CFrame change signals of simulated parts that have
//! listeners, and sends the frame's property writes to the daemon as one batch.
//!
//! Layers:
//!
//! - `values`: Lua values and the value types (`Vector`, `CFrame`, `Dim`); knows no other
//!   layer;
//! - `host`: the frame loop, `wait` and coroutines, signals, the watchdog (run-time limit,
//!   deadline, stop flag) and errors as scripts see them; knows only `values`;
//! - `api`: one file per Luau API type with its methods and handles;
//! - `props`: the properties of each API type, one row each (Lua type, the one place it
//!   reads from, the write).

mod api;
mod host;
mod members;
mod props;
mod values;

use std::rc::Rc;

use client_sdk::Client;
use mlua::{Lua, Table, Value};

pub use host::assets::AssetRoots;
pub use host::errors::colon_hint;
use host::scheduler::{self, Scheduler};
use host::signal::Signal;
pub use host::{Host, Stop, WATCH_PERIOD};
#[doc(hidden)]
pub use members::property_rows;

/// Lets `PhysicsService.New{ Placement = "auto" | DAEMON }` place planes on the daemons of
/// `cluster` (a `physics-lua --cluster` run); without it every plane is on the script's own
/// daemon.
pub fn set_cluster(lua: &Lua, cluster: client_sdk::remote::RemoteOptions) {
    api::plane::context::context(lua).set_cluster(cluster);
}

/// Installs the API into `lua`, talking to the daemon through `client`: the globals, the
/// watchdog's interrupt (see [`Host::set_max_run_time`]) and `pcall`, `xpcall` and
/// `coroutine.resume` wrapped so that they give API errors as `"chunk:line: message"`
/// strings. Call it before `lua.sandbox(true)`: it sets globals and replaces builtins.
pub fn install(lua: &Lua, client: Client) -> mlua::Result<Host> {
    let scheduler = Rc::new(Scheduler::new());
    let heart = Signal::new("Heart");
    lua.set_app_data(scheduler.clone());
    scheduler.watchdog.install(lua);
    host::errors::install(lua)?;
    api::plane::context::set_origin(lua, &client);
    let modules = api::modules(lua, client.clone())?;
    let import = lua.create_function(move |_, name: Value| {
        let found = match &name {
            Value::String(s) => modules.get::<Option<Table>>(s.clone())?,
            _ => None,
        };
        found.ok_or_else(|| {
            let asked = match &name {
                Value::String(s) => format!("\"{}\"", s.to_string_lossy()),
                other => values::describe(other),
            };
            mlua::Error::runtime(format!(
                "import: no module {asked} in this host (available: {})",
                api::MODULES.join(", ")
            ))
        })
    })?;
    let globals = lua.globals();
    globals.set("import", import)?;
    globals.set("Heart", heart.clone())?;
    // The reference's controller snippet uses DynMesh without importing it.
    let dyn_mesh: Table = globals.get::<mlua::Function>("import")?.call("DynMesh")?;
    globals.set("DynMesh", dyn_mesh)?;
    globals.set("wait", scheduler::wait_function(lua)?)?;
    let daemon = api::plane::context::context(lua);
    Ok(Host::new(lua, scheduler, heart, client, daemon))
}

/// Restores the snapshot file `path` into a new plane of the installed client, which the
/// script gets with `PhysicsService.GetStartPlane()` (`physics-lua --snapshot FILE`). Call
/// it after [`install`]; the error names the file and what is wrong with it.
pub fn start_from_snapshot(lua: &Lua, path: &std::path::Path) -> Result<(), String> {
    api::start_plane::start_from_snapshot(lua, path)
}

/// Makes `plane` (a plane of the installed client, of kind `kind`) the plane the script gets
/// with `PhysicsService.GetStartPlane()`: `physics-lua --replay FILE --until TICK SCRIPT`
/// hands over the plane its replay reached. Call it after [`install`].
pub fn start_from_plane(
    lua: &Lua,
    plane: client_sdk::Plane,
    kind: client_sdk::PlaneKind,
) -> Result<(), String> {
    api::start_plane::start_from_plane(lua, plane, kind).map_err(|e| e.to_string())
}

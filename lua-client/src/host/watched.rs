//! What the frame loop probes without knowing an API type: values with a per-frame change
//! signal ([`Watched`]) and the watch on the daemon's health ([`DaemonWatch`]).

use client_sdk::Client;
use mlua::Lua;

/// Something with a per-frame change signal: probed each frame, fired when it changed.
pub trait Watched {
    /// How many handlers listen; at zero the frame skips it.
    fn listeners(&self) -> usize;
    /// Fires the change signal if the value moved since it last fired.
    fn fire_if_changed(&self, lua: &Lua) -> mlua::Result<()>;
    /// Whether its listeners keep a script's frames running (a script's change handlers
    /// do; work the host does for the script, such as welds, does not).
    fn keeps_running(&self) -> bool {
        true
    }
}

/// The API's watch on the daemon's health, run once per frame (`PhysicsService.Stalled` /
/// `Resumed`).
pub trait DaemonWatch {
    /// Fires the stall / resume signals when the daemon's health changed.
    fn watch(&self, lua: &Lua) -> mlua::Result<()>;
    /// Whether a script listens (the host then keeps running frames while it only waits).
    fn watching(&self) -> bool;
    /// Connections to other daemons the script's planes live on (`Placement`): each frame
    /// begins and flushes on them too.
    fn placed(&self) -> Vec<Client>;
}

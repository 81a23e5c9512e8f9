//! The documented Luau `PhysicsService` API on top of client-sdk.
//!
//! [`install`] puts the API into a host's Lua state: the global `import(name)` (modules
//! `PhysicsService`, `Renderable`, `Primitives`), the `Heart` signal and `wait`. The host
//! then drives frames through the returned [`Host`]: each frame resumes due waits, fires
//! `Heart` with the frame's dt, fires the CFrame change signals of simulated parts that have
//! listeners, and sends the frame's property writes to the daemon as one batch.

mod convert;
mod object;
mod part;
mod plane;
mod primitives;
mod props;
mod scheduler;
mod signal;

use std::rc::Rc;

use client_sdk::Client;
use mlua::{Function, Lua, MultiValue, Table, Value};

use plane::Context;
use scheduler::Scheduler;

/// The modules `import` knows, in the order error messages list them.
const MODULES: [&str; 3] = ["PhysicsService", "Renderable", "Primitives"];

/// Methods of the types whose `__index` is ours alone (see `part::BasePart`).
pub(crate) struct MethodTables {
    pub part: Table,
    pub object: Table,
}

pub(crate) fn method_tables(lua: &Lua) -> Rc<MethodTables> {
    lua.app_data_ref::<Rc<MethodTables>>()
        .expect("lua_client::install registers the method tables")
        .clone()
}

/// A host's handle on the installed API: drives frames.
pub struct Host {
    lua: Lua,
    scheduler: Rc<Scheduler>,
    context: Rc<Context>,
}

/// Installs the API into `lua`, talking to the daemon through `client`.
pub fn install(lua: &Lua, client: Client) -> mlua::Result<Host> {
    let scheduler = Rc::new(Scheduler::new());
    let context = Rc::new(Context::new(client));
    lua.set_app_data(scheduler.clone());
    lua.set_app_data(context.clone());

    lua.set_app_data(Rc::new(MethodTables {
        part: part::methods(lua)?,
        object: object::methods(lua)?,
    }));
    let modules = lua.create_table()?;
    modules.set("PhysicsService", plane::module(lua)?)?;
    modules.set("Renderable", part::module(lua)?)?;
    modules.set("Primitives", primitives::module(lua)?)?;
    let import = lua.create_function(move |_, name: Value| {
        let found = match &name {
            Value::String(s) => modules.get::<Option<Table>>(s.clone())?,
            _ => None,
        };
        found.ok_or_else(|| {
            mlua::Error::runtime(format!(
                "import: no module {} in this host (available: {})",
                convert::describe(&name),
                MODULES.join(", ")
            ))
        })
    })?;
    let globals = lua.globals();
    globals.set("import", import)?;
    globals.set("Heart", scheduler.heart.clone())?;
    globals.set("wait", scheduler::wait_function(lua)?)?;
    Ok(Host {
        lua: lua.clone(),
        scheduler,
        context,
    })
}

impl Host {
    /// Runs `f` as a script thread: until it finishes or first waits.
    pub fn spawn(&self, f: Function) -> mlua::Result<()> {
        scheduler::spawn(&self.lua, f, MultiValue::new())
    }

    /// One frame of `dt` seconds, ending with the flush of every write it made.
    pub fn frame(&self, dt: f64) -> mlua::Result<()> {
        self.scheduler.frame(&self.lua, dt)?;
        self.flush()
    }

    /// Sends the queued writes as one request.
    pub fn flush(&self) -> mlua::Result<()> {
        self.context
            .client
            .flush()
            .map_err(|e| convert::sdk_error("the physics daemon rejected a write", e))
    }

    /// Whether frames still have work: `Heart` handlers, pending waits, or change listeners.
    pub fn busy(&self) -> bool {
        self.scheduler.heart.listeners() > 0
            || self.scheduler.pending_waits() > 0
            || self.scheduler.change_listeners()
    }

    /// Whether the next frame is needed regardless of waits (Heart or change listeners).
    pub fn busy_every_frame(&self) -> bool {
        self.scheduler.heart.listeners() > 0 || self.scheduler.change_listeners()
    }

    /// Seconds until the earliest pending `wait` is due.
    pub fn next_wake_in(&self) -> Option<f64> {
        self.scheduler.next_wake_in()
    }

    pub fn client(&self) -> &Client {
        &self.context.client
    }
}

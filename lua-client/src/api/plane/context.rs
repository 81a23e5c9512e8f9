//! The script's planes as the API keeps them in the Lua state: the [`Context`] (the
//! connection, the planes until `:Destroy()`, the collision-group members, the daemon's
//! health signals, `Placement`'s connections) and the script's value of each plane.

use std::cell::{Cell, RefCell};
use std::rc::Rc;

use client_sdk::{Client, Plane, DEFAULT_GROUP};
use mlua::{Lua, Value};

use super::state::{PhysicsPlane, PlaneState};
use crate::api::part::state::PartState;
use crate::host::scheduler::scheduler;
use crate::host::signal::Signal;
use crate::host::watched::DaemonWatch;
use crate::values::sdk_error;

/// A write the daemon refuses after its call returned names the line that made it.
pub(crate) fn set_origin(lua: &Lua, client: &Client) {
    let weak = lua.weak();
    client.set_origin(move || {
        weak.try_upgrade()
            .and_then(|lua| lua.inspect_stack(1, |d| d.current_line()).flatten())
            .map_or(0, |line| line as u32)
    });
}

/// Planes stay alive until `:Destroy()`, whether or not the script keeps a reference.
pub struct Context {
    /// The connection to the daemon.
    pub client: Client,
    pub(crate) planes: RefCell<Vec<Rc<PlaneState>>>,
    /// Parts ever put in a group other than "Default": they follow its renaming and
    /// removal (parts outside any plane too).
    group_members: RefCell<Vec<std::rc::Weak<PartState>>>,
    /// `PhysicsService.Stalled(silentSeconds)`: the daemon stopped beating (SIGSTOP, hung).
    pub stalled: Signal,
    /// `PhysicsService.Resumed()`: it beats again.
    pub resumed: Signal,
    /// Whether the last watch found it stalled.
    is_stalled: Cell<bool>,
    /// The cluster of a `physics-lua --cluster` run (`Placement` reaches its daemons).
    cluster: RefCell<Option<client_sdk::remote::RemoteOptions>>,
    /// Connections to the cluster's other daemons, made by `Placement` (one per daemon).
    placed: RefCell<Vec<Client>>,
}

impl Context {
    /// No planes yet.
    pub fn new(client: Client) -> Context {
        Context {
            client,
            planes: RefCell::default(),
            group_members: RefCell::default(),
            stalled: Signal::new("PhysicsService.Stalled"),
            resumed: Signal::new("PhysicsService.Resumed"),
            is_stalled: Cell::new(false),
            cluster: RefCell::new(None),
            placed: RefCell::default(),
        }
    }

    /// Once per frame: fires `Stalled` when the daemon stops beating and `Resumed` when it
    /// beats again (a stall nobody listens to is printed once).
    pub(crate) fn watch_daemon(&self, lua: &Lua) -> mlua::Result<()> {
        let health = self.client.watch_daemon();
        let stalled = matches!(health, client_sdk::DaemonHealth::Stalled { .. });
        if stalled == self.is_stalled.replace(stalled) {
            return Ok(());
        }
        match health {
            client_sdk::DaemonHealth::Stalled { silent } => {
                if self.stalled.listeners() == 0 {
                    eprintln!(
                        "the physics daemon (process {}) is stalled: no heartbeat for {:.1} s \
                         (stopped or hung); poses read now are frozen",
                        self.client.daemon_pid(),
                        silent.as_secs_f64()
                    );
                }
                self.stalled.fire(
                    lua,
                    mlua::MultiValue::from_iter([Value::Number(silent.as_secs_f64())]),
                )
            }
            _ => self.resumed.fire(lua, mlua::MultiValue::new()),
        }
    }

    /// Lets `PhysicsService.New{ Placement }` reach the daemons of `cluster`.
    pub fn set_cluster(&self, cluster: client_sdk::remote::RemoteOptions) {
        *self.cluster.borrow_mut() = Some(cluster);
    }

    /// The connections `Placement` made (beside [`Context::client`]).
    pub fn placed_clients(&self) -> Vec<Client> {
        self.placed.borrow().clone()
    }

    /// The client a plane placed by `placement` is created with: `None` or `"local"` the
    /// script's own daemon; `"auto"` the cluster's least loaded daemon; any other string
    /// the daemon of that name (a cluster run only).
    pub(crate) fn client_for(&self, lua: &Lua, placement: Option<&str>) -> mlua::Result<Client> {
        const WHAT: &str = "PhysicsService.New";
        let Some(placement) = placement.filter(|p| *p != "local") else {
            return Ok(self.client.clone());
        };
        let Some(cluster) = self.cluster.borrow().clone() else {
            return Err(mlua::Error::runtime(format!(
                "{WHAT}: Placement = {placement:?} needs a cluster run (physics-lua --cluster \
                 NAME --connect ENDPOINT); without one every plane is \"local\""
            )));
        };
        let daemon = match placement {
            "auto" => None,
            name => Some(name.to_string()),
        };
        let own = self.client.cluster_daemon().map(str::to_string);
        if daemon.is_some() && daemon == own {
            return Ok(self.client.clone());
        }
        if let Some(d) = &daemon {
            if let Some(c) = self
                .placed
                .borrow()
                .iter()
                .find(|c| c.cluster_daemon() == Some(d.as_str()))
            {
                return Ok(c.clone());
            }
        }
        let remote = client_sdk::remote::RemoteOptions { daemon, ..cluster };
        let mut options = client_sdk::ConnectOptions::new("");
        options.hold_adds_until_flush = true;
        options.refusals_at_next_call = true;
        let client = Client::connect_cluster_with(&remote, options)
            .map_err(|e| mlua::Error::runtime(format!("{WHAT}: Placement = {placement:?}: {e}")))?;
        // "auto" may land on the script's own daemon or one already reached.
        if client.cluster_daemon().map(str::to_string) == own {
            return Ok(self.client.clone());
        }
        if let Some(c) = self
            .placed
            .borrow()
            .iter()
            .find(|c| c.cluster_daemon() == client.cluster_daemon())
        {
            return Ok(c.clone());
        }
        set_origin(lua, &client);
        self.placed.borrow_mut().push(client.clone());
        Ok(client)
    }

    /// Whether `Stalled` or `Resumed` has handlers (the host then keeps watching while
    /// the script only waits).
    pub(crate) fn watching_daemon(&self) -> bool {
        self.stalled.listeners() > 0 || self.resumed.listeners() > 0
    }

    /// The script's plane `id`, if it holds it (`Open` of a plane it already has).
    pub(crate) fn plane_state(&self, id: client_sdk::PlaneId) -> Option<Rc<PlaneState>> {
        self.planes
            .borrow()
            .iter()
            .find(|p| p.plane.id() == id)
            .cloned()
    }

    /// Sets the collision group of `this` (checked against the connection's table; its body follows
    /// while simulated). `what` names the property written, for errors. The part follows
    /// its group's renaming and removal ([`Context::group_renamed`]).
    pub fn set_collision_group(
        &self,
        this: &Rc<PartState>,
        what: &str,
        name: String,
    ) -> mlua::Result<()> {
        self.client
            .collision_group_id(&name)
            .map_err(|e| sdk_error(what, e))?;
        if let Some(object) = this.object() {
            object
                .set_collision_group(&name)
                .map_err(|e| sdk_error(what, e))?;
        }
        if name != DEFAULT_GROUP {
            self.note_group_member(this);
        }
        this.store_collision_group(name);
        Ok(())
    }

    /// Remembers `part`, just put in a group other than "Default".
    pub(crate) fn note_group_member(&self, part: &Rc<PartState>) {
        if !part.mark_grouped() {
            return;
        }
        let mut members = self.group_members.borrow_mut();
        // Forget collected parts now and then (amortised: when the length doubles).
        if members.len().is_power_of_two() {
            members.retain(|w| w.strong_count() > 0);
        }
        members.push(Rc::downgrade(part));
    }

    /// Group `from` is now called `to` (removed: `to` is "Default"): every part in it
    /// reads the new name, as its body does.
    pub(crate) fn group_renamed(&self, from: &str, to: &str) {
        self.group_members
            .borrow_mut()
            .retain(|w| match w.upgrade() {
                Some(part) => {
                    part.group_renamed(from, to);
                    true
                }
                None => false,
            });
    }
}

impl DaemonWatch for Context {
    fn watch(&self, lua: &Lua) -> mlua::Result<()> {
        self.watch_daemon(lua)
    }
    fn watching(&self) -> bool {
        self.watching_daemon()
    }
    fn placed(&self) -> Vec<Client> {
        self.placed_clients()
    }
}

/// The context `install` registered in `lua`.
pub(crate) fn context(lua: &Lua) -> Rc<Context> {
    lua.app_data_ref::<Rc<Context>>()
        .expect("lua_client::install registers the context")
        .clone()
}

/// The script's handle on a new plane of this client (`New`, `FromSnapshot`).
pub(crate) fn wrap_plane(lua: &Lua, plane: Plane) -> mlua::Result<mlua::AnyUserData> {
    let ctx = context(lua);
    let state = Rc::new(PlaneState::new(plane));
    // Probed every frame; it costs one check while no part of it has touch handlers.
    scheduler(lua).watch(state.clone());
    ctx.planes.borrow_mut().push(state.clone());
    plane_ud(lua, &state)
}

/// The script's `PhysicsPlane` value of `state` (one per plane: see `identity.rs`), so
/// `map.Plane == plane`.
pub(crate) fn plane_ud(lua: &Lua, state: &Rc<PlaneState>) -> mlua::Result<mlua::AnyUserData> {
    crate::host::identity::userdata(
        lua,
        Rc::as_ptr(state).cast(),
        crate::host::identity::tag::PLANE,
        || PhysicsPlane(state.clone()),
    )
}

//! `PhysicsService.New` and the `PhysicsPlane` it returns.

pub(crate) mod props;

use std::cell::{Cell, RefCell};
use std::rc::Rc;

use std::collections::HashMap;

use client_sdk::{Client, Handle, ObjectProp, Plane, PlaneInfo, PlaneOptions, PlaneProp};
use mlua::{Lua, MetaMethod, Table, UserData, UserDataMethods, Value};

use super::contacts::ContactPump;
use super::controller::{new_controller, ControllerState};
use super::object::PhysicsObject;
use super::part::{BasePart, Body, Ended, PartState};
use crate::host::scheduler::scheduler;
use crate::props::Target;
use crate::values::{describe, expected, sdk_error};
use props::PLANE;

/// A plane as the host holds it. Its options live in the daemon alone: the property rows
/// read them back from there.
pub struct PlaneState {
    /// The SDK's plane.
    pub plane: Plane,
    alive: Cell<bool>,
    parts: RefCell<Vec<Rc<PartState>>>,
    /// The same parts by their body's handle (contacts and query hits name handles).
    by_handle: RefCell<HashMap<Handle, Rc<PartState>>>,
    /// Contact delivery of this plane (`contacts.rs`).
    pub(crate) contacts: ContactPump,
    /// Its character controllers by body handle (`controller.rs`).
    controllers: RefCell<HashMap<Handle, Rc<ControllerState>>>,
    /// Its maps by body handle (`map.rs`): hits and contacts on a map hand back its Map.
    pub(crate) maps: RefCell<HashMap<Handle, Rc<super::map::MapState>>>,
    /// Whether a part has CFrame handlers (so a step with none connected does not copy and
    /// ask every part).
    cframe_listen: super::contacts::HandlersAnswer,
}

impl PlaneState {
    /// False once `:Destroy()` was called.
    pub fn alive(&self) -> bool {
        self.alive.get()
    }

    /// The plane's options: a local lookup in the SDK's mirror for a plane this script
    /// created (not shared), otherwise one round trip that sends the queued writes first;
    /// `what` names the property read, for errors.
    pub fn info(&self, what: &str) -> mlua::Result<PlaneInfo> {
        if !self.alive() {
            return Err(mlua::Error::runtime(format!(
                "PhysicsPlane.{what}: the plane was destroyed"
            )));
        }
        self.plane
            .properties()
            .map_err(|e| sdk_error(&format!("PhysicsPlane.{what}"), e))
    }

    /// Live objects of the plane; 0 once destroyed.
    pub fn object_count(&self) -> Result<u32, client_sdk::Error> {
        if !self.alive() {
            return Ok(0);
        }
        self.plane.object_count()
    }

    /// Forgets `part`, whose body `handle` left the plane.
    pub fn forget(&self, part: &Rc<PartState>, handle: Handle) {
        self.parts.borrow_mut().retain(|p| !Rc::ptr_eq(p, part));
        self.by_handle.borrow_mut().remove(&handle);
        crate::api::contacts::forget_joints_of(self, handle);
        crate::api::contacts::handlers_changed();
    }

    /// Makes `body` the simulated body of `part` in this plane.
    pub fn adopt(&self, part: &Rc<PartState>, body: Rc<Body>, reporting: bool) {
        let handle = body.object.handle();
        part.link(body, reporting);
        self.parts.borrow_mut().push(part.clone());
        self.by_handle.borrow_mut().insert(handle, part.clone());
        crate::api::contacts::handlers_changed();
    }

    /// Keeps a controller so its events reach it.
    pub fn keep_controller(&self, c: Rc<ControllerState>) {
        self.controllers
            .borrow_mut()
            .insert(c.controller.handle(), c);
    }

    /// Forgets the controller of body `handle` (destroyed).
    pub fn forget_controller(&self, handle: Handle) {
        self.controllers.borrow_mut().remove(&handle);
    }

    /// The controller of body `handle`, if this host made it.
    pub fn controller_of(&self, handle: Handle) -> Option<Rc<ControllerState>> {
        self.controllers.borrow().get(&handle).cloned()
    }

    /// Whether any controller of the plane has signal handlers.
    pub fn controller_listeners(&self) -> bool {
        self.controllers
            .borrow()
            .values()
            .any(|c| c.listeners() > 0)
    }

    /// Whether any part of the plane passes `f`.
    pub fn any_part(&self, f: impl Fn(&PartState) -> bool) -> bool {
        self.parts.borrow().iter().any(|p| f(p))
    }

    /// The parts this host simulates in the plane, with their bodies' handles.
    pub fn parts_by_handle(&self) -> Vec<(Handle, Rc<PartState>)> {
        self.by_handle
            .borrow()
            .iter()
            .map(|(h, p)| (*h, p.clone()))
            .collect()
    }

    /// The part whose body is `handle`, if this host added it.
    pub fn part_of(&self, handle: Handle) -> Option<Rc<PartState>> {
        self.by_handle.borrow().get(&handle).cloned()
    }

    /// Removes every body (their parts stay at their last pose) and the plane itself.
    fn destroy(&self) -> Result<(), client_sdk::Error> {
        if !self.alive.replace(false) {
            return Ok(());
        }
        for part in self.parts.take() {
            part.unlink(Ended::PlaneDestroyed);
        }
        crate::api::contacts::forget_all_joints(self);
        crate::api::contacts::handlers_changed();
        self.by_handle.borrow_mut().clear();
        self.controllers.borrow_mut().clear();
        self.maps.borrow_mut().clear();
        self.plane.destroy()
    }

    /// The post-tick pass of a step: every part of the plane whose CFrame signal has
    /// listeners announces its new pose (handlers run before `Step` returns).
    fn after_tick(&self, lua: &Lua) -> mlua::Result<()> {
        self.deliver_contacts(lua)?;
        if !self
            .cframe_listen
            .get(|| self.any_part(|p| p.cframe_listeners() > 0))
        {
            return Ok(());
        }
        // A copy: handlers may add, unlink or destroy parts.
        let parts: Vec<Rc<PartState>> = self.parts.borrow().clone();
        for part in parts {
            if part.cframe_listeners() > 0 {
                part.fire_cframe_if_moved(lua)?;
            }
        }
        Ok(())
    }
}

impl Target for PlaneState {
    type Prop = PlaneProp;

    /// Applies an option change at once (with the writes queued before it): a plane
    /// option can be refused for the plane's state (`DeferGpu = true` with a joint
    /// present or no adapter), and the script learns it at the assignment, catchably.
    fn write(&self, name: &str, prop: PlaneProp) -> mlua::Result<()> {
        if !self.alive() {
            return Err(mlua::Error::runtime(format!(
                "PhysicsPlane.{name}: the plane was destroyed"
            )));
        }
        self.plane
            .set_now(prop)
            .map_err(|e| sdk_error(&format!("PhysicsPlane.{name}"), e))
    }

    fn table_rows() -> &'static [crate::props::Row<PlaneState>] {
        static ROWS: std::sync::OnceLock<Vec<crate::props::Row<PlaneState>>> =
            std::sync::OnceLock::new();
        ROWS.get_or_init(|| crate::props::table_rows(PlaneProp::ROWS))
    }

    fn table_get(
        &self,
        name: &str,
        index: usize,
    ) -> mlua::Result<client_sdk::settings::table::AnyValue> {
        props::table_get(self, name, index)
    }

    fn table_prop(
        name: &str,
        index: usize,
        v: client_sdk::settings::table::AnyValue,
    ) -> mlua::Result<PlaneProp> {
        props::table_prop(name, index, v)
    }
}

/// Planes stay alive until `:Destroy()`, whether or not the script keeps a reference.
pub struct Context {
    /// The connection to the daemon.
    pub client: Client,
    planes: RefCell<Vec<Rc<PlaneState>>>,
    /// Parts ever put in a group other than "Default": they follow its renaming and
    /// removal (parts outside any plane too).
    group_members: RefCell<Vec<std::rc::Weak<PartState>>>,
    /// `PhysicsService.Stalled(silentSeconds)`: the daemon stopped beating (SIGSTOP, hung).
    pub stalled: crate::host::signal::Signal,
    /// `PhysicsService.Resumed()`: it beats again.
    pub resumed: crate::host::signal::Signal,
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
            stalled: crate::host::signal::Signal::new("PhysicsService.Stalled"),
            resumed: crate::host::signal::Signal::new("PhysicsService.Resumed"),
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
    fn client_for(&self, lua: &Lua, placement: Option<&str>) -> mlua::Result<Client> {
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
        crate::set_origin(lua, &client);
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

impl crate::host::DaemonWatch for Context {
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

pub(crate) fn context(lua: &Lua) -> Rc<Context> {
    lua.app_data_ref::<Rc<Context>>()
        .expect("lua_client::install registers the context")
        .clone()
}

/// The Lua handle of a plane.
#[derive(Clone)]
pub struct PhysicsPlane(pub Rc<PlaneState>);

impl super::lifecycle::LuaPlane for PhysicsPlane {
    const TYPE: &'static str = "PhysicsPlane";
    fn alive(&self) -> bool {
        self.0.alive()
    }
    fn sdk_plane(&self) -> &client_sdk::Plane {
        &self.0.plane
    }
    fn after_tick(&self, lua: &Lua) -> mlua::Result<()> {
        self.0.after_tick(lua)
    }
    fn destroy(&self, lua: &Lua) -> mlua::Result<()> {
        context(lua)
            .planes
            .borrow_mut()
            .retain(|q| !Rc::ptr_eq(q, &self.0));
        self.0
            .destroy()
            .map_err(|e| sdk_error("PhysicsPlane:Destroy", e))
    }
}

impl UserData for PhysicsPlane {
    fn add_methods<M: UserDataMethods<Self>>(methods: &mut M) {
        methods.add_method("Add", |lua, p, part: Value| {
            super::object::object_ud(lua, add(&p.0, part)?)
        });
        methods.add_method("SetEnabled", |lua, p, on: Value| {
            PLANE.set(
                lua,
                &p.0,
                &Value::String(lua.create_string("Enabled")?),
                &on,
            )
        });
        super::lifecycle::add_methods(methods);
        super::query::add_methods(methods);
        super::snapshot::add_plane_methods(methods);
        methods.add_method("NewController", |_, p, (part, opts): (Value, Value)| {
            new_controller(&p.0, part, opts, false)
        });
        methods.add_method(
            "NewControlledController",
            |_, p, (part, opts): (Value, Value)| new_controller(&p.0, part, opts, true),
        );
        super::joint::add_methods(methods);
        super::ragdoll::add_methods(methods);
        super::probe::add_methods(methods);
        super::named_plane::add_methods(methods);
        super::plane_objects::add_methods(methods);
        super::move_to::add_methods(methods);
        methods.add_meta_method(MetaMethod::Index, |lua, p, key: Value| {
            PLANE.get(lua, &p.0, &key)
        });
        methods.add_meta_method(
            MetaMethod::NewIndex,
            |lua, p, (key, value): (Value, Value)| PLANE.set(lua, &p.0, &key, &value),
        );
    }
}

pub(crate) fn add(plane: &Rc<PlaneState>, part: Value) -> mlua::Result<PhysicsObject> {
    let Value::UserData(ud) = &part else {
        return Err(expected("PhysicsPlane:Add", "a BasePart", &part));
    };
    let state = match ud.borrow::<BasePart>() {
        Ok(p) => p.0.clone(),
        Err(_) => return Err(expected("PhysicsPlane:Add", "a BasePart", &part)),
    };
    let what = || format!("PhysicsPlane:Add({})", describe(&part));
    if !plane.alive() {
        return Err(mlua::Error::runtime(format!(
            "{}: the plane was destroyed",
            what()
        )));
    }
    if state.is_destroyed() {
        return Err(mlua::Error::runtime(format!(
            "{}: the part was destroyed",
            what()
        )));
    }
    if state.object().is_some() {
        return Err(mlua::Error::runtime(format!(
            "{}: the part is already in a physics plane (Unlink it first)",
            what()
        )));
    }
    let collider = state.collider();
    // A part whose Touched already has handlers reports contacts from its first tick.
    let reporting = state.touch_listeners() > 0;
    let mut props = Vec::new();
    if reporting {
        props.push(ObjectProp::ReportContacts(true));
    }
    if state.anchor_on_add() {
        props.push(ObjectProp::Anchored(true));
    }
    let group = state.collision_group();
    if group != "Default" {
        let id = plane
            .plane
            .client()
            .collision_group_id(&group)
            .map_err(|e| sdk_error(&what(), e))?;
        props.push(ObjectProp::CollisionGroup(id));
    }
    let object = plane
        .plane
        .add(collider, state.cframe().pose(), &props)
        .map_err(|e| sdk_error(&what(), e))?;
    let body = Body::new(object, Rc::downgrade(plane));
    plane.adopt(&state, body.clone(), reporting);
    if reporting {
        plane.listen_for_contacts();
    }
    Ok(PhysicsObject {
        body,
        part: state,
        part_ud: ud.clone(),
    })
}

/// `PhysicsService.New(opts?)`.
fn new_plane(lua: &Lua, opts: Value) -> mlua::Result<mlua::AnyUserData> {
    const WHAT: &str = "PhysicsService.New";
    let opts = match opts {
        Value::Nil => None,
        Value::Table(t) => Some(t),
        other => return Err(expected(WHAT, "a table of options or nil", &other)),
    };
    // Every option is part of the creation request: the plane never ticks before all of
    // them apply (a manual plane never ticks on its own at all).
    let mut options = PlaneOptions::default();
    let mut placement: Option<String> = None;
    for pair in opts.iter().flat_map(|t| t.pairs::<Value, Value>()) {
        let (key, value) = pair?;
        // Where the plane lives: not a plane setting, a choice of daemon.
        if matches!(&key, Value::String(k) if k.as_bytes() == b"Placement") {
            placement = match value {
                Value::String(p) => Some(p.to_str()?.to_string()),
                other => {
                    return Err(expected(
                        "PhysicsService.New: Placement",
                        "\"local\", \"auto\" or a daemon's name",
                        &other,
                    ))
                }
            };
            continue;
        }
        // No row of PhysicsPlane makes a GUI option (NewGUI has its own rows).
        options.set(PLANE.option(WHAT, &key, &value)?);
    }
    let ctx = context(lua);
    let plane = ctx
        .client_for(lua, placement.as_deref())?
        .create_plane(&options)
        .map_err(|e| sdk_error(WHAT, e))?;
    // Placed on a daemon by name: `--rebalance` leaves it there.
    if placement
        .as_deref()
        .is_some_and(|p| p != "local" && p != "auto")
    {
        plane.pin().map_err(|e| sdk_error(WHAT, e))?;
    }
    wrap_plane(lua, plane)
}

/// The script's handle on a new plane of this client (`New`, `FromSnapshot`).
pub(crate) fn wrap_plane(lua: &Lua, plane: Plane) -> mlua::Result<mlua::AnyUserData> {
    let ctx = context(lua);
    let state = Rc::new(PlaneState {
        plane,
        alive: Cell::new(true),
        parts: RefCell::default(),
        by_handle: RefCell::default(),
        contacts: ContactPump::default(),
        controllers: RefCell::default(),
        maps: RefCell::default(),
        cframe_listen: Default::default(),
    });
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

/// The `PhysicsService` module.
pub fn module(lua: &Lua) -> mlua::Result<Table> {
    let m = lua.create_table()?;
    m.set("New", lua.create_function(new_plane)?)?;
    let ctx = context(lua);
    m.set("Stalled", ctx.stalled.clone())?;
    m.set("Resumed", ctx.resumed.clone())?;
    m.set(
        "HumanoidRagdoll",
        lua.create_function(super::ragdoll::humanoid)?,
    )?;
    super::collision_groups::install(lua, &m)?;
    m.set("NewGUI", lua.create_function(super::gui_plane::new_gui)?)?;
    super::snapshot::install(lua, &m)?;
    super::named_plane::install(lua, &m)?;
    super::start_plane::install(lua, &m)?;
    Ok(m)
}

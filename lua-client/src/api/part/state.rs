//! The state behind a `BasePart`: its shape and mesh, its own properties and signals, and
//! its [`PartObject`] while a plane simulates it. The plane a body is in is reached through
//! [`PartPlane`] (the plane holds its parts, so this file cannot name it).

use client_sdk::Handle;
use std::cell::{Cell, RefCell};
use std::rc::{Rc, Weak};

use client_sdk::{Object, ObjectProp, Shape};
use mlua::{Lua, MultiValue, Value};

use super::pose_table::PoseTable;
use crate::host::signal::Signal;
use crate::host::watched::Watched;
use crate::props::Target;
use crate::values::{new_vector, sdk_error, CFrame, CFrameCache};

thread_local! {
    /// Counts every change that can change whether a plane's parts have touch or CFrame
    /// handlers (a part's Touched / TouchEnded / CFrame-change handlers connected or gone, a
    /// part added to or removed from a plane): a plane asks its parts again only after one.
    static HANDLERS_EPOCH: Cell<u64> = const { Cell::new(0) };
}

/// A part's touch or CFrame handlers, or a plane's parts, changed (see `HANDLERS_EPOCH`).
pub(crate) fn handlers_changed() {
    HANDLERS_EPOCH.with(|e| e.set(e.get().wrapping_add(1)));
}

/// An answer about a plane's parts' handlers ("does any part have one?"), kept while
/// [`handlers_changed`] was not called since it was found.
#[derive(Default)]
pub(crate) struct HandlersAnswer(Cell<Option<(u64, bool)>>);

impl HandlersAnswer {
    /// The kept answer, or `find`'s when handlers or parts changed since.
    pub(crate) fn get(&self, find: impl FnOnce() -> bool) -> bool {
        let epoch = HANDLERS_EPOCH.with(Cell::get);
        match self.0.get() {
            Some((seen, answer)) if seen == epoch => answer,
            _ => {
                let answer = find();
                self.0.set(Some((epoch, answer)));
                answer
            }
        }
    }
}

/// What a body, its part and its PhysicsObject ask of the plane the body is in (the plane's
/// state implements it).
pub trait PartPlane {
    /// Forgets `part`, whose body `handle` left the plane.
    fn forget(&self, part: &Rc<PartState>, handle: Handle);
    /// Starts reading the plane's events (a handler that needs them was connected).
    fn listen_for_contacts(&self);
    /// The script's value of the plane's body `handle`: its BasePart, the Map it is, or nil.
    fn body_value(&self, lua: &Lua, handle: Handle) -> mlua::Result<Value>;
}

/// Shapes a BasePart can have (the collider the plane builds from it). The part's origin is
/// the centre of its Size box for every shape.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PartShape {
    /// A box of the part's size.
    Cube,
    /// The largest sphere that fits in the part's size.
    Sphere,
    /// A capsule along the part's Y axis: radius min(Size.X, Size.Z) / 2, total height
    /// Size.Y (a ball when Size.Y is at most the diameter).
    Capsule,
    /// A cylinder along the part's Y axis: radius min(Size.X, Size.Z) / 2, height Size.Y.
    Cylinder,
    /// A ramp filling half of the Size box (Roblox's WedgePart): full bottom face, vertical
    /// face at the back (+Z), slope falling from the top-back edge to the bottom-front edge
    /// (-Z). Its centre of mass is at (0, -Size.Y/6, +Size.Z/6).
    Wedge,
    /// `Renderable.MeshPart(vertices, triangles)`: collides as the convex hull of its
    /// vertices, scaled so that their bounding box is the part's Size (which starts as that
    /// box). Not a `BasePart(shape)` name: it needs its mesh.
    Mesh,
}

impl PartShape {
    /// Every shape, in the order error messages list them.
    pub const ALL: [PartShape; 5] = [
        PartShape::Cube,
        PartShape::Sphere,
        PartShape::Capsule,
        PartShape::Cylinder,
        PartShape::Wedge,
    ];

    /// The accepted names, as error messages list them.
    pub const NAMES: &'static str = "\"Cube\", \"Sphere\", \"Capsule\", \"Cylinder\" or \"Wedge\"";

    /// The Lua name (also a new part's default name).
    pub fn name(self) -> &'static str {
        match self {
            PartShape::Cube => "Cube",
            PartShape::Sphere => "Sphere",
            PartShape::Capsule => "Capsule",
            PartShape::Cylinder => "Cylinder",
            PartShape::Wedge => "Wedge",
            PartShape::Mesh => "MeshPart",
        }
    }

    /// The shape called `name`, if any.
    pub fn from_name(name: &[u8]) -> Option<PartShape> {
        Self::ALL.into_iter().find(|s| s.name().as_bytes() == name)
    }

    /// The collider for a part of `size`: a box of that full size, the largest sphere that
    /// fits in it, or the capsule, cylinder or wedge of that size.
    pub fn collider(self, size: [f32; 3]) -> Shape {
        match self {
            PartShape::Cube => Shape::Cube { size },
            PartShape::Sphere => Shape::Sphere {
                radius: size.iter().copied().fold(f32::INFINITY, f32::min) * 0.5,
            },
            PartShape::Capsule => Shape::Capsule { size },
            PartShape::Cylinder => Shape::Cylinder { size },
            PartShape::Wedge => Shape::Wedge { size },
            PartShape::Mesh => unreachable!("a mesh part's collider comes from its mesh"),
        }
    }
}

/// The mesh of a `Renderable.MeshPart`: vertices relative to their bounding box centre,
/// 0-based triangles, and the box's extent (the Size at which they are sent unscaled).
pub struct MeshData {
    vertices: Vec<[f32; 3]>,
    triangles: Vec<[u32; 3]>,
    extent: [f32; 3],
}

impl MeshData {
    /// The collider at `size`: the vertices scaled by `size / extent` per axis (an axis
    /// without extent keeps its coordinates).
    fn collider(&self, size: [f32; 3]) -> Shape {
        let k: [f32; 3] = std::array::from_fn(|i| {
            if self.extent[i] > 0.0 {
                size[i] / self.extent[i]
            } else {
                1.0
            }
        });
        Shape::Mesh {
            vertices: self
                .vertices
                .iter()
                .map(|v| [v[0] * k[0], v[1] * k[1], v[2] * k[2]])
                .collect(),
            triangles: self.triangles.clone(),
        }
    }
}

/// Why a body stopped being its part's.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Ended {
    /// `obj:Unlink()`: the part left the plane.
    Unlinked,
    /// `obj:Destroy()` or `part:Destroy()`.
    Destroyed,
    /// `plane:Destroy()`.
    PlaneDestroyed,
}

impl Ended {
    /// What happened, as error messages say it ("PhysicsObject \"Ball\" ...").
    pub fn says(self) -> &'static str {
        match self {
            Ended::Unlinked => "was unlinked from its plane",
            Ended::Destroyed => "was destroyed",
            Ended::PlaneDestroyed => "was destroyed with its plane",
        }
    }
}

/// One object a part became in a plane, shared by the part (while it is the part's object)
/// and the PhysicsObject `plane:Add` returned. It is its part's until it ends; a later `Add`
/// of the same part makes a new one, so an old PhysicsObject can never reach the new object,
/// even where the daemon reuses its slot or handle.
pub struct PartObject {
    /// The SDK's object.
    pub object: Object,
    /// The plane the object is in.
    pub plane: Weak<dyn PartPlane>,
    ended: Cell<Option<Ended>>,
}

impl PartObject {
    /// A live body of `plane`.
    pub fn new<P: PartPlane + 'static>(object: Object, plane: Weak<P>) -> Rc<PartObject> {
        Rc::new(PartObject {
            object,
            plane,
            ended: Cell::new(None),
        })
    }

    /// Why it is no longer its part's body (`None` while it is).
    pub fn ended(&self) -> Option<Ended> {
        self.ended.get()
    }
}

/// A part: the host's own state of it, and its body while simulated.
pub struct PartState {
    /// Fixed when the part is made.
    pub shape: PartShape,
    name: RefCell<String>,
    size: Cell<[f32; 3]>,
    /// Roblox's BasePart.CollisionGroup: given to its body when it is added.
    collision_group: RefCell<String>,
    /// The pose while not simulated; the frozen last pose after the body went away.
    cframe: Cell<CFrame>,
    destroyed: Cell<bool>,
    link: RefCell<Option<Rc<PartObject>>>,
    signals: RefCell<Vec<(&'static str, Signal)>>,
    /// The last pose the per-tick change pass announced.
    last_fired: Cell<Option<CFrame>>,
    /// Whether its body was asked to report contacts (while Touched / TouchEnded listen).
    reporting: Cell<bool>,
    /// Whether the context's group registry already holds it (`Context::note_group_member`).
    grouped: Cell<bool>,
    /// The mesh of a MeshPart.
    mesh: RefCell<Option<Rc<MeshData>>>,
    /// The CFrame value last handed to scripts (reads of an unmoved pose reuse it).
    cframe_value: CFrameCache,
    /// The pose table entry of the part's BasePart value (see `pose_table`): told the
    /// object to read whenever the link changes.
    pose_slot: RefCell<Option<(Rc<PoseTable>, usize)>>,
    /// The address of the BasePart value the pose index knows it by (0: none yet).
    pub(crate) pose_key: Cell<usize>,
    /// Added anchored (`Renderable.Plane`, `Renderable.Brush`: static shapes).
    anchor_on_add: Cell<bool>,
    /// The ragdoll bone the part is (hits on it name the bone).
    bone: RefCell<Option<String>>,
}

impl PartState {
    /// A part of `shape` at the origin with Size (1, 1, 1).
    pub fn new(shape: PartShape) -> PartState {
        PartState {
            shape,
            name: RefCell::new(shape.name().to_string()),
            collision_group: RefCell::new("Default".to_string()),
            size: Cell::new([1.0; 3]),
            cframe: Cell::new(CFrame::IDENTITY),
            destroyed: Cell::new(false),
            link: RefCell::new(None),
            signals: RefCell::default(),
            last_fired: Cell::new(None),
            reporting: Cell::new(false),
            grouped: Cell::new(false),
            mesh: RefCell::new(None),
            cframe_value: CFrameCache::default(),
            pose_slot: RefCell::new(None),
            pose_key: Cell::new(0),
            anchor_on_add: Cell::new(false),
            bone: RefCell::new(None),
        }
    }

    /// The ragdoll bone the part is, if any.
    pub fn bone(&self) -> Option<String> {
        self.bone.borrow().clone()
    }

    /// Marks the part as the ragdoll bone `name`.
    pub fn set_bone(&self, name: &str) {
        *self.bone.borrow_mut() = Some(name.to_string());
    }

    /// Whether `plane:Add` anchors its body from the start.
    pub fn anchor_on_add(&self) -> bool {
        self.anchor_on_add.get()
    }

    /// Makes `plane:Add` anchor its body from the start (static shapes).
    pub fn set_anchor_on_add(&self, on: bool) {
        self.anchor_on_add.set(on);
    }

    /// A mesh part of `vertices` and 0-based `triangles` (indices checked by the caller):
    /// its origin is the vertices' bounding box centre, its Size that box, and `cframe`
    /// places the vertices' own frame (so the part's CFrame is `cframe` moved to the centre).
    pub fn mesh(vertices: Vec<[f32; 3]>, triangles: Vec<[u32; 3]>, cframe: CFrame) -> PartState {
        let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
        for v in &vertices {
            for k in 0..3 {
                lo[k] = lo[k].min(v[k]);
                hi[k] = hi[k].max(v[k]);
            }
        }
        let centre: [f32; 3] = std::array::from_fn(|k| (lo[k] + hi[k]) / 2.0);
        let extent: [f32; 3] = std::array::from_fn(|k| hi[k] - lo[k]);
        let vertices = vertices
            .iter()
            .map(|v| std::array::from_fn(|k| v[k] - centre[k]))
            .collect();
        let part = PartState::new(PartShape::Mesh);
        part.size.set(extent);
        part.cframe.set(cframe.compose(&CFrame {
            position: centre,
            rotation: CFrame::IDENTITY.rotation,
        }));
        *part.mesh.borrow_mut() = Some(Rc::new(MeshData {
            vertices,
            triangles,
            extent,
        }));
        part
    }

    /// The collider of the part at its current Size.
    pub fn collider(&self) -> Shape {
        match self.mesh.borrow().as_ref() {
            Some(mesh) => mesh.collider(self.size()),
            None => self.shape.collider(self.size()),
        }
    }

    /// The part's name.
    pub fn name(&self) -> String {
        self.name.borrow().clone()
    }

    /// Renames the part.
    pub fn set_name(&self, name: String) {
        *self.name.borrow_mut() = name;
    }

    /// The part's collision group name.
    pub fn collision_group(&self) -> String {
        self.collision_group.borrow().clone()
    }

    /// Stores the collision group name (see `Context::set_collision_group`).
    pub(crate) fn store_collision_group(&self, name: String) {
        *self.collision_group.borrow_mut() = name;
    }

    /// Marks the part as held by the group registry; true the first time.
    pub(crate) fn mark_grouped(&self) -> bool {
        !self.grouped.replace(true)
    }

    /// The part's group was renamed (or removed: `to` is [`client_sdk::DEFAULT_GROUP`]); its body, if any,
    /// follows by itself (the daemon keeps the group's index).
    pub(crate) fn group_renamed(&self, from: &str, to: &str) {
        let mut group = self.collision_group.borrow_mut();
        if *group == from {
            *group = to.to_string();
        }
    }

    /// The part's size.
    pub fn size(&self) -> [f32; 3] {
        self.size.get()
    }

    /// Resizes the part and, while it is simulated, its body (`what` names the property
    /// written, for errors); fires the Size change signal.
    pub fn resize(&self, lua: &Lua, what: &str, size: [f32; 3]) -> mlua::Result<()> {
        if let Some(object) = self.object() {
            object
                .set(ObjectProp::Size(size))
                .map_err(|e| sdk_error(what, e))?;
        } else {
            // A free part takes only a size a plane would (checked here, not first at Add).
            client_sdk::validate::size("Size", size)
                .map_err(|e| mlua::Error::runtime(format!("{what}: {}", e.message)))?;
        }
        self.size.set(size);
        self.changed(lua, "Size", new_vector(size))
    }

    /// Takes the Size its body already has (a part made for an existing object: nothing is
    /// sent, nothing fires).
    pub fn set_size_as_simulated(&self, size: [f32; 3]) {
        self.size.set(size);
    }

    /// Whether `:Destroy()` was called.
    pub fn is_destroyed(&self) -> bool {
        self.destroyed.get()
    }

    /// The part's current body, if it is in a plane.
    pub fn body(&self) -> Option<Rc<PartObject>> {
        self.link.borrow().clone()
    }

    /// The simulated body, if the part is in a plane.
    pub fn object(&self) -> Option<Object> {
        self.link.borrow().as_ref().map(|l| l.object.clone())
    }

    /// Makes `body` the part's body (the part is simulated from now on). `reporting`: the
    /// body was created reporting contacts.
    pub fn link(&self, body: Rc<PartObject>, reporting: bool) {
        self.last_fired.set(None);
        self.reporting.set(reporting);
        *self.link.borrow_mut() = Some(body);
        self.push_pose_source();
    }

    /// Handlers connected to Touched and TouchEnded.
    pub fn touch_listeners(&self) -> usize {
        ["Touched", "TouchEnded"]
            .iter()
            .filter_map(|n| self.existing_signal(n))
            .map(|s| s.listeners())
            .sum()
    }

    /// `part.Touched` / `part.TouchEnded`: while either has handlers, the part's body asks
    /// the daemon for contact events (a part nobody listens to costs nothing).
    pub fn touch_signal(self: &Rc<Self>, name: &'static str) -> Signal {
        let (signal, created) = self.signal(name);
        if created {
            let part = Rc::downgrade(self);
            signal.on_listeners(move |_| {
                handlers_changed();
                if let Some(part) = part.upgrade() {
                    part.sync_contact_reports();
                }
            });
        }
        signal
    }

    /// Asks the body to report contacts exactly while touch handlers exist.
    fn sync_contact_reports(&self) {
        let want = self.touch_listeners() > 0;
        let link = self.link.borrow();
        let Some(body) = link.as_ref() else {
            return;
        };
        if want == self.reporting.get() {
            return;
        }
        self.reporting.set(want);
        // A queued write: a refusal comes back with the frame's flush like any other write.
        let _ = body.object.set_report_contacts(want);
        if want {
            if let Some(plane) = body.plane.upgrade() {
                plane.listen_for_contacts();
            }
        }
    }

    /// Fires Touched (`contact` given) or TouchEnded with the other part.
    pub fn fire_touch(&self, lua: &Lua, other: Value, contact: Option<Value>) -> mlua::Result<()> {
        let name = if contact.is_some() {
            "Touched"
        } else {
            "TouchEnded"
        };
        match self.existing_signal(name) {
            Some(s) if s.listeners() > 0 => s.fire(
                lua,
                MultiValue::from_iter(std::iter::once(other).chain(contact)),
            ),
            _ => Ok(()),
        }
    }

    /// The pose: the newest tick's for a simulated part, else the stored one.
    pub fn cframe(&self) -> CFrame {
        if let Some(link) = self.link.borrow().as_ref() {
            if let Ok(pose) = link.object.pose() {
                return CFrame::from_pose(pose);
            }
        }
        self.cframe.get()
    }

    /// `cf` (a pose of this part) as a Lua value: the one last handed out while the pose is
    /// the same, so repeated reads of an unmoved part allocate nothing.
    pub fn cframe_value(&self, lua: &Lua, cf: CFrame) -> mlua::Result<Value> {
        self.cframe_value.value(lua, cf)
    }

    /// Reads of `part.CFrame` find the part at `at` (its pose table and slot; `None`: at
    /// none) from now on; the entry is told the object to read.
    pub(crate) fn set_pose_slot(&self, at: Option<(Rc<PoseTable>, usize)>) {
        *self.pose_slot.borrow_mut() = at;
        self.push_pose_source();
    }

    /// The pose table slot reads find the part at, if any.
    pub(crate) fn pose_slot(&self) -> Option<usize> {
        self.pose_slot.borrow().as_ref().map(|(_, slot)| *slot)
    }

    /// Tells the part's pose table entry the object its pose is read from now.
    fn push_pose_source(&self) {
        if let Some((table, slot)) = self.pose_slot.borrow().as_ref() {
            table.set_source(*slot, self.object());
        }
    }

    /// Stores a pose for a part that is not simulated.
    pub fn store_cframe(&self, cf: CFrame) {
        self.cframe.set(cf);
    }

    /// Leaves the plane: the part keeps its last simulated pose; its body ends for `why`.
    /// Returns the body it had.
    pub fn unlink(&self, why: Ended) -> Option<Rc<PartObject>> {
        let cf = self.cframe();
        self.cframe.set(cf);
        let body = self.link.borrow_mut().take()?;
        self.push_pose_source();
        body.ended.set(Some(why));
        self.reporting.set(false);
        Some(body)
    }

    /// Removes the part's body from its plane (queued), keeping the part.
    pub fn detach(self: &Rc<Self>, why: Ended) {
        if let Some(body) = self.unlink(why) {
            body.object.destroy();
            if let Some(plane) = body.plane.upgrade() {
                plane.forget(self, body.object.handle());
            }
        }
    }

    /// Removes the body, disconnects every change signal and marks the part destroyed.
    pub fn destroy(self: &Rc<Self>) {
        self.detach(Ended::Destroyed);
        self.destroyed.set(true);
        for (_, s) in self.signals.borrow().iter() {
            s.disconnect_all();
        }
    }

    /// The change signal `name` and whether it was created now.
    pub(crate) fn signal(&self, name: &'static str) -> (Signal, bool) {
        let mut signals = self.signals.borrow_mut();
        if let Some((_, s)) = signals.iter().find(|(n, _)| *n == name) {
            return (s.clone(), false);
        }
        let s = Signal::new(format!("{}.{name}", self.name.borrow()));
        signals.push((name, s.clone()));
        (s, true)
    }

    fn existing_signal(&self, name: &str) -> Option<Signal> {
        let signals = self.signals.borrow();
        signals
            .iter()
            .find(|(n, _)| *n == name)
            .map(|(_, s)| s.clone())
    }

    /// Handlers connected to the CFrame change signal.
    pub fn cframe_listeners(&self) -> usize {
        self.existing_signal("CFrame").map_or(0, |s| s.listeners())
    }

    /// Fires `name`'s change signal with `value` when someone listens.
    pub fn changed(&self, lua: &Lua, name: &str, value: Value) -> mlua::Result<()> {
        match self.existing_signal(name) {
            Some(s) if s.listeners() > 0 => s.fire(lua, MultiValue::from_iter([value])),
            _ => Ok(()),
        }
    }

    /// The per-tick pass: a simulated part whose pose moved announces its new CFrame.
    pub fn fire_cframe_if_moved(&self, lua: &Lua) -> mlua::Result<()> {
        if self.link.borrow().is_none() {
            return Ok(());
        }
        let cf = self.cframe();
        if self.last_fired.get() == Some(cf) {
            return Ok(());
        }
        self.last_fired.set(Some(cf));
        self.changed(lua, "CFrame", self.cframe_value(lua, cf)?)
    }
}

impl Watched for PartState {
    fn listeners(&self) -> usize {
        self.cframe_listeners()
    }

    fn fire_if_changed(&self, lua: &Lua) -> mlua::Result<()> {
        self.fire_cframe_if_moved(lua)
    }

    /// Only a simulated part moves by itself: once its body ended (unlinked, destroyed,
    /// its plane destroyed), its CFrame handlers wait for writes the script itself makes.
    fn keeps_running(&self) -> bool {
        self.object().is_some()
    }
}

/// The Lua handle of a part.
#[derive(Clone)]
pub struct BasePart(pub Rc<PartState>);

impl Target for BasePart {
    /// A part's properties are its own state: none is one SDK write.
    type Prop = std::convert::Infallible;

    fn write(&self, _: &str, prop: Self::Prop) -> mlua::Result<()> {
        match prop {}
    }
}

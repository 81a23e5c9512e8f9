//! `Map`: what `plane:LoadMap(path, opts?)` returns. A loaded map is one anchored
//! triangle-mesh object in the daemon; this is its handle for scripts, so a map can be
//! filtered out of (or into) a query, given a collision group, friction or bounciness,
//! moved, and removed. Queries, `Touched` / `TouchEnded` and `GetContacts` hand back the
//! same `Map` value the script holds (see `identity.rs`), and query filters accept it.
//!
//! Its build report stays readable the old way (`map.Meshes`, `map.Triangles`,
//! `map.Vertices`, `map.Validation.OpenEdges`) next to `map.Stats`. A map is static: the
//! properties of moving bodies (Velocity, Size, Weight, ...) are refused by name, with why.

use std::rc::Rc;

use client_sdk::{Handle, Object, ObjectProp};
use mlua::{AnyUserData, Lua, MetaMethod, Table, UserData, UserDataMethods, Value};

use super::plane::state::{MapState, PhysicsPlane, PlaneState};
use crate::props::{Get, Kind, Props, Row, Set, Target};
use crate::values::{describe, lua_number, sdk_error, CFrame, DESCRIBE};

/// What a map lets change, as refusals of the other object properties say: its writable
/// rows ("only CFrame, Friction, Bounciness, CanCollide and CollisionGroup can").
fn changeable() -> String {
    let names: Vec<&str> = MAP
        .rows
        .iter()
        .filter(|r| !matches!(r.set, Set::ReadOnly) && r.name != "Anchored")
        .map(|r| r.name)
        .collect();
    match names.split_last() {
        Some((last, rest)) if !rest.is_empty() => {
            format!("only {} and {last} can", rest.join(", "))
        }
        _ => format!("only {} can", names.concat()),
    }
}

/// Whether `name` is a writable PhysicsObject property that a map has no row for: a property
/// of moving bodies a map refuses (it is static).
fn refused_on_maps(name: &str) -> bool {
    let object = &super::object::props::OBJECT;
    let writable = object
        .rows
        .iter()
        .chain(object.table_rows())
        .any(|r| r.name == name && !matches!(r.set, Set::ReadOnly));
    writable && !MAP.rows.iter().any(|r| r.name == name)
}

impl MapState {
    /// The map's handle (what hits and contacts name).
    pub fn handle(&self) -> Handle {
        self.map.handle()
    }

    /// `Map terrain.glb`, with " (destroyed)" once it is gone.
    pub fn describe(&self) -> String {
        let gone = if self.alive() { "" } else { " (destroyed)" };
        format!("Map {}{gone}", self.name)
    }

    fn plane_alive(&self) -> bool {
        self.plane.upgrade().is_some_and(|p| p.alive())
    }

    /// Whether the map still exists: not destroyed, its plane not destroyed.
    pub fn alive(&self) -> bool {
        !self.destroyed.get() && self.plane_alive() && self.map.is_alive().unwrap_or(false)
    }

    /// The map's object while it exists; else an error for `what` (the property or method,
    /// e.g. `Map.Friction`) saying it is gone.
    pub fn live(&self, what: &str) -> mlua::Result<&Object> {
        if self.destroyed.get() || !self.plane_alive() {
            let why = if self.destroyed.get() {
                "was destroyed"
            } else {
                "is gone: its plane was destroyed"
            };
            return Err(mlua::Error::runtime(format!(
                "{what}: Map {} {why} (read Alive to check)",
                self.name
            )));
        }
        Ok(&self.map.object)
    }

    /// Removes the map (idempotent).
    fn destroy(&self) {
        if self.destroyed.replace(true) {
            return;
        }
        if let Some(plane) = self.plane.upgrade() {
            plane.forget_map(self.handle());
            if plane.alive() {
                self.map.destroy();
            }
        }
    }

    fn info(&self, what: &str) -> mlua::Result<client_sdk::ObjectInfo> {
        let what = format!("Map.{what}");
        self.live(&what)?
            .properties()
            .map_err(|e| sdk_error(&what, e))
    }

    /// The build report as a table: `Meshes`, `TrianglesIn`, `Triangles`, `VerticesIn`,
    /// `Vertices` and every validation count.
    fn stats(&self, lua: &Lua) -> mlua::Result<Table> {
        let r = &self.map.report;
        let t = self.validation(lua)?;
        t.set("Meshes", self.map.meshes)?;
        t.set("TrianglesIn", r.triangles_in)?;
        t.set("Triangles", r.triangles)?;
        t.set("VerticesIn", r.vertices_in)?;
        t.set("Vertices", r.vertices)?;
        Ok(t)
    }

    /// The findings a user acts on: degenerate triangles dropped, duplicate vertices
    /// merged, non-manifold, welded and open edges (what `LoadMap` always returned).
    fn validation(&self, lua: &Lua) -> mlua::Result<Table> {
        let r = &self.map.report;
        let v = lua.create_table()?;
        v.set("DegenerateTriangles", r.degenerate_triangles)?;
        v.set("DuplicateVerticesMerged", r.duplicate_vertices_merged)?;
        v.set("NonManifoldEdges", r.non_manifold_edges)?;
        v.set("WeldedEdges", r.welded_edges)?;
        v.set("OpenEdges", r.open_edges)?;
        Ok(v)
    }
}

impl Target for MapState {
    type Prop = ObjectProp;

    fn write(&self, name: &str, prop: ObjectProp) -> mlua::Result<()> {
        let what = format!("Map.{name}");
        self.live(&what)?.set(prop).map_err(|e| sdk_error(&what, e))
    }
}

/// A row read from the daemon's properties of the map (the SDK's mirror).
macro_rules! info_row {
    ($name:literal, $kind:expr, |$i:ident| $read:expr, |$a:ident| $write:expr) => {
        Row {
            name: $name,
            kind: $kind,
            get: Get::Fn(|_, m| {
                let $i = m.info($name)?;
                Ok($read)
            }),
            set: Set::Prop(|$a| Ok($write)),
        }
    };
}

/// A read-only row of what the host holds itself.
macro_rules! own_row {
    ($name:literal, |$lua:tt, $m:ident| $read:expr) => {
        Row {
            name: $name,
            kind: Kind::String,
            get: Get::Fn(|$lua, $m| Ok($read)),
            set: Set::ReadOnly,
        }
    };
}

/// The rows of `Map`.
pub static MAP: Props<MapState> = Props {
    owner: "Map",
    table: None,
    rows: &[
        // Moves the static map (it stays anchored): the newest tick, writes on top.
        Row {
            name: "CFrame",
            kind: Kind::CFrame,
            get: Get::Fn(|lua, m| {
                let s = m
                    .live("Map.CFrame")?
                    .state()
                    .map_err(|e| sdk_error("Map.CFrame", e))?;
                let cf = CFrame::from_pose(s.pose());
                cf.into_value(lua)
            }),
            set: Set::Prop(|a| Ok(ObjectProp::Pose(a.cframe()?.pose()))),
        },
        info_row!("Friction", Kind::UNIT, |i| lua_number(i.friction), |a| {
            ObjectProp::Friction(a.number()? as f32)
        }),
        // Documented as clamped to [0, 1], as on objects.
        info_row!(
            "Bounciness",
            Kind::ANY_NUMBER,
            |i| lua_number(i.bounciness),
            |a| ObjectProp::Bounciness(a.number()? as f32)
        ),
        info_row!(
            "CanCollide",
            Kind::Boolean,
            |i| Value::Boolean(i.can_collide),
            |a| ObjectProp::CanCollide(a.bool()?)
        ),
        // The daemon keeps the group's index: renaming the group renames the map's, removing
        // it puts the map in "Default", as for parts.
        Row {
            name: "CollisionGroup",
            kind: Kind::String,
            get: Get::Fn(|lua, m| {
                let id = m.info("CollisionGroup")?.collision_group;
                let name = m.map.object.plane().client().collision_group_name(id);
                Ok(Value::String(lua.create_string(name)?))
            }),
            set: Set::Fn(|_, m, a| {
                const W: &str = "Map.CollisionGroup";
                m.live(W)?
                    .set_collision_group(&a.string()?)
                    .map_err(|e| sdk_error(W, e))
            }),
        },
        // Always true; writing false is refused (a map is static).
        Row {
            name: "Anchored",
            kind: Kind::Boolean,
            get: Get::Fn(|_, m| {
                m.live("Map.Anchored")?;
                Ok(Value::Boolean(true))
            }),
            set: Set::Fn(|_, m, a| {
                m.live("Map.Anchored")?;
                match a.bool()? {
                    true => Ok(()),
                    false => Err(mlua::Error::runtime(format!(
                        "Map.Anchored cannot be false: a map is a static triangle mesh ({})",
                        changeable()
                    ))),
                }
            }),
        },
        Row {
            name: "Alive",
            kind: Kind::Boolean,
            get: Get::Fn(|_, m| Ok(Value::Boolean(m.alive()))),
            set: Set::ReadOnly,
        },
        own_row!("Name", |lua, m| Value::String(lua.create_string(&m.name)?)),
        // The plane's own value (`map.Plane == plane`); nil once the plane is collected.
        own_row!("Plane", |lua, m| match m.plane.upgrade() {
            Some(p) => Value::UserData(super::plane::context::plane_ud(lua, &p)?),
            None => Value::Nil,
        }),
        own_row!("Stats", |lua, m| Value::Table(m.stats(lua)?)),
        own_row!("Validation", |lua, m| Value::Table(m.validation(lua)?)),
        // What LoadMap's table held before it returned a Map (kept for scripts using it).
        own_row!("Meshes", |_, m| lua_number(m.map.meshes as f64)),
        own_row!("Triangles", |_, m| lua_number(
            m.map.report.triangles as f64
        )),
        own_row!("Vertices", |_, m| lua_number(m.map.report.vertices as f64)),
    ],
};

/// The Lua value of a map.
pub struct Map(pub Rc<MapState>);

impl UserData for Map {
    fn add_methods<M: UserDataMethods<Self>>(methods: &mut M) {
        // Destroying a destroyed map (or one whose plane is gone) does nothing.
        methods.add_method("Destroy", |_, m, ()| {
            m.0.destroy();
            Ok(())
        });
        methods.add_meta_method(MetaMethod::Index, |lua, m, key: Value| {
            MAP.get(lua, &m.0, &key)
        });
        methods.add_meta_method(
            MetaMethod::NewIndex,
            |lua, m, (key, value): (Value, Value)| {
                if let Value::String(s) = &key {
                    let name = s.to_string_lossy();
                    if refused_on_maps(&name) {
                        return Err(mlua::Error::runtime(format!(
                            "Map.{name} cannot change: a map is a static triangle mesh \
                             ({}; assigned {})",
                            changeable(),
                            describe(&value)
                        )));
                    }
                }
                MAP.set(lua, &m.0, &key, &value)
            },
        );
        methods.add_meta_method(MetaMethod::ToString, |_, m, ()| Ok(m.0.describe()));
        methods.add_meta_method(DESCRIBE, |_, m, ()| Ok(m.0.describe()));
        methods.add_meta_method(MetaMethod::Eq, |_, m, other: Value| {
            Ok(match other {
                Value::UserData(ud) => ud.borrow::<Map>().is_ok_and(|o| Rc::ptr_eq(&o.0, &m.0)),
                _ => false,
            })
        });
    }
}

/// The script's `Map` value of `map` (one per map: see `identity.rs`).
pub(crate) fn map_ud(lua: &Lua, map: &Rc<MapState>) -> mlua::Result<AnyUserData> {
    crate::host::identity::userdata(
        lua,
        Rc::as_ptr(map).cast(),
        crate::host::identity::tag::MAP,
        || Map(map.clone()),
    )
}

/// The handle of a live `Map` value, `None` for any other value; a destroyed map gives
/// `Some(None)` (it filters nothing, as a stale object).
pub(crate) fn map_handle(v: &Value) -> Option<Option<Handle>> {
    let Value::UserData(ud) = v else {
        return None;
    };
    let m = ud.borrow::<Map>().ok()?;
    Some(m.0.alive().then(|| m.0.handle()))
}

/// The Map of body `h` of `plane`, as a Lua value, if `h` is a map this host loaded.
pub(crate) fn map_value(lua: &Lua, plane: &PlaneState, h: Handle) -> mlua::Result<Option<Value>> {
    match plane.map_of(h) {
        Some(m) => Ok(Some(Value::UserData(map_ud(lua, &m)?))),
        None => Ok(None),
    }
}

/// `plane:LoadMap(path, opts?)` once the file is loaded: the map's Lua value, remembered by
/// its plane so hits and contacts on it hand it back.
pub(crate) fn new_map(
    lua: &Lua,
    plane: &PhysicsPlane,
    map: client_sdk::Map,
    path: &str,
) -> mlua::Result<AnyUserData> {
    let name = std::path::Path::new(path)
        .file_name()
        .map_or_else(|| path.to_string(), |n| n.to_string_lossy().into_owned());
    let state = Rc::new(MapState::new(map, &plane.0, name));
    plane.0.keep_map(state.clone());
    map_ud(lua, &state)
}

impl PlaneState {
    /// Remembers a map this host loaded into the plane.
    pub(crate) fn keep_map(&self, map: Rc<MapState>) {
        self.maps.borrow_mut().insert(map.handle(), map);
    }

    /// Forgets map `handle` (destroyed).
    pub(crate) fn forget_map(&self, handle: Handle) {
        self.maps.borrow_mut().remove(&handle);
    }

    /// The map whose body is `handle`, if this host loaded it.
    pub(crate) fn map_of(&self, handle: Handle) -> Option<Rc<MapState>> {
        self.maps.borrow().get(&handle).cloned()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn maps_refuse_what_moves_and_take_what_the_daemon_takes() {
        for name in [
            "Velocity",
            "AngularVelocity",
            "Size",
            "Weight",
            "Density",
            "CenterOfMass",
            "HitBoxQuality",
            "ImpulseDirection",
            "ConstantForce",
            "GravityScale",
        ] {
            assert!(refused_on_maps(name), "{name} should be refused on maps");
        }
        for name in [
            "CFrame",
            "Friction",
            "Bounciness",
            "CanCollide",
            "CollisionGroup",
        ] {
            assert!(!refused_on_maps(name), "{name} changes on maps");
        }
        // What the Lua Map lets change is what the daemon lets a map change (one flag,
        // `on_maps`, in the object settings table).
        for row in MAP.rows.iter().filter(|r| !matches!(r.set, Set::ReadOnly)) {
            if row.name == "Anchored" {
                continue;
            }
            let wire = ObjectProp::row_named(row.name);
            assert!(
                wire.on_maps,
                "Map.{} is writable but maps refuse it",
                row.name
            );
        }
        assert_eq!(
            changeable(),
            "only CFrame, Friction, Bounciness, CanCollide and CollisionGroup can"
        );
    }
}

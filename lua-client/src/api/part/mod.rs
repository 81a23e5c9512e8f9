//! `Renderable.BasePart`: the host stand-in for a visual part. Once a plane simulates it,
//! reading `part.CFrame` returns the pose of the newest tick, read from shared memory.

pub(crate) mod pose_index;
pub(crate) mod pose_table;
pub(crate) mod props;
pub(crate) mod state;

use std::rc::Rc;

use mlua::{Lua, MetaMethod, Table, UserData, UserDataMethods, Value};

use super::method_tables::index;
use crate::host::scheduler::scheduler;
use crate::values::{describe, expected, finite_number, finite_vector, CFrame, DESCRIBE};
use props::PART;
use state::{handlers_changed, BasePart, PartShape, PartState};

/// `Renderable.MeshPart(vertices, triangles)`: `vertices` an array of Vectors, `triangles`
/// an array of `{i, j, k}` 1-based indices into it. Errors name the entry and its value.
fn mesh_part(vertices: Value, triangles: Value) -> mlua::Result<PartState> {
    const WHAT: &str = "Renderable.MeshPart";
    let Value::Table(vt) = &vertices else {
        return Err(expected(WHAT, "an array of Vectors as vertices", &vertices));
    };
    let Value::Table(tt) = &triangles else {
        return Err(expected(
            WHAT,
            "an array of {i, j, k} vertex indices as triangles",
            &triangles,
        ));
    };
    let mut verts = Vec::new();
    for (i, v) in vt.clone().sequence_values::<Value>().enumerate() {
        verts.push(finite_vector(&format!("{WHAT} vertices[{}]", i + 1), &v?)?);
    }
    if verts.len() < 4 {
        return Err(mlua::Error::runtime(format!(
            "{WHAT}: vertices needs at least 4 points (a solid), got {}",
            verts.len()
        )));
    }
    let mut tris = Vec::new();
    for (i, t) in tt.clone().sequence_values::<Value>().enumerate() {
        let what = format!("{WHAT} triangles[{}]", i + 1);
        let t = t?;
        let Value::Table(corners) = &t else {
            return Err(expected(&what, "a table {i, j, k}", &t));
        };
        let mut tri = [0u32; 3];
        for (c, slot) in tri.iter_mut().enumerate() {
            let v: Value = corners.get(c + 1)?;
            let n = finite_number(&what, &v)?;
            if n.fract() != 0.0 || n < 1.0 || n > verts.len() as f64 {
                return Err(mlua::Error::runtime(format!(
                    "{what}[{}]: {} is not a vertex index (1 to {})",
                    c + 1,
                    describe(&v),
                    verts.len()
                )));
            }
            *slot = n as u32 - 1;
        }
        tris.push(tri);
    }
    Ok(PartState::mesh(verts, tris, CFrame::IDENTITY))
}

/// `self` of a method called on a BasePart, or an error saying how it was called.
fn this_part(what: &str, v: &Value) -> mlua::Result<Rc<PartState>> {
    match v {
        Value::UserData(ud) => ud.borrow::<BasePart>().map(|p| p.0.clone()).ok(),
        _ => None,
    }
    .ok_or_else(|| expected(what, "a BasePart as self (call it with ':')", v))
}

/// BasePart's methods, looked up by `__index` after its properties.
pub fn methods(lua: &Lua) -> mlua::Result<Table> {
    let t = lua.create_table()?;
    let changed = |what: &'static str| {
        move |lua: &Lua, (this, name): (Value, Value)| {
            let part = this_part(what, &this)?;
            let row = PART.row(&name).ok_or_else(|| {
                let names: Vec<&str> = PART.rows.iter().map(|r| r.name).collect();
                mlua::Error::runtime(format!(
                    "{what} expects a property name ({}), got {}",
                    names.join(", "),
                    describe(&name)
                ))
            })?;
            let (signal, created) = part.signal(row.name);
            if created && row.name == "CFrame" {
                scheduler(lua).watch(part.clone());
                // Its planes' post-tick pass asks their parts again (`PlaneState::after_tick`).
                signal.on_listeners(|_| handlers_changed());
            }
            signal.userdata(lua)
        }
    };
    t.set(
        "GetPropertyChanged",
        lua.create_function(changed("BasePart:GetPropertyChanged"))?,
    )?;
    t.set(
        "GetPropertyChangedSignal",
        lua.create_function(changed("BasePart:GetPropertyChangedSignal"))?,
    )?;
    t.set(
        "Destroy",
        lua.create_function(|_, this: Value| {
            this_part("BasePart:Destroy", &this)?.destroy();
            Ok(())
        })?,
    )?;
    Ok(t)
}

impl BasePart {
    /// `BasePart "Name"`: how `tostring` and error messages show a part.
    fn describe(&self) -> String {
        format!("BasePart \"{}\"", self.0.name())
    }
}

impl UserData for BasePart {
    // Methods live in a table `__index` consults after the properties (see `method_tables::index`).
    fn add_methods<M: UserDataMethods<Self>>(methods: &mut M) {
        methods.add_meta_method(MetaMethod::Index, |lua, part, key: Value| {
            index(lua, &PART, |m| &m.part, part, key)
        });
        methods.add_meta_method(
            MetaMethod::NewIndex,
            |lua, part, (key, value): (Value, Value)| PART.set(lua, part, &key, &value),
        );
        methods.add_meta_method(MetaMethod::ToString, |_, part, ()| {
            let gone = if part.0.is_destroyed() {
                " (destroyed)"
            } else {
                ""
            };
            Ok(format!("{}{gone}", part.describe()))
        });
        methods.add_meta_method(DESCRIBE, |_, part, ()| Ok(part.describe()));
        methods.add_meta_method(MetaMethod::Eq, |_, part, other: Value| {
            Ok(match other {
                Value::UserData(ud) => ud
                    .borrow::<BasePart>()
                    .is_ok_and(|o| Rc::ptr_eq(&o.0, &part.0)),
                _ => false,
            })
        });
    }
}

/// The `Renderable` module: `Renderable.BasePart(shape)`.
pub fn module(lua: &Lua) -> mlua::Result<Table> {
    let renderable = lua.create_table()?;
    renderable.set(
        "BasePart",
        lua.create_function(|lua, shape: Value| {
            let shape = match &shape {
                Value::Nil => Some(PartShape::Cube),
                Value::String(s) => PartShape::from_name(&s.as_bytes()),
                _ => None,
            }
            .ok_or_else(|| expected("Renderable.BasePart", PartShape::NAMES, &shape))?;
            part_ud(lua, &Rc::new(PartState::new(shape)))
        })?,
    )?;
    renderable.set(
        "MeshPart",
        lua.create_function(|lua, (vertices, triangles): (Value, Value)| {
            part_ud(lua, &Rc::new(mesh_part(vertices, triangles)?))
        })?,
    )?;
    Ok(renderable)
}

/// The script's `BasePart` value of `part` (one per part: see `identity.rs`).
pub(crate) fn part_ud(lua: &Lua, part: &Rc<PartState>) -> mlua::Result<mlua::AnyUserData> {
    let ud = crate::host::identity::userdata(
        lua,
        Rc::as_ptr(part).cast(),
        crate::host::identity::tag::PART,
        || BasePart(part.clone()),
    )?;
    pose_index::register(lua, &ud, part)?;
    Ok(ud)
}

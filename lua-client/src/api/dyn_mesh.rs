//! `DynMesh`: decorative geometry welded to a part, on the host. `DynMesh.new(part)` wraps
//! a driving part (a controller's `BasePart()`, any part); `mesh:Weld(other, {Offset =
//! CFrame})` makes `other` ride along: at the start of every frame (before `Heart`) and
//! after every `plane:Step` (before its CFrame signals fire) its CFrame becomes the
//! driver's CFrame times the offset. No daemon cost and no physics body:
//! welded parts are for hats, arms, weapons, billboards. Deforming a mesh belongs to the
//! host's renderer, not to this service.

use std::cell::{Cell, RefCell};
use std::rc::{Rc, Weak};

use mlua::{Lua, MetaMethod, Table, UserData, UserDataMethods, Value};

use super::part::state::{BasePart, PartState};
use crate::host::scheduler::scheduler;
use crate::host::Watched;
use crate::values::{expected, CFrame};

struct Weld {
    part: Rc<PartState>,
    offset: CFrame,
}

/// A driving part and what is welded to it.
pub struct MeshState {
    driver: Rc<PartState>,
    welds: RefCell<Vec<Weld>>,
    destroyed: Cell<bool>,
}

impl MeshState {
    /// Moves every welded part to the driver's CFrame times its offset; forgets destroyed
    /// parts.
    fn follow(&self, lua: &Lua) -> mlua::Result<()> {
        if self.driver.is_destroyed() {
            return Ok(());
        }
        let at = self.driver.cframe();
        self.welds.borrow_mut().retain(|w| !w.part.is_destroyed());
        let welds: Vec<(Rc<PartState>, CFrame)> = self
            .welds
            .borrow()
            .iter()
            .map(|w| (w.part.clone(), w.offset))
            .collect();
        for (part, offset) in welds {
            let cf = at.compose(&offset);
            if part.cframe() != cf {
                part.store_cframe(cf);
                part.changed(lua, "CFrame", part.cframe_value(lua, cf)?)?;
            }
        }
        Ok(())
    }
}

impl Watched for MeshState {
    fn listeners(&self) -> usize {
        self.welds.borrow().len()
    }

    fn fire_if_changed(&self, lua: &Lua) -> mlua::Result<()> {
        self.follow(lua)
    }

    fn keeps_running(&self) -> bool {
        false
    }
}

/// Every DynMesh of a Lua state, for the welds to follow after each `plane:Step`.
#[derive(Default)]
struct Meshes(RefCell<Vec<Weak<MeshState>>>);

/// Moves the welded parts of every DynMesh to their drivers (after a `plane:Step`, whose
/// ticks moved the drivers; a script stepping in a loop without yielding sees its welds
/// follow each step). Costs one length check while no DynMesh exists.
pub(crate) fn follow_all(lua: &Lua) -> mlua::Result<()> {
    let meshes: Vec<Rc<MeshState>> = match lua.app_data_ref::<Meshes>() {
        Some(m) => {
            let mut list = m.0.borrow_mut();
            list.retain(|w| w.strong_count() > 0);
            list.iter().filter_map(Weak::upgrade).collect()
        }
        None => return Ok(()),
    };
    for mesh in meshes {
        if !mesh.destroyed.get() {
            mesh.follow(lua)?;
        }
    }
    Ok(())
}

/// The Lua value of a `DynMesh`.
pub struct DynMesh(Rc<MeshState>);

fn part_arg(what: &str, v: &Value) -> mlua::Result<Rc<PartState>> {
    match v {
        Value::UserData(ud) => ud.borrow::<BasePart>().map(|p| p.0.clone()).ok(),
        _ => None,
    }
    .ok_or_else(|| expected(what, "a BasePart", v))
}

impl DynMesh {
    fn live(&self, what: &str) -> mlua::Result<()> {
        match self.0.destroyed.get() {
            true => Err(mlua::Error::runtime(format!(
                "{what}: the DynMesh was destroyed"
            ))),
            false => Ok(()),
        }
    }
}

impl UserData for DynMesh {
    fn add_methods<M: UserDataMethods<Self>>(methods: &mut M) {
        methods.add_method("Weld", |lua, m, (part, opts): (Value, Value)| {
            const W: &str = "DynMesh:Weld";
            m.live(W)?;
            let part = part_arg(W, &part)?;
            if Rc::ptr_eq(&part, &m.0.driver) {
                return Err(mlua::Error::runtime(format!(
                    "{W}: a part cannot be welded to itself"
                )));
            }
            if part.object().is_some() {
                return Err(mlua::Error::runtime(format!(
                    "{W}: the part is simulated in a plane (Unlink it first): welded parts \
                     are decorative and follow their driver on the host"
                )));
            }
            let offset = match &opts {
                Value::Nil => CFrame::IDENTITY,
                Value::Table(t) => match t.get::<Value>("Offset")? {
                    Value::Nil => CFrame::IDENTITY,
                    other => match CFrame::from_value(&other) {
                        Some(cf) => cf,
                        None => return Err(expected(&format!("{W} Offset"), "a CFrame", &other)),
                    },
                },
                other => {
                    return Err(expected(
                        W,
                        "a table of options ({ Offset = CFrame }) or nil",
                        other,
                    ))
                }
            };
            {
                let mut welds = m.0.welds.borrow_mut();
                welds.retain(|w| !Rc::ptr_eq(&w.part, &part));
                welds.push(Weld { part, offset });
            }
            // In place at once, not only from the next frame.
            m.0.follow(lua)
        });
        methods.add_method("Unweld", |_, m, part: Value| {
            const W: &str = "DynMesh:Unweld";
            m.live(W)?;
            let part = part_arg(W, &part)?;
            m.0.welds
                .borrow_mut()
                .retain(|w| !Rc::ptr_eq(&w.part, &part));
            Ok(())
        });
        methods.add_method("BasePart", |lua, m, ()| {
            super::part::part_ud(lua, &m.0.driver)
        });
        methods.add_method("GetWelded", |lua, m, ()| {
            let list = lua.create_table()?;
            for w in m.0.welds.borrow().iter() {
                list.push(super::part::part_ud(lua, &w.part)?)?;
            }
            Ok(list)
        });
        methods.add_method("Destroy", |_, m, ()| {
            m.0.destroyed.set(true);
            m.0.welds.borrow_mut().clear();
            Ok(())
        });
        methods.add_meta_method(MetaMethod::ToString, |_, m, ()| {
            let state = if m.0.destroyed.get() {
                " (destroyed)"
            } else {
                ""
            };
            Ok(format!(
                "DynMesh of BasePart \"{}\"{state}",
                m.0.driver.name()
            ))
        });
    }
}

/// The `DynMesh` module: `DynMesh.new(part)`.
pub fn module(lua: &Lua) -> mlua::Result<Table> {
    let m = lua.create_table()?;
    m.set(
        "new",
        lua.create_function(|lua, part: Value| {
            let driver = part_arg("DynMesh.new", &part)?;
            let state = Rc::new(MeshState {
                driver,
                welds: RefCell::default(),
                destroyed: Cell::new(false),
            });
            // Probed every frame; it costs one length check while nothing is welded.
            scheduler(lua).watch(state.clone());
            if lua.app_data_ref::<Meshes>().is_none() {
                lua.set_app_data(Meshes::default());
            }
            if let Some(meshes) = lua.app_data_ref::<Meshes>() {
                meshes.0.borrow_mut().push(Rc::downgrade(&state));
            }
            Ok(DynMesh(state))
        })?,
    )?;
    Ok(m)
}

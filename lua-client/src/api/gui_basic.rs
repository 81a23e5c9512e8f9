//! The `GUI` module: `GUI.Basic.Square/Circle/Triangle/Image/Text()` primitives, headless
//! (no window) the way `Renderable.BasePart` is. A primitive has `Size`, `Position`,
//! `Rotation` (degrees), `ZIndex`, `Shape` (read-only), `Name`, `:GetPropertyChangedSignal(name)`
//! and `:Destroy()`. Once a GUI plane simulates it (`plane:Add`), `Position` and `Rotation`
//! read the newest tick from shared memory, writing them teleports the body, and writing
//! `Size` or `ZIndex` changes the body at the next tick. Its Position / Rotation signals
//! fire, only while listened to, after each tick that moved it.

use std::cell::{Cell, RefCell};
use std::collections::HashMap;
use std::rc::Rc;

use client_sdk::{GuiObject, GuiObjectProp, GuiShape};
use mlua::{Lua, MetaMethod, MultiValue, Table, UserData, UserDataMethods, Value};

use crate::host::signal::Signal;
use crate::values::{describe, dim_arg, expected, finite_number, new_dim, number, sdk_error};

/// What a primitive knows about itself.
pub struct PrimState {
    /// Its shape.
    pub shape: GuiShape,
    size: Cell<[f32; 2]>,
    position: Cell<[f32; 2]>,
    rotation: Cell<f32>,
    z_index: Cell<i32>,
    name: RefCell<String>,
    /// The body simulating it, while a GUI plane does.
    body: RefCell<Option<GuiObject>>,
    signals: RefCell<HashMap<&'static str, Signal>>,
    /// Position and rotation last announced to listeners.
    announced: Cell<([f32; 2], f32)>,
}

/// Properties of a primitive that have change signals.
const PROPS: [&str; 5] = ["Position", "Rotation", "Size", "ZIndex", "Name"];

impl PrimState {
    fn new(shape: GuiShape) -> PrimState {
        PrimState {
            shape,
            size: Cell::new([100.0, 100.0]),
            position: Cell::new([0.0, 0.0]),
            rotation: Cell::new(0.0),
            z_index: Cell::new(0),
            name: RefCell::new(shape.name().to_string()),
            body: RefCell::new(None),
            signals: RefCell::default(),
            announced: Cell::new(([0.0; 2], 0.0)),
        }
    }

    /// Its Size.
    pub fn size(&self) -> [f32; 2] {
        self.size.get()
    }

    /// Its ZIndex.
    pub fn z_index(&self) -> i32 {
        self.z_index.get()
    }

    /// Its Rotation (degrees), from the newest tick while simulated.
    pub fn rotation(&self) -> f32 {
        if let Some(Ok(r)) = self.body.borrow().as_ref().map(|b| b.rotation()) {
            self.rotation.set(r);
        }
        self.rotation.get()
    }

    /// Its Position, from the newest tick while simulated.
    pub fn position(&self) -> [f32; 2] {
        if let Some(Ok(p)) = self.body.borrow().as_ref().map(|b| b.position()) {
            self.position.set(p);
        }
        self.position.get()
    }

    /// The body simulating it.
    pub fn body(&self) -> Option<GuiObject> {
        self.body.borrow().clone()
    }

    /// A plane simulates it now.
    pub fn link(&self, body: GuiObject) {
        *self.body.borrow_mut() = Some(body);
        self.announced.set((self.position(), self.rotation()));
    }

    /// The body ended: the primitive keeps its last simulated values.
    pub fn unlink(&self) {
        self.position();
        self.rotation();
        *self.body.borrow_mut() = None;
    }

    fn signal(&self, name: &'static str) -> Signal {
        self.signals
            .borrow_mut()
            .entry(name)
            .or_insert_with(|| Signal::new(format!("{}.{name} changed", self.name.borrow())))
            .clone()
    }

    fn fire(&self, lua: &Lua, name: &'static str, value: Value) -> mlua::Result<()> {
        let s = self.signals.borrow().get(name).cloned();
        match s {
            Some(s) if s.listeners() > 0 => s.fire(lua, MultiValue::from_iter([value])),
            _ => Ok(()),
        }
    }

    /// Whether anyone listens to its Position or Rotation.
    pub fn motion_listeners(&self) -> bool {
        let s = self.signals.borrow();
        ["Position", "Rotation"]
            .iter()
            .any(|n| s.get(n).is_some_and(|s| s.listeners() > 0))
    }

    /// After a tick: announce a new Position / Rotation to listeners.
    pub fn fire_if_moved(&self, lua: &Lua) -> mlua::Result<()> {
        if !self.motion_listeners() {
            return Ok(());
        }
        let (p, r) = (self.position(), self.rotation());
        let (p0, r0) = self.announced.replace((p, r));
        if p != p0 {
            self.fire(
                lua,
                "Position",
                Value::UserData(lua.create_userdata(new_dim(p))?),
            )?;
        }
        if r != r0 {
            self.fire(lua, "Rotation", crate::values::lua_number(r))?;
        }
        Ok(())
    }

    fn set_body_prop(&self, what: &str, prop: GuiObjectProp) -> mlua::Result<()> {
        if let Some(b) = self.body.borrow().as_ref() {
            b.set(prop).map_err(|e| sdk_error(what, e))?;
        }
        Ok(())
    }
}

/// A GUI primitive's Lua handle.
#[derive(Clone)]
pub struct GuiPrimitive(pub Rc<PrimState>);

fn get(lua: &Lua, p: &PrimState, key: &Value) -> mlua::Result<Value> {
    let Value::String(k) = key else {
        return Err(mlua::Error::runtime(format!(
            "GuiPrimitive has no property {}",
            describe(key)
        )));
    };
    let dim = |v: [f32; 2]| -> mlua::Result<Value> {
        Ok(Value::UserData(lua.create_userdata(new_dim(v))?))
    };
    Ok(match &*k.to_string_lossy() {
        "Size" => dim(p.size())?,
        "Position" => dim(p.position())?,
        "Rotation" => crate::values::lua_number(p.rotation()),
        "ZIndex" => Value::Integer(p.z_index() as i64),
        "Shape" => Value::String(lua.create_string(p.shape.name())?),
        "Name" => Value::String(lua.create_string(&*p.name.borrow())?),
        "GetPropertyChangedSignal" | "GetPropertyChanged" => {
            Value::Function(lua.create_function(|lua, (this, name): (Value, Value)| {
                let prim = this_prim("GuiPrimitive:GetPropertyChangedSignal", &this)?;
                let n = match &name {
                    Value::String(s) => {
                        PROPS.iter().find(|p| s.as_bytes() == p.as_bytes()).copied()
                    }
                    _ => None,
                }
                .ok_or_else(|| {
                    expected(
                        "GuiPrimitive:GetPropertyChangedSignal",
                        &format!("a property name ({})", PROPS.join(", ")),
                        &name,
                    )
                })?;
                prim.0.signal(n).userdata(lua)
            })?)
        }
        "Destroy" => Value::Function(lua.create_function(|_, this: Value| {
            let prim = this_prim("GuiPrimitive:Destroy", &this)?;
            if let Some(b) = prim.0.body() {
                b.destroy();
            }
            prim.0.unlink();
            Ok(())
        })?),
        other => {
            return Err(mlua::Error::runtime(format!(
                "GuiPrimitive has no property \"{other}\""
            )))
        }
    })
}

fn set(lua: &Lua, p: &PrimState, key: &Value, value: &Value) -> mlua::Result<()> {
    let name = match key {
        Value::String(k) => k.to_string_lossy(),
        _ => String::new(),
    };
    let what = format!("GuiPrimitive.{name}");
    match name.as_str() {
        "Size" => {
            let s = dim_arg(&what, value)?;
            GuiObjectProp::Size(s)
                .checked()
                .map_err(|e| mlua::Error::runtime(format!("{what}: {}", e.message)))?;
            p.set_body_prop(&what, GuiObjectProp::Size(s))?;
            p.size.set(s);
            p.fire(lua, "Size", value.clone())
        }
        "Position" => {
            let v = dim_arg(&what, value)?;
            p.set_body_prop(&what, GuiObjectProp::Position(v))?;
            p.position.set(v);
            p.fire(lua, "Position", value.clone())
        }
        "Rotation" => {
            let r = finite_number(&what, value)? as f32;
            p.set_body_prop(&what, GuiObjectProp::Rotation(r))?;
            p.rotation.set(r);
            p.fire(lua, "Rotation", value.clone())
        }
        "ZIndex" => {
            let z = match number(value) {
                Some(n) if n.fract() == 0.0 && n.abs() <= i32::MAX as f64 => n as i32,
                _ => return Err(expected(&what, "an integer", value)),
            };
            p.set_body_prop(&what, GuiObjectProp::ZIndex(z))?;
            p.z_index.set(z);
            p.fire(lua, "ZIndex", value.clone())
        }
        "Name" => match value {
            Value::String(s) => {
                *p.name.borrow_mut() = s.to_string_lossy();
                p.fire(lua, "Name", value.clone())
            }
            _ => Err(expected(&what, "a string", value)),
        },
        "Shape" => Err(mlua::Error::runtime(format!(
            "GuiPrimitive.Shape is read-only (assigned {})",
            describe(value)
        ))),
        _ => Err(mlua::Error::runtime(format!(
            "GuiPrimitive has no property \"{name}\" (assigned {})",
            describe(value)
        ))),
    }
}

/// The primitive behind `this` (a method's self), or an error naming the call.
pub fn this_prim(what: &str, this: &Value) -> mlua::Result<GuiPrimitive> {
    match this {
        Value::UserData(ud) => ud
            .borrow::<GuiPrimitive>()
            .map(|p| p.clone())
            .map_err(|_| expected(what, "a GUI primitive", this)),
        _ => Err(expected(what, "a GUI primitive", this)),
    }
}

impl UserData for GuiPrimitive {
    fn add_methods<M: UserDataMethods<Self>>(methods: &mut M) {
        methods.add_meta_method(MetaMethod::Index, |lua, p, key: Value| get(lua, &p.0, &key));
        methods.add_meta_method(
            MetaMethod::NewIndex,
            |lua, p, (key, value): (Value, Value)| set(lua, &p.0, &key, &value),
        );
        methods.add_meta_method(MetaMethod::ToString, |_, p, ()| {
            Ok(format!(
                "GUI.Basic.{} {:?}",
                p.0.shape.name(),
                p.0.name.borrow()
            ))
        });
    }
}

/// The `GUI` module.
pub fn module(lua: &Lua) -> mlua::Result<Table> {
    let basic = lua.create_table()?;
    for shape in GuiShape::ALL {
        basic.set(
            shape.name(),
            lua.create_function(move |_, _: MultiValue| {
                Ok(GuiPrimitive(Rc::new(PrimState::new(shape))))
            })?,
        )?;
    }
    let gui = lua.create_table()?;
    gui.set("Basic", basic)?;
    Ok(gui)
}

//! GuiPhysicsPlane properties, which are also the options of `PhysicsService.NewGUI`: rows
//! on the shared row system (`crate::props`), like `PhysicsPlane`'s. The 2D settings are not
//! listed here: they are the GUI plane settings table's rows flagged `lua` (the
//! `table` of [`GUI_PLANE`]), read from the daemon's info (one round trip) and written as one
//! `PlaneProp::Gui`. `BoundsMin` / `BoundsMax` (the table's `Bounds` pair) are options of
//! `NewGUI` only (given as a pair). What is left here are the rows that are not 2D settings.

use client_sdk::settings::plane::MAX_ROLLBACK_TICKS;
use client_sdk::validate::MAX_TICK_RATE;
use client_sdk::{GuiPlaneInfo, GuiPlaneProp, PlaneProp};
use mlua::{Error as LuaError, Lua, Value};

use super::state::GuiPlaneState;
use crate::props::{Get, Kind, Props, Row, Set, Table, Target};
use crate::values::{lua_number, new_dim, sdk_error};

impl Target for GuiPlaneState {
    type Prop = PlaneProp;

    /// Applies the change at once (with the writes queued before it), so a refusal is
    /// the assignment's error.
    fn write(&self, name: &str, prop: PlaneProp) -> mlua::Result<()> {
        self.check_alive(name)?;
        match prop {
            PlaneProp::Gui(g) => self.plane.set(g),
            other => self.plane.set_common(other),
        }
        .map_err(|e| sdk_error(&format!("GuiPhysicsPlane.{name}"), e))
    }
}

/// The plane's settings as the daemon reports them (`what` names the property read).
fn info(p: &GuiPlaneState, what: &str) -> Result<GuiPlaneInfo, LuaError> {
    p.check_alive(what)?;
    p.plane
        .info()
        .map_err(|e| sdk_error(&format!("GuiPhysicsPlane.{what}"), e))
}

fn dim_value(lua: &Lua, d: [f32; 2]) -> Result<Value, LuaError> {
    Ok(Value::UserData(lua.create_userdata(new_dim(d))?))
}

fn bound(lua: &Lua, p: &GuiPlaneState, what: &str, max: bool) -> Result<Value, LuaError> {
    match info(p, what)?.bounds {
        Some((lo, hi)) => dim_value(lua, if max { hi } else { lo }),
        None => Ok(Value::Nil),
    }
}

/// The rows of `GuiPhysicsPlane` beyond its 2D settings (options of `NewGUI` as well).
pub static GUI_PLANE: Props<GuiPlaneState> = Props {
    owner: "GuiPhysicsPlane",
    table: Some(Table::new(
        GuiPlaneProp::ROWS,
        |p, name, index| Ok(info(p, name)?.settings.get(index)),
        |index, v| GuiPlaneProp::from_any(index, v).map(PlaneProp::Gui),
    )),
    rows: &[
        Row {
            name: "Enabled",
            kind: Kind::Boolean,
            get: Get::Fn(|_, p| Ok(Value::Boolean(info(p, "Enabled")?.enabled))),
            set: Set::Prop(|a| Ok(PlaneProp::Enabled(a.bool()?))),
        },
        Row {
            name: "TickRate",
            kind: Kind::Number {
                min: 0.0,
                max: MAX_TICK_RATE as f64,
            },
            get: Get::Fn(|_, p| Ok(lua_number(info(p, "TickRate")?.tick_rate))),
            set: Set::Prop(|a| Ok(PlaneProp::TickRate(a.number()? as f32))),
        },
        Row {
            name: "BoundsMin",
            kind: Kind::Dim,
            get: Get::Fn(|lua, p| bound(lua, p, "BoundsMin", false)),
            set: Set::ReadOnly,
        },
        Row {
            name: "BoundsMax",
            kind: Kind::Dim,
            get: Get::Fn(|lua, p| bound(lua, p, "BoundsMax", true)),
            set: Set::ReadOnly,
        },
        Row {
            name: "ObjectCount",
            kind: Kind::ANY_INTEGER,
            get: Get::Fn(|_, p| {
                if !p.alive() {
                    return Ok(Value::Integer(0));
                }
                let n = p
                    .plane
                    .object_count()
                    .map_err(|e| sdk_error("GuiPhysicsPlane.ObjectCount", e))?;
                Ok(Value::Integer(n as i64))
            }),
            set: Set::ReadOnly,
        },
        Row {
            name: "Alive",
            kind: Kind::Boolean,
            get: Get::Fn(|_, p| Ok(Value::Boolean(p.alive()))),
            set: Set::ReadOnly,
        },
        // The plane's Name (nil: unnamed); an option of NewGUI only.
        Row {
            name: "Name",
            kind: Kind::String,
            get: Get::Fn(|lua, p| {
                let name = common(p, "Name")?.name;
                Ok(match name.is_none() {
                    true => Value::Nil,
                    false => Value::String(lua.create_string(name.as_str())?),
                })
            }),
            set: Set::CreationOnly(|arg| {
                let text = arg.string()?;
                client_sdk::PlaneName::new(&text)
                    .map(PlaneProp::Name)
                    .map_err(|e| LuaError::runtime(e.message))
            }),
        },
        // Written to the daemon's state directory; an option of NewGUI only.
        Row {
            name: "Persistent",
            kind: Kind::Boolean,
            get: Get::Fn(|_, p| Ok(Value::Boolean(common(p, "Persistent")?.persistent))),
            set: Set::CreationOnly(|a| Ok(PlaneProp::Persistent(a.bool()?))),
        },
        // Ticks kept for Rewind.
        Row {
            name: "RollbackTicks",
            kind: Kind::Number {
                min: 0.0,
                max: MAX_ROLLBACK_TICKS as f64,
            },
            get: Get::Fn(|_, p| {
                Ok(Value::Integer(
                    common(p, "RollbackTicks")?.rollback_ticks as i64,
                ))
            }),
            set: Set::Prop(|a| Ok(PlaneProp::RollbackTicks(a.number()? as u32))),
        },
        // Fired once (lost ticks) after Open of a plane restored from its file.
        Row {
            name: "Recovered",
            kind: Kind::String,
            get: Get::Fn(crate::api::named_plane::gui_recovered_signal),
            set: Set::ReadOnly,
        },
    ],
};

/// The options every plane kind has, as the daemon reports them for this GUI plane
/// (`Name`, `Persistent`, `RollbackTicks`).
fn common(p: &GuiPlaneState, what: &str) -> Result<client_sdk::PlaneSettings, LuaError> {
    p.check_alive(what)?;
    p.plane
        .plane()
        .info()
        .map(|i| i.settings)
        .map_err(|e| sdk_error(&format!("GuiPhysicsPlane.{what}"), e))
}

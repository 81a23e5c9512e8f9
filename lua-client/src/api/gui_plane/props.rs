//! GuiPhysicsPlane properties, which are also the options of `PhysicsService.NewGUI`: rows
//! on the shared row system (`crate::props`), like `PhysicsPlane`'s. The settings read the
//! daemon's info (one round trip); every write is one `PlaneProp` (`PlaneProp::Gui` for the
//! 2D settings). `BoundsMin` / `BoundsMax` are options of `NewGUI` only (given as a pair).

use client_sdk::settings::plane::MAX_ROLLBACK_TICKS;
use client_sdk::validate::MAX_TICK_RATE;
use client_sdk::{GuiPlaneInfo, GuiPlaneProp, PlaneProp};
use mlua::{Error as LuaError, Lua, Value};

use super::GuiPlaneState;
use crate::props::{Get, Kind, Props, Row, Set, Target};
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

/// One 2D setting: read from the info field, written as that `GuiPlaneProp`.
macro_rules! setting {
    ($name:literal, $kind:expr, $variant:ident, $field:ident, dim) => {
        Row {
            name: $name,
            kind: $kind,
            get: Get::Fn(|lua, p| dim_value(lua, info(p, $name)?.$field)),
            set: Set::Prop(|a| Ok(PlaneProp::Gui(GuiPlaneProp::$variant(a.dim()?)))),
        }
    };
    ($name:literal, $kind:expr, $variant:ident, $field:ident, number) => {
        Row {
            name: $name,
            kind: $kind,
            get: Get::Fn(|_, p| Ok(lua_number(info(p, $name)?.$field))),
            set: Set::Prop(|a| Ok(PlaneProp::Gui(GuiPlaneProp::$variant(a.number()? as f32)))),
        }
    };
}

/// The rows of `GuiPhysicsPlane` (options of `NewGUI` as well).
pub static GUI_PLANE: Props<GuiPlaneState> = Props {
    owner: "GuiPhysicsPlane",
    rows: &[
        setting!("Gravity", Kind::Dim, Gravity, gravity, dim),
        setting!(
            "LinearDamping",
            Kind::NON_NEGATIVE,
            LinearDamping,
            linear_damping,
            number
        ),
        setting!(
            "AngularDamping",
            Kind::NON_NEGATIVE,
            AngularDamping,
            angular_damping,
            number
        ),
        setting!("Drag", Kind::NON_NEGATIVE, Drag, drag, number),
        setting!(
            "ConstantForce",
            Kind::Dim,
            ConstantForce,
            constant_force,
            dim
        ),
        setting!(
            "RestThreshold",
            Kind::NON_NEGATIVE,
            RestThreshold,
            rest_threshold,
            number
        ),
        Row {
            name: "SolverIterations",
            kind: Kind::ANY_INTEGER,
            get: Get::Fn(|_, p| {
                Ok(Value::Integer(
                    info(p, "SolverIterations")?.solver_iterations as i64,
                ))
            }),
            // The daemon clamps the count to its range.
            set: Set::Prop(|a| {
                let n = a.number()?.clamp(0.0, u32::MAX as f64) as u32;
                Ok(PlaneProp::Gui(GuiPlaneProp::SolverIterations(n)))
            }),
        },
        Row {
            name: "NeverSleep",
            kind: Kind::Boolean,
            get: Get::Fn(|_, p| Ok(Value::Boolean(info(p, "NeverSleep")?.never_sleep))),
            set: Set::Prop(|a| Ok(PlaneProp::Gui(GuiPlaneProp::NeverSleep(a.bool()?)))),
        },
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

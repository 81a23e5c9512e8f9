//! PhysicsPlane properties, which are also the options of `PhysicsService.New`. The options
//! themselves are not listed here: they are the plane settings table's rows flagged `lua`
//! (the `table` of [`PLANE`]), which read the SDK's property mirror
//! (`plane.properties()`: a local lookup for a plane the script created and did not share,
//! kept current by the script's own writes; otherwise one round trip that sends the queued
//! writes first, so a script reads what it wrote) and write one `PlaneProp`; `Threads` and
//! `Shared` (flagged `creation_only`) are options of the creation call only. What is left
//! here are the rows that are not options.

use client_sdk::PlaneProp;
use mlua::{Error as LuaError, Value};

use super::state::PlaneState;
use crate::props::{Get, Kind, Props, Row, Set, Table, Target};
use crate::values::sdk_error;

/// The rows of `PhysicsPlane` beyond its options.
pub static PLANE: Props<PlaneState> = Props {
    owner: "PhysicsPlane",
    table: Some(Table::new(
        PlaneProp::ROWS,
        |p, name, index| Ok(p.info(name)?.settings.get(index)),
        PlaneProp::from_any,
    )),
    rows: &[
        // Fired with the number of contact events lost when the script fell behind.
        Row {
            name: "EventsLost",
            kind: Kind::String,
            get: Get::Fn(|lua, p| Ok(Value::UserData(p.events_lost_signal().userdata(lua)?))),
            set: Set::ReadOnly,
        },
        Row {
            name: "Alive",
            kind: Kind::Boolean,
            get: Get::Fn(|_, p| Ok(Value::Boolean(p.alive()))),
            set: Set::ReadOnly,
        },
        Row {
            name: "ObjectCount",
            kind: Kind::Integer {
                min: 0,
                max: i64::MAX,
            },
            get: Get::Fn(|_, p| {
                let n = p
                    .object_count()
                    .map_err(|e| sdk_error("PhysicsPlane.ObjectCount", e))?;
                Ok(crate::values::lua_number(n))
            }),
            set: Set::ReadOnly,
        },
        // The plane's Name (nil: unnamed); an option of New only.
        Row {
            name: "Name",
            kind: Kind::String,
            get: Get::Fn(|lua, p| {
                let name = p.info("Name")?.settings.name;
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
        // The cluster daemon the plane lives on (nil: this host's daemon, no cluster); follows
        // MoveTo.
        Row {
            name: "Daemon",
            kind: Kind::String,
            get: Get::Fn(|lua, p| {
                Ok(match p.plane.daemon() {
                    Some(d) => Value::String(lua.create_string(d)?),
                    None => Value::Nil,
                })
            }),
            set: Set::ReadOnly,
        },
        // Fired once (lost ticks) after Open of a plane restored from its file.
        Row {
            name: "Recovered",
            kind: Kind::String,
            get: Get::Fn(crate::api::named_plane::recovered_signal),
            set: Set::ReadOnly,
        },
    ],
};

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
}

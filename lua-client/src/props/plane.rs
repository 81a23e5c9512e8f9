//! PhysicsPlane properties, which are also the options of `PhysicsService.New`. Every option
//! reads the SDK's property mirror (`plane.properties()`: a local lookup for a plane the
//! script created and did not share, kept current by the script's own writes; otherwise one
//! round trip that sends the queued writes first, so a script reads what it wrote) and
//! writes one `PlaneProp`.

use client_sdk::validate::{MAX_SOLVER_ITERATIONS, MAX_THREADS, MAX_TICK_RATE};
use client_sdk::PlaneProp;
use mlua::Value;

use super::{Get, Kind, Props, Row, Set};
use crate::api::plane::PlaneState;
use crate::values::{new_vector, sdk_error};

/// A number option read back from the daemon's plane info.
macro_rules! number_row {
    ($name:literal, $kind:expr, $field:ident, $prop:path) => {
        Row {
            name: $name,
            kind: $kind,
            get: Get::Fn(|_, p| Ok(crate::values::lua_number(p.info($name)?.$field))),
            set: Set::Prop(|a| Ok($prop(a.number()? as f32))),
        }
    };
}

/// A boolean option read back from the daemon's plane info.
macro_rules! bool_row {
    ($name:literal, $field:ident, $prop:path) => {
        Row {
            name: $name,
            kind: Kind::Boolean,
            get: Get::Fn(|_, p| Ok(Value::Boolean(p.info($name)?.$field))),
            set: Set::Prop(|a| Ok($prop(a.bool()?))),
        }
    };
}

/// A Vector option read back from the daemon's plane info.
macro_rules! vector_row {
    ($name:literal, $field:ident, $prop:path) => {
        Row {
            name: $name,
            kind: Kind::Vector,
            get: Get::Fn(|_, p| Ok(new_vector(p.info($name)?.$field))),
            set: Set::Prop(|a| Ok($prop(a.vector()?))),
        }
    };
}

/// The rows of `PhysicsPlane`.
pub static PLANE: Props<PlaneState> = Props {
    owner: "PhysicsPlane",
    rows: &[
        vector_row!("Gravity", gravity, PlaneProp::Gravity),
        // Fired with the number of contact events lost when the script fell behind.
        Row {
            name: "EventsLost",
            kind: Kind::String,
            get: Get::Fn(|lua, p| Ok(Value::UserData(p.events_lost_signal().userdata(lua)?))),
            set: Set::ReadOnly,
        },
        bool_row!("Enabled", enabled, PlaneProp::Enabled),
        number_row!(
            "TickRate",
            Kind::Number {
                min: 0.0,
                max: MAX_TICK_RATE as f64,
            },
            tick_rate,
            PlaneProp::TickRate
        ),
        Row {
            name: "Threads",
            kind: Kind::Integer {
                min: 1,
                max: MAX_THREADS as i64,
            },
            get: Get::Fn(|_, p| Ok(crate::values::lua_number(p.info("Threads")?.threads))),
            set: Set::CreationOnly(|a| Ok(PlaneProp::Threads(a.integer()? as u32))),
        },
        Row {
            // Other clients (processes) may change the plane, not only read it.
            name: "Shared",
            kind: Kind::Boolean,
            get: Get::Fn(|_, p| Ok(Value::Boolean(p.info("Shared")?.shared))),
            set: Set::CreationOnly(|a| Ok(PlaneProp::Shared(a.bool()?))),
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
        number_row!(
            "LinearDamping",
            Kind::NON_NEGATIVE,
            linear_damping,
            PlaneProp::LinearDamping
        ),
        number_row!(
            "AngularDamping",
            Kind::NON_NEGATIVE,
            angular_damping,
            PlaneProp::AngularDamping
        ),
        number_row!("Drag", Kind::NON_NEGATIVE, drag, PlaneProp::Drag),
        number_row!("Buoyancy", Kind::ANY_NUMBER, buoyancy, PlaneProp::Buoyancy),
        number_row!(
            "RestThreshold",
            Kind::NON_NEGATIVE,
            rest_threshold,
            PlaneProp::RestThreshold
        ),
        vector_row!("ConstantForce", constant_force, PlaneProp::ConstantForce),
        Row {
            // Documented as clamped to [1, 64]: any integer is accepted and clamped.
            name: "SolverIterations",
            kind: Kind::ANY_INTEGER,
            get: Get::Fn(|_, p| {
                Ok(Value::Number(
                    p.info("SolverIterations")?.solver_iterations as f64,
                ))
            }),
            set: Set::Prop(|a| {
                Ok(PlaneProp::SolverIterations(
                    a.integer()?.clamp(1, MAX_SOLVER_ITERATIONS as i64) as u32,
                ))
            }),
        },
        bool_row!("LoopSolver", loop_solver, PlaneProp::LoopSolver),
        bool_row!("NeverSleep", never_sleep, PlaneProp::NeverSleep),
        number_row!(
            "MaxLinearSpeed",
            Kind::Positive,
            max_linear_speed,
            PlaneProp::MaxLinearSpeed
        ),
        number_row!(
            "MaxAngularSpeed",
            Kind::Positive,
            max_angular_speed,
            PlaneProp::MaxAngularSpeed
        ),
        bool_row!("DeferGpu", defer_gpu, PlaneProp::DeferGpu),
        Row {
            // Most objects other clients may have added to a Shared plane; owner only.
            name: "SharedObjectLimit",
            kind: Kind::Integer {
                min: 0,
                max: u32::MAX as i64,
            },
            get: Get::Fn(|_, p| {
                Ok(crate::values::lua_number(
                    p.info("SharedObjectLimit")?.shared_object_limit,
                ))
            }),
            set: Set::Prop(|a| Ok(PlaneProp::SharedObjectLimit(a.integer()? as u32))),
        },
    ],
};

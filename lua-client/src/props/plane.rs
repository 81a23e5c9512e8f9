//! PhysicsPlane properties (also the options of `PhysicsService.New`). Options the script
//! does not cache are read back from the daemon (`plane.info()`, one round trip). Rows marked
//! `not_yet` are documented but belong to a backend not built yet.

use client_sdk::validate::{MAX_SOLVER_ITERATIONS, MAX_THREADS, MAX_TICK_RATE};
use client_sdk::{PlaneInfo, PlaneOptions, PlaneProp};
use mlua::{Error as LuaError, Value};

use super::{Arg, Get, Kind, Props, Row, Set};
use crate::api::plane::PlaneState;
use crate::values::{new_vector, sdk_error};

fn info(p: &PlaneState, what: &str) -> Result<PlaneInfo, LuaError> {
    p.plane
        .info()
        .map_err(|e| sdk_error(&format!("PhysicsPlane.{what}"), e))
}

/// A number option read back from the daemon's plane info.
macro_rules! number_row {
    ($name:literal, $kind:expr, $field:ident, $prop:path) => {
        Row {
            name: $name,
            kind: $kind,
            get: Get::Fn(|_, p| Ok(Value::Number(info(p, $name)?.$field as f64))),
            set: Set::Fn(|_, p, a| p.set($prop(a.number()? as f32))),
        }
    };
}

macro_rules! bool_row {
    ($name:literal, $field:ident, $prop:path) => {
        Row {
            name: $name,
            kind: Kind::Boolean,
            get: Get::Fn(|_, p| Ok(Value::Boolean(info(p, $name)?.$field))),
            set: Set::Fn(|_, p, a| p.set($prop(a.bool()?))),
        }
    };
}

pub static PLANE: Props<PlaneState> = Props {
    owner: "PhysicsPlane",
    rows: &[
        Row {
            name: "Gravity",
            kind: Kind::Vector,
            get: Get::Fn(|_, p| Ok(new_vector(p.gravity.get()))),
            set: Set::Fn(|_, p, a| {
                let g = a.vector()?;
                p.set(PlaneProp::Gravity(g))?;
                p.gravity.set(g);
                Ok(())
            }),
        },
        Row {
            name: "Enabled",
            kind: Kind::Boolean,
            get: Get::Fn(|_, p| Ok(Value::Boolean(p.enabled.get()))),
            set: Set::Fn(|_, p, a| {
                let on = a.bool()?;
                p.set(PlaneProp::Enabled(on))?;
                p.enabled.set(on);
                Ok(())
            }),
        },
        Row {
            name: "TickRate",
            kind: Kind::Number {
                min: 0.0,
                max: MAX_TICK_RATE as f64,
            },
            get: Get::Fn(|_, p| Ok(Value::Number(p.tick_rate.get() as f64))),
            set: Set::Fn(|_, p, a| {
                let hz = a.number()? as f32;
                p.set(PlaneProp::TickRate(hz))?;
                p.tick_rate.set(hz);
                Ok(())
            }),
        },
        Row {
            name: "Threads",
            kind: Kind::Integer {
                min: 1,
                max: MAX_THREADS as i64,
            },
            get: Get::Fn(|_, p| Ok(Value::Number(p.threads as f64))),
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
                Ok(Value::Number(n as f64))
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
        Row {
            name: "ConstantForce",
            kind: Kind::Vector,
            get: Get::Fn(|_, p| Ok(new_vector(info(p, "ConstantForce")?.constant_force))),
            set: Set::Fn(|_, p, a| p.set(PlaneProp::ConstantForce(a.vector()?))),
        },
        Row {
            // Documented as clamped to [1, 64]: any integer is accepted and clamped.
            name: "SolverIterations",
            kind: Kind::Integer {
                min: i64::MIN,
                max: i64::MAX,
            },
            get: Get::Fn(|_, p| {
                Ok(Value::Number(
                    info(p, "SolverIterations")?.solver_iterations as f64,
                ))
            }),
            set: Set::Fn(|_, p, a| {
                p.set(PlaneProp::SolverIterations(
                    a.integer()?.clamp(1, MAX_SOLVER_ITERATIONS as i64) as u32,
                ))
            }),
        },
        bool_row!("LoopSolver", loop_solver, PlaneProp::LoopSolver),
        bool_row!("NeverSleep", never_sleep, PlaneProp::NeverSleep),
        Row::not_yet("DeferGpu", Kind::Boolean),
    ],
};

type CreateFn = fn(&mut PlaneOptions, &Arg) -> Result<(), LuaError>;

/// Options that must be part of the creation request (a manual plane must never tick on
/// its own, Threads is fixed at creation). Every other option is set right after creation.
pub static AT_CREATION: &[(&str, CreateFn)] = &[
    ("Gravity", |o, a| {
        o.gravity = Some(a.vector()?);
        Ok(())
    }),
    ("Threads", |o, a| {
        o.threads = Some(a.integer()? as u32);
        Ok(())
    }),
    ("TickRate", |o, a| {
        o.tick_rate = Some(a.number()? as f32);
        Ok(())
    }),
    ("Enabled", |o, a| {
        o.enabled = Some(a.bool()?);
        Ok(())
    }),
];

/// Documented methods the SDK cannot do yet.
pub const NOT_YET_METHODS: &[&str] = &["NewController", "NewControlledController"];

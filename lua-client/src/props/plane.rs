//! PhysicsPlane properties (also the options of `PhysicsService.New`). Rows marked `not_yet`
//! are documented but not in the SDK yet.

use client_sdk::{PlaneOptions, PlaneProp};
use mlua::{Error as LuaError, Value};

use super::{Arg, Get, Kind, Props, Row, Set};
use crate::convert::{new_vector, sdk_error};
use crate::plane::PlaneState;

/// Mirrors the daemon's limits so a bad value fails at the assignment, not a frame later.
const MAX_THREADS: i64 = 64;
const MAX_TICK_RATE: f64 = 10_000.0;

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
                max: MAX_TICK_RATE,
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
                max: MAX_THREADS,
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
        Row::not_yet("LinearDamping", Kind::NON_NEGATIVE),
        Row::not_yet("AngularDamping", Kind::NON_NEGATIVE),
        Row::not_yet("Drag", Kind::NON_NEGATIVE),
        Row::not_yet("Buoyancy", Kind::ANY_NUMBER),
        Row::not_yet("ConstantForce", Kind::Vector),
        Row::not_yet("RestThreshold", Kind::NON_NEGATIVE),
        Row::not_yet("SolverIterations", Kind::Integer { min: 1, max: 64 }),
        Row::not_yet("LoopSolver", Kind::Boolean),
        Row::not_yet("NeverSleep", Kind::Boolean),
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

//! Proximity queries and explosions as PhysicsPlane methods: `ProbeGround` (a sphere cast
//! down: the ground, and whether it is walkable), `GetClosestPoint`, `GetClearance` (the gap
//! between a shape and the scene, with both closest points), `ProbeWall` (the wall beside a
//! capsule) and `Explode` (knockback). Results are tables in the style of RaycastResult;
//! `params` takes the query keys (`FilterType`, `Filter`, `CollisionGroup`,
//! `RespectCanCollide`) plus each method's own (`MaxSlopeAngle`, `MaxDistance`, `Falloff`).

use client_sdk::{Falloff, ProbeHit, QueryParams, Shape};
use mlua::{Lua, Table, UserDataMethods, Value};

use super::object::state::PhysicsObject;
use super::part::state::BasePart;
use super::plane::state::{PhysicsPlane, PlaneState};
use super::query::{
    cframe_arg, live, object_handle, params, part_and_object, positive_arg, vector_arg, PARAM_KEYS,
};
use crate::values::{describe, expected, finite_number, new_vector, sdk_error};

/// A method's own params keys, parsed beside the query keys.
#[derive(Default)]
struct Extra {
    max_slope: Option<f32>,
    max_distance: Option<f32>,
    falloff: Option<Falloff>,
}

/// `params` split into the query keys and the method's own `keys` (any other key is an
/// error naming it and every accepted key).
fn split_params(
    lua: &Lua,
    what: &str,
    v: &Value,
    keys: &[&str],
) -> mlua::Result<(Option<QueryParams>, Extra)> {
    let t = match v {
        Value::Nil => return Ok((None, Extra::default())),
        Value::Table(t) => t,
        other => return Err(expected(&format!("{what} params"), "a table or nil", other)),
    };
    let base = lua.create_table()?;
    let mut extra = Extra::default();
    for pair in t.pairs::<Value, Value>() {
        let (key, value) = pair?;
        let name = match &key {
            Value::String(s) => s.to_str()?.to_string(),
            other => describe(other),
        };
        let field = format!("{what} params.{name}");
        if !keys.contains(&name.as_str()) {
            if !PARAM_KEYS.split(", ").any(|k| k == name) {
                return Err(mlua::Error::runtime(format!(
                    "{what}: unknown params key \"{name}\" (expected one of {PARAM_KEYS}, {})",
                    keys.join(", ")
                )));
            }
            base.raw_set(key, value)?;
            continue;
        }
        match name.as_str() {
            "MaxSlopeAngle" => match finite_number(&field, &value) {
                Ok(n) if (0.0..=89.0).contains(&n) => extra.max_slope = Some(n as f32),
                _ => return Err(expected(&field, "a number of degrees in [0, 89]", &value)),
            },
            "MaxDistance" => match finite_number(&field, &value) {
                Ok(n) if n >= 0.0 => extra.max_distance = Some(n as f32),
                _ => return Err(expected(&field, "a number >= 0", &value)),
            },
            "Falloff" => {
                extra.falloff = Some(match &value {
                    Value::String(s) if &*s.as_bytes() == b"Linear" => Falloff::Linear,
                    Value::String(s) if &*s.as_bytes() == b"None" => Falloff::None,
                    Value::String(s) if &*s.as_bytes() == b"InverseSquare" => {
                        Falloff::InverseSquare
                    }
                    other => {
                        return Err(expected(
                            &field,
                            "\"Linear\", \"None\" or \"InverseSquare\"",
                            other,
                        ))
                    }
                })
            }
            _ => unreachable!("every key of `keys` is parsed above"),
        }
    }
    Ok((params(what, &Value::Table(base))?, extra))
}

/// A non-negative number argument.
fn reach_arg(what: &str, v: &Value) -> mlua::Result<f32> {
    match finite_number(what, v) {
        Ok(n) if n >= 0.0 => Ok(n as f32),
        _ => Err(expected(what, "a number >= 0", v)),
    }
}

/// The result table of a proximity query, or nil: `Hit` (true), `Position`, `Normal`,
/// `Distance`, `Object`, `Part`, `Instance`, and the fields `fill` adds.
fn result(
    lua: &Lua,
    plane: &PlaneState,
    hit: Option<ProbeHit>,
    fill: impl FnOnce(&Table, &ProbeHit) -> mlua::Result<()>,
) -> mlua::Result<Value> {
    let Some(hit) = hit else {
        return Ok(Value::Nil);
    };
    let t = lua.create_table()?;
    t.set("Hit", true)?;
    t.set("Position", new_vector(hit.position))?;
    t.set("Normal", new_vector(hit.normal))?;
    t.set("Distance", hit.distance)?;
    let (part, object) = part_and_object(lua, plane, hit.object)?;
    t.set("Object", object)?;
    t.set("Part", part.clone())?;
    t.set("Instance", part)?;
    fill(&t, &hit)?;
    Ok(Value::Table(t))
}

/// `GetClearance`'s shape: a number is a sphere's radius (as Spherecast takes it), a Vector
/// a box's size (as Blockcast), a BasePart or PhysicsObject its own shape (as Shapecast;
/// the part itself is then never found). Returns the shape and the part's handle if simulated.
fn shape_arg(what: &str, v: &Value) -> mlua::Result<(Shape, Option<client_sdk::Handle>)> {
    match v {
        Value::Number(_) | Value::Integer(_) => Ok((
            Shape::Sphere {
                radius: positive_arg(what, v)?,
            },
            None,
        )),
        Value::Vector(_) => Ok((
            Shape::Cube {
                size: vector_arg(what, v)?,
            },
            None,
        )),
        Value::UserData(ud) if ud.is::<BasePart>() || ud.is::<PhysicsObject>() => {
            let part = match ud.borrow::<BasePart>() {
                Ok(p) => p.0.clone(),
                Err(_) => ud.borrow::<PhysicsObject>()?.part.clone(),
            };
            Ok((part.collider(), object_handle(what, v).ok()))
        }
        other => Err(expected(
            what,
            "a radius (number), a box size (Vector), a BasePart or a PhysicsObject",
            other,
        )),
    }
}

/// Adds the proximity methods and `Explode` to PhysicsPlane.
pub fn add_methods<M: UserDataMethods<PhysicsPlane>>(methods: &mut M) {
    methods.add_method(
        "ProbeGround",
        |lua, p, (position, radius, max_distance, opts): (Value, Value, Value, Value)| {
            const W: &str = "PhysicsPlane:ProbeGround";
            live(&p.0, W)?;
            let position = vector_arg(&format!("{W} position"), &position)?;
            let radius = positive_arg(&format!("{W} radius"), &radius)?;
            let max_distance = reach_arg(&format!("{W} maxDistance"), &max_distance)?;
            let (params, extra) = split_params(lua, W, &opts, &["MaxSlopeAngle"])?;
            let hit =
                p.0.plane
                    .probe_ground(
                        position,
                        radius,
                        max_distance,
                        extra.max_slope,
                        params.as_ref(),
                    )
                    .map_err(|e| sdk_error(W, e))?;
            result(lua, &p.0, hit, |t, h| t.set("Walkable", h.walkable))
        },
    );
    methods.add_method(
        "GetClosestPoint",
        |lua, p, (position, opts): (Value, Value)| {
            const W: &str = "PhysicsPlane:GetClosestPoint";
            live(&p.0, W)?;
            let position = vector_arg(&format!("{W} position"), &position)?;
            let (params, extra) = split_params(lua, W, &opts, &["MaxDistance"])?;
            let hit =
                p.0.plane
                    .closest_point(position, extra.max_distance, params.as_ref())
                    .map_err(|e| sdk_error(W, e))?;
            result(lua, &p.0, hit, |_, _| Ok(()))
        },
    );
    methods.add_method(
        "GetClearance",
        |lua, p, (shape, cframe, opts): (Value, Value, Value)| {
            const W: &str = "PhysicsPlane:GetClearance";
            live(&p.0, W)?;
            let (shape, own) = shape_arg(&format!("{W} shape"), &shape)?;
            let cframe = cframe_arg(&format!("{W} cframe"), &cframe)?;
            let (params, extra) = split_params(lua, W, &opts, &["MaxDistance"])?;
            let own = own.map(|h| client_sdk::Object::from_handle(&p.0.plane, h));
            let hit =
                p.0.plane
                    .clearance(
                        shape,
                        cframe.pose(),
                        own.as_ref(),
                        extra.max_distance,
                        params.as_ref(),
                    )
                    .map_err(|e| sdk_error(W, e))?;
            result(lua, &p.0, hit, |t, h| {
                t.set("PointOnShape", new_vector(h.point_on_shape))?;
                t.set("PointOnHit", new_vector(h.position))
            })
        },
    );
    methods.add_method(
        "ProbeWall",
        |lua,
         p,
         (cframe, radius, height, max_distance, opts): (Value, Value, Value, Value, Value)| {
            const W: &str = "PhysicsPlane:ProbeWall";
            live(&p.0, W)?;
            let cframe = cframe_arg(&format!("{W} cframe"), &cframe)?;
            let radius = positive_arg(&format!("{W} radius"), &radius)?;
            let height = positive_arg(&format!("{W} height"), &height)?;
            let max_distance = reach_arg(&format!("{W} maxDistance"), &max_distance)?;
            let (params, extra) = split_params(lua, W, &opts, &["MaxSlopeAngle"])?;
            let hit =
                p.0.plane
                    .probe_wall(
                        cframe.pose(),
                        radius,
                        height,
                        max_distance,
                        extra.max_slope,
                        params.as_ref(),
                    )
                    .map_err(|e| sdk_error(W, e))?;
            result(lua, &p.0, hit, |t, h| {
                t.set("PointOnShape", new_vector(h.point_on_shape))
            })
        },
    );
    methods.add_method(
        "Explode",
        |lua, p, (center, radius, impulse, opts): (Value, Value, Value, Value)| {
            const W: &str = "PhysicsPlane:Explode";
            live(&p.0, W)?;
            let center = vector_arg(&format!("{W} center"), &center)?;
            let radius = positive_arg(&format!("{W} radius"), &radius)?;
            let impulse = finite_number(&format!("{W} impulse"), &impulse)? as f32;
            let (params, extra) = split_params(lua, W, &opts, &["Falloff"])?;
            let found =
                p.0.plane
                    .explode(
                        center,
                        radius,
                        impulse,
                        extra.falloff.unwrap_or_default(),
                        params.as_ref(),
                    )
                    .map_err(|e| sdk_error(W, e))?;
            let count = found.len();
            let list = lua.create_table()?;
            let mut n = 0;
            for h in found {
                if let (part @ Value::UserData(_), _) = part_and_object(lua, &p.0, h)? {
                    n += 1;
                    list.raw_set(n, part)?;
                }
            }
            Ok((count, list))
        },
    );
}

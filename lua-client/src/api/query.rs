//! Scene queries as PhysicsPlane methods, with Roblox's names and conventions: `Raycast`,
//! `Spherecast`, `Blockcast`, `Shapecast` return a RaycastResult table or nil;
//! `GetPartBoundsInRadius`, `GetPartBoundsInBox`, `GetPartsInPart` return arrays of
//! BaseParts (and Maps); `RaycastMany` casts many rays in one round trip. `params` is an optional table
//! of `FilterType` ("Exclude" / "Include"), `Filter` (PhysicsObjects, BaseParts or Maps),
//! `CollisionGroup` (a registered name), `RespectCanCollide` and `MaxParts` (overlap
//! queries list at most that many; their second return value says whether it cut the list).

use std::rc::Rc;

use client_sdk::{FilterType, Found, Handle, Hit, QueryParams, Ray};
use mlua::{Lua, Table, UserDataMethods, Value};

use super::object::state::PhysicsObject;
use super::part::state::BasePart;
use super::plane::state::{PhysicsPlane, PlaneState};
use crate::values::{describe, expected, finite_number, new_vector, sdk_error, vector, CFrame};

pub(super) const PARAM_KEYS: &str =
    "FilterType, Filter, CollisionGroup, RespectCanCollide, MaxParts";

/// The handle of a PhysicsObject or of a simulated BasePart, or an error for `what`.
pub(super) fn object_handle(what: &str, v: &Value) -> mlua::Result<Handle> {
    let not = || expected(what, "a PhysicsObject or a BasePart in a plane", v);
    let Value::UserData(ud) = v else {
        return Err(not());
    };
    if let Ok(o) = ud.borrow::<PhysicsObject>() {
        return o.live(what).map(|obj| obj.handle());
    }
    if let Ok(p) = ud.borrow::<BasePart>() {
        return p.0.object().map(|o| o.handle()).ok_or_else(not);
    }
    Err(not())
}

pub(super) fn vector_arg(what: &str, v: &Value) -> mlua::Result<[f32; 3]> {
    match vector(v) {
        Some(x) if x.iter().all(|c| c.is_finite()) => Ok(x),
        _ => Err(expected(what, "a Vector with finite components", v)),
    }
}

pub(super) fn cframe_arg(what: &str, v: &Value) -> mlua::Result<CFrame> {
    CFrame::from_value(v).ok_or_else(|| expected(what, "a CFrame", v))
}

pub(super) fn positive_arg(what: &str, v: &Value) -> mlua::Result<f32> {
    match finite_number(what, v) {
        Ok(n) if n > 0.0 => Ok(n as f32),
        _ => Err(expected(what, "a number > 0", v)),
    }
}

/// `params`: nil or a table of the documented keys; unknown keys are errors naming them.
pub(super) fn params(what: &str, v: &Value) -> mlua::Result<Option<QueryParams>> {
    let t = match v {
        Value::Nil => return Ok(None),
        Value::Table(t) => t,
        other => return Err(expected(&format!("{what} params"), "a table or nil", other)),
    };
    let mut p = QueryParams::default();
    for pair in t.pairs::<Value, Value>() {
        let (key, value) = pair?;
        let key = match &key {
            Value::String(s) => s.to_str()?.to_string(),
            other => describe(other),
        };
        let field = format!("{what} params.{key}");
        match key.as_str() {
            "FilterType" => {
                p.filter_type = match &value {
                    Value::String(s) if &*s.as_bytes() == b"Exclude" => FilterType::Exclude,
                    Value::String(s) if &*s.as_bytes() == b"Include" => FilterType::Include,
                    other => return Err(expected(&field, "\"Exclude\" or \"Include\"", other)),
                }
            }
            "Filter" => {
                let Value::Table(list) = &value else {
                    return Err(expected(
                        &field,
                        "an array of PhysicsObjects, BaseParts or Maps",
                        &value,
                    ));
                };
                for (i, item) in list.sequence_values::<Value>().enumerate() {
                    let item = item?;
                    // A Map filters its map; a destroyed one filters nothing.
                    if let Some(map) = super::map::map_handle(&item) {
                        p.filter.extend(map);
                        continue;
                    }
                    // A BasePart that is not simulated, or a stale object, can be hit by
                    // nothing: it filters nothing either.
                    if let Ok(h) = object_handle(&format!("{field}[{}]", i + 1), &item) {
                        p.filter.push(h);
                    } else if !is_part_or_object(&item) {
                        return Err(
                            object_handle(&format!("{field}[{}]", i + 1), &item).unwrap_err()
                        );
                    }
                }
            }
            "CollisionGroup" => match &value {
                Value::String(s) => p.collision_group = Some(s.to_str()?.to_string()),
                other => return Err(expected(&field, "a collision group name", other)),
            },
            "RespectCanCollide" => match value {
                Value::Boolean(b) => p.respect_can_collide = b,
                other => return Err(expected(&field, "a boolean", &other)),
            },
            "MaxParts" => {
                p.max_parts = match finite_number(&field, &value) {
                    Ok(n) if n >= 0.0 && n.fract() == 0.0 && n <= u32::MAX as f64 => n as usize,
                    _ => return Err(expected(&field, "a whole number >= 0", &value)),
                }
            }
            _ => {
                return Err(mlua::Error::runtime(format!(
                    "{what}: unknown params key \"{key}\" (expected one of {PARAM_KEYS})"
                )))
            }
        }
    }
    Ok(Some(p))
}

fn is_part_or_object(v: &Value) -> bool {
    matches!(v, Value::UserData(ud) if ud.is::<BasePart>() || ud.is::<PhysicsObject>())
}

/// The part and PhysicsObject of a handle this host added (a map's Map for both).
pub(super) fn part_and_object(
    lua: &Lua,
    plane: &PlaneState,
    h: Handle,
) -> mlua::Result<(Value, Value)> {
    // A map is its own part and object.
    if let Some(map) = super::map::map_value(lua, plane, h)? {
        return Ok((map.clone(), map));
    }
    let Some(part) = plane.part_of(h) else {
        return Ok((Value::Nil, Value::Nil));
    };
    let part_ud = super::part::part_ud(lua, &part)?;
    let object = match part.body() {
        Some(body) => Value::UserData(super::object::object_ud(
            lua,
            PhysicsObject {
                body,
                part: part.clone(),
                part_ud: part_ud.clone(),
            },
        )?),
        None => Value::Nil,
    };
    Ok((Value::UserData(part_ud), object))
}

/// A RaycastResult: Position, Normal, Distance, Object, Part (Instance is Part, Roblox's name).
fn result(lua: &Lua, plane: &PlaneState, hit: Option<Hit>) -> mlua::Result<Value> {
    let Some(hit) = hit else {
        return Ok(Value::Nil);
    };
    let t = lua.create_table()?;
    t.set("Position", new_vector(hit.position))?;
    t.set("Normal", new_vector(hit.normal))?;
    t.set("Distance", hit.distance)?;
    let (part, object) = part_and_object(lua, plane, hit.object)?;
    t.set("Object", object)?;
    t.set("Part", part.clone())?;
    t.set("Instance", part)?;
    t.set("Bone", plane.part_of(hit.object).and_then(|p| p.bone()))?;
    Ok(Value::Table(t))
}

/// The parts an overlap query found, and whether `MaxParts` cut the list.
fn parts(lua: &Lua, plane: &PlaneState, found: Found) -> mlua::Result<(Table, bool)> {
    let list = lua.create_table()?;
    let mut n = 0;
    for h in found.objects {
        if let (part @ Value::UserData(_), _) = part_and_object(lua, plane, h)? {
            n += 1;
            list.raw_set(n, part)?;
        }
    }
    Ok((list, found.truncated))
}

pub(super) fn live(plane: &Rc<PlaneState>, what: &str) -> mlua::Result<()> {
    match plane.alive() {
        true => Ok(()),
        false => Err(mlua::Error::runtime(format!(
            "{what}: the plane was destroyed"
        ))),
    }
}

/// One ray of `RaycastMany`: `{origin, direction}` or `{Origin = ..., Direction = ...}`.
fn ray(what: &str, v: &Value) -> mlua::Result<Ray> {
    let Value::Table(t) = v else {
        return Err(expected(what, "a table {origin, direction}", v));
    };
    let pick = |i: usize, key: &str| -> mlua::Result<Value> {
        let v: Value = t.raw_get(i)?;
        Ok(match v {
            Value::Nil => t.raw_get(key)?,
            v => v,
        })
    };
    Ok(Ray {
        origin: vector_arg(&format!("{what}.origin"), &pick(1, "Origin")?)?,
        direction: vector_arg(&format!("{what}.direction"), &pick(2, "Direction")?)?,
    })
}

/// Adds the query methods to PhysicsPlane.
pub fn add_methods<M: UserDataMethods<PhysicsPlane>>(methods: &mut M) {
    methods.add_method(
        "Raycast",
        |lua, p, (origin, direction, opts): (Value, Value, Value)| {
            const W: &str = "PhysicsPlane:Raycast";
            live(&p.0, W)?;
            let origin = vector_arg(&format!("{W} origin"), &origin)?;
            let direction = vector_arg(&format!("{W} direction"), &direction)?;
            let params = params(W, &opts)?;
            let hit =
                p.0.plane
                    .raycast(origin, direction, params.as_ref())
                    .map_err(|e| sdk_error(W, e))?;
            result(lua, &p.0, hit)
        },
    );
    methods.add_method("RaycastMany", |lua, p, (rays, opts): (Value, Value)| {
        const W: &str = "PhysicsPlane:RaycastMany";
        live(&p.0, W)?;
        let Value::Table(list) = &rays else {
            return Err(expected(W, "an array of {origin, direction}", &rays));
        };
        let rays = list
            .sequence_values::<Value>()
            .enumerate()
            .map(|(i, v)| ray(&format!("{W} rays[{}]", i + 1), &v?))
            .collect::<mlua::Result<Vec<Ray>>>()?;
        let params = params(W, &opts)?;
        let hits =
            p.0.plane
                .raycast_many(&rays, params.as_ref())
                .map_err(|e| sdk_error(W, e))?;
        let out = lua.create_table_with_capacity(hits.len(), 0)?;
        for (i, hit) in hits.into_iter().enumerate() {
            let v = match hit {
                Some(_) => result(lua, &p.0, hit)?,
                None => Value::Boolean(false),
            };
            out.raw_set(i + 1, v)?;
        }
        Ok(out)
    });
    methods.add_method(
        "Spherecast",
        |lua, p, (origin, radius, direction, opts): (Value, Value, Value, Value)| {
            const W: &str = "PhysicsPlane:Spherecast";
            live(&p.0, W)?;
            let origin = vector_arg(&format!("{W} origin"), &origin)?;
            let radius = positive_arg(&format!("{W} radius"), &radius)?;
            let direction = vector_arg(&format!("{W} direction"), &direction)?;
            let params = params(W, &opts)?;
            let hit =
                p.0.plane
                    .spherecast(origin, radius, direction, params.as_ref())
                    .map_err(|e| sdk_error(W, e))?;
            result(lua, &p.0, hit)
        },
    );
    methods.add_method(
        "Blockcast",
        |lua, p, (cframe, size, direction, opts): (Value, Value, Value, Value)| {
            const W: &str = "PhysicsPlane:Blockcast";
            live(&p.0, W)?;
            let cframe = cframe_arg(&format!("{W} cframe"), &cframe)?;
            let size = vector_arg(&format!("{W} size"), &size)?;
            let direction = vector_arg(&format!("{W} direction"), &direction)?;
            let params = params(W, &opts)?;
            let hit =
                p.0.plane
                    .blockcast(cframe.pose(), size, direction, params.as_ref())
                    .map_err(|e| sdk_error(W, e))?;
            result(lua, &p.0, hit)
        },
    );
    methods.add_method(
        "Shapecast",
        |lua, p, (part, direction, opts): (Value, Value, Value)| {
            const W: &str = "PhysicsPlane:Shapecast";
            live(&p.0, W)?;
            let handle = object_handle(&format!("{W} part"), &part)?;
            let direction = vector_arg(&format!("{W} direction"), &direction)?;
            let params = params(W, &opts)?;
            let object = client_sdk::Object::from_handle(&p.0.plane, handle);
            let hit =
                p.0.plane
                    .shapecast(&object, direction, params.as_ref())
                    .map_err(|e| sdk_error(W, e))?;
            result(lua, &p.0, hit)
        },
    );
    methods.add_method(
        "GetPartBoundsInRadius",
        |lua, p, (position, radius, opts): (Value, Value, Value)| {
            const W: &str = "PhysicsPlane:GetPartBoundsInRadius";
            live(&p.0, W)?;
            let position = vector_arg(&format!("{W} position"), &position)?;
            let radius = positive_arg(&format!("{W} radius"), &radius)?;
            let params = params(W, &opts)?;
            let found =
                p.0.plane
                    .bounds_in_radius_found(position, radius, params.as_ref())
                    .map_err(|e| sdk_error(W, e))?;
            parts(lua, &p.0, found)
        },
    );
    methods.add_method(
        "GetPartBoundsInBox",
        |lua, p, (cframe, size, opts): (Value, Value, Value)| {
            const W: &str = "PhysicsPlane:GetPartBoundsInBox";
            live(&p.0, W)?;
            let cframe = cframe_arg(&format!("{W} cframe"), &cframe)?;
            let size = vector_arg(&format!("{W} size"), &size)?;
            let params = params(W, &opts)?;
            let found =
                p.0.plane
                    .bounds_in_box_found(cframe.pose(), size, params.as_ref())
                    .map_err(|e| sdk_error(W, e))?;
            parts(lua, &p.0, found)
        },
    );
    methods.add_method("GetPartsInPart", |lua, p, (part, opts): (Value, Value)| {
        const W: &str = "PhysicsPlane:GetPartsInPart";
        live(&p.0, W)?;
        let handle = object_handle(&format!("{W} part"), &part)?;
        let params = params(W, &opts)?;
        let object = client_sdk::Object::from_handle(&p.0.plane, handle);
        let found =
            p.0.plane
                .parts_in_part_found(&object, params.as_ref())
                .map_err(|e| sdk_error(W, e))?;
        parts(lua, &p.0, found)
    });
}

//! `plane:GetObjects()`: every object of a 3D plane as `PhysicsObject` values with their
//! parts, including objects the script did not add (a plane from `FromSnapshot`, `Open` or
//! `physics-lua --snapshot` holds the snapshot's objects): each gets a part of its shape and
//! Size, simulated from then on like a part the script added. Objects the script holds come
//! back as the same values. Mesh parts and triangle-mesh maps are left out (their meshes stay
//! in the daemon; maps have their own handles).

use std::rc::Rc;

use client_sdk::{Handle, Object, ShapeKind};
use mlua::{UserDataMethods, Value};

use super::object::object_ud;
use super::object::state::PhysicsObject;
use super::part::part_ud;
use super::part::state::{PartObject, PartShape, PartState};
use super::plane::state::{PhysicsPlane, PlaneState};
use crate::values::sdk_error;

const WHAT: &str = "PhysicsPlane:GetObjects";

/// The part shape an object of `kind` is, if a part can stand for it.
fn part_shape(kind: ShapeKind) -> Option<PartShape> {
    match kind {
        ShapeKind::Cube => Some(PartShape::Cube),
        ShapeKind::Sphere => Some(PartShape::Sphere),
        ShapeKind::Capsule => Some(PartShape::Capsule),
        ShapeKind::Cylinder => Some(PartShape::Cylinder),
        ShapeKind::Wedge => Some(PartShape::Wedge),
        ShapeKind::Mesh | ShapeKind::TriMesh => None,
    }
}

/// The part of object `handle`: the script's own, or a new one of its shape and Size.
fn part_of(state: &Rc<PlaneState>, handle: Handle) -> mlua::Result<Option<Rc<PartState>>> {
    if let Some(part) = state.part_of(handle) {
        return Ok(Some(part));
    }
    let object = Object::from_handle(&state.plane, handle);
    let info = match object.info() {
        Ok(info) => info,
        // Gone since the tick was read: not an object any more.
        Err(client_sdk::Error::Command(e)) if e.kind == client_sdk::ErrorKind::StaleHandle => {
            return Ok(None)
        }
        Err(e) => return Err(sdk_error(WHAT, e)),
    };
    let Some(shape) = part_shape(info.shape) else {
        return Ok(None);
    };
    let part = Rc::new(PartState::new(shape));
    part.set_size_as_simulated(info.size);
    let body = PartObject::new(object, Rc::downgrade(state));
    state.adopt(&part, body, false);
    Ok(Some(part))
}

/// Adds `GetObjects` to `PhysicsPlane`.
pub fn add_methods<M: UserDataMethods<PhysicsPlane>>(methods: &mut M) {
    methods.add_method("GetObjects", |lua, p, ()| {
        let state = &p.0;
        if !state.alive() {
            return Err(mlua::Error::runtime(format!(
                "{WHAT}: the plane was destroyed"
            )));
        }
        let sample = state.plane.snapshot().map_err(|e| sdk_error(WHAT, e))?;
        let mut handles: Vec<Handle> = sample
            .bodies()
            .iter()
            .enumerate()
            .filter(|(_, b)| b.is_alive())
            .map(|(slot, b)| Handle {
                slot: slot as u32,
                generation: b.generation,
            })
            .collect();
        drop(sample);
        // The script's own objects added since the newest tick are not in it yet.
        handles.extend(state.parts_by_handle().into_iter().map(|(h, _)| h));
        handles.sort_by_key(|h| (h.slot, h.generation));
        handles.dedup();
        let out = lua.create_table()?;
        for handle in handles {
            let Some(part) = part_of(state, handle)? else {
                continue;
            };
            let Some(body) = part.body() else {
                continue;
            };
            let object = PhysicsObject {
                body,
                part_ud: part_ud(lua, &part)?,
                part,
            };
            out.push(Value::UserData(object_ud(lua, object)?))?;
        }
        Ok(out)
    });
}

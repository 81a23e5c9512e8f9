//! What the viewer shows of one body, as JSON: its published state, and what the record
//! does not carry (shape and size, a controller's capsule, a GUI object's ZIndex and path),
//! asked of the daemon.

use client_sdk::{BodyState, Error, Handle, Plane, ShapeKind, FLAG_ON_GROUND};
use serde::Serialize;
use serde_json::{json, Value};
use shm_layout::FLAG_CONTROLLER;

/// The bodies of a plane's snapshot answer.
pub fn bodies_of(snapshot: Value) -> Vec<Value> {
    match snapshot {
        Value::Object(mut o) => match o.remove("bodies") {
            Some(Value::Array(bodies)) => bodies,
            _ => Vec::new(),
        },
        _ => Vec::new(),
    }
}

/// `value` as JSON (an error object when it cannot be).
pub fn to_json<T: Serialize>(value: &T) -> Value {
    serde_json::to_value(value).unwrap_or_else(|e| json!({ "error": e.to_string() }))
}

/// The published state of one body.
pub fn body_json(slot: u32, b: &BodyState) -> Value {
    json!({
        "slot": slot,
        "generation": b.generation,
        "position": b.position,
        "rotation": b.rotation,
        "velocity": b.linear_velocity,
        "angular_velocity": b.angular_velocity,
        "sleeping": b.is_sleeping(),
        "anchored": b.is_anchored(),
        "controller": b.flags & FLAG_CONTROLLER != 0,
        "on_ground": b.flags & FLAG_ON_GROUND != 0,
    })
}

/// Asks the daemon for what the published record does not carry: the shape and size (and
/// for controllers their capsule, for GUI objects ZIndex and path).
pub fn describe(plane: &Plane, handle: Handle, b: &BodyState, gui: bool) -> Result<Value, Error> {
    if gui {
        let info = plane.gui_object_info(handle)?;
        let mut view = json!({
            "shape": info.shape.name(),
            "size": [info.size[0], info.size[1], 0.0],
            "z_index": info.z_index,
        });
        if info.controlled {
            if let Ok(c) = plane.gui_controller_info(handle) {
                view["controller"] = json!({ "waypoints": c.waypoints,
                    "next_waypoint": c.next_waypoint, "on_ground": c.on_ground });
            }
        }
        return Ok(view);
    }
    let info = plane.object_info(handle)?;
    let shape = match info.shape {
        ShapeKind::Cube => "Cube",
        ShapeKind::Sphere => "Sphere",
        ShapeKind::Mesh => "Mesh",
        ShapeKind::Capsule => "Capsule",
        ShapeKind::Cylinder => "Cylinder",
        ShapeKind::Wedge => "Wedge",
        ShapeKind::TriMesh => "TriMesh",
    };
    let mut view = json!({ "shape": shape, "size": info.size });
    if b.flags & FLAG_CONTROLLER != 0 {
        if let Ok(c) = plane.controller_info(handle) {
            view["controller"] = json!({
                "radius": c.capsule_radius,
                "half_height": c.capsule_half_height,
                "path_length": c.path_length,
                "path_index": c.path_index,
                "walk_speed": c.walk_speed,
            });
        }
    }
    Ok(view)
}

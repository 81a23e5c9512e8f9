//! BasePart properties: the host's own state of the part (name, size, shape, and the pose
//! while not simulated); the pose of a simulated part is its body's, read from the newest
//! tick and written as a teleport, and its size is written to the body as well.

use mlua::Value;

use super::state::BasePart;
use crate::props::{Get, Kind, Props, Row, Set};
use crate::values::{new_vector, sdk_error};

/// The rows of `BasePart`.
pub static PART: Props<BasePart> = Props {
    owner: "BasePart",
    table: None,
    rows: &[
        Row {
            name: "CFrame",
            kind: Kind::CFrame,
            get: Get::Fn(|lua, p| p.0.cframe_value(lua, p.0.cframe())),
            // Writing the CFrame of a simulated part teleports its body (sent with the frame's
            // batch; the per-tick pass announces the move). Otherwise it just moves the part.
            set: Set::Fn(|lua, p, a| {
                let cf = a.cframe()?;
                match p.0.object() {
                    Some(object) => object
                        .set_pose(cf.pose())
                        .map_err(|e| sdk_error("BasePart.CFrame", e)),
                    None => {
                        p.0.store_cframe(cf);
                        p.0.changed(lua, "CFrame", p.0.cframe_value(lua, cf)?)
                    }
                }
            }),
        },
        Row {
            name: "Size",
            kind: Kind::PositiveVector,
            get: Get::Fn(|_, p| Ok(new_vector(p.0.size()))),
            // Resizes the body too while the part is simulated (as PhysicsObject.Size does).
            set: Set::Fn(|lua, p, a| p.0.resize(lua, "BasePart.Size", a.vector()?)),
        },
        Row {
            name: "Name",
            kind: Kind::String,
            get: Get::Fn(|lua, p| Ok(Value::String(lua.create_string(p.0.name())?))),
            set: Set::Fn(|lua, p, a| {
                let name = a.string()?;
                let value = Value::String(lua.create_string(&name)?);
                p.0.set_name(name);
                p.0.changed(lua, "Name", value)
            }),
        },
        // Roblox's contact signals: Touched(otherPart, contact), TouchEnded(otherPart). The
        // part's body reports contacts only while either has handlers.
        Row {
            name: "Touched",
            kind: Kind::String,
            get: Get::Fn(|lua, p| Ok(Value::UserData(p.0.touch_signal("Touched").userdata(lua)?))),
            set: Set::ReadOnly,
        },
        Row {
            name: "TouchEnded",
            kind: Kind::String,
            get: Get::Fn(|lua, p| {
                Ok(Value::UserData(
                    p.0.touch_signal("TouchEnded").userdata(lua)?,
                ))
            }),
            set: Set::ReadOnly,
        },
        // Roblox's BasePart.CollisionGroup (PhysicsObject.CollisionGroup reads the body's).
        Row {
            name: "CollisionGroup",
            kind: Kind::String,
            get: Get::Fn(|lua, p| Ok(Value::String(lua.create_string(p.0.collision_group())?))),
            set: Set::Fn(|lua, p, a| {
                let ctx = crate::api::plane::context::context(lua);
                ctx.set_collision_group(&p.0, "BasePart.CollisionGroup", a.string()?)
            }),
        },
        Row {
            name: "Shape",
            kind: Kind::String,
            get: Get::Fn(|lua, p| Ok(Value::String(lua.create_string(p.0.shape.name())?))),
            set: Set::ReadOnly,
        },
    ],
};

//! `plane:NewRagdoll(desc)` and `PhysicsService.HumanoidRagdoll(cframe, scale)`: the SDK's
//! ragdolls ([`client_sdk::RagdollDesc`]) with a Capsule part per bone, so every bone is a
//! PhysicsObject of the script.
//!
//! A description is `{Bones = {{Name, Parent?, Radius, Length, CFrame, Joint?, SwingLimit,
//! TwistLimit}, ...}}` (parents before children; `Joint` the world point of the joint at
//! rest, default the bone's +Y end). A ragdoll is `{Bones = {[name] = PhysicsObject},
//! Joints = {[name] = Joint}, Destroy = function}`.

use std::rc::Rc;

use client_sdk::ragdoll::BONE_PROPS;
use client_sdk::{Bone, JointKind, Pose, RagdollDesc};
use mlua::{AnyUserData, Lua, ObjectLike, Table, UserDataMethods, Value};

use super::joint::state::LuaJoint;
use super::part::state::{PartShape, PartState};
use super::plane::add;
use super::plane::state::PhysicsPlane;
use crate::values::{describe, expected, finite_number, finite_vector, sdk_error, CFrame};

const WHAT: &str = "PhysicsPlane:NewRagdoll";

fn cframe_of(what: &str, v: &Value) -> mlua::Result<CFrame> {
    CFrame::from_value(v).ok_or_else(|| expected(what, "a CFrame", v))
}

fn bone_of(i: usize, v: Value) -> mlua::Result<Bone> {
    let at = |f: &str| format!("{WHAT} Bones[{}].{f}", i + 1);
    let Value::Table(t) = &v else {
        return Err(expected(
            &format!("{WHAT} Bones[{}]", i + 1),
            "a bone table",
            &v,
        ));
    };
    for pair in t.clone().pairs::<Value, Value>() {
        let (k, _) = pair?;
        let ok = matches!(&k, Value::String(s) if ["Name", "Parent", "Radius", "Length", "CFrame", "Joint", "SwingLimit", "TwistLimit"].contains(&s.to_string_lossy().as_str()));
        if !ok {
            return Err(mlua::Error::runtime(format!(
                "{WHAT} Bones[{}]: unknown key {} (expected Name, Parent, Radius, Length, \
                 CFrame, Joint, SwingLimit, TwistLimit)",
                i + 1,
                describe(&k)
            )));
        }
    }
    let string = |f: &str, v: Value| -> mlua::Result<String> {
        match v {
            Value::String(s) => Ok(s.to_string_lossy()),
            other => Err(expected(&at(f), "a string", &other)),
        }
    };
    let num = |f: &str| -> mlua::Result<f32> { Ok(finite_number(&at(f), &t.get(f)?)? as f32) };
    Ok(Bone {
        name: string("Name", t.get("Name")?)?,
        parent: match t.get::<Value>("Parent")? {
            Value::Nil => None,
            v => Some(string("Parent", v)?),
        },
        radius: num("Radius")?,
        length: num("Length")?,
        pose: cframe_of(&at("CFrame"), &t.get("CFrame")?)?.pose(),
        joint: match t.get::<Value>("Joint")? {
            Value::Nil => None,
            v => Some(finite_vector(&at("Joint"), &v)?),
        },
        swing_limit: num("SwingLimit")?,
        twist_limit: num("TwistLimit")?,
    })
}

fn desc_of(desc: &Value) -> mlua::Result<RagdollDesc> {
    let bones = match desc {
        Value::Table(t) => match t.get::<Value>("Bones")? {
            Value::Table(b) => b,
            other => {
                return Err(expected(
                    &format!("{WHAT} Bones"),
                    "an array of bones",
                    &other,
                ))
            }
        },
        other => {
            return Err(expected(
                WHAT,
                "a ragdoll description {Bones = {...}}",
                other,
            ))
        }
    };
    let mut d = RagdollDesc::default();
    for (i, v) in bones.sequence_values::<Value>().enumerate() {
        d.bones.push(bone_of(i, v?)?);
    }
    d.check().map_err(|e| sdk_error(WHAT, e))?;
    Ok(d)
}

fn desc_table(lua: &Lua, d: &RagdollDesc) -> mlua::Result<Table> {
    let bones = lua.create_table()?;
    for b in &d.bones {
        let t = lua.create_table()?;
        t.set("Name", b.name.as_str())?;
        if let Some(p) = &b.parent {
            t.set("Parent", p.as_str())?;
        }
        t.set("Radius", b.radius)?;
        t.set("Length", b.length)?;
        t.set("CFrame", CFrame::from_pose(b.pose))?;
        if let Some(j) = b.joint {
            t.set("Joint", crate::values::new_vector(j))?;
        }
        t.set("SwingLimit", b.swing_limit)?;
        t.set("TwistLimit", b.twist_limit)?;
        bones.push(t)?;
    }
    let desc = lua.create_table()?;
    desc.set("Bones", bones)?;
    Ok(desc)
}

fn new_ragdoll(lua: &Lua, plane: &PhysicsPlane, desc: Value) -> mlua::Result<Table> {
    let d = desc_of(&desc)?;
    let bones = lua.create_table()?;
    let mut objects = Vec::new();
    for b in &d.bones {
        let part = Rc::new(PartState::new(PartShape::Capsule));
        part.set_name(b.name.clone());
        part.set_bone(&b.name);
        part.resize(lua, WHAT, [2.0 * b.radius, b.length, 2.0 * b.radius])?;
        part.store_cframe(CFrame::from_pose(b.pose));
        let ud = super::part::part_ud(lua, &part)?;
        let obj = add(&plane.0, Value::UserData(ud))?;
        for p in BONE_PROPS {
            obj.body.object.set(p).map_err(|e| sdk_error(WHAT, e))?;
        }
        objects.push(obj.body.object.clone());
        bones.set(b.name.as_str(), super::object::object_ud(lua, obj)?)?;
    }
    let joints = lua.create_table()?;
    for (i, b) in d.bones.iter().enumerate() {
        if let Some((p, opts)) = d.joint_of(i) {
            let j = plane
                .0
                .plane
                .joint(JointKind::ConeTwist, &objects[i], Some(&objects[p]), &opts)
                .map_err(|e| sdk_error(WHAT, e))?;
            let ends = (&objects[i], Some(&objects[p]));
            joints.set(
                b.name.as_str(),
                LuaJoint::new(j, plane.0.clone(), ends.0, ends.1),
            )?;
        }
    }
    let doll = lua.create_table()?;
    doll.set("Bones", bones)?;
    doll.set("Joints", joints)?;
    doll.set(
        "Destroy",
        lua.create_function(|_, this: Table| {
            let bones: Table = this.get("Bones")?;
            for pair in bones.pairs::<Value, AnyUserData>() {
                let (_, o) = pair?;
                o.call_method::<()>("Destroy", ())?;
            }
            Ok(())
        })?,
    )?;
    super::animated_ragdoll::install(lua, &doll)?;
    Ok(doll)
}

/// `PhysicsService.HumanoidRagdoll(cframe, scale?)`: the default 15-bone humanoid's
/// description, its LowerTorso centre at `cframe` (feet 2.9 × scale below).
pub fn humanoid(lua: &Lua, (cframe, scale): (Value, Value)) -> mlua::Result<Table> {
    let what = "PhysicsService.HumanoidRagdoll";
    let cf = cframe_of(&format!("{what} cframe"), &cframe)?;
    let scale = match scale {
        Value::Nil => 1.0,
        v => {
            let s = finite_number(&format!("{what} scale"), &v)?;
            if s <= 0.0 {
                return Err(expected(&format!("{what} scale"), "a positive number", &v));
            }
            s as f32
        }
    };
    let pose: Pose = cf.pose();
    desc_table(lua, &RagdollDesc::humanoid(pose, scale))
}

/// Registers `NewRagdoll` on PhysicsPlane.
pub fn add_methods<M: UserDataMethods<PhysicsPlane>>(methods: &mut M) {
    methods.add_method("NewRagdoll", |lua, p, desc: Value| {
        new_ragdoll(lua, p, desc)
    });
}

//! `CFrame`: an immutable position + rotation. Rotation is read and written as Euler radians
//! (see `rotation` for the convention) and kept as a quaternion.

use std::cell::RefCell;
use std::fmt;

use client_sdk::Pose;
use mlua::{
    AnyUserData, Lua, MetaMethod, UserData, UserDataFields, UserDataMethods, Value, Variadic,
};

use super::convert::{describe, expected, finite_vector, new_vector, number, vector};
use super::rotation::{self, Quat, V3};

/// A pose: position and rotation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CFrame {
    /// World-space position.
    pub position: V3,
    /// Rotation as a unit quaternion.
    pub rotation: Quat,
}

impl CFrame {
    /// At the origin, not rotated.
    pub const IDENTITY: CFrame = CFrame {
        position: [0.0; 3],
        rotation: rotation::IDENTITY,
    };

    /// As the SDK's pose.
    pub fn pose(&self) -> Pose {
        Pose {
            position: self.position,
            rotation: self.rotation,
        }
    }

    /// From the SDK's pose.
    pub fn from_pose(p: Pose) -> CFrame {
        CFrame {
            position: p.position,
            rotation: p.rotation,
        }
    }

    /// `self * other`: `other` given in this frame's local space, returned in world space.
    pub fn compose(&self, other: &CFrame) -> CFrame {
        CFrame {
            position: self.point_to_world(other.position),
            rotation: rotation::mul(self.rotation, other.rotation),
        }
    }

    /// The frame that undoes this one: `cf * cf:Inverse()` is the identity.
    pub fn inverse(&self) -> CFrame {
        let inv = rotation::conjugate(self.rotation);
        let p = rotation::rotate(inv, self.position);
        CFrame {
            position: [-p[0], -p[1], -p[2]],
            rotation: inv,
        }
    }

    /// `v`, given in this frame's local space, in world space.
    pub fn point_to_world(&self, v: V3) -> V3 {
        let r = rotation::rotate(self.rotation, v);
        [
            r[0] + self.position[0],
            r[1] + self.position[1],
            r[2] + self.position[2],
        ]
    }

    fn axis(&self, v: V3) -> Value {
        new_vector(rotation::rotate(self.rotation, v))
    }
}

/// The Lua value of a CFrame that something (a part, an object) hands out again and again:
/// its last value, returned as long as the pose is bit for bit the same, so reading the pose
/// of a body that did not move since the last read (a second read in the same tick, a body
/// at rest) allocates nothing. CFrame values are immutable, so a script cannot tell a
/// returned value from a fresh equal one (except by `rawequal`).
#[derive(Default)]
pub struct CFrameCache(RefCell<Option<(CFrame, AnyUserData)>>);

impl CFrameCache {
    /// `cf` as a Lua value: the cached one when it is the same pose, else a new one (which
    /// the cache keeps).
    pub fn value(&self, lua: &Lua, cf: CFrame) -> mlua::Result<Value> {
        if let Some((cached, ud)) = &*self.0.borrow() {
            if cached.same_bits(&cf) {
                return Ok(Value::UserData(ud.clone()));
            }
        }
        let ud = cf.new_userdata(lua)?;
        *self.0.borrow_mut() = Some((cf, ud.clone()));
        Ok(Value::UserData(ud))
    }
}

impl CFrame {
    /// Whether both hold the same bits (unlike `==`, tells -0 from 0, as `tostring` does).
    fn same_bits(&self, other: &CFrame) -> bool {
        let bits = |cf: &CFrame| {
            let mut b = [0u32; 7];
            for (i, c) in cf.position.iter().chain(&cf.rotation).enumerate() {
                b[i] = c.to_bits();
            }
            b
        };
        bits(self) == bits(other)
    }

    /// A new CFrame userdata. While the Lua state has a memory limit, mlua makes every
    /// userdata in a protected call (a closure allocated and called per value), which costs
    /// more than the value itself; a CFrame is a few dozen bytes, so the limit is lifted for
    /// this one allocation and restored at once: the next allocation past the limit still
    /// fails with Lua's memory error.
    pub fn new_userdata(self, lua: &Lua) -> mlua::Result<AnyUserData> {
        match lua.set_memory_limit(0) {
            Ok(0) => lua.create_userdata(self),
            Ok(limit) => {
                let ud = lua.create_userdata(self);
                lua.set_memory_limit(limit)?;
                ud
            }
            // No memory control (a module's Lua state): nothing to lift.
            Err(_) => lua.create_userdata(self),
        }
    }
}

impl fmt::Display for CFrame {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let [x, y, z] = self.position;
        let [a, b, c] = rotation::to_euler(self.rotation);
        write!(f, "CFrame(Position {x}, {y}, {z}; Rotation {a}, {b}, {c})")
    }
}

/// A CFrame argument of a method, or an error naming the method.
fn cframe_arg(what: &str, value: &Value) -> mlua::Result<CFrame> {
    match value {
        Value::UserData(ud) => match ud.borrow::<CFrame>() {
            Ok(cf) => Ok(*cf),
            Err(_) => Err(expected(what, "a CFrame", value)),
        },
        _ => Err(expected(what, "a CFrame", value)),
    }
}

impl UserData for CFrame {
    fn add_fields<F: UserDataFields<Self>>(fields: &mut F) {
        fields.add_field_method_get("Position", |_, cf| Ok(new_vector(cf.position)));
        fields.add_field_method_get("Rotation", |_, cf| {
            Ok(new_vector(rotation::to_euler(cf.rotation)))
        });
        fields.add_field_method_get("X", |_, cf| Ok(cf.position[0]));
        fields.add_field_method_get("Y", |_, cf| Ok(cf.position[1]));
        fields.add_field_method_get("Z", |_, cf| Ok(cf.position[2]));
        fields.add_field_method_get("LookVector", |_, cf| Ok(cf.axis([0.0, 0.0, -1.0])));
        fields.add_field_method_get("RightVector", |_, cf| Ok(cf.axis([1.0, 0.0, 0.0])));
        fields.add_field_method_get("UpVector", |_, cf| Ok(cf.axis([0.0, 1.0, 0.0])));
    }

    fn add_methods<M: UserDataMethods<Self>>(methods: &mut M) {
        // With no argument the frame itself is the world-space pose (as `Right:ToWorldSpace()`).
        methods.add_method("ToWorldSpace", |_, cf, other: Value| match other {
            Value::Nil => Ok(*cf),
            v => Ok(cf.compose(&cframe_arg("CFrame:ToWorldSpace", &v)?)),
        });
        methods.add_method("ToObjectSpace", |_, cf, other: Value| {
            Ok(cf
                .inverse()
                .compose(&cframe_arg("CFrame:ToObjectSpace", &other)?))
        });
        methods.add_method("PointToWorldSpace", |_, cf, v: Value| {
            let v = finite_vector("CFrame:PointToWorldSpace", &v)?;
            Ok(new_vector(cf.point_to_world(v)))
        });
        methods.add_method("PointToObjectSpace", |_, cf, v: Value| {
            let v = finite_vector("CFrame:PointToObjectSpace", &v)?;
            Ok(new_vector(cf.inverse().point_to_world(v)))
        });
        methods.add_method("Inverse", |_, cf, ()| Ok(cf.inverse()));
        methods.add_meta_function(MetaMethod::Mul, |lua, (a, b): (Value, Value)| {
            let lhs = cframe_arg("CFrame * ...", &a)?;
            match &b {
                Value::Vector(_) => Ok(new_vector(
                    lhs.point_to_world(finite_vector("CFrame * Vector", &b)?),
                )),
                _ => lua
                    .create_userdata(lhs.compose(&cframe_arg("CFrame * CFrame", &b)?))
                    .map(Value::UserData),
            }
        });
        methods.add_meta_function(MetaMethod::Add, |_, (a, b): (Value, Value)| {
            let mut cf = cframe_arg("CFrame + Vector", &a)?;
            let v = finite_vector("CFrame + Vector", &b)?;
            cf.position = [0, 1, 2].map(|i| cf.position[i] + v[i]);
            Ok(cf)
        });
        methods.add_meta_function(MetaMethod::Sub, |_, (a, b): (Value, Value)| {
            let mut cf = cframe_arg("CFrame - Vector", &a)?;
            let v = finite_vector("CFrame - Vector", &b)?;
            cf.position = [0, 1, 2].map(|i| cf.position[i] - v[i]);
            Ok(cf)
        });
        methods.add_meta_method(MetaMethod::Eq, |_, cf, other: Value| {
            Ok(cframe_arg("==", &other).is_ok_and(|o| o == *cf))
        });
        methods.add_meta_method(MetaMethod::ToString, |_, cf, ()| Ok(cf.to_string()));
    }
}

/// Components of `args` as numbers, or None when any is not a number.
fn numbers(args: &[Value]) -> Option<Vec<f32>> {
    args.iter().map(|v| number(v).map(|n| n as f32)).collect()
}

/// `CFrame.new()`, `CFrame.new(position)`, `CFrame.new(position, rotation)` (rotation in Euler
/// radians), `CFrame.new(x, y, z)` and `CFrame.new(x, y, z, rx, ry, rz)`.
pub fn new(_: &Lua, args: Variadic<Value>) -> mlua::Result<CFrame> {
    let bad = || {
        let given: Vec<String> = args.iter().map(describe).collect();
        mlua::Error::runtime(format!(
            "CFrame.new expects (), (position: Vector, rotation: Vector?), (x, y, z) or \
             (x, y, z, rx, ry, rz), got ({})",
            given.join(", ")
        ))
    };
    let (position, euler) = match args.len() {
        0 => ([0.0; 3], [0.0; 3]),
        1 | 2 => {
            let p = vector(&args[0]).ok_or_else(bad)?;
            let r = match args.get(1) {
                None | Some(Value::Nil) => [0.0; 3],
                Some(v) => vector(v).ok_or_else(bad)?,
            };
            (p, r)
        }
        3 => {
            let n = numbers(&args).ok_or_else(bad)?;
            ([n[0], n[1], n[2]], [0.0; 3])
        }
        6 => {
            let n = numbers(&args).ok_or_else(bad)?;
            ([n[0], n[1], n[2]], [n[3], n[4], n[5]])
        }
        _ => return Err(bad()),
    };
    if !position.iter().chain(&euler).all(|c| c.is_finite()) {
        return Err(mlua::Error::runtime(format!(
            "CFrame.new expects finite components, got position {position:?}, rotation {euler:?}"
        )));
    }
    Ok(CFrame {
        position,
        rotation: rotation::from_euler(euler),
    })
}

/// `CFrame.Angles(rx, ry, rz)`: a pure rotation.
pub fn angles(_: &Lua, (rx, ry, rz): (Value, Value, Value)) -> mlua::Result<CFrame> {
    let mut e = [0.0f32; 3];
    for (i, (v, name)) in [(rx, "rx"), (ry, "ry"), (rz, "rz")].iter().enumerate() {
        e[i] = super::convert::finite_number(&format!("CFrame.Angles {name}"), v)? as f32;
    }
    Ok(CFrame {
        position: [0.0; 3],
        rotation: rotation::from_euler(e),
    })
}

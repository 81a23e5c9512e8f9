//! Quake's movement model on the horizontal velocity: ground friction with a stop speed
//! and acceleration toward the wish speed.

use rapier3d::prelude::*;

/// Quake's PM_Friction on the horizontal velocity: speed drops by
/// friction × max(speed, stop_speed) × dt, never below zero.
pub(super) fn apply_friction(v: Vector, friction: f32, stop_speed: f32, dt: f32) -> Vector {
    let h = horizontal(v);
    let speed = h.length();
    if speed < 1e-6 {
        return Vector::new(0.0, v.y, 0.0);
    }
    let drop = speed.max(stop_speed) * friction * dt;
    let scale = (speed - drop).max(0.0) / speed;
    Vector::new(h.x * scale, v.y, h.z * scale)
}

/// Quake's PM_Accelerate: raises the speed along `dir` toward `wish_speed` by at most
/// accel × wish_speed × dt, leaving other directions alone.
pub(super) fn accelerate(v: Vector, dir: Vector, wish_speed: f32, accel: f32, dt: f32) -> Vector {
    let current = v.dot(dir);
    let add = wish_speed - current;
    if add <= 0.0 {
        return v;
    }
    v + dir * (accel * wish_speed * dt).min(add)
}

/// `v` without its vertical part.
pub(super) fn horizontal(v: Vector) -> Vector {
    Vector::new(v.x, 0.0, v.z)
}

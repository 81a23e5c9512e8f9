//! Quaternion helpers for CFrame. Quaternions are `[x, y, z, w]` like the wire format.
//!
//! Euler angles follow the X, Y, Z convention: `from_euler(a, b, c) = Rx(a) · Ry(b) · Rz(c)`,
//! so a point is turned about Z first, then Y, then X (the order Roblox's `CFrame.Angles`
//! uses). `to_euler` inverts it, with `b` in [-π/2, π/2].

/// A unit quaternion `[x, y, z, w]`.
pub type Quat = [f32; 4];
/// A 3D vector.
pub type V3 = [f32; 3];

/// No rotation.
pub const IDENTITY: Quat = [0.0, 0.0, 0.0, 1.0];

fn axis(i: usize, angle: f64) -> [f64; 4] {
    let (s, c) = (angle * 0.5).sin_cos();
    let mut q = [0.0, 0.0, 0.0, c];
    q[i] = s;
    q
}

fn mul64(a: [f64; 4], b: [f64; 4]) -> [f64; 4] {
    let [ax, ay, az, aw] = a;
    let [bx, by, bz, bw] = b;
    [
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
        aw * bw - ax * bx - ay * by - az * bz,
    ]
}

/// The rotation of Euler radians `e` (Rx · Ry · Rz).
pub fn from_euler(e: V3) -> Quat {
    let q = mul64(
        mul64(axis(0, e[0] as f64), axis(1, e[1] as f64)),
        axis(2, e[2] as f64),
    );
    q.map(|c| c as f32)
}

/// Euler radians of `q`, the inverse of [`from_euler`].
pub fn to_euler(q: Quat) -> V3 {
    let m = matrix(q);
    // atan2 rather than asin(m02): asin loses half the digits near ±90°.
    let cb = m[0][0].hypot(m[0][1]);
    let b = m[0][2].atan2(cb);
    let (a, c) = if cb > 1e-6 {
        ((-m[1][2]).atan2(m[2][2]), (-m[0][1]).atan2(m[0][0]))
    } else {
        // Gimbal lock: only a ± c is defined; put it all in a.
        (m[2][1].atan2(m[1][1]), 0.0)
    };
    [a as f32, b as f32, c as f32]
}

/// Row-major rotation matrix of a (normalised) quaternion.
fn matrix(q: Quat) -> [[f64; 3]; 3] {
    let [x, y, z, w] = q.map(|c| c as f64);
    [
        [
            1.0 - 2.0 * (y * y + z * z),
            2.0 * (x * y - z * w),
            2.0 * (x * z + y * w),
        ],
        [
            2.0 * (x * y + z * w),
            1.0 - 2.0 * (x * x + z * z),
            2.0 * (y * z - x * w),
        ],
        [
            2.0 * (x * z - y * w),
            2.0 * (y * z + x * w),
            1.0 - 2.0 * (x * x + y * y),
        ],
    ]
}

/// `a · b`: `b` applied first, then `a`.
pub fn mul(a: Quat, b: Quat) -> Quat {
    mul64(a.map(|c| c as f64), b.map(|c| c as f64)).map(|c| c as f32)
}

/// The inverse rotation of a unit quaternion.
pub fn conjugate(q: Quat) -> Quat {
    [-q[0], -q[1], -q[2], q[3]]
}

/// `v` turned by `q`.
pub fn rotate(q: Quat, v: V3) -> V3 {
    let m = matrix(q);
    let v = v.map(|c| c as f64);
    let row = |r: [f64; 3]| (r[0] * v[0] + r[1] * v[1] + r[2] * v[2]) as f32;
    [row(m[0]), row(m[1]), row(m[2])]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: V3, b: V3, tol: f32) -> bool {
        a.iter().zip(b).all(|(x, y)| (x - y).abs() <= tol)
    }

    #[test]
    fn euler_round_trips() {
        for e in [
            [0.3, -0.7, 1.2],
            [0.0, 0.0, 0.0],
            [-2.5, 1.4, -3.0],
            [1.0, 0.0, 0.0],
            [0.2, std::f32::consts::FRAC_PI_2, 0.0],
            [0.0, -1.5, 0.1],
        ] {
            let back = to_euler(from_euler(e));
            assert!(close(back, e, 1e-5), "{e:?} -> {back:?}");
        }
    }

    #[test]
    fn composition_order_is_x_then_y_then_z_matrices() {
        // Rz(90°) alone turns +X into +Y; Rx(90°) · Rz(90°) then turns +Y into +Z.
        let q = from_euler([
            std::f32::consts::FRAC_PI_2,
            0.0,
            std::f32::consts::FRAC_PI_2,
        ]);
        assert!(close(rotate(q, [1.0, 0.0, 0.0]), [0.0, 0.0, 1.0], 1e-6));
    }

    #[test]
    fn conjugate_undoes_rotation() {
        let q = from_euler([0.4, 0.5, -0.6]);
        let v = [1.0, 2.0, 3.0];
        assert!(close(rotate(conjugate(q), rotate(q, v)), v, 1e-5));
        assert!(close(rotate(mul(q, conjugate(q)), v), v, 1e-5));
    }
}

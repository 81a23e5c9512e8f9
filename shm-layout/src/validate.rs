//! Input checks shared by client and daemon: each error names the field and the value.
//! `checked` returns the value as the daemon will use it (normalised, clamped where the
//! API documents clamping) or an error; the SDK runs it to fail early, the daemon again
//! because it trusts no client.

use crate::error::CommandError;
use crate::geometry::{Pose, Vec3};

/// Most worker threads one plane may ask for.
pub const MAX_THREADS: u32 = 64;
/// Fastest automatic tick rate (Hz).
pub const MAX_TICK_RATE: f32 = 10_000.0;
/// Slowest automatic tick rate (one tick per 100 s); 0 is manual.
pub const MIN_TICK_RATE: f32 = 0.01;
/// Largest accepted step: longer steps are almost certainly a unit mistake.
pub const MAX_DT: f32 = 1.0;
/// `SolverIterations` is clamped to [1, this].
pub const MAX_SOLVER_ITERATIONS: u32 = 64;
/// `HitBoxQuality` is clamped to [1, this].
pub const MAX_HIT_BOX_QUALITY: u32 = 32;
/// Smallest mass of a dynamic body: a zero-mass body neither falls nor takes impulses.
pub const MIN_MASS: f32 = 1e-4;
/// Bounds the memory one mesh part can make the daemon allocate.
pub const MAX_MESH_VERTICES: usize = 1 << 16;
/// Most triangles one mesh part may carry.
pub const MAX_MESH_TRIANGLES: usize = 1 << 17;

/// `Vector(x, y, z)`: a vector as the API prints it (Luau's `tostring`), for messages.
pub fn show_vector(v: [f32; 3]) -> String {
    format!("Vector({}, {}, {})", v[0], v[1], v[2])
}

/// A vector with finite components.
pub fn finite3(field: &str, v: Vec3) -> Result<Vec3, CommandError> {
    if v.iter().all(|c| c.is_finite()) {
        Ok(v)
    } else {
        Err(CommandError::invalid_field(
            field,
            format!(
                "{field} must have finite components, got {}",
                show_vector(v)
            ),
        ))
    }
}

/// A finite number > 0.
pub fn positive(field: &str, v: f32) -> Result<f32, CommandError> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(CommandError::invalid_field(
            field,
            format!("{field} must be a positive finite number, got {v}"),
        ))
    }
}

/// A finite number within `[lo, hi]` (refused outside).
pub fn in_range(field: &str, v: f32, lo: f32, hi: f32) -> Result<f32, CommandError> {
    if v.is_finite() && (lo..=hi).contains(&v) {
        Ok(v)
    } else {
        Err(CommandError::invalid_field(
            field,
            format!("{field} must be within [{lo}, {hi}], got {v}"),
        ))
    }
}

/// Largest coordinate of a position (units). Beyond it f32 positions are coarser than a
/// unit and the collision library's numerics break down (a body at 1e20 made it panic).
pub const MAX_COORDINATE: f32 = 1e7;
/// Largest extent of a part and largest body-local offset (Size, radius, mesh vertices,
/// CenterOfMass, a pin's point).
pub const MAX_SIZE: f32 = 1e5;
/// Smallest extent of a part (a size of 1e-30 has no usable mass or inertia).
pub const MIN_SIZE: f32 = 1e-3;

/// A vector whose components are finite and within `[-max, max]`.
pub fn bounded3(field: &str, v: Vec3, max: f32) -> Result<Vec3, CommandError> {
    if v.iter().all(|c| c.is_finite() && c.abs() <= max) {
        Ok(v)
    } else {
        Err(CommandError::invalid_field(
            field,
            format!(
                "{field} must have finite components within [-{max}, {max}], got {}",
                show_vector(v)
            ),
        ))
    }
}

/// A finite position within [`MAX_COORDINATE`] and a finite, non-degenerate quaternion
/// (returned normalised).
pub fn pose(field: &str, p: Pose) -> Result<Pose, CommandError> {
    Ok(Pose {
        position: bounded3(&format!("{field}.position"), p.position, MAX_COORDINATE)?,
        rotation: rotation(&format!("{field}.rotation"), p.rotation)?,
    })
}

/// A finite number >= 0.
pub fn non_negative(field: &str, v: f32) -> Result<f32, CommandError> {
    if v.is_finite() && v >= 0.0 {
        Ok(v)
    } else {
        Err(CommandError::invalid_field(
            field,
            format!("{field} must be a finite number >= 0, got {v}"),
        ))
    }
}

/// A finite value, clamped to `[lo, hi]` (for options the API documents as clamped).
pub fn clamped(field: &str, v: f32, lo: f32, hi: f32) -> Result<f32, CommandError> {
    if v.is_finite() {
        Ok(v.clamp(lo, hi))
    } else {
        Err(CommandError::invalid_field(
            field,
            format!("{field} must be a finite number, got {v}"),
        ))
    }
}

/// A finite, non-degenerate quaternion, returned normalised.
pub fn rotation(field: &str, q: [f32; 4]) -> Result<[f32; 4], CommandError> {
    let norm = q.iter().map(|c| c * c).sum::<f32>().sqrt();
    if !q.iter().all(|c| c.is_finite()) || norm < 1e-6 {
        return Err(CommandError::invalid_field(
            field,
            format!(
                "{field} must be a finite non-zero quaternion, got ({}, {}, {}, {})",
                q[0], q[1], q[2], q[3]
            ),
        ));
    }
    Ok(q.map(|c| c / norm))
}

/// A size with components within [[`MIN_SIZE`], [`MAX_SIZE`]] (errors name `field.X`, `.Y`,
/// `.Z`).
pub fn size(field: &str, v: Vec3) -> Result<Vec3, CommandError> {
    for (axis, c) in ["X", "Y", "Z"].iter().zip(v) {
        extent(&format!("{field}.{axis}"), c)?;
    }
    Ok(v)
}

/// One extent of a part: positive, within [[`MIN_SIZE`], [`MAX_SIZE`]].
pub fn extent(field: &str, v: f32) -> Result<f32, CommandError> {
    positive(field, v)?;
    if (MIN_SIZE..=MAX_SIZE).contains(&v) {
        Ok(v)
    } else {
        Err(CommandError::invalid_field(
            field,
            format!("{field} must be within [{MIN_SIZE}, {MAX_SIZE}], got {v}"),
        ))
    }
}

/// A finite number.
pub fn finite(field: &str, v: f32) -> Result<f32, CommandError> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(CommandError::invalid_field(
            field,
            format!("{field} must be a finite number, got {v}"),
        ))
    }
}

/// Checks a 2D value: both components finite (and within the coordinate range).
pub fn finite2(field: &str, v: [f32; 2]) -> Result<[f32; 2], CommandError> {
    for (c, axis) in v.iter().zip(["X", "Y"]) {
        if !c.is_finite() || c.abs() > MAX_COORDINATE {
            return Err(CommandError::invalid_field(
                format!("{field}.{axis}"),
                format!("{field}.{axis} must be a finite number within ±{MAX_COORDINATE}, got {c}"),
            ));
        }
    }
    Ok(v)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{ObjectProp, PlaneProp, Shape};

    #[test]
    fn errors_name_field_and_value() {
        let e = finite3("Velocity", [0.0, f32::NAN, 0.0]).unwrap_err();
        assert!(
            e.message.contains("Velocity") && e.message.contains("NaN"),
            "{e}"
        );
        let e = positive("Size.x", -1.0).unwrap_err();
        assert!(
            e.message.contains("Size.x") && e.message.contains("-1"),
            "{e}"
        );
        assert!(in_range("TickRate", 2000.0, 0.0, 1000.0).is_err());
    }

    #[test]
    fn props_are_clamped_where_documented_and_rejected_elsewhere() {
        assert_eq!(
            PlaneProp::SolverIterations(500).checked().unwrap(),
            PlaneProp::SolverIterations(64)
        );
        assert_eq!(
            PlaneProp::SolverIterations(0).checked().unwrap(),
            PlaneProp::SolverIterations(1)
        );
        assert_eq!(
            ObjectProp::Bounciness(3.0).checked().unwrap(),
            ObjectProp::Bounciness(1.0)
        );
        assert_eq!(
            ObjectProp::HitBoxQuality(99).checked().unwrap(),
            ObjectProp::HitBoxQuality(32)
        );
        let e = ObjectProp::Friction(-0.5).checked().unwrap_err();
        assert!(
            e.message.contains("Friction") && e.message.contains("-0.5"),
            "{e}"
        );
        let e = PlaneProp::Drag(f32::NAN).checked().unwrap_err();
        assert!(
            e.message.contains("Drag") && e.message.contains("NaN"),
            "{e}"
        );
        let e = ObjectProp::Weight(0.0).checked().unwrap_err();
        assert!(e.message.contains("Weight"), "{e}");
        let e = ObjectProp::Size([1.0, -2.0, 1.0]).checked().unwrap_err();
        assert!(
            e.message.contains("Size.Y") && e.message.contains("-2"),
            "{e}"
        );
    }

    #[test]
    fn coordinates_and_sizes_are_bounded() {
        let far = Pose::at([0.0, 0.0, 1e20]);
        let e = pose("CFrame", far).unwrap_err();
        assert_eq!(e.field.as_deref(), Some("CFrame.position"));
        assert!(
            e.message.contains("1e20") || e.message.contains("100000000000000000000"),
            "{e}"
        );
        assert!(pose("CFrame", Pose::at([1e5, -1e5, 5e6])).is_ok());
        let e = ObjectProp::Size([3.88, 3.67, 3.4e38])
            .checked()
            .unwrap_err();
        assert_eq!(e.field.as_deref(), Some("Size.Z"));
        assert!(ObjectProp::Size([1e-30, 1.0, 1.0]).checked().is_err());
        assert!(ObjectProp::Size([0.05, 1e5, 1.0]).checked().is_ok());
        assert!(ObjectProp::CenterOfMass([0.0, 1e9, 0.0]).checked().is_err());
        assert!(Shape::Sphere { radius: 1e20 }.check().is_err());
    }

    #[test]
    fn meshes_are_checked() {
        let cube: Vec<Vec3> = (0..8)
            .map(|i| [(i & 1) as f32, ((i >> 1) & 1) as f32, ((i >> 2) & 1) as f32])
            .collect();
        let ok = Shape::Mesh {
            vertices: cube.clone(),
            triangles: vec![[0, 1, 2]],
        };
        assert!(ok.check().is_ok());
        let bad = Shape::Mesh {
            vertices: cube,
            triangles: vec![[0, 1, 8]],
        };
        let e = bad.check().unwrap_err();
        assert!(e.message.contains("triangles[0]"), "{e}");
        let few = Shape::Mesh {
            vertices: vec![[0.0; 3]; 3],
            triangles: vec![],
        };
        assert!(few.check().is_err());
    }

    #[test]
    fn pose_normalises_rotation_and_rejects_zero() {
        let p = pose(
            "CFrame",
            Pose {
                position: [1.0; 3],
                rotation: [0.0, 0.0, 0.0, 2.0],
            },
        )
        .unwrap();
        assert_eq!(p.rotation, [0.0, 0.0, 0.0, 1.0]);
        assert!(pose(
            "CFrame",
            Pose {
                position: [0.0; 3],
                rotation: [0.0; 4]
            }
        )
        .is_err());
    }
}

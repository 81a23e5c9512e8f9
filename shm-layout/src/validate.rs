//! Input checks shared by client and daemon: each error names the field and the value.
//! `checked` returns the value as the daemon will use it (normalised, clamped where the
//! API documents clamping) or an error; the SDK runs it to fail early, the daemon again
//! because it trusts no client.

use crate::command::{ObjectProp, PlaneProp, Pose, Shape, Vec3};
use crate::CommandError;

pub const MAX_THREADS: u32 = 64;
pub const MAX_TICK_RATE: f32 = 10_000.0;
/// Largest accepted step: longer steps are almost certainly a unit mistake.
pub const MAX_DT: f32 = 1.0;
pub const MAX_SOLVER_ITERATIONS: u32 = 64;
pub const MAX_HIT_BOX_QUALITY: u32 = 32;
/// Smallest mass of a dynamic body: a zero-mass body neither falls nor takes impulses.
pub const MIN_MASS: f32 = 1e-4;
/// Bounds the memory one mesh part can make the daemon allocate.
pub const MAX_MESH_VERTICES: usize = 1 << 16;
pub const MAX_MESH_TRIANGLES: usize = 1 << 17;

pub fn finite3(field: &str, v: Vec3) -> Result<Vec3, CommandError> {
    if v.iter().all(|c| c.is_finite()) {
        Ok(v)
    } else {
        Err(CommandError::invalid(format!(
            "{field} must have finite components, got {v:?}"
        )))
    }
}

pub fn positive(field: &str, v: f32) -> Result<f32, CommandError> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(CommandError::invalid(format!(
            "{field} must be a positive finite number, got {v}"
        )))
    }
}

pub fn in_range(field: &str, v: f32, lo: f32, hi: f32) -> Result<f32, CommandError> {
    if v.is_finite() && (lo..=hi).contains(&v) {
        Ok(v)
    } else {
        Err(CommandError::invalid(format!(
            "{field} must be within [{lo}, {hi}], got {v}"
        )))
    }
}

/// A finite position and a finite, non-degenerate quaternion (returned normalised).
pub fn pose(field: &str, p: Pose) -> Result<Pose, CommandError> {
    Ok(Pose {
        position: finite3(&format!("{field}.position"), p.position)?,
        rotation: rotation(&format!("{field}.rotation"), p.rotation)?,
    })
}

pub fn non_negative(field: &str, v: f32) -> Result<f32, CommandError> {
    if v.is_finite() && v >= 0.0 {
        Ok(v)
    } else {
        Err(CommandError::invalid(format!(
            "{field} must be a finite number >= 0, got {v}"
        )))
    }
}

/// A finite value, clamped to `[lo, hi]` (for options the API documents as clamped).
pub fn clamped(field: &str, v: f32, lo: f32, hi: f32) -> Result<f32, CommandError> {
    if v.is_finite() {
        Ok(v.clamp(lo, hi))
    } else {
        Err(CommandError::invalid(format!(
            "{field} must be a finite number, got {v}"
        )))
    }
}

/// A finite, non-degenerate quaternion, returned normalised.
pub fn rotation(field: &str, q: [f32; 4]) -> Result<[f32; 4], CommandError> {
    let norm = q.iter().map(|c| c * c).sum::<f32>().sqrt();
    if !q.iter().all(|c| c.is_finite()) || norm < 1e-6 {
        return Err(CommandError::invalid(format!(
            "{field} must be a finite non-zero quaternion, got {q:?}"
        )));
    }
    Ok(q.map(|c| c / norm))
}

pub fn size(field: &str, v: Vec3) -> Result<Vec3, CommandError> {
    for (axis, c) in ["X", "Y", "Z"].iter().zip(v) {
        positive(&format!("{field}.{axis}"), c)?;
    }
    Ok(v)
}

impl PlaneProp {
    /// The option as the daemon applies it, or an error naming it and the value.
    pub fn checked(self) -> Result<PlaneProp, CommandError> {
        use PlaneProp::*;
        Ok(match self {
            Gravity(g) => Gravity(finite3("Gravity", g)?),
            Threads(n) if !(1..=MAX_THREADS).contains(&n) => {
                return Err(CommandError::invalid(format!(
                    "Threads must be within [1, {MAX_THREADS}], got {n}"
                )))
            }
            TickRate(hz) => TickRate(in_range("TickRate", hz, 0.0, MAX_TICK_RATE)?),
            LinearDamping(k) => LinearDamping(non_negative("LinearDamping", k)?),
            AngularDamping(k) => AngularDamping(non_negative("AngularDamping", k)?),
            Drag(k) => Drag(non_negative("Drag", k)?),
            Buoyancy(b) => Buoyancy(finite("Buoyancy", b)?),
            ConstantForce(f) => ConstantForce(finite3("ConstantForce", f)?),
            RestThreshold(v) => RestThreshold(non_negative("RestThreshold", v)?),
            SolverIterations(n) => SolverIterations(n.clamp(1, MAX_SOLVER_ITERATIONS)),
            other => other,
        })
    }
}

impl ObjectProp {
    /// The property as the daemon applies it, or an error naming it and the value.
    pub fn checked(self) -> Result<ObjectProp, CommandError> {
        use ObjectProp::*;
        Ok(match self {
            Pose(p) => Pose(pose("CFrame", p)?),
            Velocity(v) => Velocity(finite3("Velocity", v)?),
            AngularVelocity(w) => AngularVelocity(finite3("AngularVelocity", w)?),
            Weight(w) => {
                let w = positive("Weight", w)?;
                if w < MIN_MASS {
                    return Err(CommandError::invalid(format!(
                        "Weight must be at least {MIN_MASS}, got {w}"
                    )));
                }
                Weight(w)
            }
            Density(d) => Density(non_negative("Density", d)?),
            Bounciness(e) => Bounciness(clamped("Bounciness", e, 0.0, 1.0)?),
            Friction(mu) => Friction(in_range("Friction", mu, 0.0, 1.0)?),
            HitBoxQuality(q) => HitBoxQuality(q.clamp(1, MAX_HIT_BOX_QUALITY)),
            Size(v) => Size(size("Size", v)?),
            CenterOfMass(c) => CenterOfMass(finite3("CenterOfMass", c)?),
            ImpulseDirection(a) => ImpulseDirection(finite3("ImpulseDirection", a)?),
            ConstantForce(f) => ConstantForce(finite3("ConstantForce", f)?),
            RotateTo(Some(r)) => RotateTo(Some(crate::command::RotateTo {
                target: rotation("RotateTo.target", r.target)?,
                strength: non_negative("RotateTo.strength", r.strength)?,
            })),
            Pin(Some(p)) => Pin(Some(crate::command::Pin {
                force: non_negative("SetPin.force", p.force)?,
                relative: finite3("SetPin.relative", p.relative)?,
                target: pose("SetPin.target", p.target)?,
            })),
            other => other,
        })
    }
}

impl Shape {
    /// Positive sizes, finite vertices, triangle indices in range, bounded mesh size.
    pub fn check(&self) -> Result<(), CommandError> {
        match self {
            Shape::Cube { size: s } => size("Size", *s).map(|_| ()),
            Shape::Sphere { radius } => positive("radius", *radius).map(|_| ()),
            Shape::Mesh {
                vertices,
                triangles,
            } => {
                if vertices.len() < 4 || vertices.len() > MAX_MESH_VERTICES {
                    return Err(CommandError::invalid(format!(
                        "Mesh.vertices must hold 4 to {MAX_MESH_VERTICES} points, got {}",
                        vertices.len()
                    )));
                }
                if triangles.len() > MAX_MESH_TRIANGLES {
                    return Err(CommandError::invalid(format!(
                        "Mesh.triangles must hold at most {MAX_MESH_TRIANGLES} triangles, got {}",
                        triangles.len()
                    )));
                }
                for (i, v) in vertices.iter().enumerate() {
                    finite3(&format!("Mesh.vertices[{i}]"), *v)?;
                }
                let n = vertices.len() as u32;
                if let Some((i, t)) = triangles
                    .iter()
                    .enumerate()
                    .find(|(_, t)| t.iter().any(|&k| k >= n))
                {
                    return Err(CommandError::invalid(format!(
                        "Mesh.triangles[{i}] = {t:?} indexes past the {n} vertices"
                    )));
                }
                Ok(())
            }
        }
    }
}

pub fn finite(field: &str, v: f32) -> Result<f32, CommandError> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(CommandError::invalid(format!(
            "{field} must be a finite number, got {v}"
        )))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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

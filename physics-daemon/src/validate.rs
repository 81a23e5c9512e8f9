//! Input checks shared by every command: each error names the field and the value.

use shm_layout::{CommandError, Pose, Vec3};

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
    finite3(&format!("{field}.position"), p.position)?;
    let q = p.rotation;
    let norm = q.iter().map(|c| c * c).sum::<f32>().sqrt();
    if !q.iter().all(|c| c.is_finite()) || norm < 1e-6 {
        return Err(CommandError::invalid(format!(
            "{field}.rotation must be a finite non-zero quaternion, got {q:?}"
        )));
    }
    Ok(Pose {
        position: p.position,
        rotation: q.map(|c| c / norm),
    })
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

//! Naming the first difference between two versions of one tick (a replay against the run
//! it replays): which object, which field, both values (shortest round-trip decimals, so
//! `1.25 vs 1.2500001` shows a one-ulp difference) — what `physics-bench snapshot
//! --validate` reports when a restored plane's replay diverges.

use shm_layout::BodyState;

/// The first field that differs between two ticks' body arrays.
#[derive(Debug, Clone, PartialEq)]
pub struct FieldDifference {
    /// The object's slot (its handle's slot).
    pub slot: usize,
    /// The field, e.g. `linvel.y`, `position.x`, `rotation.w`, `alive`, `generation`.
    pub field: &'static str,
    /// Its value in the first array.
    pub first: String,
    /// Its value in the second array.
    pub second: String,
}

impl std::fmt::Display for FieldDifference {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "object {} {}: {} vs {}",
            self.slot, self.field, self.first, self.second
        )
    }
}

const POSITION: [&str; 3] = ["position.x", "position.y", "position.z"];
const ROTATION: [&str; 4] = ["rotation.x", "rotation.y", "rotation.z", "rotation.w"];
const LINVEL: [&str; 3] = ["linvel.x", "linvel.y", "linvel.z"];
const ANGVEL: [&str; 3] = ["angvel.x", "angvel.y", "angvel.z"];

/// The first field (by slot, then position, rotation, linear and angular velocity, flags,
/// generation) whose bits differ between `a` and `b`; a slot only one of them has is named
/// as `alive`. `None` when every bit agrees.
pub fn first_difference(a: &[BodyState], b: &[BodyState]) -> Option<FieldDifference> {
    let empty = BodyState::default();
    for slot in 0..a.len().max(b.len()) {
        let (x, y) = (a.get(slot).unwrap_or(&empty), b.get(slot).unwrap_or(&empty));
        let diff = |field: &'static str, p: String, q: String| FieldDifference {
            slot,
            field,
            first: p,
            second: q,
        };
        if x.is_alive() != y.is_alive() {
            return Some(diff(
                "alive",
                x.is_alive().to_string(),
                y.is_alive().to_string(),
            ));
        }
        let floats = POSITION
            .iter()
            .zip(x.position.iter().zip(&y.position))
            .chain(ROTATION.iter().zip(x.rotation.iter().zip(&y.rotation)))
            .chain(
                LINVEL
                    .iter()
                    .zip(x.linear_velocity.iter().zip(&y.linear_velocity)),
            )
            .chain(
                ANGVEL
                    .iter()
                    .zip(x.angular_velocity.iter().zip(&y.angular_velocity)),
            );
        for (field, (p, q)) in floats {
            if p.to_bits() != q.to_bits() {
                return Some(diff(field, format!("{p:?}"), format!("{q:?}")));
            }
        }
        if x.flags != y.flags {
            return Some(diff(
                "flags",
                format!("{:#x}", x.flags),
                format!("{:#x}", y.flags),
            ));
        }
        if x.generation != y.generation {
            return Some(diff(
                "generation",
                x.generation.to_string(),
                y.generation.to_string(),
            ));
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    use shm_layout::FLAG_ALIVE;

    fn body(vy: f32) -> BodyState {
        BodyState {
            flags: FLAG_ALIVE,
            linear_velocity: [0.0, vy, 0.0],
            rotation: [0.0, 0.0, 0.0, 1.0],
            ..BodyState::default()
        }
    }

    #[test]
    fn the_first_differing_field_is_named_with_both_values() {
        let a: Vec<BodyState> = (0..20).map(|_| body(1.25)).collect();
        let mut b = a.clone();
        assert_eq!(first_difference(&a, &b), None);
        b[17].linear_velocity[1] = f32::from_bits(1.25f32.to_bits() + 1);
        b[18].position[0] = 3.0;
        let d = first_difference(&a, &b).unwrap();
        assert_eq!(d.to_string(), "object 17 linvel.y: 1.25 vs 1.2500001");
        // -0.0 and 0.0 are different bits.
        let mut c = a.clone();
        c[2].angular_velocity[2] = -0.0;
        assert_eq!(first_difference(&a, &c).unwrap().field, "angvel.z");
        // A slot only one side has.
        let d = first_difference(&a, &a[..19]).unwrap();
        assert_eq!((d.slot, d.field), (19, "alive"));
    }
}

//! Box2D v3's card house, built once for `physics-bench stability` and the integration tests:
//! 0.4 × 0.002 cards (0.3 deep) leaning in pairs at ±25° with a flat card across each two
//! neighbouring pairs, five levels (5 + 4 + 3 + 2 + 1 pairs: 30 leaning and 10 flat cards).
//! The cards start where Box2D places them: the first level 1.7 mm into the floor, every
//! level above with 2.3 mm gaps under and over its flat cards and each pair's tips 4 mm
//! apart, so the house settles by about 2 cm at its top before it stands (see
//! [`CARD_HOUSE_SETTLE`]).

use shm_layout::{ObjectProp, Pose, Shape};

use crate::builders::{floor, Built};
use crate::target::SceneTarget;

/// Half the height of a card (Box2D's `cardHeight`).
pub const CARD_HALF_HEIGHT: f32 = 0.2;
/// Thickness of a card (twice Box2D's `cardThickness`).
pub const CARD_THICKNESS: f32 = 0.002;
/// Depth of a card (the third dimension Box2D does not have).
pub const CARD_DEPTH: f32 = 0.3;
/// How far a leaning card is tilted from the vertical.
pub const CARD_LEAN_DEGREES: f32 = 25.0;
/// Seconds the house is given to settle from its start positions before it is watched: the
/// top pair lands after five ticks of free fall at 60 Hz, the last contacts come to rest
/// within about 0.3 s.
pub const CARD_HOUSE_SETTLE: f32 = 0.5;

/// One card of the house: its handle and where it started.
#[derive(Debug, Clone, Copy)]
pub struct Card<H> {
    /// The card.
    pub handle: H,
    /// Its start position.
    pub start: [f32; 3],
}

/// Unit quaternion `[x, y, z, w]` for `angle` radians about the z axis.
fn about_z(angle: f32) -> [f32; 4] {
    let (s, c) = (angle / 2.0).sin_cos();
    [0.0, 0.0, s, c]
}

/// A 20-wide floor (top at y = 0) and the card house on it, `levels` levels (Box2D's is 5);
/// `props` go to the floor and to every card (friction, HitBoxQuality). Returns the cards in
/// Box2D's order: per level, per pair, the flat card (all pairs but the last) then the left
/// and right leaning cards.
pub fn card_house<T: SceneTarget + ?Sized>(
    target: &mut T,
    levels: usize,
    props: &[ObjectProp],
) -> Built<T, Vec<Card<T::Handle>>> {
    floor(target, 20.0, props)?;
    let card = Shape::Cube {
        size: [CARD_THICKNESS, 2.0 * CARD_HALF_HEIGHT, CARD_DEPTH],
    };
    let lean = CARD_LEAN_DEGREES.to_radians();
    let mut cards = Vec::new();
    let (mut pairs, mut x0, mut y) = (levels, 0.0f32, CARD_HALF_HEIGHT - 0.02);
    while pairs > 0 {
        let mut x = x0;
        for i in 0..pairs {
            if i != pairs - 1 {
                let start = [x + 0.25, y + CARD_HALF_HEIGHT - 0.015, 0.0];
                let flat = Pose {
                    position: start,
                    rotation: about_z(std::f32::consts::FRAC_PI_2),
                };
                let handle = target.add(card.clone(), flat, props)?;
                cards.push(Card { handle, start });
            }
            for (dx, angle) in [(0.0, -lean), (0.175, lean)] {
                x += dx;
                let pose = Pose {
                    position: [x, y, 0.0],
                    rotation: about_z(angle),
                };
                let handle = target.add(card.clone(), pose, props)?;
                cards.push(Card {
                    handle,
                    start: pose.position,
                });
            }
            x += 0.175;
        }
        y += 2.0 * CARD_HALF_HEIGHT - 0.03;
        x0 += 0.175;
        pairs -= 1;
    }
    Ok(cards)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::target::Spawn;

    #[test]
    fn five_levels_are_thirty_leaning_and_ten_flat_cards() {
        let mut spawns: Vec<Spawn> = Vec::new();
        let cards = card_house(&mut spawns, 5, &[]).unwrap();
        assert_eq!(cards.len(), 40);
        // The floor first, then the cards; a flat card lies on its side (a quarter turn).
        assert_eq!(spawns.len(), 41);
        let flat = spawns[1..]
            .iter()
            .filter(|s| (s.pose.rotation[2] - (std::f32::consts::FRAC_PI_4).sin()).abs() < 1e-6)
            .count();
        assert_eq!(flat, 10);
        // The first level's feet reach 1.7 mm into the floor: y − h·cos 25° − t/2·sin 25°.
        let lowest = spawns[2].pose.position[1]
            - CARD_HALF_HEIGHT * 25f32.to_radians().cos()
            - CARD_THICKNESS / 2.0 * 25f32.to_radians().sin();
        assert!((lowest + 0.0017).abs() < 1e-4, "{lowest}");
    }
}

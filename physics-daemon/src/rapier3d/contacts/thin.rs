//! Thin colliders: their contacts are recomputed every step.
//!
//! rapier 0.36.1 recycles a contact pair whose two colliders moved less than its recycle
//! window relative to each other since the pair's last full update
//! (`normalized_contact_recycle_distance`, 0.05, and each body turned less than 11.5°): the
//! step keeps the pair's points, normal and world-frozen lever arms instead of recomputing
//! them, a large saving in piles that barely move. A pair without contacts is not looked at
//! again until it drifted past the prediction distance.
//!
//! A window that wide is wrong for a collider thinner than the window itself. In Box2D's card
//! house (cards 0.002 thick, μ 0.7, ±25°), two leaning cards rotate toward each other while
//! their pair is skipped, and their tips are 11–12 mm across each other (six card
//! thicknesses) when the pair is next computed; the recycled contact then keeps that crossed
//! contact's normal for another 30 ticks, the tips slide along each other at the friction
//! limit (friction impulse = μ · normal impulse, 1–2 mm a step) and the top pair falls within
//! 1.5 s. Recomputed every step, the same contact is pushed out in 0.3 s and holds with a
//! friction impulse of 0.56 · N (a pin-jointed pair needs tan 25° = 0.47), and the house
//! stands. Measured on that house: a window of 0.002 (the card's thickness) holds it, 0.005
//! does not.
//!
//! So a collider whose thinnest extent is under the recycle window opts its pairs out of
//! recycling. Rapier never recycles a pair where either collider asks for a hook, and the
//! one hook that costs nothing on solid pairs is `FILTER_INTERSECTION_PAIR` (it is consulted
//! only for sensor pairs, and the plane's hooks keep rapier's default there: every
//! intersection is kept). Everything else (boxes, balls, piles 0.05 and thicker) keeps
//! recycling and pays nothing. Maps are surfaces, not thin bodies: they keep recycling.

use rapier3d::prelude::*;

/// The recycle window the plane runs with (rapier's default; the plane's length unit is 1).
fn recycle_window() -> f32 {
    IntegrationParameters::default().contact_recycle_distance()
}

/// Whether `shape` is thinner than the recycle window along its thinnest axis.
pub(crate) fn is_thin(shape: &dyn Shape) -> bool {
    let aabb = shape.compute_local_aabb();
    let extents = aabb.maxs - aabb.mins;
    extents.min_element() < recycle_window()
}

/// The hook flags that keep `shape`'s contact pairs from being recycled: the opt-out for a
/// thin body (see the module doc), none otherwise and for a map (`is_map`).
pub(crate) fn recycling_opt_out(shape: &dyn Shape, is_map: bool) -> ActiveHooks {
    if !is_map && is_thin(shape) {
        ActiveHooks::FILTER_INTERSECTION_PAIR
    } else {
        ActiveHooks::empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_card_is_thin_a_five_centimetre_box_and_a_map_are_not() {
        let card = SharedShape::cuboid(0.001, 0.2, 0.15);
        assert!(is_thin(&*card));
        assert_eq!(
            recycling_opt_out(&*card, false),
            ActiveHooks::FILTER_INTERSECTION_PAIR
        );
        assert_eq!(recycling_opt_out(&*card, true), ActiveHooks::empty());
        // 0.05 across is the window itself: not thinner than it.
        let small = SharedShape::cuboid(0.025, 0.025, 0.025);
        assert!(!is_thin(&*small));
        assert!(is_thin(&*SharedShape::ball(0.02)));
        assert!(!is_thin(&*SharedShape::cuboid(0.5, 0.5, 0.5)));
    }
}

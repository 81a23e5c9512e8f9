//! Scenes other engines publish benchmark figures for, laid out exactly as their own
//! benchmark programs lay them out, so `physics-bench peers` steps the same world:
//!
//! - [`jolt_pyramid`]: Jolt's PerformanceTest scene "Pyramid" (`PyramidScene.h`): 1,240 boxes
//!   2 × 2 × 2 in a 15-layer square pyramid, 0.5 apart between layers, on a 100 × 2 × 100
//!   static floor whose top is y = 0.
//! - [`large_pyramid_gui`]: Box2D v3's benchmark `large_pyramid`: rows of 100, 99, … 1
//!   squares of half-size 0.5 (5,050), each row shifted by half a square, resting on a 200 × 2
//!   ground whose top is y = 0; built on a GUI plane (pixels, +Y down).
//!
//! The layouts are plain functions ([`jolt_pyramid_layout`], [`large_pyramid_layout`]) so
//! tests can check them without a plane.

use client_sdk::{GuiObject, GuiPlane};
use shm_layout::{GuiObjectProp, GuiShape, ObjectProp, Pose, Vec2};

use crate::builders::{cube, slab, Built};
use crate::target::SceneTarget;

/// Layers of Jolt's pyramid (`cPyramidHeight`).
pub const JOLT_PYRAMID_HEIGHT: usize = 15;
/// Side of each box of Jolt's pyramid (`cBoxSize`).
pub const JOLT_BOX_SIZE: f32 = 2.0;
/// Vertical gap between the layers of Jolt's pyramid at the start (`cBoxSeparation`).
pub const JOLT_BOX_SEPARATION: f32 = 0.5;
/// Jolt's floor: a static box of half-extents (50, 1, 50) centred at y = −1.
pub const JOLT_FLOOR_SIZE: [f32; 3] = [100.0, 2.0, 100.0];

/// Boxes in Jolt's pyramid: layer `i` is a (15 − i) × (15 − i) square, so Σ k² for
/// k = 1..=15.
pub const JOLT_PYRAMID_BOXES: usize =
    JOLT_PYRAMID_HEIGHT * (JOLT_PYRAMID_HEIGHT + 1) * (2 * JOLT_PYRAMID_HEIGHT + 1) / 6;

/// Centres of the boxes of Jolt's pyramid, layer by layer from the bottom, as
/// `PyramidScene::StartTest` places them: for layer `i`, `j` and `k` in
/// `i/2 .. 15 − (i+1)/2`, the box is at (−15 + 2j + o, 1 + 2.5 i, −15 + 2k + o) with `o` = 1
/// on odd layers (half a box, so each box sits on four below) and 0 on even ones.
pub fn jolt_pyramid_layout() -> Vec<[f32; 3]> {
    let n = JOLT_PYRAMID_HEIGHT;
    let half = JOLT_BOX_SIZE / 2.0;
    let mut out = Vec::with_capacity(JOLT_PYRAMID_BOXES);
    for i in 0..n {
        let offset = if i % 2 == 1 { half } else { 0.0 };
        let y = half + (JOLT_BOX_SIZE + JOLT_BOX_SEPARATION) * i as f32;
        // Jolt's bounds, `i / 2 .. 15 − (i + 1) / 2`.
        let (lo, hi) = (i / 2, n - i.div_ceil(2));
        for j in lo..hi {
            for k in lo..hi {
                out.push([
                    -(n as f32) + JOLT_BOX_SIZE * j as f32 + offset,
                    y,
                    -(n as f32) + JOLT_BOX_SIZE * k as f32 + offset,
                ]);
            }
        }
    }
    out
}

/// Height of the top box's centre once every layer has landed on the one below (no gaps):
/// half a box above the floor plus one box per layer below it.
pub fn jolt_pyramid_rest_top() -> f32 {
    JOLT_BOX_SIZE / 2.0 + JOLT_BOX_SIZE * (JOLT_PYRAMID_HEIGHT - 1) as f32
}

/// Jolt's pyramid on `target`: the anchored floor (with `floor_props`), then the boxes of
/// [`jolt_pyramid_layout`] in its order, each with `box_props`. Returns the boxes.
pub fn jolt_pyramid<T: SceneTarget + ?Sized>(
    target: &mut T,
    floor_props: &[ObjectProp],
    box_props: &[ObjectProp],
) -> Built<T, Vec<T::Handle>> {
    slab(target, [0.0; 3], JOLT_FLOOR_SIZE, floor_props)?;
    jolt_pyramid_layout()
        .into_iter()
        .map(|at| target.add(cube(JOLT_BOX_SIZE), Pose::at(at), box_props))
        .collect()
}

/// Squares in the bottom row of Box2D's `large_pyramid` (`baseCount` in a release build).
pub const LARGE_PYRAMID_BASE: usize = 100;
/// Half the side of each square of Box2D's `large_pyramid` (`h`).
pub const LARGE_PYRAMID_HALF: f32 = 0.5;
/// Box2D's ground for it: `b2MakeBox(100, 1)` (half-extents) centred at y = −1.
pub const LARGE_PYRAMID_GROUND: [f32; 2] = [200.0, 2.0];

/// Centres of the squares of Box2D's `large_pyramid` of `base`, in Box2D's units and axes
/// (+Y up), row by row from the bottom as `LargePyramid` creates them: row `i` at
/// y = (2i + 1)·h, square `j` of `i..base` at x = (i + 1)·h + 2(j − i)·h − h·base. Squares of a
/// row touch; each row rests on the one below, shifted by h.
pub fn large_pyramid_layout(base: usize) -> Vec<[f32; 2]> {
    let h = LARGE_PYRAMID_HALF;
    let mut out = Vec::with_capacity(base * (base + 1) / 2);
    for i in 0..base {
        let y = (2.0 * i as f32 + 1.0) * h;
        for j in i..base {
            let x = (i as f32 + 1.0) * h + 2.0 * (j - i) as f32 * h - h * base as f32;
            out.push([x, y]);
        }
    }
    out
}

/// One body of a scene with where it started.
#[derive(Debug, Clone)]
pub struct Placed<H> {
    /// The body.
    pub handle: H,
    /// Its start position (the target's units and axes).
    pub start: [f32; 3],
}

/// Box2D's `large_pyramid` of `base` on a GUI plane at `px_per_unit` pixels per Box2D unit:
/// positions scaled and Y flipped (the GUI plane's +Y is down), the ground anchored.
/// `box_props` go to every square. Returns the squares, bottom row first, with their starts
/// in pixels.
pub fn large_pyramid_gui(
    plane: &GuiPlane,
    base: usize,
    px_per_unit: f32,
    box_props: &[GuiObjectProp],
) -> Result<Vec<Placed<GuiObject>>, client_sdk::Error> {
    let k = px_per_unit;
    let [gw, gh] = LARGE_PYRAMID_GROUND;
    plane.add(
        GuiShape::Square,
        [gw * k, gh * k],
        [0.0, gh / 2.0 * k],
        &[GuiObjectProp::Anchored(true)],
    )?;
    let side = 2.0 * LARGE_PYRAMID_HALF * k;
    large_pyramid_layout(base)
        .into_iter()
        .map(|[x, y]| {
            let at: Vec2 = [x * k, -y * k];
            let handle = plane.add(GuiShape::Square, [side, side], at, box_props)?;
            Ok(Placed {
                handle,
                start: [at[0], at[1], 0.0],
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::target::Spawn;

    /// Whether two axis-aligned boxes of sides `size` centred at `a` and `b` overlap by more
    /// than `slack` on every axis (boxes that only touch do not).
    fn overlap<const N: usize>(a: [f32; N], b: [f32; N], size: f32, slack: f32) -> bool {
        (0..N).all(|d| (a[d] - b[d]).abs() < size - slack)
    }

    #[test]
    fn jolts_pyramid_has_1240_boxes_none_overlapping_above_the_floor() {
        let boxes = jolt_pyramid_layout();
        assert_eq!(boxes.len(), 1_240);
        assert_eq!(JOLT_PYRAMID_BOXES, 1_240);
        for (i, a) in boxes.iter().enumerate() {
            // Every bottom face at or above the floor's top (y = 0).
            assert!(a[1] - 1.0 >= 0.0, "box {i} at {a:?}");
            for (j, b) in boxes.iter().enumerate().skip(i + 1) {
                assert!(
                    !overlap(*a, *b, JOLT_BOX_SIZE, 1e-4),
                    "{i} {a:?} / {j} {b:?}"
                );
            }
        }
        // Layer i holds (15 − i)² boxes; the top one stands alone above the centre.
        let mut at = 0;
        for i in 0..JOLT_PYRAMID_HEIGHT {
            let n = (JOLT_PYRAMID_HEIGHT - i).pow(2);
            let y = 1.0 + 2.5 * i as f32;
            assert!(boxes[at..at + n].iter().all(|b| b[1] == y), "layer {i}");
            at += n;
        }
        assert_eq!(boxes[1_239], [-1.0, 36.0, -1.0]);
        assert_eq!(jolt_pyramid_rest_top(), 29.0);
    }

    #[test]
    fn each_jolt_box_above_the_bottom_layer_rests_on_four_below() {
        let boxes = jolt_pyramid_layout();
        for a in boxes.iter().filter(|a| a[1] > 1.0) {
            // Below: the layer 2.5 lower, centres 1 away on both horizontal axes.
            let under = boxes
                .iter()
                .filter(|b| (a[1] - b[1] - 2.5).abs() < 1e-4)
                .filter(|b| (a[0] - b[0]).abs() == 1.0 && (a[2] - b[2]).abs() == 1.0)
                .count();
            assert_eq!(under, 4, "{a:?}");
        }
    }

    #[test]
    fn the_jolt_builder_adds_the_floor_then_the_layout() {
        let mut spawns: Vec<Spawn> = Vec::new();
        let Ok(boxes) = jolt_pyramid(&mut spawns, &[], &[ObjectProp::Friction(0.2)]);
        assert_eq!(boxes.len(), 1_240);
        assert_eq!(spawns.len(), 1_241);
        // The floor: 100 × 2 × 100, top at y = 0, anchored.
        assert_eq!(spawns[0].pose.position, [0.0, -1.0, 0.0]);
        assert_eq!(spawns[0].props, [ObjectProp::Anchored(true)]);
        assert_eq!(spawns[1].pose.position, jolt_pyramid_layout()[0]);
        assert_eq!(spawns[1].props, [ObjectProp::Friction(0.2)]);
    }

    #[test]
    fn box2ds_large_pyramid_has_5050_touching_squares_on_the_ground() {
        let squares = large_pyramid_layout(LARGE_PYRAMID_BASE);
        assert_eq!(squares.len(), 5_050);
        // Bottom row: 100 squares from −49.5 to 49.5, resting on y = 0, 1 apart (touching).
        for (j, s) in squares[..100].iter().enumerate() {
            assert_eq!(*s, [j as f32 - 49.5, 0.5]);
        }
        // Row i: 100 − i squares at y = i + 0.5, shifted by i / 2.
        let mut at = 0;
        for i in 0..LARGE_PYRAMID_BASE {
            let n = LARGE_PYRAMID_BASE - i;
            assert_eq!(squares[at], [i as f32 * 0.5 - 49.5, i as f32 + 0.5]);
            at += n;
        }
        assert_eq!(squares[5_049], [0.0, 99.5]);
        // None overlaps another (squares of a row and of neighbouring rows only touch).
        for (i, a) in squares.iter().enumerate() {
            for b in &squares[i + 1..] {
                assert!(!overlap(*a, *b, 1.0, 1e-4), "{a:?} / {b:?}");
            }
        }
    }
}

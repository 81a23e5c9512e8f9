//! A controller stands on any anchored box floor: property test over floor widths (1 to
//! 10,000), thicknesses (0.05 to 20), where the floor lies, where over it the controller
//! drops, and the controller's size. Before the plane's queries clipped large boxes (see
//! `physics-daemon/src/rapier3d/clipped.rs`) a Size (2, 5, 2) controller fell through a
//! 400 × 1 × 400 floor when dropped over its centre and stood 0.49 too low on a
//! 5000 × 2 × 5000 one.

use client_sdk::{PlaneOptions, Pose, Shape};
use integration_tests::Scene;
use proptest::prelude::*;
use proptest::test_runner::{Config, TestCaseError, TestRunner};
use shm_layout::ObjectProp;

const DT: f32 = 1.0 / 60.0;
/// The gap a controller keeps to what it stands on, and how far off it may settle.
const SKIN: f32 = 0.01;
const TOLERANCE: f32 = 0.02;

fn gravity_50() -> PlaneOptions {
    PlaneOptions {
        gravity: Some([0.0, -50.0, 0.0]),
        ..Default::default()
    }
}

/// One case: a floor `width` × `thickness` × `width` whose top centre is `top`, a controller
/// of `radius` and total `height` dropped from `drop` above it at `offset` (x, z) from the
/// floor's centre.
#[derive(Debug, Clone, Copy)]
struct Case {
    width: f32,
    thickness: f32,
    top: [f32; 3],
    offset: [f32; 2],
    radius: f32,
    height: f32,
    drop: f32,
}

/// Runs `case` on `s`'s plane (removing what it added): the controller must stand on the
/// floor, `SKIN` above it, with OnGround.
fn stands(s: &Scene, case: Case) -> Result<(), TestCaseError> {
    let Case {
        width,
        thickness,
        top,
        offset,
        radius,
        height,
        drop,
    } = case;
    let floor = s
        .plane
        .add(
            Shape::Cube {
                size: [width, thickness, width],
            },
            Pose::at([top[0], top[1] - thickness / 2.0, top[2]]),
            &[ObjectProp::Anchored(true)],
        )
        .expect("floor");
    let start = [
        top[0] + offset[0],
        top[1] + height / 2.0 + drop,
        top[2] + offset[1],
    ];
    let c = s
        .plane
        .new_controller(
            Pose::at(start),
            [2.0 * radius, height, 2.0 * radius],
            false,
            &[],
        )
        .expect("controller");
    // Long enough to fall `drop` (≤ 5 at g = 50: 0.45 s) and settle.
    s.run(DT, 60);
    let y = c.object().position().unwrap()[1];
    let on_ground = c.on_ground().unwrap();
    c.destroy();
    floor.destroy();
    let want = top[1] + height / 2.0 + SKIN;
    prop_assert!(
        on_ground && (y - want).abs() < TOLERANCE,
        "floor {width} x {thickness} x {width} top {top:?}, controller r {radius} h {height} \
         at offset {offset:?} from {drop} above: centre at {y} (want {want}), OnGround {on_ground}"
    );
    Ok(())
}

/// The cases the defect report named, first: every one must stand.
#[test]
fn the_reported_floors_hold_a_controller() {
    let s = Scene::new("kcc-floors-named", gravity_50());
    for (width, thickness, offset) in [
        (400.0, 1.0, [0.0, 0.0]),
        (400.0, 1.0, [3.0, -2.0]),
        (50.0, 1.0, [0.0, 0.0]),
        (100.0, 1.0, [0.0, 0.0]),
        (2048.0, 1.0, [0.0, 0.0]),
        (5000.0, 2.0, [0.0, 0.0]),
        (10_000.0, 0.05, [0.0, 0.0]),
        (1.0, 20.0, [0.0, 0.0]),
    ] {
        let case = Case {
            width,
            thickness,
            top: [0.0; 3],
            offset,
            radius: 1.0,
            height: 5.0,
            drop: 3.5,
        };
        stands(&s, case).unwrap_or_else(|e| panic!("{e}"));
    }
}

fn log_uniform(lo: f32, hi: f32) -> impl Strategy<Value = f32> {
    (lo.ln()..hi.ln()).prop_map(f32::exp)
}

#[test]
fn any_floor_holds_any_controller() {
    let s = Scene::new("kcc-floors-any", gravity_50());
    let cases = (
        log_uniform(1.0, 10_000.0),
        log_uniform(0.05, 20.0),
        // Where the floor lies: at the origin half the time, anywhere within ±1,000 else.
        prop_oneof![Just([0.0f32; 3]), prop::array::uniform3(-1000.0f32..1000.0)],
        // Where over it the controller drops, as a fraction of the half width.
        prop_oneof![Just([0.0f32; 2]), prop::array::uniform2(-0.95f32..0.95)],
        log_uniform(0.25, 3.0),
        1.0f32..4.0,
        0.0f32..5.0,
    );
    let mut runner = TestRunner::new(Config {
        cases: 64,
        failure_persistence: None,
        ..Config::default()
    });
    runner
        .run(
            &cases,
            |(width, thickness, top, fraction, radius, height_ratio, drop)| {
                let half = width / 2.0;
                let offset = [fraction[0] * half, fraction[1] * half];
                let case = Case {
                    width,
                    thickness,
                    top,
                    offset,
                    radius,
                    height: 2.0 * radius * height_ratio,
                    drop,
                };
                stands(&s, case)
            },
        )
        .unwrap();
}

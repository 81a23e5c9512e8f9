//! Character controllers through a real daemon: the movement model against numbers
//! (acceleration, jump apex, slopes, steps, ground snap, walls, platforms, pushing,
//! depenetration, GroundY, paths) and its events.

// Controllers on floors of every kind, and on a plane with Threads > 1.
mod floors;
mod threads;

use client_sdk::{
    Contact, Controller, ControllerProp, Events, Object, ObjectProp, PlaneOptions, Pose, Shape,
};
use integration_tests::{quat, Scene};
use shm_layout::{
    EVENT_CONTROLLER_JUMPED, EVENT_CONTROLLER_LANDED, EVENT_PATH_FINISHED, EVENT_WAYPOINT_REACHED,
};

const DT: f32 = 1.0 / 60.0;
const G: f32 = 50.0;
/// The default character: Size (2, 5, 2): capsule radius 1, total height 5.
const SIZE: [f32; 3] = [2.0, 5.0, 2.0];
const HALF: f32 = 2.5;
/// The gap the controller keeps to what it stands on.
const SKIN: f32 = 0.01;

fn scene(tag: &str) -> Scene {
    let s = Scene::new(tag, PlaneOptions::default());
    s.floor();
    s
}

/// Yaw of a controller facing +Z: its LookVector (the CFrame's −Z, as on Roblox) turned
/// half a turn. The scenes here lie along +Z.
const FACING_PLUS_Z: f32 = std::f32::consts::PI;

/// A character at `at` facing +Z (so MoveForward walks +Z and +x of the intent is −X).
fn character(s: &Scene, at: [f32; 3], props: &[ControllerProp]) -> Controller {
    s.plane
        .new_controller(
            Pose {
                position: at,
                rotation: quat([0.0, 1.0, 0.0], FACING_PLUS_Z),
            },
            SIZE,
            false,
            props,
        )
        .expect("new controller")
}

/// The shortest signed angle from `a` to `b`.
fn angle_diff(a: f32, b: f32) -> f32 {
    let tau = std::f32::consts::TAU;
    (b - a + std::f32::consts::PI).rem_euclid(tau) - std::f32::consts::PI
}

fn speed_h(c: &Controller) -> f32 {
    let v = c.info().unwrap().velocity;
    (v[0] * v[0] + v[2] * v[2]).sqrt()
}

fn y(c: &Controller) -> f32 {
    c.object().position().unwrap()[1]
}

fn kinds(events: &Events, kind: u32) -> usize {
    events.records.iter().filter(|r| r.kind == kind).count()
}

fn anchored(s: &Scene, size: [f32; 3], pose: Pose) -> Object {
    s.anchored_box(size, pose)
}

#[test]
fn walk_speed_is_reached_with_acceleration_and_standing_is_still() {
    let s = scene("kcc-walk");
    let c = character(&s, [0.0, HALF + 0.5, 0.0], &[]);
    s.run(DT, 30);
    assert!(c.on_ground().unwrap(), "settled on the floor");
    let rest = y(&c);
    assert!(
        (rest - (HALF + SKIN)).abs() < 0.02,
        "stands on the floor: centre at {rest}"
    );
    // Standing still for 10 s: no vertical jitter.
    let (mut lo, mut hi) = (f32::MAX, f32::MIN);
    for _ in 0..600 {
        s.plane.step(DT).unwrap();
        let y = y(&c);
        lo = lo.min(y);
        hi = hi.max(y);
    }
    assert!(hi - lo < 1e-3, "jitter {}", hi - lo);

    // Forward (+Z, facing +Z): accelerates over several ticks, then holds WalkSpeed exactly.
    c.set_move_vector(0.0, 1.0).unwrap();
    s.run(DT, 2);
    let early = speed_h(&c);
    assert!(early > 1.0 && early < 12.0, "no instant snap: {early}");
    s.run(DT, 28);
    let v = speed_h(&c);
    assert!((v - 16.0).abs() < 0.16, "WalkSpeed reached: {v}");
    let z0 = c.object().position().unwrap()[2];
    s.run(DT, 60);
    let z1 = c.object().position().unwrap()[2];
    assert!(
        ((z1 - z0) - 16.0).abs() < 0.2,
        "1 s at WalkSpeed covers 16: {}",
        z1 - z0
    );
    // Letting go: friction stops it within a fraction of a second, exactly.
    c.set_move_vector(0.0, 0.0).unwrap();
    s.run(DT, 30);
    assert_eq!(speed_h(&c), 0.0, "stopped");
    assert!(c.on_ground().unwrap());
}

#[test]
fn jump_apex_is_jump_power_squared_over_2g_and_events_fire_once() {
    let s = scene("kcc-jump");
    s.plane.subscribe_events().unwrap();
    let c = character(&s, [0.0, HALF + SKIN, 0.0], &[]);
    s.run(DT, 10);
    let rest = y(&c);
    let _ = s.plane.events().unwrap();
    assert!(c.jump().unwrap(), "launches from the ground");
    let mut top = rest;
    let mut events = Events::default();
    for _ in 0..120 {
        s.plane.step(DT).unwrap();
        top = top.max(y(&c));
        let e = s.plane.events().unwrap();
        events.records.extend(e.records);
    }
    let apex = 28.0f32 * 28.0 / (2.0 * G);
    assert!(
        ((top - rest) - apex).abs() < 0.02 * apex,
        "apex {} vs {apex}",
        top - rest
    );
    assert_eq!(kinds(&events, EVENT_CONTROLLER_JUMPED), 1);
    assert_eq!(kinds(&events, EVENT_CONTROLLER_LANDED), 1);
    assert!((y(&c) - rest).abs() < 1e-3, "back on the floor");
    assert!(c.on_ground().unwrap());
    // Air control: the same intent gains speed at AirControl (0.3) of the ground rate.
    assert!(c.jump().unwrap());
    s.plane.step(DT).unwrap();
    c.set_move_vector(0.0, 1.0).unwrap();
    s.run(DT, 6);
    let air = speed_h(&c);
    // Ground: accelerate adds Acceleration × WalkSpeed × dt = 10 × 16 / 60 per tick.
    let per_tick = 10.0 * 16.0 * DT;
    assert!(
        (air - 6.0 * 0.3 * per_tick).abs() < 0.05,
        "6 ticks of air control: {air} vs {}",
        6.0 * 0.3 * per_tick
    );
    c.set_move_vector(0.0, 0.0).unwrap();
    s.run(DT, 120);
    // In the air, Jump does nothing.
    assert!(c.jump().unwrap());
    s.plane.step(DT).unwrap();
    assert!(!c.jump().unwrap(), "no jump in the air");
}

#[test]
fn slopes_steeper_than_max_slope_are_not_climbed_and_gentle_ones_are() {
    let s = scene("kcc-slope");
    // Two ramps rising toward +Z: 30° at x = -20, 60° at x = +20 (MaxSlope 45 default).
    for (x, deg) in [(-20.0f32, 30.0f32), (20.0, 60.0)] {
        let a = deg.to_radians();
        anchored(
            &s,
            [10.0, 1.0, 40.0],
            Pose {
                position: [x, 0.0, 20.0],
                rotation: quat([1.0, 0.0, 0.0], -a),
            },
        );
    }
    let gentle = character(&s, [-20.0, HALF + SKIN, -2.0], &[]);
    let steep = character(&s, [20.0, HALF + SKIN, -2.0], &[]);
    for c in [&gentle, &steep] {
        c.set_move_vector(0.0, 1.0).unwrap();
    }
    s.run(DT, 120);
    assert!(y(&gentle) > HALF + 3.0, "climbs 30°: y {}", y(&gentle));
    assert!(
        y(&steep) < HALF + 1.5,
        "does not climb 60°: y {}",
        y(&steep)
    );
    // Put on the steep ramp, it slides down (not held there).
    let a = 60f32.to_radians();
    let z = 25.0;
    let surface = (z - 20.0) * a.tan() + 0.5 / a.cos();
    steep
        .set(ControllerProp::Position([20.0, surface + HALF + 1.5, z]))
        .unwrap();
    steep.set_move_vector(0.0, 0.0).unwrap();
    s.run(DT, 3);
    let start = y(&steep);
    s.run(DT, 30);
    assert!(
        y(&steep) < start - 1.0,
        "slides down 60°: {start} -> {}",
        y(&steep)
    );
}

#[test]
fn steps_below_step_height_are_walked_up_and_walls_stop_and_slide() {
    let s = scene("kcc-steps");
    // A staircase of 0.5-high steps, 2 deep, rising toward +Z from z = 4.
    for i in 0..6 {
        let h = 0.5 * (i + 1) as f32;
        anchored(
            &s,
            [6.0, h, 2.0],
            Pose::at([0.0, h / 2.0, 5.0 + 2.0 * i as f32]),
        );
    }
    // A 2-high wall across x = 30.
    anchored(&s, [1.0, 2.0, 40.0], Pose::at([30.0, 1.0, 0.0]));
    let climber = character(&s, [0.0, HALF + SKIN, 0.0], &[]);
    climber.set_move_vector(0.0, 1.0).unwrap();
    let blocked = character(&s, [24.0, HALF + SKIN, 0.0], &[]);
    // Diagonally into the wall (+X and +Z facing +Z, where right is −X): slides along +Z.
    blocked.set(ControllerProp::LookWhereMoving(false)).unwrap();
    blocked.set_move_vector(-0.7, 0.7).unwrap();
    let mut grounded_ticks = 0;
    let mut top: f32 = 0.0;
    let mut stair_ticks = 0;
    for _ in 0..90 {
        s.plane.step(DT).unwrap();
        // On the staircase (it ends at z = 16, where a 3-high drop begins).
        if climber.object().position().unwrap()[2] < 15.0 {
            stair_ticks += 1;
            grounded_ticks += usize::from(climber.on_ground().unwrap());
        }
        top = top.max(y(&climber));
    }
    assert!(
        (top - (HALF + SKIN + 3.0)).abs() < 0.02,
        "walked up to the top step (3 high): y {top}"
    );
    assert!(
        grounded_ticks + 2 >= stair_ticks && stair_ticks > 30,
        "no hopping: grounded {grounded_ticks} of {stair_ticks} ticks on the stairs"
    );
    let p = blocked.object().position().unwrap();
    assert!(
        p[0] <= 30.0 - 0.5 - 1.0 + 0.02,
        "the wall stops it: x {}",
        p[0]
    );
    assert!(p[2] > 8.0, "slides along the wall: z {}", p[2]);
    assert!(y(&blocked) < HALF + 0.1, "a 2-high wall is not a step");
}

#[test]
fn walking_down_a_slope_snaps_to_the_ground() {
    let s = scene("kcc-snap");
    let a = 20f32.to_radians();
    // A ramp falling toward +Z, top near z = 0.
    anchored(
        &s,
        [10.0, 1.0, 40.0],
        Pose {
            position: [0.0, 7.0, 18.0],
            rotation: quat([1.0, 0.0, 0.0], a),
        },
    );
    let c = character(&s, [0.0, 20.0, 2.0], &[]);
    s.run(DT, 60);
    assert!(c.on_ground().unwrap());
    c.set_move_vector(0.0, 1.0).unwrap();
    let mut airborne = 0;
    for _ in 0..50 {
        s.plane.step(DT).unwrap();
        airborne += usize::from(!c.on_ground().unwrap());
    }
    assert_eq!(airborne, 0, "never leaves the slope walking down it");
}

#[test]
fn platforms_carry_riders_up_down_and_sideways_and_jumps_inherit_their_velocity() {
    let s = scene("kcc-platform");
    let top0 = 2.0;
    let platform = anchored(&s, [8.0, 1.0, 8.0], Pose::at([0.0, top0 - 0.5, 0.0]));
    let c = character(&s, [0.0, top0 + HALF + SKIN, 0.0], &[]);
    s.run(DT, 10);
    assert!(c.on_ground().unwrap());
    // Up and down at 6 units/s by pose writes each frame; never dips in or floats.
    let mut top = top0;
    let mut worst: f32 = 0.0;
    for i in 0..120 {
        let v = if i < 60 { 6.0 } else { -6.0 };
        top += v * DT;
        platform.set_pose(Pose::at([0.0, top - 0.5, 0.0])).unwrap();
        s.plane.step(DT).unwrap();
        let bottom = y(&c) - HALF;
        worst = worst.max((bottom - top).abs());
    }
    assert!(
        worst < 0.05,
        "rides at the platform's top: worst gap {worst}"
    );
    // Standing still on the box: no jitter over 10 s.
    let (mut lo, mut hi) = (f32::MAX, f32::MIN);
    for _ in 0..600 {
        s.plane.step(DT).unwrap();
        lo = lo.min(y(&c));
        hi = hi.max(y(&c));
    }
    assert!(hi - lo < 1e-3, "jitter on a box {}", hi - lo);
    // Sideways at 5 units/s: carried along.
    let x0 = c.object().position().unwrap()[0];
    let mut x = 0.0;
    for _ in 0..30 {
        x += 5.0 * DT;
        platform.set_pose(Pose::at([x, top - 0.5, 0.0])).unwrap();
        s.plane.step(DT).unwrap();
    }
    let carried = c.object().position().unwrap()[0] - x0;
    assert!((carried - x).abs() < 0.05, "carried {carried} vs {x}");
    // Jumping off keeps the platform's velocity.
    assert!(c.jump().unwrap());
    x += 5.0 * DT;
    platform.set_pose(Pose::at([x, top - 0.5, 0.0])).unwrap();
    s.plane.step(DT).unwrap();
    let vx = c.info().unwrap().velocity[0];
    assert!((vx - 5.0).abs() < 0.3, "inherits 5 units/s: {vx}");
}

#[test]
fn a_rotating_platform_turns_its_rider() {
    let s = scene("kcc-turntable");
    let table = anchored(&s, [20.0, 1.0, 20.0], Pose::at([0.0, 0.5, 0.0]));
    let c = character(&s, [6.0, 1.0 + HALF + SKIN, 0.0], &[]);
    s.run(DT, 10);
    assert!(c.on_ground().unwrap());
    // 1 rad/s about Y by pose writes: after 1 s the rider is 1 rad around, radius kept.
    for i in 1..=60 {
        let angle = i as f32 * DT;
        table
            .set_pose(Pose {
                position: [0.0, 0.5, 0.0],
                rotation: quat([0.0, 1.0, 0.0], angle),
            })
            .unwrap();
        s.plane.step(DT).unwrap();
    }
    let p = c.object().position().unwrap();
    let r = (p[0] * p[0] + p[2] * p[2]).sqrt();
    // A positive turn about Y takes +X toward -Z.
    let angle = (-p[2]).atan2(p[0]);
    assert!((r - 6.0).abs() < 0.05, "radius {r}");
    assert!((angle - 1.0).abs() < 0.03, "turned {angle} rad");
    let yaw = c.info().unwrap().rotation[1];
    assert!(
        angle_diff(FACING_PLUS_Z + 1.0, yaw).abs() < 0.03,
        "facing turned with it: {yaw}"
    );
}

#[test]
fn light_crates_are_pushed_heavy_ones_block_and_controllers_collide() {
    let s = scene("kcc-push");
    let crate_at = |x: f32, density: f32| {
        s.plane
            .add(
                Shape::Cube { size: [2.0; 3] },
                Pose::at([x, 1.0, 6.0]),
                &[ObjectProp::Density(density)],
            )
            .unwrap()
    };
    let light = crate_at(-10.0, 0.1);
    let heavy = crate_at(10.0, 100.0);
    let a = character(&s, [-10.0, HALF + SKIN, 0.0], &[]);
    let b = character(&s, [10.0, HALF + SKIN, 0.0], &[]);
    for c in [&a, &b] {
        c.set_move_vector(0.0, 1.0).unwrap();
    }
    s.run(DT, 120);
    let light_z = light.position().unwrap()[2];
    let heavy_z = heavy.position().unwrap()[2];
    assert!(
        light_z > 10.0,
        "the light crate (mass 0.8) is pushed: z {light_z}"
    );
    assert!(
        (heavy_z - 6.0).abs() < 0.05,
        "the heavy crate (mass 800; friction 20,000 > push 500) blocks: z {heavy_z}"
    );
    let bz = b.object().position().unwrap()[2];
    assert!(
        bz < 6.0 - 1.0 - 1.0 + 0.05,
        "blocked by the heavy crate: z {bz}"
    );

    // Two controllers walking into each other stop apart.
    let c1 = character(&s, [40.0, HALF + SKIN, 0.0], &[]);
    let c2 = character(&s, [40.0, HALF + SKIN, 10.0], &[]);
    c1.set_move_vector(0.0, 1.0).unwrap();
    c2.set_move_vector(0.0, -1.0).unwrap();
    s.run(DT, 90);
    let gap = c2.object().position().unwrap()[2] - c1.object().position().unwrap()[2];
    assert!(gap > 2.0 - 0.05, "capsules of radius 1 stay apart: {gap}");
}

#[test]
fn spawned_inside_geometry_it_is_pushed_out_and_ground_y_holds_it_up() {
    let s = scene("kcc-depen");
    anchored(&s, [4.0, 4.0, 4.0], Pose::at([0.0, 2.0, 0.0]));
    let c = character(&s, [0.5, 2.0, 0.0], &[]);
    s.run(DT, 60);
    let p = c.object().position().unwrap();
    let outside = p[0].abs() >= 3.0 - 0.05 || p[1] >= 4.0 + HALF - 0.05;
    assert!(outside, "pushed out of the box: {p:?}");
    s.run(DT, 60);
    assert!(c.on_ground().unwrap(), "stands after being freed: {p:?}");

    // No floor at all: GroundY holds it at GroundY + half height.
    let empty = Scene::new("kcc-groundy", PlaneOptions::default());
    let c = empty
        .plane
        .new_controller(
            Pose::at([0.0, 10.0, 0.0]),
            SIZE,
            false,
            &[ControllerProp::GroundY(Some(-3.0))],
        )
        .unwrap();
    empty.run(DT, 90);
    assert!((y(&c) - (-3.0 + HALF)).abs() < 1e-3, "y {}", y(&c));
    assert!(c.on_ground().unwrap());
    // Without GroundY it falls.
    c.set(ControllerProp::GroundY(None)).unwrap();
    empty.run(DT, 30);
    assert!(y(&c) < -3.0, "falls without a fallback: {}", y(&c));
}

#[test]
fn paths_are_walked_in_order_with_one_event_per_waypoint_and_one_finish() {
    let s = scene("kcc-path");
    s.plane.subscribe_events().unwrap();
    let c = character(&s, [0.0, HALF + SKIN, 0.0], &[]);
    let waypoints = [[10.0, 0.0, 0.0], [10.0, 0.0, 10.0], [0.0, 0.0, 10.0]];
    assert_eq!(c.compute_path(&waypoints).unwrap(), 3);
    let mut reached = Vec::new();
    let mut finished = 0;
    for _ in 0..300 {
        s.plane.step(DT).unwrap();
        for r in s.plane.events().unwrap().records {
            match r.kind {
                EVENT_WAYPOINT_REACHED => reached.push(r.b_slot),
                EVENT_PATH_FINISHED => finished += 1,
                _ => {}
            }
        }
    }
    assert_eq!(reached, vec![1, 2, 3]);
    assert_eq!(finished, 1);
    let p = c.object().position().unwrap();
    assert!(
        (p[0]).abs() < 1.5 && (p[2] - 10.0).abs() < 1.5,
        "ends near the last waypoint: {p:?}"
    );
    let info = c.info().unwrap();
    assert_eq!((info.path_length, info.path_index), (0, 0));
    // Facing follows the walk (LookWhereMoving): last leg toward -X, so the LookVector
    // (−sin yaw, 0, −cos yaw) is −X: yaw π/2, read in (−π, π].
    assert!(
        (info.rotation[1] - std::f32::consts::FRAC_PI_2).abs() < 0.2,
        "yaw {}",
        info.rotation[1]
    );
    let _ = Contact::from_record;
}

#[test]
fn steps_up_to_step_height_are_climbed_and_taller_ones_are_not() {
    // The default StepHeight of a radius-1 capsule is 0.6 × 1 + 0.5 = 1.1.
    for (h, climbs) in [(0.3f32, true), (0.7, true), (1.0, true), (1.3, false)] {
        let s = scene("kcc-stepheight");
        anchored(&s, [10.0, h, 10.0], Pose::at([0.0, h / 2.0, 10.0]));
        let c = character(&s, [0.0, HALF + SKIN, 0.0], &[]);
        c.set_move_vector(0.0, 1.0).unwrap();
        s.run(DT, 60);
        let p = c.object().position().unwrap();
        if climbs {
            assert!(
                (p[1] - (h + HALF + SKIN)).abs() < 0.02 && p[2] > 8.0,
                "a {h} step is walked up: {p:?}"
            );
        } else {
            assert!(p[1] < HALF + 0.1 && p[2] < 4.1, "a {h} step blocks: {p:?}");
        }
    }
}

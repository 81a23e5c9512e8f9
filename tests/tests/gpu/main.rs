//! The GPU path (`DeferGpu`) through a real daemon, on whatever Vulkan adapter the machine
//! has (Mesa's lavapipe in CI): free fall against the closed form and the CPU path, the
//! bounce apex ratio e², 1,000 boxes settling in an anchored container, live flips that
//! keep every pose and velocity, ops the GPU path refuses, and the refusal when no adapter
//! exists (`PHYSICS_GPU=off` in the daemon's environment hides them).

// Snapshots of DeferGpu planes.
mod snapshot;

use client_sdk::{ErrorKind, Object, ObjectProp, PlaneOptions, PlaneProp, Pose, Shape};
use integration_tests::{no_damping, Scene, TestDaemon};

const DT: f32 = 1.0 / 60.0;

fn gpu() -> PlaneOptions {
    PlaneOptions {
        defer_gpu: Some(true),
        ..no_damping()
    }
}

fn ball(scene: &Scene, at: [f32; 3], props: &[ObjectProp]) -> Object {
    scene
        .plane
        .add(Shape::Sphere { radius: 0.5 }, Pose::at(at), props)
        .unwrap()
}

#[test]
fn free_fall_matches_the_closed_form_and_the_cpu_path() {
    let scene = Scene::new("gpu-fall", gpu());
    assert!(scene.plane.info().unwrap().settings.defer_gpu);
    let cpu = scene.client.create_plane(&PlaneOptions {
        tick_rate: Some(0.0),
        ..no_damping()
    });
    let cpu = cpu.unwrap();
    let (y0, vx) = (100.0f32, 3.0f32);
    let on_gpu = ball(
        &scene,
        [0.0, y0, 0.0],
        &[ObjectProp::Velocity([vx, 0.0, 0.0])],
    );
    let on_cpu = cpu
        .add(
            Shape::Sphere { radius: 0.5 },
            Pose::at([0.0, y0, 0.0]),
            &[ObjectProp::Velocity([vx, 0.0, 0.0])],
        )
        .unwrap();
    let g = 50.0f32;
    let mut worst_cpu_gap = 0.0f32;
    for n in 1..=60u32 {
        scene.plane.step(DT).unwrap();
        cpu.step(DT).unwrap();
        let t = n as f32 * DT;
        let p = on_gpu.position().unwrap();
        let v = on_gpu.velocity().unwrap();
        // Semi-implicit Euler over 4 substeps (h = dt/4) lags the parabola by g·h·t/2.
        let exact = y0 - 0.5 * g * t * t;
        let bound = 0.5 * g * (DT / 4.0) * t + 1e-4 * n as f32;
        assert!(
            (p[1] - exact).abs() <= bound,
            "t={t}: y={}, exact={exact}",
            p[1]
        );
        assert!(
            (v[1] + g * t).abs() <= 1e-3 * n as f32,
            "t={t}: vy={}",
            v[1]
        );
        assert!((p[0] - vx * t).abs() < 1e-3, "t={t}: x={}", p[0]);
        let q = on_cpu.position().unwrap();
        worst_cpu_gap = worst_cpu_gap.max((p[1] - q[1]).abs());
    }
    println!("GPU − CPU height, worst over 1 s: {worst_cpu_gap}");
    // The CPU path runs the same integrator: the two agree to f32 rounding.
    assert!(
        worst_cpu_gap < 2e-3,
        "GPU and CPU differ by {worst_cpu_gap}"
    );
    let header = *scene.plane.snapshot().unwrap().header();
    assert_eq!(header.tick, 60);
    assert_eq!(header.body_count, 1);
}

#[test]
fn a_ball_bounces_with_apex_ratio_e_squared() {
    let scene = Scene::new("gpu-bounce", gpu());
    scene.floor();
    let e = 0.8f32;
    let h0 = 10.0f32;
    let b = ball(&scene, [0.0, h0 + 0.5, 0.0], &[ObjectProp::Bounciness(e)]);
    // Apexes: heights of the ball's bottom where vy turns from + to −.
    let mut apexes = Vec::new();
    let mut last_vy = 0.0f32;
    for _ in 0..(5.0 / DT) as u32 {
        scene.plane.step(DT).unwrap();
        let vy = b.velocity().unwrap()[1];
        if last_vy > 0.0 && vy <= 0.0 {
            apexes.push(b.position().unwrap()[1] - 0.5);
        }
        last_vy = vy;
    }
    assert!(apexes.len() >= 3, "apexes {apexes:?}");
    println!("apexes {apexes:?}");
    let mut previous = h0;
    for (i, apex) in apexes.iter().take(3).enumerate() {
        let ratio = apex / previous;
        // e² = 0.64; a tick of 1/60 s samples the apex within g·dt²/8 and the contact is
        // found a substep late: 4 % covers both at these heights.
        assert!(
            (ratio - e * e).abs() < 0.04 * e * e,
            "bounce {}: apex {apex} after {previous}, ratio {ratio} (e² = {})",
            i + 1,
            e * e
        );
        previous = *apex;
    }
}

#[test]
fn a_thousand_boxes_settle_in_an_anchored_container() {
    let scene = Scene::new(
        "gpu-container",
        PlaneOptions {
            defer_gpu: Some(true),
            ..Default::default()
        },
    );
    let (_, width) = physics_scenes::debris_layout(1000, 10, 2.0);
    physics_scenes::container(&mut &scene.plane, width, 20.0).unwrap();
    let boxes = physics_scenes::debris(&mut &scene.plane, 1000, 10, 2.0, &[]).unwrap();
    scene.run(DT, 240);
    let snapshot = scene.plane.snapshot().unwrap();
    let header = *snapshot.header();
    let half = width / 2.0;
    let mut top = 0.0f32;
    let mut fastest = 0.0f32;
    for b in &boxes {
        let s = snapshot.get(b.handle()).expect("published");
        let [x, y, z] = s.position;
        assert!(x.is_finite() && y.is_finite() && z.is_finite(), "{s:?}");
        // Inside the walls and above the floor (a box's centre is 0.5 from its faces; the
        // bound allows the stated penetration).
        assert!(
            x.abs() < half - 0.5 + 0.1 && z.abs() < half - 0.5 + 0.1 && y > 0.5 - 0.1,
            "box left the container: {:?}",
            s.position
        );
        top = top.max(y);
        let v = s.linear_velocity;
        fastest = fastest.max((v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt());
    }
    // Ten layers of unit boxes: the top layer rests near y = 9.5 when nothing sinks.
    assert!(top < 9.5 + 0.1 && top > 9.5 - 0.5, "top box at {top}");
    assert!(
        header.max_penetration < 0.1,
        "deepest penetration {} (bound 0.1 = a tenth of a box)",
        header.max_penetration
    );
    assert!(fastest < 1.0, "still moving at {fastest} units/s after 4 s");
    // Every box rests on the one below or on the floor: about 1,000 touching pairs (a pair
    // held exactly at contact counts as not touching).
    assert!(
        header.contact_pairs > 800,
        "{} contacts",
        header.contact_pairs
    );
    println!(
        "top {top}, deepest {}, fastest {fastest}, contacts {}",
        header.max_penetration, header.contact_pairs
    );
}

/// A ball thrown sideways in a plane that flips between CPU and GPU every `flip` ticks, and
/// the same ball in a plane that never flips.
fn flipping(flip: u32, ticks: u32) -> (Vec<[f32; 3]>, Vec<[f32; 3]>) {
    let scene = Scene::new("gpu-flip", no_damping());
    let other = scene
        .client
        .create_plane(&PlaneOptions {
            tick_rate: Some(0.0),
            ..no_damping()
        })
        .unwrap();
    let props = [
        ObjectProp::Velocity([4.0, 10.0, -2.0]),
        ObjectProp::AngularVelocity([0.0, 3.0, 0.0]),
    ];
    let a = ball(&scene, [0.0, 50.0, 0.0], &props);
    let b = other
        .add(
            Shape::Sphere { radius: 0.5 },
            Pose::at([0.0, 50.0, 0.0]),
            &props,
        )
        .unwrap();
    let (mut flipped, mut straight) = (Vec::new(), Vec::new());
    for n in 0..ticks {
        if n > 0 && n % flip == 0 {
            let on = !scene.plane.info().unwrap().settings.defer_gpu;
            scene.plane.set(PlaneProp::DeferGpu(on)).unwrap();
            assert_eq!(scene.plane.info().unwrap().settings.defer_gpu, on);
        }
        scene.plane.step(DT).unwrap();
        other.step(DT).unwrap();
        flipped.push(a.position().unwrap());
        straight.push(b.position().unwrap());
    }
    (flipped, straight)
}

#[test]
fn a_live_flip_mid_fall_continues_the_same_trajectory() {
    let (flipped, straight) = flipping(20, 80);
    for (n, (p, q)) in flipped.iter().zip(&straight).enumerate() {
        let gap = (0..3).map(|i| (p[i] - q[i]).abs()).fold(0.0, f32::max);
        assert!(gap < 2e-3, "tick {n}: flipped {p:?}, never flipped {q:?}");
    }
}

#[test]
fn flipping_back_and_forth_loses_nothing() {
    // Zero gravity, no damping, bodies far apart: every body keeps its velocity exactly, and
    // a plane that flips before every tick must match one that never flips.
    let options = PlaneOptions {
        gravity: Some([0.0; 3]),
        ..no_damping()
    };
    let scene = Scene::new("gpu-flip-many", options.clone());
    let other = scene
        .client
        .create_plane(&PlaneOptions {
            tick_rate: Some(0.0),
            ..options
        })
        .unwrap();
    let add = |plane: &client_sdk::Plane| -> Vec<Object> {
        (0..40)
            .map(|i| {
                let f = i as f32;
                let sphere = i % 2 == 0;
                let shape = if sphere {
                    Shape::Sphere { radius: 0.4 }
                } else {
                    Shape::Cube {
                        size: [0.5, 0.7, 0.9],
                    }
                };
                let spin = if sphere {
                    [0.5, f * 0.01, 0.0]
                } else {
                    [0.0; 3]
                };
                plane
                    .add(
                        shape,
                        Pose::at([f * 3.0, 10.0 + f, -f]),
                        &[
                            ObjectProp::Velocity([f * 0.1, -f * 0.2, 1.0]),
                            ObjectProp::AngularVelocity(spin),
                            ObjectProp::Anchored(i % 7 == 3),
                        ],
                    )
                    .unwrap()
            })
            .collect()
    };
    let flipped = add(&scene.plane);
    let straight = add(&other);
    for n in 0..20 {
        scene.plane.set(PlaneProp::DeferGpu(n % 2 == 0)).unwrap();
        scene.plane.step(DT).unwrap();
        other.step(DT).unwrap();
        let (a, b) = (scene.plane.snapshot().unwrap(), other.snapshot().unwrap());
        for (x, y) in flipped.iter().zip(&straight) {
            let (s, t) = (a.get(x.handle()).unwrap(), b.get(y.handle()).unwrap());
            assert_eq!(
                s.linear_velocity, t.linear_velocity,
                "tick {n}: {s:?} vs {t:?}"
            );
            assert_eq!(
                s.angular_velocity, t.angular_velocity,
                "tick {n}: {s:?} vs {t:?}"
            );
            assert_eq!(s.flags, t.flags, "tick {n}: {s:?} vs {t:?}");
            for i in 0..3 {
                assert!(
                    (s.position[i] - t.position[i]).abs() < 1e-4,
                    "tick {n}: {s:?} vs {t:?}"
                );
            }
            for i in 0..4 {
                assert!(
                    (s.rotation[i] - t.rotation[i]).abs() < 1e-4,
                    "tick {n}: {s:?} vs {t:?}"
                );
            }
        }
    }
}

#[test]
fn ops_the_gpu_path_cannot_run_are_refused_and_queries_see_gpu_poses() {
    let scene = Scene::new("gpu-ops", gpu());
    let b = ball(&scene, [0.0, 20.0, 0.0], &[]);
    scene.run(DT, 30);
    let y = b.position().unwrap()[1];
    assert!(y < 20.0 - 5.0, "fell to {y}");
    // A ray straight down from above hits the ball where the GPU put it.
    let hit = scene
        .plane
        .raycast([0.0, 100.0, 0.0], [0.0, -200.0, 0.0], None)
        .unwrap()
        .expect("hit");
    assert!(
        (hit.position[1] - (y + 0.5)).abs() < 1e-3,
        "{hit:?} vs y {y}"
    );
    // RotateTo needs the CPU path.
    let err = b
        .set(ObjectProp::RotateTo(Some(shm_layout::RotateTo {
            target: [0.0, 0.0, 0.0, 1.0],
            strength: 5.0,
        })))
        .and_then(|_| scene.client.flush())
        .unwrap_err();
    assert!(err.to_string().contains("GPU path"), "{err}");
    // Writes of the supported kind apply on the GPU: a teleport and a velocity.
    b.set(ObjectProp::Pose(Pose::at([5.0, 50.0, 0.0]))).unwrap();
    b.set_velocity([0.0, 0.0, 0.0]).unwrap();
    scene.plane.step(DT).unwrap();
    let p = b.position().unwrap();
    assert!(
        (p[0] - 5.0).abs() < 1e-4 && (p[1] - 50.0).abs() < 0.1,
        "{p:?}"
    );
    // An impulse: Δv = J / mass (Weight 1).
    b.apply_impulse([10.0, 0.0, 0.0]).unwrap();
    scene.plane.step(DT).unwrap();
    let v = b.velocity().unwrap();
    assert!((v[0] - 10.0).abs() < 1e-3, "{v:?}");
}

#[test]
fn without_an_adapter_defer_gpu_fails_and_the_plane_stays_on_the_cpu() {
    let daemon = TestDaemon::start_with("gpu-none", &[], &[("PHYSICS_GPU", "off")]);
    let client = daemon.client();
    let err = client
        .create_plane(&PlaneOptions {
            defer_gpu: Some(true),
            ..PlaneOptions::manual()
        })
        .unwrap_err();
    assert!(
        matches!(&err, client_sdk::Error::Command(e) if e.kind == ErrorKind::InvalidValue),
        "{err}"
    );
    let text = err.to_string();
    assert!(
        text.contains("DeferGpu") && text.contains("no GPU adapter"),
        "{text}"
    );
    // No plane came of it, and the message does not claim one did.
    assert!(
        text.contains("no plane was created") && !text.contains("stays on the CPU"),
        "{text}"
    );
    let plane = client.create_plane(&PlaneOptions::manual()).unwrap();
    let b = plane
        .add(
            Shape::Sphere { radius: 0.5 },
            Pose::at([0.0, 10.0, 0.0]),
            &[],
        )
        .unwrap();
    let err = plane
        .set(PlaneProp::DeferGpu(true))
        .and_then(|_| client.flush());
    let err = err.unwrap_err().to_string();
    assert!(err.contains("stays on the CPU"), "{err}");
    assert!(!plane.info().unwrap().settings.defer_gpu);
    plane.step(DT).unwrap();
    assert!(b.position().unwrap()[1] < 10.0);
}

//! The publish path: one tick of a plane written into a loaned shared-memory sample and sent,
//! for a settled (sleeping) pile and for bodies that are all awake.
//!
//! cargo bench -p physics-daemon --bench publish

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use iceoryx2::prelude::*;
use physics_daemon::publish::PlaneOutput;
use physics_daemon::rapier3d::Plane;
use shm_layout::{names, ObjectProp, PlaneProp, Pose, Shape};

const DT: f32 = 1.0 / 60.0;

/// Columns of five cubes on a floor, stepped until rapier puts them to sleep.
fn settled_pile(n: usize) -> Plane {
    let mut plane = Plane::new(1, &[PlaneProp::TickRate(0.0)]).expect("plane");
    let side = ((n / 5) as f64).sqrt().ceil() as usize;
    let width = side as f32 * 1.25;
    plane
        .add_object(
            &Shape::Cube {
                size: [width + 2.0, 1.0, width + 2.0],
            },
            Pose::at([width / 2.0, -0.5, width / 2.0]),
            &[ObjectProp::Anchored(true)],
        )
        .expect("floor");
    for i in 0..n {
        let (column, layer) = (i / 5, i % 5);
        let x = (column % side) as f32 * 1.25 + 0.5;
        let z = (column / side) as f32 * 1.25 + 0.5;
        plane
            .add_object(
                &Shape::Cube { size: [1.0; 3] },
                Pose::at([x, 0.5 + layer as f32, z]),
                &[],
            )
            .expect("cube");
    }
    for _ in 0..180 {
        plane.step(DT).expect("step");
    }
    plane
}

/// Cubes far apart, moving, no gravity: every body awake.
fn awake(n: usize) -> Plane {
    let props = [PlaneProp::TickRate(0.0), PlaneProp::Gravity([0.0; 3])];
    let mut plane = Plane::new(1, &props).expect("plane");
    for i in 0..n {
        let p = [(i % 32) as f32, ((i / 32) % 32) as f32, (i / 1024) as f32].map(|c| c * 3.0);
        plane
            .add_object(
                &Shape::Cube { size: [1.0; 3] },
                Pose::at(p),
                &[ObjectProp::Velocity([0.1, 0.2, 0.3])],
            )
            .expect("cube");
    }
    plane.step(DT).expect("step");
    plane
}

fn publish(c: &mut Criterion) {
    let domain = format!("crit-pub-{}", std::process::id());
    let config = names::config(&domain).expect("domain");
    let node = NodeBuilder::new()
        .config(&config)
        .signal_handling_mode(SignalHandlingMode::Disabled)
        .create::<ipc::Service>()
        .expect("node");
    let mut group = c.benchmark_group("publish");
    for n in [1_000usize, 10_000] {
        for (scene, mut plane) in [("settled_pile", settled_pile(n)), ("awake", awake(n))] {
            let out = PlaneOutput::new(&node, plane.id).expect("output");
            // A reader holding the newest sample, as a game would.
            let reader = node
                .service_builder(&names::plane_bodies(plane.id))
                .publish_subscribe::<[shm_layout::BodyState]>()
                .user_header::<shm_layout::TickHeader>()
                .open()
                .expect("open")
                .subscriber_builder()
                .create()
                .expect("subscriber");
            group.bench_function(BenchmarkId::new(scene, n), |b| {
                b.iter(|| {
                    out.publish(&mut plane).expect("publish");
                    black_box(reader.receive().expect("receive"));
                })
            });
        }
    }
    group.finish();
    drop(node);
    let _ = physics_daemon::cleanup_domain(&domain);
}

criterion_group!(benches, publish);
criterion_main!(benches);

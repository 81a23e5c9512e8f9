//! Publishing a tick per body: the sample written into shared memory after a step of a
//! settled pile (nothing moved) and of free bodies (every body moved), with a reader
//! holding the newest sample as a game would.

use std::hint::black_box;

use gungraun::{library_benchmark, library_benchmark_group};
use iceoryx2::prelude::*;
use physics_daemon::publish::PlaneOutput;
use physics_scenes::LocalPlane;
use shm_layout::{names, BodyState, TickHeader};

use crate::common::{free, settled_pile, DT};

/// A plane, its output and a reader, on a node of a domain of this process's own.
pub struct Published {
    plane: LocalPlane,
    out: PlaneOutput,
    reader: iceoryx2::port::subscriber::Subscriber<ipc::Service, [BodyState], TickHeader>,
    _node: Node<ipc::Service>,
}

fn published(mut plane: LocalPlane) -> Published {
    let domain = format!("counts-pub-{}", std::process::id());
    let config = names::config(&domain).expect("domain");
    let node = NodeBuilder::new()
        .config(&config)
        .signal_handling_mode(SignalHandlingMode::Disabled)
        .create::<ipc::Service>()
        .expect("node");
    let out = PlaneOutput::new(&node, plane.id).expect("output");
    let reader = node
        .service_builder(&names::plane_bodies(plane.id))
        .publish_subscribe::<[BodyState]>()
        .user_header::<TickHeader>()
        .open()
        .expect("open")
        .subscriber_builder()
        .create()
        .expect("subscriber");
    // The first sample writes every slot; the measured one is a tick's after a step.
    out.publish(&mut plane).expect("publish");
    drop(reader.receive().expect("receive"));
    plane.step(DT).expect("step");
    Published {
        plane,
        out,
        reader,
        _node: node,
    }
}

fn settled(n: usize) -> Published {
    published(settled_pile(n))
}

fn moving(n: usize) -> Published {
    published(free(n))
}

#[library_benchmark]
#[bench::n100(args = (100), setup = settled)]
#[bench::n1000(args = (1000), setup = settled)]
#[bench::moving_n100(args = (100), setup = moving)]
#[bench::moving_n1000(args = (1000), setup = moving)]
fn publish(mut p: Published) -> Published {
    p.out.publish(&mut p.plane).expect("publish");
    black_box(p.reader.receive().expect("receive"));
    p
}

library_benchmark_group!(name = publish_group; benchmarks = publish);

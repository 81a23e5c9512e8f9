//! A client process that takes iceoryx2 slots in a daemon's services and never says Hello,
//! for the hostile-transport tests. It prints "ready" once it holds them, then sleeps until
//! killed.
//!
//! hoarder nodes DOMAIN N           N nodes, each with a request port on the control service
//! hoarder readers DOMAIN PLANE N   one node with N subscribers of the plane's body states

use std::io::Write;

use iceoryx2::prelude::*;
use shm_layout::{names, BodyState, TickHeader};

fn node(domain: &str) -> Node<ipc::Service> {
    NodeBuilder::new()
        .config(&names::config(domain).expect("valid domain"))
        .signal_handling_mode(SignalHandlingMode::Disabled)
        .create::<ipc::Service>()
        .expect("create node")
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let domain = &args[2];
    let mut keep: Vec<Box<dyn std::any::Any>> = Vec::new();
    match args[1].as_str() {
        "nodes" => {
            let n: usize = args[3].parse().expect("count");
            for _ in 0..n {
                let node = node(domain);
                let port = node
                    .service_builder(&names::control())
                    .request_response::<[u8], [u8]>()
                    .request_user_header::<u128>()
                    .open()
                    .expect("open the control service")
                    .client_builder()
                    .create()
                    .expect("create a request port");
                keep.push(Box::new(port));
                keep.push(Box::new(node));
            }
        }
        "readers" => {
            let plane: u32 = args[3].parse().expect("plane id");
            let n: usize = args[4].parse().expect("count");
            let node = node(domain);
            let service = node
                .service_builder(&names::plane_bodies(plane))
                .publish_subscribe::<[BodyState]>()
                .user_header::<TickHeader>()
                .open()
                .expect("open the plane's body service");
            for _ in 0..n {
                let sub = service
                    .subscriber_builder()
                    .buffer_size(1)
                    .create()
                    .expect("create a subscriber");
                keep.push(Box::new(sub));
            }
            keep.push(Box::new(service));
            keep.push(Box::new(node));
        }
        other => panic!("unknown mode {other}"),
    }
    println!("ready");
    std::io::stdout().flush().unwrap();
    std::thread::sleep(std::time::Duration::from_secs(3600));
}

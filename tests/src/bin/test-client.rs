//! A second client process for the multi-process tests.
//!
//! test-client hold DOMAIN                  create a plane + ball, print "plane=ID", then sleep
//! test-client read DOMAIN PLANE SLOT GEN   attach, print "tick=T x y z" of that body
//! test-client hold-once DOMAIN             create a plane, print "plane=ID", exit
//! test-client start-and-hold DOMAIN        start a daemon on demand, print "daemon=PID", sleep
//! test-client share DOMAIN LIMIT N         create a Shared plane with SharedObjectLimit
//!                                          LIMIT, print "plane=ID"; on a line from stdin
//!                                          add N cubes to a private plane, print "added=K"
//! test-client burn DOMAIN N RATE           create N planes ticking at RATE Hz, each with 50
//!                                          balls on a floor, print "ready", sleep
//! test-client clients DOMAIN N             hold up to N clients (connections) at once,
//!                                          print "refused=ERROR" for the first refused
//!                                          one, then "connected=K", sleep

use std::io::Write;

use client_sdk::{Client, Handle, Object, PlaneOptions, Pose, Shape};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args[1] == "start-and-hold" {
        let session = client_sdk::connect_or_start(&args[2]).expect("connect or start");
        let pid = session.daemon.as_ref().expect("a daemon was started").pid();
        println!("daemon={pid}");
        std::io::stdout().flush().unwrap();
        std::thread::sleep(std::time::Duration::from_secs(3600));
        return;
    }
    if args[1] == "start-and-leave" {
        // Starts a daemon on demand, says goodbye, and lives on without a connection.
        let client_sdk::Session { client, daemon } =
            client_sdk::connect_or_start(&args[2]).expect("connect or start");
        drop(client);
        let daemon = daemon.expect("a daemon was started");
        println!("daemon={}", daemon.pid());
        std::io::stdout().flush().unwrap();
        std::thread::sleep(std::time::Duration::from_secs(3600));
        drop(daemon);
        return;
    }
    let client = Client::connect(&args[2]).expect("connect");
    match args[1].as_str() {
        "hold" => {
            let plane = client
                .create_plane(&PlaneOptions::manual())
                .expect("create plane");
            plane
                .add(
                    Shape::Sphere { radius: 0.5 },
                    Pose::at([0.0, 5.0, 0.0]),
                    &[],
                )
                .expect("add");
            println!("plane={}", plane.id());
            std::io::stdout().flush().unwrap();
            std::thread::sleep(std::time::Duration::from_secs(3600));
        }
        "hold-once" => {
            let plane = client
                .create_plane(&PlaneOptions::manual())
                .expect("create plane");
            println!("plane={}", plane.id());
        }
        "read" => {
            let n = |i: usize| args[i].parse::<u32>().expect("number");
            let plane = client.attach_plane(n(3)).expect("attach");
            let obj = Object::from_handle(
                &plane,
                Handle {
                    slot: n(4),
                    generation: n(5),
                },
            );
            let p = obj.position().expect("position");
            println!(
                "tick={} {} {} {}",
                plane.snapshot().unwrap().tick(),
                p[0],
                p[1],
                p[2]
            );
        }
        "share" => {
            let n = |i: usize| args[i].parse::<u32>().expect("number");
            let shared = client
                .create_plane(&PlaneOptions {
                    shared: Some(true),
                    shared_object_limit: Some(n(3)),
                    ..PlaneOptions::manual()
                })
                .expect("create shared plane");
            println!("plane={}", shared.id());
            std::io::stdout().flush().unwrap();
            let mut line = String::new();
            std::io::stdin().read_line(&mut line).unwrap();
            let own = client
                .create_plane(&PlaneOptions::manual())
                .expect("create plane");
            let added = (0..n(4))
                .take_while(|i| {
                    own.add(
                        Shape::Cube { size: [0.5; 3] },
                        Pose::at([*i as f32, 0.0, 0.0]),
                        &[],
                    )
                    .is_ok()
                })
                .count();
            println!("added={added}");
            std::io::stdout().flush().unwrap();
            std::thread::sleep(std::time::Duration::from_secs(3600));
        }
        "burn" => {
            let n = args[3].parse::<u32>().expect("number");
            let rate = args[4].parse::<f32>().expect("rate");
            let planes: Vec<_> = (0..n)
                .map(|_| {
                    let plane = client
                        .create_plane(&PlaneOptions {
                            tick_rate: Some(rate),
                            never_sleep: Some(true),
                            ..PlaneOptions::default()
                        })
                        .expect("create plane");
                    for i in 0..50 {
                        plane
                            .add(
                                Shape::Sphere { radius: 0.5 },
                                Pose::at([(i % 10) as f32 * 1.5, 1.0 + (i / 10) as f32, 0.0]),
                                &[],
                            )
                            .expect("add");
                    }
                    plane
                })
                .collect();
            client.flush().expect("flush");
            println!("ready");
            std::io::stdout().flush().unwrap();
            std::thread::sleep(std::time::Duration::from_secs(3600));
            drop(planes);
        }
        "clients" => {
            let n = args[3].parse::<usize>().expect("number");
            let mut held = vec![client];
            while held.len() < n {
                match Client::connect(&args[2]) {
                    Ok(c) => held.push(c),
                    Err(e) => {
                        println!("refused={e}");
                        break;
                    }
                }
            }
            println!("connected={}", held.len());
            std::io::stdout().flush().unwrap();
            std::thread::sleep(std::time::Duration::from_secs(3600));
        }
        other => panic!("unknown mode {other}"),
    }
}

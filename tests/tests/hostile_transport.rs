//! Hostile clients below the payload: a client owns the shared memory its requests live in,
//! so it can write any value into the iceoryx2 request header before (or after) sending.
//! Each test here is such a client, built on raw iceoryx2 ports in this process, tampering
//! with one header field; each asserts that the daemon survives, is not misled, and serves
//! an honest client afterwards. The fuzzer (`fuzz.rs`) covers the payload above the header.

use std::time::{Duration, Instant};

use client_sdk::{Client, ErrorKind, PlaneOptions, Pose, Shape};
use iceoryx2::pending_response::PendingResponse;
use iceoryx2::port::client::Client as RequestPort;
use iceoryx2::port::listener::Listener;
use iceoryx2::port::notifier::Notifier;
use iceoryx2::prelude::*;
use integration_tests::TestDaemon;
use shm_layout::codec::{decode_response, encode_request};
use shm_layout::{names, Command, CommandResult, PlaneOp, PlaneProp, Request, Response};

/// Where each field sits in iceoryx2 0.10's `#[repr(C)]` request header (node id, client id,
/// channel id, request id, element count, payload offset); the tests read the fields back
/// through iceoryx2's accessors where it has them, so a moved field fails loudly.
const NODE_ID: usize = 0;
const CLIENT_ID: usize = 16;
const CHANNEL_ID: usize = 32;
const NUMBER_OF_ELEMENTS: usize = 48;

type Header = iceoryx2::service::header::request_response::RequestHeader;

/// A client process that speaks the wire protocol through its own raw ports.
struct Hostile {
    _node: Node<ipc::Service>,
    port: RequestPort<ipc::Service, [u8], u128, [u8], ()>,
    wake: Notifier<ipc::Service>,
    replies: Listener<ipc::Service>,
}

impl Hostile {
    fn open(domain: &str) -> Hostile {
        let (node, control) = open_control(domain);
        let port = control
            .client_builder()
            .initial_max_slice_len(4096)
            .allocation_strategy(AllocationStrategy::PowerOfTwo)
            .create()
            .unwrap();
        let wake = node
            .service_builder(&names::control_wake())
            .event()
            .open()
            .unwrap()
            .notifier_builder()
            .create()
            .unwrap();
        let replies = node
            .service_builder(&names::client_wake(node.id().value()))
            .event()
            .create()
            .unwrap()
            .listener_builder()
            .create()
            .unwrap();
        Hostile {
            _node: node,
            port,
            wake,
            replies,
        }
    }

    /// Sends `commands`, letting `tamper` write into the header (in this process's own
    /// shared memory) first.
    fn send(
        &self,
        commands: Vec<Command>,
        tamper: impl FnOnce(*mut u8),
    ) -> PendingResponse<ipc::Service, [u8], u128, [u8], ()> {
        let bytes = encode_request(&Request { commands });
        let request = self
            .port
            .loan_slice_uninit(bytes.len())
            .unwrap()
            .write_from_slice(&bytes);
        assert_eq!(
            std::mem::size_of::<Header>(),
            64,
            "iceoryx2's header changed"
        );
        let header = request.header() as *const Header as *mut u8;
        tamper(header);
        let pending = request.send().unwrap();
        self.wake.notify().unwrap();
        pending
    }

    /// The results of `pending`, or `None` when no reply came within `timeout`.
    fn reply(
        &self,
        pending: &PendingResponse<ipc::Service, [u8], u128, [u8], ()>,
        timeout: Duration,
    ) -> Option<Vec<CommandResult>> {
        let deadline = Instant::now() + timeout;
        while Instant::now() < deadline {
            if let Some(response) = pending.receive().unwrap() {
                return match decode_response(response.payload()).unwrap() {
                    Response::Results(r) => Some(r),
                    Response::Rejected(e) => Some(vec![Err(e)]),
                };
            }
            let _ = self.replies.timed_wait(|_| {}, Duration::from_millis(20));
        }
        None
    }

    fn call(&self, commands: Vec<Command>, tamper: impl FnOnce(*mut u8)) -> Vec<CommandResult> {
        let pending = self.send(commands, tamper);
        self.reply(&pending, Duration::from_secs(5))
            .expect("the daemon answers")
    }

    fn hello(&self) {
        let r = self.call(
            vec![Command::Hello {
                crate_version: shm_layout::CRATE_VERSION.to_string(),
                pid: std::process::id(),
            }],
            |_| {},
        );
        assert!(r[0].is_ok(), "{r:?}");
    }
}

/// Writes `value` at byte `offset` of the header.
fn poke<T: Copy>(header: *mut u8, offset: usize, value: T) {
    // SAFETY: the header is 64 bytes of our own, writable shared memory (asserted in `send`);
    // writing it is exactly what a hostile process can do to its mapping.
    unsafe { std::ptr::write_unaligned(header.add(offset).cast::<T>(), value) };
}

fn peek<T: Copy>(header: *mut u8, offset: usize) -> T {
    // SAFETY: as in `poke`.
    unsafe { std::ptr::read_unaligned(header.add(offset).cast::<T>()) }
}

/// The daemon still runs, an honest new client gets a plane and a body falls in it, and
/// `survivor` (connected before the attack) still owns and steps its plane.
fn serves_on(daemon: &mut TestDaemon, survivor: &client_sdk::Plane) {
    assert!(daemon.is_running(), "the daemon died");
    falls_one_step(&daemon.client());
    survivor.step(0.1).unwrap();
}

/// A ball dropped in a new plane of `client` falls as the integrator says.
fn falls_one_step(client: &client_sdk::Client) {
    let plane = client
        .create_plane(&PlaneOptions {
            gravity: Some([0.0, -9.81, 0.0]),
            linear_damping: Some(0.0),
            ..PlaneOptions::manual()
        })
        .unwrap();
    let ball = plane
        .add(
            Shape::Sphere { radius: 0.5 },
            Pose::at([0.0, 10.0, 0.0]),
            &[],
        )
        .unwrap();
    plane.step(0.1).unwrap();
    // Semi-implicit Euler from rest in k equal sub-steps of h/k drops g h^2 (k+1)/(2k):
    // between g h^2 / 2 (k -> inf) and g h^2 (k = 1), whatever the plane's sub-stepping;
    // f32 rounding of a 10-unit coordinate is ~1e-6.
    let (g, h) = (9.81f32, 0.1f32);
    let drop = 10.0 - ball.position().unwrap()[1];
    assert!(
        drop >= 0.5 * g * h * h - 1e-4 && drop <= g * h * h + 1e-4,
        "drop = {drop}"
    );
}

fn step_request(plane: u32) -> Vec<Command> {
    vec![Command::plane(plane, PlaneOp::Step { dt: 0.1 })]
}

#[test]
fn channel_ids_out_of_range_are_dropped() {
    let mut daemon = TestDaemon::start("hostile-chan");
    let victim = daemon.client();
    let survivor = victim.create_plane(&PlaneOptions::manual()).unwrap();
    let hostile = Hostile::open(&daemon.domain);
    hostile.hello();
    for channel in [4usize, 1_000_000, usize::MAX] {
        let pending = hostile.send(step_request(survivor.id()), |h| {
            poke(h, CHANNEL_ID, channel);
            assert_eq!(peek::<usize>(h, CHANNEL_ID), channel);
        });
        // Refused without an answer: the reply would need the forged channel.
        assert!(hostile
            .reply(&pending, Duration::from_millis(300))
            .is_none());
        serves_on(&mut daemon, &survivor);
    }
    // The hostile client's own untampered requests are still served.
    assert!(hostile.call(vec![Command::ListPlanes], |_| {})[0].is_ok());
}

#[test]
fn element_counts_past_the_chunk_are_refused() {
    let mut daemon = TestDaemon::start("hostile-len");
    let victim = daemon.client();
    let survivor = victim.create_plane(&PlaneOptions::manual()).unwrap();
    let hostile = Hostile::open(&daemon.domain);
    hostile.hello();
    // 1e6 and 16e6 bytes (under the 16 MiB request limit) point far past a 30-byte request;
    // the larger ones are over the limit or overflow `count * size`.
    for count in [1_000_000u64, 16_000_000, 1 << 40, u64::MAX / 2, u64::MAX] {
        let pending = hostile.send(step_request(survivor.id()), |h| {
            poke(h, NUMBER_OF_ELEMENTS, count);
            // SAFETY: `h` is the header `send` holds.
            let read = unsafe { &*(h as *const Header) }.number_of_elements();
            assert_eq!(read, count);
        });
        match hostile.reply(&pending, Duration::from_millis(500)) {
            // Dropped by the transport (the count overflows a slice).
            None => assert!(count > isize::MAX as u64, "count {count} got no reply"),
            Some(r) => {
                let e = r[0].as_ref().unwrap_err();
                assert!(
                    matches!(e.kind, ErrorKind::Quota | ErrorKind::Malformed),
                    "count {count}: {e}"
                );
                assert!(e.message.contains(&count.to_string()), "count {count}: {e}");
            }
        }
        serves_on(&mut daemon, &survivor);
    }
}

#[test]
fn a_forged_client_id_gets_no_reply_and_misroutes_none() {
    let mut daemon = TestDaemon::start("hostile-port");
    let victim = daemon.client();
    let survivor = victim.create_plane(&PlaneOptions::manual()).unwrap();
    let hostile = Hostile::open(&daemon.domain);
    hostile.hello();
    let other = Hostile::open(&daemon.domain);
    other.hello();
    let other_port = other.port.id().value();
    let pending = hostile.send(vec![Command::ListPlanes], |h| {
        poke(h, CLIENT_ID, other_port);
        // SAFETY: `h` is the header `send` holds.
        assert_eq!(
            unsafe { &*(h as *const Header) }.client_id().value(),
            other_port
        );
    });
    assert!(hostile
        .reply(&pending, Duration::from_millis(300))
        .is_none());
    // The port named in the forgery got nothing it did not ask for: its next reply is the
    // answer to its own request.
    let r = other.call(vec![Command::plane(survivor.id(), PlaneOp::Info)], |_| {});
    assert!(r[0].is_ok(), "{r:?}");
    serves_on(&mut daemon, &survivor);
}

#[test]
fn a_forged_node_id_acts_as_the_sender_itself() {
    let mut daemon = TestDaemon::start("hostile-node");
    let victim = daemon.client();
    let plane = victim.create_plane(&PlaneOptions::manual()).unwrap();
    let hostile = Hostile::open(&daemon.domain);
    hostile.hello();
    let victim_node = victim.node_id();
    let as_victim = |h: *mut u8| {
        poke(h, NODE_ID, victim_node);
        // SAFETY: `h` is the header `send` holds.
        assert_eq!(
            unsafe { &*(h as *const Header) }.node_id().value(),
            victim_node
        );
    };
    // Changing and destroying the victim's plane: refused as the hostile client's own.
    for op in [PlaneOp::Set(PlaneProp::TickRate(30.0)), PlaneOp::Destroy] {
        let r = hostile.call(vec![Command::plane(plane.id(), op.clone())], as_victim);
        let e = r[0].as_ref().unwrap_err();
        assert_eq!(e.kind, ErrorKind::NotOwner, "{op:?}: {e}");
    }
    // A forged Goodbye ends the sender's own connection, not the victim's.
    let r = hostile.call(vec![Command::Goodbye], as_victim);
    assert!(r[0].is_ok(), "{r:?}");
    let r = hostile.call(vec![Command::ListPlanes], |_| {});
    assert_eq!(r[0].as_ref().unwrap_err().kind, ErrorKind::NotConnected);
    // A node id the daemon never saw, on an unconnected sender: still that sender.
    let r = hostile.call(vec![Command::ListPlanes], |h| poke(h, NODE_ID, 0x1234u128));
    assert_eq!(r[0].as_ref().unwrap_err().kind, ErrorKind::NotConnected);
    // The victim's plane is untouched and still its own.
    assert_eq!(plane.info().unwrap().tick_rate, 0.0);
    serves_on(&mut daemon, &plane);
}

#[test]
fn a_forgotten_client_says_hello_again() {
    let daemon = TestDaemon::start("hostile-rejoin");
    let client = daemon.client();
    // The client's own Goodbye, sent behind the SDK's back: the daemon forgets it.
    let bye = encode_request(&Request {
        commands: vec![Command::Goodbye],
    });
    client.raw_request(&bye).unwrap();
    // The SDK gets NotConnected, says Hello again and repeats the command.
    falls_one_step(&client);
}

/// A `hoarder` process (see `tests/src/bin/hoarder.rs`) holding slots; killed when dropped.
struct Hoarder(std::process::Child);

impl Hoarder {
    fn start(args: &[&str]) -> Hoarder {
        use std::io::BufRead;
        let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_hoarder"))
            .args(args)
            .stdout(std::process::Stdio::piped())
            .spawn()
            .expect("spawn hoarder");
        let mut line = String::new();
        std::io::BufReader::new(child.stdout.take().unwrap())
            .read_line(&mut line)
            .unwrap();
        assert_eq!(line.trim(), "ready", "the hoarder could not take its slots");
        Hoarder(child)
    }
}

impl Drop for Hoarder {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// How long until `f` succeeds (polled every 20 ms), or `None` after `limit`.
fn time_until<T>(limit: Duration, mut f: impl FnMut() -> Option<T>) -> Option<(T, Duration)> {
    let started = Instant::now();
    while started.elapsed() < limit {
        if let Some(v) = f() {
            return Some((v, started.elapsed()));
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    None
}

#[test]
fn nodes_that_never_say_hello_are_evicted() {
    let mut daemon = TestDaemon::start_with("hostile-nodes", &["--hello-timeout-ms", "3000"], &[]);
    let victim = daemon.client();
    let survivor = victim.create_plane(&PlaneOptions::manual()).unwrap();
    // 126 nodes with the daemon's node and the victim's fill the control service's 128
    // node places: nobody else can open it.
    let hoarder = Hoarder::start(&["nodes", &daemon.domain, "126"]);
    let (_, waited) = time_until(Duration::from_secs(60), || {
        Client::connect(&daemon.domain).ok()
    })
    .expect("a new client got in within 60 s");
    // Before: never (`ExceedsMaxNumberOfNodes` until the hoarder exits). Now the hoarder's
    // nodes go as it creates them (over --max-nodes-per-process and --max-ports-per-process,
    // or older than --hello-timeout-ms); while the daemon removes them, Hellos can go
    // unanswered and the SDK asks again with new ports every second. Measured here: 8 to 13 s
    // after the hoarder holds all 126 (2 shared cores), 22 s on a machine busy with
    // builds: the bound above is for "at all", not a speed target.
    eprintln!("a new client got in after {waited:?}");
    serves_on(&mut daemon, &survivor);
    drop(hoarder);

    // Few nodes (under the per-process cap) without Hello go after --hello-timeout-ms.
    let _few = Hoarder::start(&["nodes", &daemon.domain, "8"]);
    let started = Instant::now();
    let held = || control_ports(&daemon.domain);
    // The victim's port and the hoarder's 8: not evicted at once. A port of the client that
    // got in above, or of the big hoarder's last nodes, can still be listed while iceoryx2
    // removes it (seen once as 10), so at least 9.
    let at_start = held();
    assert!(
        at_start >= 9,
        "held {at_start} ports, expected the victim's and the hoarder's 8"
    );
    // The victim's port stays; the hoarder's 8 must go. One port besides the victim's was
    // seen still listed after 30 s in 2 of 6 full runs on a loaded machine, and two in 1 of
    // 4 runs of this file beside two CPU hogs (the daemon of before the idle loop's alarm as
    // well as after; cause not found: most likely stragglers of the first phase, see
    // above), so two are tolerated: a daemon that evicts none of the 8 (9 ports), or only
    // half, still fails here.
    let mut last = at_start;
    time_until(Duration::from_secs(30), || {
        last = held();
        (last <= 3).then_some(())
    })
    .unwrap_or_else(|| panic!("the nodes without Hello were evicted: {last} ports still held"));
    // Held when ready (above), gone after the timeout (3 s from when the daemon first saw
    // them, no later than `ready`) plus one guard period (500 ms) and the polling: 3.5 s on
    // a quiet machine, over 10 s twice in a full suite run beside an hour-long soak on 2
    // cores. The bound is for "at all" (a daemon that never evicts fails it); "not at once"
    // is checked above.
    let total = started.elapsed();
    assert!(total < Duration::from_secs(30), "evicted after {total:?}");
    serves_on(&mut daemon, &survivor);
}

#[test]
fn a_client_that_says_goodbye_may_say_hello_again_on_its_node() {
    let mut daemon = TestDaemon::start_with("hello-again", &["--hello-timeout-ms", "2000"], &[]);
    let victim = daemon.client();
    let survivor = victim.create_plane(&PlaneOptions::manual()).unwrap();
    let hostile = Hostile::open(&daemon.domain);
    hostile.hello();
    // Its node is now older than the Hello timeout.
    std::thread::sleep(Duration::from_millis(2500));
    let goodbye = hostile.call(vec![Command::Goodbye], |_| {});
    assert!(goodbye[0].is_ok(), "{goodbye:?}");
    // A node that joins the domain makes the resource guard list the nodes at its next
    // look (at most a period, 500 ms, later).
    std::thread::sleep(Duration::from_millis(700));
    let newcomer = open_control(&daemon.domain);
    std::thread::sleep(Duration::from_millis(800));
    // 1.5 s after its Goodbye, within the timeout: served. (When the Hello clock ran from
    // the node's first sighting, the guard had cut the node off by now and this Hello
    // went unanswered.)
    hostile.hello();
    assert!(hostile.call(vec![Command::ListPlanes], |_| {})[0].is_ok());
    drop(newcomer);
    serves_on(&mut daemon, &survivor);

    // Without a Hello for the whole timeout after a Goodbye, its port goes.
    let held = control_ports(&daemon.domain);
    let goodbye = hostile.call(vec![Command::Goodbye], |_| {});
    assert!(goodbye[0].is_ok(), "{goodbye:?}");
    let left = Instant::now();
    let mut last = held;
    time_until(Duration::from_secs(20), || {
        last = control_ports(&daemon.domain);
        (last < held).then_some(())
    })
    .unwrap_or_else(|| panic!("the silent node was not evicted: {last} of {held} ports held"));
    // Its clock ran from the Goodbye (2 s), not from its first sighting (long past); the
    // daemon notes the Goodbye as it answers it, before `left`.
    assert!(
        left.elapsed() >= Duration::from_millis(1900),
        "evicted {:?} after its Goodbye, before the Hello timeout",
        left.elapsed()
    );
    serves_on(&mut daemon, &survivor);
}

/// The daemon's control service, as a process of the domain opens it.
type ControlService = iceoryx2::service::port_factory::request_response::PortFactory<
    ipc::Service,
    [u8],
    u128,
    [u8],
    (),
>;

/// A node of this process in `domain`, and the daemon's control service opened from it.
fn open_control(domain: &str) -> (Node<ipc::Service>, ControlService) {
    let config = names::config(domain).unwrap();
    let node = NodeBuilder::new()
        .config(&config)
        .signal_handling_mode(SignalHandlingMode::Disabled)
        .create::<ipc::Service>()
        .unwrap();
    let control = node
        .service_builder(&names::control())
        .request_response::<[u8], [u8]>()
        .request_user_header::<u128>()
        .open()
        .unwrap();
    (node, control)
}

/// The clients (ports) of the control service of `domain`, as the daemon's guard sees them.
fn control_ports(domain: &str) -> usize {
    let (_node, control) = open_control(domain);
    control.dynamic_config().number_of_clients()
}

#[test]
fn an_idle_daemon_sleeps_until_a_process_joins_its_domain() {
    let daemon = TestDaemon::start_with("idle-guard", &["--hello-timeout-ms", "1000"], &[]);
    // The readiness check's client goes; the guard looks once more, then has nothing to cap.
    std::thread::sleep(Duration::from_secs(2));
    let before = integration_tests::wake_ups(daemon.pid());
    std::thread::sleep(Duration::from_secs(4));
    let woke = integration_tests::wake_ups(daemon.pid()) - before;
    // A resource guard looking every 500 ms wakes 8 times in 4 s; with no other process in
    // the domain there is nothing to look at (the loop and the heartbeat sleep too). Up to
    // 3 allows a last look delayed by a loaded machine.
    assert!(
        woke <= 3,
        "a daemon without clients woke {woke} times in 4 s"
    );

    // Sleeping, it still sees a process that joins: nodes that never say Hello are evicted
    // after --hello-timeout-ms (1 s) and a guard period, as when it was awake.
    let _few = Hoarder::start(&["nodes", &daemon.domain, "4"]);
    let started = Instant::now();
    let mut last = control_ports(&daemon.domain);
    assert!(last >= 4, "the hoarder's 4 ports are listed: {last}");
    time_until(Duration::from_secs(20), || {
        last = control_ports(&daemon.domain);
        (last == 0).then_some(())
    })
    .unwrap_or_else(|| panic!("the nodes without Hello were not evicted: {last} ports held"));
    assert!(
        started.elapsed() >= Duration::from_millis(900),
        "evicted before the Hello timeout: {:?}",
        started.elapsed()
    );
}

#[test]
fn a_daemon_whose_clients_sit_idle_sleeps_and_still_releases_a_killed_one_at_once() {
    use std::io::BufRead;
    let daemon = TestDaemon::start("idle-clients");
    // Killed when the test ends, passing or not (a holder left running keeps the test's
    // output open).
    let mut holder = Hoarder(
        std::process::Command::new(env!("CARGO_BIN_EXE_test-client"))
            .args(["hold", &daemon.domain])
            .stdout(std::process::Stdio::piped())
            .spawn()
            .unwrap(),
    );
    let mut line = String::new();
    std::io::BufReader::new(holder.0.stdout.take().unwrap())
        .read_line(&mut line)
        .unwrap();
    let plane_id: u32 = line.trim().strip_prefix("plane=").unwrap().parse().unwrap();
    // The connection's requests done, the loop looks once more and then has nothing to do.
    std::thread::sleep(Duration::from_secs(2));
    let before = integration_tests::wake_ups(daemon.pid());
    std::thread::sleep(Duration::from_secs(4));
    let woke = integration_tests::wake_ups(daemon.pid()) - before;
    // With a client holding an idle manual plane, a loop looking every 500 ms, a guard
    // looking every 500 ms and a heartbeat of its own every 200 ms woke 36 times in 4 s, and
    // 15-16 with the heartbeat on the guard's looks. Now the guard's 8 looks (which beat) and
    // at most a quiet look of the loop; up to 12 allows a loaded machine's delays.
    assert!(
        woke <= 12,
        "a daemon with one idle client woke {woke} times in 4 s"
    );

    // Asleep, it still hears at once of a client that dies (its process's pidfd rings the
    // loop's alarm): the plane is released well before the loop's next quiet look (5 s).
    let client = Client::connect(&daemon.domain).unwrap();
    let theirs = client.attach_plane(plane_id).unwrap();
    assert_eq!(theirs.info().unwrap().object_count, 1);
    std::thread::sleep(Duration::from_millis(1500));
    holder.0.kill().unwrap();
    holder.0.wait().unwrap();
    let killed = Instant::now();
    time_until(Duration::from_secs(10), || match theirs.info() {
        Err(client_sdk::Error::Command(e)) if e.kind == ErrorKind::UnknownPlane => Some(()),
        _ => None,
    })
    .unwrap_or_else(|| panic!("plane {plane_id} of the killed client was not released"));
    let took = killed.elapsed();
    assert!(
        took < Duration::from_secs(2),
        "the killed client's plane was released after {took:?}"
    );
}

#[test]
fn one_process_cannot_hold_a_planes_reader_slots() {
    let mut daemon = TestDaemon::start("hostile-readers");
    let victim = daemon.client();
    let plane = victim.create_plane(&PlaneOptions::manual()).unwrap();
    // The victim's reader and 63 of the hoarder's fill the plane's 64 reader places.
    let _hoarder = Hoarder::start(&["readers", &daemon.domain, &plane.id().to_string(), "63"]);
    let reader = daemon.client();
    let (attached, waited) = time_until(Duration::from_secs(5), || {
        reader.attach_plane(plane.id()).ok()
    })
    .expect("another client could attach");
    // Over --max-ports-per-process (16): evicted at the next housekeeping.
    assert!(waited < Duration::from_millis(1500), "waited {waited:?}");
    plane.step(0.1).unwrap();
    assert_eq!(attached.info().unwrap().tick, 1);
    serves_on(&mut daemon, &plane);
}

/// A daemon and a client process holding a plane, both SIGKILLed: what they leave.
fn killed_deployment(tag: &str) -> (String, usize) {
    use std::io::BufRead;
    let mut daemon = TestDaemon::start(tag);
    let domain = daemon.domain.clone();
    let mut holder = std::process::Command::new(env!("CARGO_BIN_EXE_test-client"))
        .args(["hold", &domain])
        .stdout(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let mut line = String::new();
    std::io::BufReader::new(holder.stdout.take().unwrap())
        .read_line(&mut line)
        .unwrap();
    assert!(line.starts_with("plane="), "{line}");
    daemon.kill9();
    holder.kill().unwrap();
    holder.wait().unwrap();
    // The daemon's Drop would clean up: keep the domain as the kill left it.
    std::mem::forget(daemon);
    let left = integration_tests::domain_files(&domain).len();
    (domain, left)
}

/// The files of `domain` other than iceoryx2's node counter (`*.global_mgmt`, one per domain,
/// removed by the last process of a domain that exits cleanly, or by `--cleanup`).
fn files_but_the_counter(domain: &str) -> Vec<std::path::PathBuf> {
    integration_tests::domain_files(domain)
        .into_iter()
        .filter(|p| !p.to_string_lossy().ends_with(".global_mgmt"))
        .collect()
}

#[test]
fn the_next_client_removes_a_killed_daemons_files() {
    let (domain, left) = killed_deployment("leftover-client");
    // Measured before: 22 segments in /dev/shm and 47 files under the iceoryx2 root.
    assert!(left > 20, "the kill left {left} files");
    match Client::connect(&domain) {
        Err(client_sdk::Error::NoDaemon { detail, .. }) => {
            assert!(detail.contains("dead processes"), "{detail}")
        }
        other => panic!("expected NoDaemon, got {:?}", other.map(|_| ())),
    }
    let rest = files_but_the_counter(&domain);
    assert!(rest.is_empty(), "left: {rest:?}");
    // The domain works again at once.
    let mut daemon = TestDaemon::start_in(&domain);
    falls_one_step(&daemon.client());
    assert!(daemon.is_running());
}

#[test]
fn cleanup_flag_removes_a_killed_daemons_files() {
    let (domain, left) = killed_deployment("leftover-flag");
    assert!(left > 20, "the kill left {left} files");
    let out = std::process::Command::new(client_sdk::daemon_executable())
        .args(["--cleanup", "--domain", &domain])
        .env("PHYSICS_LOG", "warn")
        .output()
        .unwrap();
    assert!(out.status.success());
    let said = String::from_utf8_lossy(&out.stdout);
    assert!(
        said.contains(&format!("removed {left} files")) && said.contains("0 left"),
        "{said}"
    );
    assert!(integration_tests::domain_files(&domain).is_empty());
    let daemon = TestDaemon::start_in(&domain);
    falls_one_step(&daemon.client());
}

#[test]
fn a_killed_hoarders_files_go_within_a_period() {
    let daemon = TestDaemon::start_with(
        "leftover-nodes",
        // Caps out of the way: the files must go because the process died.
        &[
            "--hello-timeout-ms",
            "600000",
            "--max-nodes-per-process",
            "1000",
            "--max-ports-per-process",
            "1000",
        ],
        &[],
    );
    // The daemon's resource guard joins the control service in its first period (500 ms).
    std::thread::sleep(Duration::from_millis(700));
    let before = integration_tests::domain_files(&daemon.domain);
    let baseline = before.len();
    let mut hoarder = Hoarder::start(&["nodes", &daemon.domain, "40"]);
    let held = integration_tests::domain_files(&daemon.domain).len();
    assert!(held > baseline + 100, "{baseline} → {held} files");
    let _ = hoarder.0.kill();
    let _ = hoarder.0.wait();
    let started = Instant::now();
    time_until(Duration::from_secs(5), || {
        (integration_tests::domain_files(&daemon.domain).len() <= baseline).then_some(())
    })
    .unwrap_or_else(|| {
        panic!(
            "the dead hoarder's files were not removed: {baseline} before, {held} held, now \
             also {:?}",
            integration_tests::domain_files(&daemon.domain)
                .into_iter()
                .filter(|f| !before.contains(f))
                .collect::<Vec<_>>()
        )
    });
    // One guard period (500 ms) plus the removal of 40 nodes' files.
    let took = started.elapsed();
    assert!(took < Duration::from_millis(2500), "took {took:?}");
    falls_one_step(&daemon.client());
}

/// A fresh directory under /tmp for one test, removed when dropped.
struct TempDir(std::path::PathBuf);

impl TempDir {
    fn new(tag: &str) -> TempDir {
        let dir = std::env::temp_dir().join(integration_tests::unique_domain(tag));
        std::fs::create_dir(&dir).unwrap();
        TempDir(dir)
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

fn as_root() {
    // SAFETY: geteuid(2) has no side effects.
    assert_eq!(
        unsafe { libc::geteuid() },
        0,
        "making files of another user needs root"
    );
}

#[test]
fn a_squatted_root_directory_is_reported_with_its_owner_and_a_way_out() {
    as_root();
    let dir = TempDir::new("squat-root");
    // Another user (nobody) made the directory the daemon would use first.
    let root = dir.0.join("iceoryx2");
    std::fs::create_dir(&root).unwrap();
    std::os::unix::fs::chown(&root, Some(65534), Some(65534)).unwrap();
    let domain = integration_tests::unique_domain("squat-root");
    let mut daemon = std::process::Command::new(client_sdk::daemon_executable())
        .args(["--domain", &domain])
        .env(names::RUNTIME_DIR_ENV, &dir.0)
        .env("PHYSICS_LOG", "error")
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let exited = time_until(Duration::from_secs(10), || daemon.try_wait().unwrap());
    if exited.is_none() {
        let _ = daemon.kill();
    }
    let out = daemon.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        exited.is_some(),
        "the daemon started in a squatted directory"
    );
    assert!(!out.status.success(), "{stderr}");
    for part in [
        root.to_string_lossy().as_ref(),
        "nobody, uid 65534",
        "the root directory",
        names::RUNTIME_DIR_ENV,
    ] {
        assert!(stderr.contains(part), "missing {part:?} in: {stderr}");
    }
}

#[test]
fn the_root_directory_is_the_users_runtime_directory() {
    use std::os::unix::fs::PermissionsExt;
    let dir = TempDir::new("xdg");
    std::fs::set_permissions(&dir.0, std::fs::Permissions::from_mode(0o700)).unwrap();
    let domain = integration_tests::unique_domain("xdg");
    let with_env = |cmd: &mut std::process::Command| {
        cmd.env_remove(names::RUNTIME_DIR_ENV)
            .env("XDG_RUNTIME_DIR", &dir.0)
            .env("PHYSICS_LOG", "warn");
    };
    let mut daemon = std::process::Command::new(client_sdk::daemon_executable());
    daemon.args(["--domain", &domain]);
    with_env(&mut daemon);
    let mut daemon = daemon.spawn().unwrap();
    // A client with the same environment finds it and gets a plane.
    let got = time_until(Duration::from_secs(10), || {
        let mut client = std::process::Command::new(env!("CARGO_BIN_EXE_test-client"));
        client.args(["hold-once", &domain]);
        with_env(&mut client);
        let out = client.output().unwrap();
        out.status
            .success()
            .then(|| String::from_utf8_lossy(&out.stdout).to_string())
    });
    // SAFETY: kill(2) on our own child.
    unsafe { libc::kill(daemon.id() as i32, libc::SIGINT) };
    let _ = daemon.wait();
    let (said, _) = got.expect("a client of the same user reached the daemon");
    assert!(said.starts_with("plane="), "{said}");
    // Its node records went under $XDG_RUNTIME_DIR/iceoryx2 (mode 0700, the user's own), and
    // none into the /tmp default this test process uses.
    let root = dir.0.join("iceoryx2");
    assert!(root.is_dir(), "no {}", root.display());
    assert!(integration_tests::domain_files(&domain)
        .iter()
        .all(|f| f.starts_with("/dev/shm")));
}

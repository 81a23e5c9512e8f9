//! Snapshots in pieces through a real daemon at its default limits (8 MiB a reply, 16 MiB a
//! request, 64 MiB of state bytes a client): a 20,000-body plane's snapshot (over 8 MiB)
//! comes down in pieces, restores and starts a new plane in pieces, and both continue bit
//! for bit. Forged pieces (wrong offset, wrong total, another connection's transfer, an
//! unfinished upload) are refused by name; what a transfer holds counts against the state
//! quota and goes with the connection that held it.

use client_sdk::{Client, Object, Plane, PlaneOptions};
use integration_tests::TestDaemon;
use physics_scenes::pile;
use shm_layout::codec::{decode_response, encode_request};
use shm_layout::{Command, PlaneOp, Reply, Request, Response, TransferOp, TransferReply};

const DT: f32 = 1.0 / 60.0;
const BODIES: usize = 20_000;
/// Ticks replayed after the snapshot.
const AFTER: u32 = 6;

/// Steps `AFTER` ticks, waking and pushing one cube at the third: each tick's hash.
fn replay(plane: &Plane, pushed: &Object) -> Vec<u64> {
    (1..=AFTER)
        .map(|t| {
            if t == 3 {
                pushed.set_velocity([3.0, 4.0, 0.0]).unwrap();
            }
            plane.step(DT).unwrap();
            plane.state_hash().unwrap()
        })
        .collect()
}

#[test]
fn a_20000_body_plane_snapshots_restores_and_starts_anew_in_pieces_bit_for_bit() {
    let daemon = TestDaemon::start("pieces");
    let client = daemon.client();
    let plane = client.create_plane(&PlaneOptions::manual()).unwrap();
    let objects = pile(&mut &plane, BODIES).unwrap();
    for _ in 0..5 {
        plane.step(DT).unwrap();
    }
    let snapshot = plane.take_snapshot().unwrap();
    // Larger than one reply at the default --max-reply-bytes: without pieces it is refused.
    assert!(
        snapshot.len() > 8 << 20,
        "{} bytes: the test needs a snapshot past one reply",
        snapshot.len()
    );
    println!(
        "{BODIES} bodies: {:.1} MiB",
        snapshot.len() as f64 / (1u64 << 20) as f64
    );
    assert_eq!(snapshot.state_hash(), plane.state_hash().unwrap());
    let pushed = &objects[BODIES / 2];
    let reference = replay(&plane, pushed);
    assert!(reference.windows(2).all(|w| w[0] != w[1]), "the pile moves");

    // Restore (up in pieces): the same handles, the same hashes.
    assert_eq!(plane.restore(&snapshot).unwrap(), 5);
    assert_eq!(plane.state_hash().unwrap(), snapshot.state_hash());
    assert_eq!(replay(&plane, pushed), reference, "replay after Restore");

    // A new plane from it, for another connection: the same again.
    let other = daemon.client();
    let copy = other.plane_from_snapshot(&snapshot, &[]).unwrap();
    assert_eq!(copy.state_hash().unwrap(), snapshot.state_hash());
    let pushed = Object::from_handle(&copy, pushed.handle());
    assert_eq!(
        replay(&copy, &pushed),
        reference,
        "replay after FromSnapshot"
    );

    // And it comes down again, byte for byte the snapshot of that state.
    copy.restore(&snapshot).unwrap();
    assert_eq!(copy.take_snapshot().unwrap().bytes(), snapshot.bytes());
}

/// Sends `commands` as one request, bypassing the SDK: one result each.
fn raw(client: &Client, commands: Vec<Command>) -> Vec<Result<Reply, String>> {
    let bytes = client
        .raw_request(&encode_request(&Request { commands }))
        .unwrap();
    match decode_response(&bytes).unwrap() {
        Response::Results(r) => r.into_iter().map(|r| r.map_err(|e| e.message)).collect(),
        other => panic!("{other:?}"),
    }
}

fn one(client: &Client, command: Command) -> Result<Reply, String> {
    raw(client, vec![command]).pop().unwrap()
}

fn open(client: &Client, total: u64) -> Result<u32, String> {
    match one(client, Command::Transfer(TransferOp::Open { total }))? {
        Reply::Transfer(TransferReply::Opened { transfer, piece }) => {
            // A piece fits the default 16 MiB request.
            assert!(piece > 0 && piece < 16 << 20, "piece {piece}");
            Ok(transfer)
        }
        other => panic!("{other:?}"),
    }
}

fn put(client: &Client, transfer: u32, total: u64, offset: u64, n: usize) -> Result<Reply, String> {
    one(
        client,
        Command::Transfer(TransferOp::Put {
            transfer,
            total,
            offset,
            bytes: vec![7; n],
        }),
    )
}

#[test]
fn forged_pieces_are_refused_by_name_and_transfers_go_with_their_connection() {
    let daemon = TestDaemon::start("pieces-forged");
    let a = daemon.client();
    let plane = a.create_plane(&PlaneOptions::manual()).unwrap();
    let t = open(&a, 100).unwrap();
    put(&a, t, 100, 0, 10).unwrap();
    let e = put(&a, t, 100, 5, 10).unwrap_err();
    assert!(e.contains("offset 5") && e.contains("received 10"), "{e}");
    let e = put(&a, t, 99, 10, 10).unwrap_err();
    assert!(e.contains("total 99") && e.contains("total 100"), "{e}");
    let e = put(&a, t, 100, 10, 91).unwrap_err();
    assert!(e.contains("passes the total 100"), "{e}");
    // Another connection cannot add to it, read it or restore from it.
    let b = daemon.client();
    let theirs = b.create_plane(&PlaneOptions::manual()).unwrap();
    let e = put(&b, t, 100, 10, 10).unwrap_err();
    assert!(
        e.contains(&format!("transfer {t} is not open on this connection")),
        "{e}"
    );
    let e = one(&b, restore_of(&theirs, t)).unwrap_err();
    assert!(e.contains("not open on this connection"), "{e}");
    // An unfinished upload does not restore (and is dropped).
    let e = one(&a, restore_of(&plane, t)).unwrap_err();
    assert!(e.contains("holds 10 of its 100 bytes"), "{e}");
    let e = put(&a, t, 100, 10, 10).unwrap_err();
    assert!(e.contains("not open"), "{e}");
    // Bytes that are no snapshot are refused by the snapshot checks, as a Restore's.
    let t = open(&a, 64).unwrap();
    put(&a, t, 64, 0, 64).unwrap();
    let e = one(&a, restore_of(&plane, t)).unwrap_err();
    assert!(e.contains("not a plane snapshot"), "{e}");

    // What uploads hold counts against the process's 64 MiB of state bytes...
    let big = 40 << 20;
    let held = open(&a, big).unwrap();
    put(&a, held, big, 0, 1 << 20).unwrap();
    let e = open(&b, big).unwrap_err();
    assert!(e.contains("max-state-bytes-per-client"), "{e}");
    // ...until the connection holding it goes, half sent: nothing of it stays.
    drop((plane, a));
    let c = daemon.client();
    let again = open(&c, big).unwrap();
    assert_ne!(again, held);
    // The daemon serves on.
    theirs.step(DT).unwrap();
}

fn restore_of(plane: &Plane, transfer: u32) -> Command {
    Command::plane(
        plane.id(),
        PlaneOp::RestoreUploaded {
            transfer,
            overrides: vec![],
        },
    )
}

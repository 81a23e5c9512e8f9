//! The zero-copy connection under every reply, plane and event stream (iceoryx2-cal,
//! patched: `vendor/iceoryx2-cal-0.10.0/PATCHED.md`). A connection keeps one flag per chunk
//! for every segment its sender's data may grow to (255) and every channel; the daemon's
//! reply connections hold 12.5 million. Creating one wrote them all (31 MB backed per
//! client) and closing one swapped them all back (~130 ms of the request loop per client
//! that left). The first test builds such a connection directly and checks that neither
//! touches the flags nobody used, and that a closed receiver's chunks still all come back;
//! the second checks, through a real daemon, that clients leaving no longer stall another
//! client's requests. (A file of its own: its timing is not shared with other tests' load.)

use std::time::{Duration, Instant};

use client_sdk::{PlaneOptions, Pose, Shape};
use iceoryx2::prelude::SemanticString;
use iceoryx2_cal::named_concept::NamedConceptBuilder;
use iceoryx2_cal::shm_allocator::pointer_offset::SegmentId;
use iceoryx2_cal::zero_copy_connection::posix_shared_memory::Connection;
use iceoryx2_cal::zero_copy_connection::{
    ChannelId, FileName, PointerOffset, ZeroCopyConnection, ZeroCopyConnectionBuilder,
    ZeroCopyReceiver, ZeroCopySender,
};
use integration_tests::TestDaemon;

/// The daemon's reply connection: 512 client ports × 8 × 3 chunks a segment, 255 segments,
/// 4 request slots.
const CHUNKS: usize = 12_288;
const SEGMENTS: u8 = 255;
const CHANNELS: usize = 4;
const CHUNK: usize = 64;

fn builder(name: &FileName) -> <Connection as ZeroCopyConnection>::Builder {
    <Connection as ZeroCopyConnection>::Builder::new(name)
        .number_of_chunks_per_segment(CHUNKS)
        .max_supported_shared_memory_segments(SEGMENTS)
        .number_of_channels(CHANNELS)
        .receiver_max_borrowed_chunks_per_channel(4)
        .buffer_size(4)
}

/// Bytes of the files under /dev/shm whose name holds `tag`: (size, backed).
fn files(tag: &str) -> (u64, u64) {
    use std::os::unix::fs::MetadataExt;
    std::fs::read_dir("/dev/shm")
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().contains(tag))
        .filter_map(|e| e.metadata().ok())
        .fold((0, 0), |(s, b), m| (s + m.size(), b + m.blocks() * 512))
}

#[test]
fn a_connection_backs_only_what_it_uses_and_a_closed_receivers_chunks_all_come_back() {
    let tag = format!("connmem{}", std::process::id());
    let name = FileName::new(tag.as_bytes()).unwrap();
    let sender = builder(&name).create_sender().unwrap();
    let receiver = builder(&name).create_receiver().unwrap();
    let (size, backed) = files(&tag);
    eprintln!("a new connection: {size} bytes, {backed} backed");
    assert!(
        size > 12_000_000,
        "the connection is as large as sized: {size} bytes"
    );
    // Before: every flag written at creation (size ≈ backed).
    assert!(
        backed < 1 << 20,
        "a new connection backed {backed} of its {size} bytes"
    );

    // Chunks in three (segment, channel) lists, one of them returned by the receiver.
    let sent = [
        (0u8, 0usize, 3usize),
        (7, 2, 100),
        (254, 3, CHUNKS - 1),
        (7, 2, 5),
    ];
    let mut held = Vec::new();
    for &(segment, channel, index) in &sent {
        let offset =
            PointerOffset::from_offset_and_segment_id(index * CHUNK, SegmentId::new(segment));
        assert!(sender
            .try_send(offset, CHUNK, ChannelId::new(channel))
            .unwrap()
            .is_none());
        let got = receiver
            .receive(ChannelId::new(channel))
            .unwrap()
            .expect("the chunk arrives");
        assert_eq!(got, offset);
        held.push((channel, got));
    }
    // The receiver gives back the last one; the sender reclaims it.
    let (channel, back) = held.pop().unwrap();
    receiver.release(back, ChannelId::new(channel)).unwrap();
    assert_eq!(sender.reclaim(ChannelId::new(channel)).unwrap(), Some(back));

    // The receiver goes; the sender takes back every chunk it still held.
    drop(receiver);
    let mut swept = Vec::new();
    // SAFETY: the receiver is gone, so no chunk of the connection is in use.
    unsafe { sender.acquire_used_offsets(|o| swept.push(o)) };
    let mut expected: Vec<_> = held.iter().map(|(_, o)| *o).collect();
    expected.sort_by_key(|o| (o.segment_id().value(), o.offset()));
    swept.sort_by_key(|o| (o.segment_id().value(), o.offset()));
    assert_eq!(swept, expected, "every chunk still held, and only those");
    // A second sweep finds nothing.
    let mut again = 0;
    // SAFETY: as above.
    unsafe { sender.acquire_used_offsets(|_| again += 1) };
    assert_eq!(again, 0);
    // Before: the sweep swapped every flag of every list, backing the whole file.
    let (_, backed) = files(&tag);
    assert!(
        backed < 1 << 20,
        "the sweep backed {backed} of the connection's {size} bytes"
    );
    drop(sender);
}

/// Processes that connect, make a plane and leave, one after another, while another client
/// steps. The daemon swept each departed client's reply connection (12.5 million flags) on
/// the request loop: the other client's Step waited 266–268 ms (release) behind five of
/// them. Now only the flags replies went to are swept.
#[test]
fn clients_that_come_and_go_do_not_stall_another_clients_step() {
    let daemon = TestDaemon::start("come-and-go");
    let victim = daemon.client();
    let mine = victim.create_plane(&PlaneOptions::manual()).unwrap();
    mine.add(Shape::Cube { size: [1.0; 3] }, Pose::IDENTITY, &[])
        .unwrap();
    let step = || {
        let t = Instant::now();
        mine.step(1.0 / 60.0).unwrap();
        t.elapsed()
    };
    let alone = (0..100).map(|_| step()).max().unwrap();
    let domain = daemon.domain.clone();
    let visitors = std::thread::spawn(move || {
        for _ in 0..5 {
            let out = std::process::Command::new(env!("CARGO_BIN_EXE_test-client"))
                .args(["hold-once", &domain])
                .output()
                .unwrap();
            assert!(out.status.success(), "{out:?}");
        }
    });
    // Step while they come and go, and until the daemon's next looks (twice a second
    // while busy) have closed what they left.
    let mut worst = Duration::ZERO;
    let mut steps = 0;
    let mut gone = None;
    while gone.is_none_or(|g: Instant| g.elapsed() < Duration::from_millis(1500)) {
        worst = worst.max(step());
        steps += 1;
        if gone.is_none() && visitors.is_finished() {
            gone = Some(Instant::now());
        }
    }
    visitors.join().unwrap();
    eprintln!("worst step {worst:?} of {steps} beside 5 visiting processes (alone {alone:?})");
    assert!(
        worst < Duration::from_millis(120).max(alone * 2),
        "a step waited {worst:?} while 5 processes came and went (alone: {alone:?})"
    );
}

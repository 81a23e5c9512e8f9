//! Encoding and decoding per command: a frame's batch of velocity writes, as a client
//! sends it and the daemon reads it.

use std::hint::black_box;

use gungraun::{library_benchmark, library_benchmark_group};
use shm_layout::codec;
use shm_layout::{Command, Handle, ObjectOp, ObjectProp, Request};

/// `n` SetObject Velocity writes to different objects.
pub fn batch(n: usize) -> Request {
    Request {
        commands: (0..n as u32)
            .map(|i| {
                Command::object(
                    1,
                    Handle {
                        slot: i,
                        generation: 1,
                    },
                    ObjectOp::Set(ObjectProp::Velocity([i as f32, 0.5, -1.0])),
                )
            })
            .collect(),
    }
}

fn encoded(n: usize) -> Vec<u8> {
    codec::encode_request(&batch(n))
}

#[library_benchmark]
#[bench::n10(args = (10), setup = batch)]
#[bench::n1000(args = (1000), setup = batch)]
fn encode(request: Request) -> Vec<u8> {
    black_box(codec::encode_request(black_box(&request)))
}

#[library_benchmark]
#[bench::n10(args = (10), setup = encoded)]
#[bench::n1000(args = (1000), setup = encoded)]
fn decode(bytes: Vec<u8>) -> Request {
    black_box(codec::decode_request(black_box(&bytes)).expect("a valid request"))
}

library_benchmark_group!(name = codec_group; benchmarks = encode, decode);

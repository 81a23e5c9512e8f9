//! The command codec: a frame's worth of writes (1,000 SetObject) and a single one, encoded
//! and decoded, plus the reply.
//!
//! cargo bench -p shm-layout --bench codec

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use shm_layout::codec;
use shm_layout::{Command, Handle, ObjectOp, ObjectProp, Reply, Request, Response};

fn batch(n: usize) -> Request {
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

fn codec(c: &mut Criterion) {
    let mut group = c.benchmark_group("codec");
    for n in [1usize, 1_000] {
        let request = batch(n);
        let bytes = codec::encode_request(&request);
        let response = Response::Results(vec![Ok(Reply::Applied { tick: 7 }); n]);
        let reply = codec::encode_response(&response);
        group.throughput(Throughput::Elements(n as u64));
        group.bench_with_input(BenchmarkId::new("encode_request", n), &request, |b, r| {
            b.iter(|| black_box(codec::encode_request(r)))
        });
        group.bench_with_input(BenchmarkId::new("decode_request", n), &bytes, |b, r| {
            b.iter(|| black_box(codec::decode_request(r).expect("valid")))
        });
        group.bench_with_input(BenchmarkId::new("encode_response", n), &response, |b, r| {
            b.iter(|| black_box(codec::encode_response(r)))
        });
        group.bench_with_input(BenchmarkId::new("decode_response", n), &reply, |b, r| {
            b.iter(|| black_box(codec::decode_response(r).expect("valid")))
        });
    }
    group.finish();
}

criterion_group!(benches, codec);
criterion_main!(benches);

//! Recording per command and per tick: a frame of velocity writes (one per object) and a
//! step on a plane of free bodies wrapped as the daemon wraps every plane
//! (`physics_daemon::record::Recorded`), with a recording running and without. The
//! difference is what recording costs the plane's thread (encoding each op into the tick's
//! batch, framing the tick's entries and handing them to the writer); the writer thread's
//! work is not counted (Callgrind counts the benchmark function's thread).

use std::hint::black_box;

use gungraun::{library_benchmark, library_benchmark_group};
use physics_daemon::backend::Backend;
use physics_daemon::record::{RecordSettings, Recorded};
use physics_scenes::free_bodies;
use shm_layout::{Handle, ObjectOp, ObjectProp, PlaneOp, PlaneProp, RecordOp};

use crate::common::{plane, DT};

/// A wrapped plane of `n` free bodies (recording when `record`) and its handles.
fn frame_setup(n: usize, record: bool) -> (Recorded, Vec<Handle>) {
    let mut inner = plane(&[PlaneProp::Gravity([0.0; 3])]);
    let handles = free_bodies(&mut inner, n).expect("free bodies");
    let mut plane = Recorded::new(Box::new(inner), 1, RecordSettings::default());
    for _ in 0..2 {
        plane.step(DT).expect("step");
    }
    if record {
        let path = std::env::temp_dir().join(format!("physics-bench-record-n{n}.physrec"));
        let _ = std::fs::remove_file(&path);
        plane
            .apply(PlaneOp::Record(RecordOp::Start {
                path: path.display().to_string(),
            }))
            .expect("recording starts");
    }
    (plane, handles)
}

fn recording(n: usize) -> (Recorded, Vec<Handle>) {
    frame_setup(n, true)
}

fn not_recording(n: usize) -> (Recorded, Vec<Handle>) {
    frame_setup(n, false)
}

/// One frame: a velocity write on every object, then a step.
fn frame(plane: &mut Recorded, handles: &[Handle]) {
    for (i, &handle) in handles.iter().enumerate() {
        let op = PlaneOp::Object {
            handle,
            op: ObjectOp::Set(ObjectProp::Velocity([i as f32 * 0.01, 0.5, -1.0])),
        };
        black_box(plane.apply(op).expect("applied"));
    }
    black_box(plane.step(DT).expect("stepped"));
}

#[library_benchmark]
#[bench::n10(args = (10), setup = recording)]
#[bench::n100(args = (100), setup = recording)]
fn recorded_frame((mut plane, handles): (Recorded, Vec<Handle>)) -> Recorded {
    frame(&mut plane, &handles);
    plane
}

#[library_benchmark]
#[bench::n10(args = (10), setup = not_recording)]
#[bench::n100(args = (100), setup = not_recording)]
fn unrecorded_frame((mut plane, handles): (Recorded, Vec<Handle>)) -> Recorded {
    frame(&mut plane, &handles);
    plane
}

library_benchmark_group!(name = record_group; benchmarks = recorded_frame, unrecorded_frame);

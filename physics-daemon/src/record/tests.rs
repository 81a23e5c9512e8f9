//! The wrapper in one process: a plane recorded while ops and steps go through it, the file
//! parsed, then replayed into a fresh plane from the start keyframe; every tick's hash
//! must equal the recorded one.

use shm_layout::recording::{Event, KeyframeWhy, Recording};
use shm_layout::{
    Handle, ObjectOp, ObjectProp, PlaneKind, PlaneOp, PlaneProp, Pose, QueryOp, RecordOp, Reply,
    Shape,
};

use super::{RecordSettings, Recorded};
use crate::backend::Backend;

fn plane(settings: RecordSettings) -> Recorded {
    let props = [PlaneProp::TickRate(0.0), PlaneProp::RollbackTicks(4)];
    let inner = crate::kinds::create(PlaneKind::Rapier3d, 1, &props).unwrap();
    Recorded::new(inner, 1, settings)
}

fn add(p: &mut Recorded, shape: Shape, at: [f32; 3], props: Vec<ObjectProp>) -> Handle {
    match p
        .apply(PlaneOp::AddObject {
            shape,
            pose: Pose::at(at),
            props,
        })
        .unwrap()
    {
        Reply::Object { handle, .. } => handle,
        other => panic!("{other:?}"),
    }
}

fn temp(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("record-unit-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join(name);
    let _ = std::fs::remove_file(&p);
    p
}

/// Replays `rec` into a new plane; the ticks whose hashes agree, or the first that differs.
fn replay(rec: &Recording) -> Result<u64, u64> {
    let mut p = plane(RecordSettings::default());
    let mut ticks = 0;
    for e in &rec.events {
        match e {
            // The Restore or Rewind was repeated with its batch: the keyframe must agree.
            Event::Keyframe {
                why: KeyframeWhy::Jump,
                tick,
                state_hash,
                ..
            } => {
                assert_eq!((p.tick(), p.header().state_hash), (*tick, *state_hash));
            }
            Event::Keyframe { why, range, .. } if *why != KeyframeWhy::Periodic => {
                p.apply(PlaneOp::Restore {
                    bytes: rec.snapshot(range).to_vec(),
                    overrides: vec![PlaneProp::TickRate(0.0)],
                })
                .unwrap();
            }
            Event::Keyframe { .. } => {}
            Event::Batch { .. } => {
                for op in rec.ops(e).unwrap() {
                    let _ = p.apply(op);
                }
            }
            Event::Tick {
                tick,
                dt,
                state_hash,
            } => {
                assert!(p.step(*dt).unwrap());
                if p.tick() != *tick || p.header().state_hash != *state_hash {
                    return Err(*tick);
                }
                ticks += 1;
            }
        }
    }
    Ok(ticks)
}

#[test]
fn a_recorded_plane_replays_with_every_hash_equal() {
    let path = temp("a.physrec");
    let settings = RecordSettings {
        keyframe_every: 7,
        ..RecordSettings::default()
    };
    let mut p = plane(settings);
    add(
        &mut p,
        Shape::Cube {
            size: [40.0, 1.0, 40.0],
        },
        [0.0, -0.5, 0.0],
        vec![ObjectProp::Anchored(true)],
    );
    let reply = p
        .apply(PlaneOp::Record(RecordOp::Start {
            path: path.display().to_string(),
        }))
        .unwrap();
    assert!(matches!(reply, Reply::Recording(_)), "{reply:?}");
    let mut balls = Vec::new();
    for t in 0..40u32 {
        if t % 5 == 0 {
            balls.push(add(
                &mut p,
                Shape::Sphere { radius: 0.5 },
                [t as f32 * 0.1, 3.0 + t as f32 * 0.05, 0.0],
                vec![],
            ));
        }
        for (i, h) in balls.iter().enumerate() {
            let v = [0.3 * i as f32, 0.0, -0.2 * t as f32];
            let _ = p.apply(PlaneOp::Object {
                handle: *h,
                op: ObjectOp::Set(ObjectProp::Velocity(v)),
            });
        }
        if t == 20 {
            p.apply(PlaneOp::Set(PlaneProp::Gravity([0.0, -20.0, 3.0])))
                .unwrap();
            p.apply(PlaneOp::Rewind(2)).unwrap();
        }
        if t == 30 {
            p.apply(PlaneOp::Object {
                handle: balls[0],
                op: ObjectOp::Destroy,
            })
            .unwrap();
        }
        let _ = p.apply(PlaneOp::Query(QueryOp::Raycast {
            rays: vec![shm_layout::Ray {
                origin: [0.0, 10.0, 0.0],
                direction: [0.0, -20.0, 0.0],
            }],
            filter: Default::default(),
        }));
        assert!(p.step(1.0 / 60.0).unwrap());
    }
    let info = match p.apply(PlaneOp::Record(RecordOp::Stop)).unwrap() {
        Reply::Recording(info) => info,
        other => panic!("{other:?}"),
    };
    assert_eq!(info.ticks, 40);
    assert_eq!(info.bytes, std::fs::metadata(&path).unwrap().len());
    let rec = Recording::parse(std::fs::read(&path).unwrap()).unwrap();
    assert_eq!(rec.end.as_deref(), Some("stopped"));
    let periodic = rec
        .events
        .iter()
        .filter(|e| {
            matches!(
                e,
                Event::Keyframe {
                    why: KeyframeWhy::Periodic,
                    ..
                }
            )
        })
        .count();
    // Every 7 ticks, counted again from the Rewind: ticks 7, 14, then 7 and 14 after it.
    assert_eq!(periodic, 4, "periodic keyframes");
    assert!(rec.events.iter().any(|e| matches!(
        e,
        Event::Keyframe {
            why: KeyframeWhy::Jump,
            ..
        }
    )));
    assert_eq!(replay(&rec), Ok(40));
    // A second Stop finds nothing running; a second recording into the same file is refused.
    assert_eq!(
        p.apply(PlaneOp::Record(RecordOp::Stop)).unwrap(),
        Reply::Done
    );
    let e = p
        .apply(PlaneOp::Record(RecordOp::Start {
            path: path.display().to_string(),
        }))
        .unwrap_err();
    assert!(e.message.contains("exists"), "{}", e.message);
}

#[test]
fn recording_refuses_relative_paths_and_a_second_start() {
    let mut p = plane(RecordSettings::default());
    let e = p
        .apply(PlaneOp::Record(RecordOp::Start {
            path: "rel.physrec".into(),
        }))
        .unwrap_err();
    assert!(e.message.contains("absolute"), "{}", e.message);
    let path = temp("b.physrec");
    p.apply(PlaneOp::Record(RecordOp::Start {
        path: path.display().to_string(),
    }))
    .unwrap();
    let e = p
        .apply(PlaneOp::Record(RecordOp::Start {
            path: String::new(),
        }))
        .unwrap_err();
    assert!(e.message.contains("records already"), "{}", e.message);
    drop(p);
    let rec = Recording::parse(std::fs::read(&path).unwrap()).unwrap();
    assert!(rec.end.unwrap().contains("removed"));
}

#[test]
fn a_recording_ends_at_its_most_bytes_and_what_it_holds_replays() {
    let path = temp("c.physrec");
    let mut p = plane(RecordSettings {
        max_bytes: 20_000,
        ..RecordSettings::default()
    });
    let balls: Vec<Handle> = (0..5)
        .map(|i| {
            add(
                &mut p,
                Shape::Sphere { radius: 0.5 },
                [i as f32 * 2.0, 3.0, 0.0],
                vec![],
            )
        })
        .collect();
    p.apply(PlaneOp::Record(RecordOp::Start {
        path: path.display().to_string(),
    }))
    .unwrap();
    for t in 0..400u32 {
        for h in &balls {
            let _ = p.apply(PlaneOp::Object {
                handle: *h,
                op: ObjectOp::Set(ObjectProp::Velocity([0.0, 0.1 * t as f32, 0.0])),
            });
        }
        p.step(1.0 / 60.0).unwrap();
    }
    // It ended by itself: nothing is recording any more.
    assert!(!p.recording());
    let bytes = std::fs::read(&path).unwrap();
    assert!(bytes.len() <= 20_000 + 200, "{} bytes", bytes.len());
    let rec = Recording::parse(bytes).unwrap();
    assert!(
        rec.end
            .as_deref()
            .unwrap()
            .contains("--record-max-bytes (20000 bytes)"),
        "{:?}",
        rec.end
    );
    let ticks = rec.tick_count();
    assert!(ticks > 10 && ticks < 400, "{ticks} ticks");
    assert_eq!(replay(&rec), Ok(ticks));
}

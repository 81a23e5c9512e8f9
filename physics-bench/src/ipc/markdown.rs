//! The human-readable `ipc.md`.

use std::collections::BTreeMap;
use std::fmt::Write as _;

use super::ipc_report::IpcReport;
use super::plan::GOAL_BODIES;
use crate::report::{num, Table};
use crate::scene::Kind;

/// How each figure is obtained (also stored in the JSON).
pub fn method() -> BTreeMap<&'static str, &'static str> {
    BTreeMap::from([
        (
            "scenes",
            "pile: columns of 5 unit cubes on an anchored floor (one extra body), stepped 180 \
             ticks so rapier puts them to sleep; free: unit cubes 3 units apart with random \
             linear and angular velocities, no gravity, all awake. Manual planes, dt = 1/60 s, \
             Threads = 1, rapier defaults otherwise.",
        ),
        (
            "overhead_ratio",
            "median over repeats of (wall time per tick when this process steps the daemon \
             plane with Step and reads every pose of the published sample) / (wall time per \
             tick stepping the same scene in this process with the daemon's own plane code, \
             physics_daemon::rapier3d::Plane, and reading every pose from the rapier world); each \
             pair of blocks timed back to back. Both use one core (global rayon pool of 1).",
        ),
        (
            "delivery",
            "zero_copy_us: the plane ticks at 60 Hz; this process waits for each tick with \
             Plane::wait_tick (it sleeps on the tick event, polling shared memory only from \
             0.3 ms before the tick is due to 0.7 ms after); time \
             from the header's tick_end_ns (taken before the daemon copies the poses into \
             shared memory) until it holds the sample, i.e. every pose, readable in place \
             (read_all_us: then reading every pose once, the reader's own work). \
             socket_serde_us: the same poses gathered from the same world into a Vec, \
             serialised with postcard, written to a Unix socket; another thread reads and \
             deserialises them (then reads every pose, untimed). publish_us: \
             the daemon's PlaneOutput::publish on the same world, timed in process; \
             handover_us = zero_copy_us - publish_us. The *_poll figures repeat both with \
             readers that poll instead of sleeping (Plane::wait_tick_spin on the shared-memory \
             queue; a non-blocking socket read loop): the data path without the wake-up \
             latency of the scheduler (the socket's sleeping reader pays it in full).",
        ),
        (
            "round_trip_us",
            "one SetVelocity queued, then flush timed (request, daemon applies, reply), on the \
             10,000-body pile; batched_writes_per_s: 1,000 SetVelocity writes queued and \
             flushed as one request, timed from the first write to the reply.",
        ),
        (
            "threads",
            "per scene, a Threads = 1 and a Threads = 2 plane in one daemon, stepped \
             alternately (ticks 10-99 after building, dt = 1/60 s); medians of the tick \
             header's step_time_us, the daemon's own timing of Plane::step (forces, speed \
             limits, rapier's step, contact figures, events, state hash; not the publish). \
             Scenes: pile = 10,000 unit cubes in columns of 5 on an anchored floor; pyramid = \
             base-100 pyramid of unit cubes (5,050) on an anchored floor; both NeverSleep, so \
             every body stays awake and in contact. free = 20,000 free-flying cubes, no \
             gravity, no contacts (no goal: rapier sizes its solver workers by constraint \
             chunks, so a step without contacts integrates on one thread).",
        ),
        (
            "head_of_line",
            "Step round trips of a one-ball manual plane (a client alone in the daemon), then \
             the same while another client's 10,000-body free-flying plane ticks at 60 Hz in \
             the same daemon; p50 / p99 / max of each, goal judged on p99.",
        ),
        (
            "multi_plane",
            "10,000 free-flying bodies per plane, each plane stepped back to back by a client \
             thread of its own for the window: ticks per second of one plane, then of two \
             planes together in one daemon.",
        ),
        (
            "lua",
            "physics-lua (next to the bench) runs examples/cframe_cost.luau (medians per frame \
             of 1,000 part.CFrame reads of falling parts at 60 Hz) and \
             examples/property_cost.luau (medians of 1,000 obj.Weight, \
             plane.LinearDamping, plane.ObjectCount and obj.Sleeping reads, per read), each \
             against a daemon of its own.",
        ),
        (
            "idle_cpu_percent",
            "utime + stime of the daemon process from /proc/PID/stat over the window, with no \
             client, then with one client holding a manual plane with one body.",
        ),
        (
            "many_planes",
            "100 planes of 1,000 bodies (900 unit cubes settled in a pile, 100 flying at 2 \
             units/s without gravity, no damping) created by one client, each stepped 180 \
             manual ticks, then set to TickRate 60; over the window every plane's newest tick \
             header is read every 20 ms. Lateness of a tick seen: tick_end_ns − tick·period \
             minus the same plane's smallest such phase (its best tick), all planes' ticks \
             together; CPU per body-tick: the daemon's utime + stime over the window / \
             (bodies × ticks made). The same for one plane of 100,000 bodies of the same mix.",
        ),
        (
            "memory",
            "daemon VmRSS and the size of the domain's /dev/shm files after the pile settled, \
             per body = growth over the empty daemon / bodies; shm backed = pages really \
             allocated in those files.",
        ),
    ])
}

pub fn render(r: &IpcReport) -> String {
    let mut md = String::new();
    let _ = writeln!(
        md,
        "# physics-bench ipc{}\n\n{} CPU(s), {:.0} s. Ratios are measured side by side in this \
         run; absolute times depend on the machine's load.\n",
        if r.quick { " --quick" } else { "" },
        r.cpus,
        r.seconds
    );

    md.push_str("## Overhead and delivery per scene\n\n");
    let mut t = Table::new(&[
        "bodies",
        "scene",
        "daemon µs/tick",
        "in-process µs/tick",
        "overhead_ratio",
        "asleep",
        "zero_copy_us",
        "socket_serde_us",
        "speedup",
        "publish_us",
        "handover_us",
        "zero_copy_poll_us",
        "socket_serde_poll_us",
        "speedup_poll",
        "handover_poll_us",
        "read_all_us",
    ]);
    for s in &r.scenes {
        for kind in [Kind::Pile, Kind::Free] {
            let (Some(o), Some(d)) = (s.ticks.get(&kind), s.delivery.get(&kind)) else {
                continue;
            };
            t.row(&[
                s.bodies.to_string(),
                kind.name().into(),
                num(Some(o.daemon_tick_us)),
                num(Some(o.in_process_tick_us)),
                format!("{:.3}", o.overhead_ratio),
                format!("{:.0} %", o.asleep_fraction * 100.0),
                num(Some(d.zero_copy_us)),
                num(Some(d.socket_serde_us)),
                format!("{}×", num(Some(d.speedup))),
                num(Some(d.publish_us)),
                num(Some(d.handover_us)),
                num(Some(d.zero_copy_poll_us)),
                num(Some(d.socket_serde_poll_us)),
                format!("{}×", num(Some(d.speedup_poll))),
                num(Some(d.handover_poll_us)),
                num(Some(d.read_all_us)),
            ]);
        }
    }
    md.push_str(&t.finish());

    let q = &r.requests;
    let _ = writeln!(
        md,
        "\n## Requests ({GOAL_BODIES}-body plane)\n\n\
         - round_trip_us (one SetVelocity, {} samples): p50 {} / p99 {} / max {}\n\
         - batched_writes_per_s ({}-command batch, median of {}): {}",
        q.round_trips,
        num(Some(q.round_trip_us.p50)),
        num(Some(q.round_trip_us.p99)),
        num(Some(q.round_trip_us.max)),
        q.batch_size,
        q.batches,
        num(Some(q.batched_writes_per_s)),
    );
    let _ = writeln!(
        md,
        "\n## Threads (awake scenes)\n\n\
         | scene | step, Threads = 1 (µs) | step, Threads = 2 (µs) | speedup | ticks |\n\
         |---|---|---|---|---|"
    );
    for th in &r.threads {
        let _ = writeln!(
            md,
            "| {} | {} | {} | {}× | {} |",
            th.scene.describe(),
            num(Some(th.threads1_step_us)),
            num(Some(th.threads2_step_us)),
            num(Some(th.speedup)),
            th.ticks
        );
    }
    let idle = &r.idle_cpu_percent;
    let _ = writeln!(
        md,
        "\n## Idle CPU ({} s windows)\n\n- no clients: {:.3} %\n- one idle manual plane: {:.3} %",
        idle.window_s, idle.no_clients, idle.idle_manual_plane
    );

    md.push_str("\n## Many planes (60 Hz)\n\n");
    let mut t = Table::new(&[
        "planes × bodies",
        "lateness p50 / p99 / max (ms)",
        "ticks/s a plane",
        "CPU ns per body-tick",
        "daemon CPU %",
        "daemon threads",
    ]);
    for p in [&r.many_planes.many, &r.many_planes.one] {
        t.row(&[
            format!("{} × {}", p.planes, p.bodies_per_plane),
            format!(
                "{:.2} / {:.2} / {:.2}",
                p.lateness_ms.p50, p.lateness_ms.p99, p.lateness_ms.max
            ),
            num(Some(p.ticks_per_s)),
            num(Some(p.cpu_ns_per_body_tick)),
            num(Some(p.cpu_percent)),
            p.daemon_threads.to_string(),
        ]);
    }
    md.push_str(&t.finish());

    md.push_str("\n## Memory (settled pile)\n\n");
    let mut t = Table::new(&[
        "bodies",
        "daemon RSS MiB",
        "RSS / body B",
        "shm MiB",
        "shm / body B",
        "shm backed MiB",
        "shm backed / body B",
    ]);
    let mib = |b: u64| num(Some(b as f64 / (1024.0 * 1024.0)));
    for m in &r.memory {
        t.row(&[
            m.bodies.to_string(),
            mib(m.rss_bytes),
            num(Some(m.rss_per_body_bytes)),
            mib(m.shm_bytes),
            num(Some(m.shm_per_body_bytes)),
            mib(m.shm_backed_bytes),
            num(Some(m.shm_backed_per_body_bytes)),
        ]);
    }
    md.push_str(&t.finish());

    md.push_str("\n## Method\n\n");
    for (name, text) in &r.method {
        let _ = writeln!(md, "- **{name}**: {text}");
    }
    md
}

//! The human-readable `ipc.md`.

use std::collections::BTreeMap;
use std::fmt::Write as _;

use super::ipc_report::IpcReport;
use super::many_planes::ManyPlanes;
use super::plan::GOAL_BODIES;
use crate::estimator::{Estimator, JudgedGoal};
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
            "wall-min-of-blocks: (wall time per tick when this process steps the daemon plane \
             with Step and reads every pose of the published sample) / (wall time per tick \
             stepping the same scene in this process with the daemon's own plane code, \
             physics_scenes::LocalPlane, and reading every pose from the world), in blocks \
             ABBA, the minimum of each side's blocks. Both use one core (global rayon pool of \
             1). Beside it, the CPU time of both processes per tick (the client's own clock \
             and every thread of the daemon from /proc/PID/task/*/schedstat), minima and \
             medians of blocks: the daemon side counts the client's bounded polling for the \
             Step reply, so CPU is reported, not judged.",
        ),
        (
            "delivery",
            "wall-median-of-samples: zero_copy_us: the plane ticks at 60 Hz; this process waits for each tick with \
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
            "step-in-process: per scene, the daemon's plane code (physics_scenes::LocalPlane) \
             created in this process with Threads = 1 and with Threads = 2 (its own pool of 2 \
             workers pinned to cores of their own, apart from the global pool of 1), 10 ticks \
             skipped, then 12 blocks of 4 steps each, ABBA; wall time of Plane::step alone \
             (forces, speed limits, rapier's step, contact figures, events, state hash), the \
             minimum of each side's blocks (medians beside). No client shares the cores. \
             Reported beside without a goal: a Threads = 1 and a Threads = 2 plane in one \
             daemon stepped alternately by this process (ticks 10-99), medians of the tick \
             header's step_time_us. Scenes: pile = 10,000 unit cubes in columns of 5 on an anchored floor; pyramid = \
             base-100 pyramid of unit cubes (5,050) on an anchored floor; both NeverSleep, so \
             every body stays awake and in contact. free = 20,000 free-flying cubes, no \
             gravity, no contacts (no goal: rapier sizes its solver workers by constraint \
             chunks, so a step without contacts integrates on one thread).",
        ),
        (
            "head_of_line",
            "wall-p99-min-of-blocks: Step round trips of a one-ball manual plane in blocks \
             ABBA: beside another client's 10,000-body free-flying plane ticking at 60 Hz in \
             the same daemon, and with that plane paused (TickRate 0); the p99 of each block, \
             the goal judged on the minima of the blocks' p99s (medians beside); p50 / p99 / \
             max of all round trips of each side reported.",
        ),
        (
            "multi_plane",
            "wall-min-of-blocks: 10,000 free-flying bodies per plane, each plane stepped back \
             to back by a client thread of its own; blocks ABBA of one plane stepping alone \
             and of two planes at once in one daemon; wall time per tick of all planes \
             together, the minimum of each side's blocks (its ticks/s the inverse); CPU of \
             both processes per tick beside.",
        ),
        (
            "lua",
            "wall-median-of-samples: physics-lua (next to the bench) runs examples/cframe_cost.luau (medians per frame \
             of 1,000 part.CFrame reads of falling parts at 60 Hz) and \
             examples/property_cost.luau (medians of 1,000 obj.Weight, \
             plane.LinearDamping, plane.ObjectCount and obj.Sleeping reads, per read), each \
             against a daemon of its own.",
        ),
        (
            "idle_cpu_percent",
            "cpu-over-window: the daemon's CPU time over the window (every thread's \
             /proc/PID/task/*/schedstat ns), with no client, then with one client holding a \
             manual plane with one body.",
        ),
        (
            "many_planes",
            "100 planes of 1,000 bodies (900 unit cubes settled in a pile, 100 flying at 2 \
             units/s without gravity, no damping) created by one client in one daemon, each \
             stepped 180 manual ticks; one plane of 100,000 bodies of the same mix in another \
             daemon. Blocks ABBA: one daemon's planes set to TickRate 60 (0.4 s to start, \
             then the block), the other's paused. cpu-median-of-blocks: the daemon's CPU time \
             over a block (every thread's schedstat ns; the client only reads headers and is \
             left out) / (bodies × ticks made), the median of each side's blocks; cores \
             needed = that × 100 × 1,000 × 60. rate-slowest-plane: 10 planes of 1,000 bodies \
             in a daemon of their own, the same blocks; per block each plane's ticks (header \
             tick counter at the end minus at the start) / the block's wall time, the \
             slowest plane's; the median of the blocks. Lateness (no goal): every plane's \
             newest header read every 20 ms; tick_end_ns − tick·period minus the same \
             plane's smallest such phase in the block.",
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
        "estimator",
        "wall ratio, medians",
        "CPU µs/tick daemon / in process",
        "CPU ratio, min / median",
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
                o.estimator.name().into(),
                format!("{:.3}", o.ratios.wall_median),
                format!(
                    "{} / {}",
                    num(Some(o.daemon_cpu_us)),
                    num(Some(o.in_process_cpu_us))
                ),
                format!("{:.3} / {:.3}", o.ratios.cpu_min, o.ratios.cpu_median),
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
        "\n## Requests ({GOAL_BODIES}-body plane, {})\n\n\
         - round_trip_us (one SetVelocity, {} samples): p50 {} / p99 {} / max {}\n\
         - batched_writes_per_s ({}-command batch, median of {}): {}",
        q.estimator.name(),
        q.round_trips,
        num(Some(q.round_trip_us.p50)),
        num(Some(q.round_trip_us.p99)),
        num(Some(q.round_trip_us.max)),
        q.batch_size,
        q.batches,
        num(Some(q.batched_writes_per_s)),
    );
    md.push_str("\n## Threads (awake scenes)\n\n");
    let mut t = Table::new(&[
        "scene",
        "where",
        "step, Threads = 1 (µs)",
        "step, Threads = 2 (µs)",
        "speedup",
        "speedup, medians of blocks",
        "CPU, 2 over 1",
        "ticks",
        "estimator",
    ]);
    for th in &r.threads {
        t.row(&[
            th.scene.describe(),
            "in process (judged)".into(),
            num(Some(th.threads1_step_us)),
            num(Some(th.threads2_step_us)),
            format!("{}×", num(Some(th.speedup))),
            format!("{}×", num(Some(th.speedup_median))),
            format!("{}×", num(Some(th.cpu_ratio))),
            th.ticks.to_string(),
            th.estimator.name().into(),
        ]);
        let d = &th.daemon;
        t.row(&[
            th.scene.describe(),
            "daemon, stepped by this process".into(),
            num(Some(d.threads1_step_us)),
            num(Some(d.threads2_step_us)),
            format!("{}×", num(Some(d.speedup))),
            "".into(),
            "".into(),
            d.ticks.to_string(),
            d.estimator.name().into(),
        ]);
    }
    md.push_str(&t.finish());

    md.push_str("\n## Planes side by side\n\n");
    let h = &r.head_of_line;
    let m = &r.multi_plane;
    let mut t = Table::new(&[
        "row",
        "A",
        "B",
        "A / B (judged)",
        "medians of blocks",
        "CPU µs A / B",
        "estimator",
    ]);
    t.row(&[
        format!(
            "head-of-line: round trip p99 beside a {}-body plane at {} Hz / alone",
            h.busy_bodies, h.busy_tick_rate
        ),
        format!("{} µs", num(Some(min(&h.beside_p99_blocks_us)))),
        format!("{} µs", num(Some(min(&h.alone_p99_blocks_us)))),
        format!("{:.2}×", h.p99_ratio),
        format!("{:.2}×", h.p99_ratio_median),
        format!(
            "{} / {} a round trip",
            num(Some(h.blocks.a.cpu_us.median)),
            num(Some(h.blocks.b.cpu_us.median))
        ),
        h.estimator.name().into(),
    ]);
    t.row(&[
        format!("multi-plane: ticks/s of two {}-body planes / one", m.bodies),
        format!("{} ticks/s", num(Some(m.two_planes_ticks_per_s))),
        format!("{} ticks/s", num(Some(m.one_plane_ticks_per_s))),
        format!("{:.2}×", m.ratio),
        format!("{:.2}×", m.ratio_median),
        format!(
            "{} / {} a tick",
            num(Some(m.two_planes_cpu_us)),
            num(Some(m.one_plane_cpu_us))
        ),
        m.estimator.name().into(),
    ]);
    md.push_str(&t.finish());

    let idle = &r.idle_cpu_percent;
    let _ = writeln!(
        md,
        "\n## Idle CPU ({} s windows, {})\n\n- no clients: {:.3} %\n- one idle manual plane: {:.3} %",
        idle.window_s,
        Estimator::CpuOverWindow.name(),
        idle.no_clients,
        idle.idle_manual_plane
    );

    md.push_str("\n## Many planes (60 Hz)\n\n");
    md.push_str(&many_planes(&r.many_planes));

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

    md.push_str("\n## Estimators\n\n");
    md.push_str(&estimators(&r.goals));

    md.push_str("\n## Method\n\n");
    for (name, text) in &r.method {
        let _ = writeln!(md, "- **{name}**: {text}");
    }
    md
}

/// The smallest of `values` (NaN when there is none).
fn min(values: &[f64]) -> f64 {
    let m = values.iter().copied().fold(f64::INFINITY, f64::min);
    if m.is_finite() {
        m
    } else {
        f64::NAN
    }
}

/// The many-planes table: the two configurations compared and the on-time run.
pub fn many_planes(m: &ManyPlanes) -> String {
    let mut t = Table::new(&[
        "planes × bodies",
        "lateness p50 / p99 / max (ms)",
        "ticks/s a plane (slowest)",
        "CPU ns per body-tick, median (min) of blocks",
        "daemon CPU %",
        "daemon threads",
        "estimator",
    ]);
    for (p, estimator) in [
        (&m.many, m.estimator),
        (&m.one, m.estimator),
        (&m.on_time, m.on_time_estimator),
    ] {
        t.row(&[
            format!("{} × {}", p.planes, p.bodies_per_plane),
            format!(
                "{:.2} / {:.2} / {:.2}",
                p.lateness_ms.p50, p.lateness_ms.p99, p.lateness_ms.max
            ),
            format!(
                "{} ({})",
                num(Some(p.ticks_per_s)),
                num(Some(p.slowest_ticks_per_s))
            ),
            format!(
                "{} ({})",
                num(Some(p.cpu_ns_per_body_tick)),
                num(Some(p.cpu_ns_per_body_tick_min))
            ),
            num(Some(p.cpu_percent)),
            p.daemon_threads.to_string(),
            estimator.name().into(),
        ]);
    }
    let mut md = t.finish();
    let _ = writeln!(
        md,
        "\n{} blocks of {:.1} s a side. CPU per body-tick, many over one: {:.2}× (minima \
         {:.2}×). Cores {} × {} bodies at 60 Hz need at the measured cost: {:.2}.",
        m.many.blocks,
        m.many.block_s,
        m.cpu_ratio,
        m.cpu_ratio_min,
        m.many.planes,
        m.many.bodies_per_plane,
        m.cores_needed
    );
    md
}

/// Each goal with its estimator, then every estimator used with its meaning.
fn estimators(goals: &[JudgedGoal]) -> String {
    let mut t = Table::new(&["goal", "estimator"]);
    for g in goals {
        t.row(&[g.goal.clone(), g.estimator.name().into()]);
    }
    let mut md = t.finish();
    md.push('\n');
    for e in Estimator::ALL {
        if goals.iter().any(|g| g.estimator == e) {
            let _ = writeln!(md, "- **{}**: {}", e.name(), e.meaning());
        }
    }
    md
}

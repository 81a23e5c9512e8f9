//! `physics-bench ipc`: what running physics in the daemon costs over running rapier in the
//! game process, and how delivery compares with the usual serialise-over-a-socket way.

mod idle;
mod ipc_report;
mod lua;
mod many_planes;
mod markdown;
mod plan;
mod planes;
mod scene_run;
mod socket;
mod threads;

use std::collections::BTreeMap;
use std::path::PathBuf;
use std::time::{Duration, Instant};

use super::error::{BenchError, BenchResult};
use super::estimator::{self, Estimator, JudgedGoal};
use super::progress::Progress;
use super::report;
use super::scene::{Kind, Scene};
use ipc_report::{IpcReport, SizeReport};
use many_planes::ManyPlanes;
use plan::{Plan, GOAL_BODIES};
use threads::ThreadsScene;

/// Options of the `ipc` subcommand.
#[derive(Debug, Clone, clap::Args)]
pub struct IpcArgs {
    /// Every figure at 10,000 bodies only, with fewer repeats (under 2 minutes).
    #[arg(long)]
    pub quick: bool,
    /// Folder receiving ipc.json and ipc.md.
    #[arg(long, default_value = "bench-out")]
    pub out: PathBuf,
    /// Only the many-planes row (writes ipc-many-planes.json and .md).
    #[arg(long)]
    pub many_planes_only: bool,
}

pub fn run(args: &IpcArgs) -> BenchResult<()> {
    let started = Instant::now();
    let plan = Plan::new(args.quick);
    if args.many_planes_only {
        return many_planes_only(args, &plan);
    }
    let kinds = [Kind::Pile, Kind::Free];
    let phases = 2 + 1 + 3 + (plan.sizes.len() * kinds.len() * 4) as u64 + 1 + 1;
    let progress = Progress::new(phases);

    let idle = idle::run(Duration::from_secs(plan.idle_window_s), &progress)?;
    progress.note(format!(
        "idle CPU: {:.3} % without clients, {:.3} % with an idle manual plane",
        idle.no_clients, idle.idle_manual_plane
    ));

    let mut threads = Vec::new();
    for scene in ThreadsScene::ALL {
        progress.phase(format!("threads: {}, Threads = 1 vs 2", scene.describe()));
        let t = threads::run(scene)?;
        progress.done();
        progress.note(format!(
            "threads ({}): in process, step {:.0} µs with 1, {:.0} µs with 2 → {:.2}× \
             (medians {:.2}×); in a daemon {:.0} / {:.0} µs → {:.2}×",
            scene.name(),
            t.threads1_step_us,
            t.threads2_step_us,
            t.speedup,
            t.speedup_median,
            t.daemon.threads1_step_us,
            t.daemon.threads2_step_us,
            t.daemon.speedup
        ));
        threads.push(t);
    }

    progress.phase(format!(
        "head-of-line: a small plane alone and beside a {GOAL_BODIES}-body plane at 60 Hz"
    ));
    let head_of_line = planes::head_of_line(GOAL_BODIES, plan.head_of_line_round_trips)?;
    progress.done();
    let h = &head_of_line;
    progress.note(format!(
        "head-of-line: p50/p99/max {:.0}/{:.0}/{:.0} µs alone, {:.0}/{:.0}/{:.0} µs beside          ({:.0} ticks/s) → p99 {:.2}×",
        h.alone_us.p50,
        h.alone_us.p99,
        h.alone_us.max,
        h.beside_busy_us.p50,
        h.beside_busy_us.p99,
        h.beside_busy_us.max,
        h.busy_ticks_per_s,
        h.p99_ratio
    ));
    progress.phase(format!(
        "multi-plane: two {GOAL_BODIES}-body planes stepped at once vs one"
    ));
    let multi_plane = planes::multi_plane(GOAL_BODIES, plan.multi_plane_s)?;
    progress.done();
    progress.note(format!(
        "multi-plane: {:.1} ticks/s with one, {:.1} with two → {:.2}× (medians {:.2}×; CPU \
         {:.0} / {:.0} µs a tick)",
        multi_plane.one_plane_ticks_per_s,
        multi_plane.two_planes_ticks_per_s,
        multi_plane.ratio,
        multi_plane.ratio_median,
        multi_plane.one_plane_cpu_us,
        multi_plane.two_planes_cpu_us
    ));
    progress.phase("Lua: part.CFrame and obj.Weight reads".to_string());
    let lua = lua::measure()?;
    progress.done();
    progress.note(format!(
        "Lua: 1,000 part.CFrame reads {:.0} µs per frame; one obj.Weight read {:.3} µs, \
         plane.LinearDamping {:.3} µs",
        lua.cframe_x1000_us, lua.weight_read_us, lua.linear_damping_read_us
    ));

    progress.phase(format!(
        "many planes: {MANY_PLANES} planes × {MANY_PLANES_BODIES} bodies at 60 Hz vs one plane"
    ));
    let many_planes = many_planes::run(MANY_PLANES, MANY_PLANES_BODIES, plan.many_planes_s)?;
    progress.done();
    progress.note(many_planes_note(&many_planes));

    let mut scenes = Vec::new();
    let mut memory = Vec::new();
    let mut requests = None;
    for &bodies in &plan.sizes {
        let mut size = SizeReport {
            bodies,
            overhead_ratio: BTreeMap::new(),
            delivery: BTreeMap::new(),
            ticks: BTreeMap::new(),
        };
        for kind in kinds {
            let scene = Scene { kind, bodies };
            let with_requests = bodies == GOAL_BODIES && kind == Kind::Pile;
            let outcome = scene_run::run(scene, &plan, with_requests, &progress)?;
            let (o, d) = (&outcome.overhead, &outcome.delivery);
            progress.note(format!(
                "{bodies:>6} {:<4}: tick {:>8.1} µs daemon / {:>8.1} µs in process = {:.3} \
                 (wall medians {:.3}, CPU {:.1} / {:.1} µs = {:.3})  \
                 delivery {:>7.1} µs zero-copy / {:>8.1} µs socket = {:.1}×",
                kind.name(),
                o.daemon_tick_us,
                o.in_process_tick_us,
                o.overhead_ratio,
                o.ratios.wall_median,
                o.daemon_cpu_us,
                o.in_process_cpu_us,
                o.ratios.cpu_median,
                d.zero_copy_us,
                d.socket_serde_us,
                d.speedup
            ));
            size.overhead_ratio.insert(kind, o.overhead_ratio);
            size.delivery.insert(kind, outcome.delivery);
            size.ticks.insert(kind, outcome.overhead);
            if kind == Kind::Pile && (bodies == GOAL_BODIES || bodies == 50_000) {
                memory.push(outcome.memory);
            }
            if let Some(r) = outcome.requests {
                progress.done();
                progress.note(format!(
                    "round trip p50 {:.1} µs p99 {:.1} µs max {:.1} µs; {:.0} batched writes/s",
                    r.round_trip_us.p50,
                    r.round_trip_us.p99,
                    r.round_trip_us.max,
                    r.batched_writes_per_s
                ));
                requests = Some(r);
            }
        }
        scenes.push(size);
    }
    progress.finish();
    let requests = requests.ok_or_else(|| {
        BenchError::Failed(format!("round trips are measured at {GOAL_BODIES} bodies"))
    })?;

    let mut report = IpcReport {
        quick: args.quick,
        method: markdown::method(),
        round_trip_us: requests.round_trip_us,
        batched_writes_per_s: requests.batched_writes_per_s,
        requests,
        threads,
        head_of_line,
        multi_plane,
        lua,
        idle_cpu_percent: idle,
        memory,
        goals: Vec::new(),
        estimators: estimator::glossary(),
        scenes,
        plan,
        cpus: std::thread::available_parallelism().map_or(1, |n| n.get()),
        seconds: 0.0,
        many_planes,
    };
    report.goals = goals(&report);
    report.seconds = started.elapsed().as_secs_f64();
    let md = markdown::render(&report);
    let (json, md_path) = report::write(&args.out, "ipc", &report, &md)?;
    report::print(&md_path);
    eprintln!(
        "wrote {} and {} in {:.0} s",
        json.display(),
        md_path.display(),
        report.seconds
    );
    Ok(())
}

/// Planes of the many-planes figure.
const MANY_PLANES: usize = 100;
/// Bodies of each of them.
const MANY_PLANES_BODIES: usize = 1_000;

fn many_planes_note(m: &ManyPlanes) -> String {
    format!(
        "many planes: lateness p50/p99/max {:.2}/{:.2}/{:.2} ms, {:.1} ticks/s a plane, {:.1} ns \
         CPU per body-tick ({} daemon threads; {:.2} cores for {} × {} at 60 Hz); one plane: \
         {:.2}/{:.2}/{:.2} ms, {:.1} ticks/s, {:.1} ns → {:.2}× (minima {:.2}×); {} planes: \
         slowest {:.1} ticks/s",
        m.many.lateness_ms.p50,
        m.many.lateness_ms.p99,
        m.many.lateness_ms.max,
        m.many.ticks_per_s,
        m.many.cpu_ns_per_body_tick,
        m.many.daemon_threads,
        m.cores_needed,
        m.many.planes,
        m.many.bodies_per_plane,
        m.one.lateness_ms.p50,
        m.one.lateness_ms.p99,
        m.one.lateness_ms.max,
        m.one.ticks_per_s,
        m.one.cpu_ns_per_body_tick,
        m.cpu_ratio,
        m.cpu_ratio_min,
        m.on_time.planes,
        m.on_time.slowest_ticks_per_s
    )
}

/// The goal rows of the many-planes figure.
fn many_planes_goals(m: &ManyPlanes) -> Vec<JudgedGoal> {
    let on_time = &m.on_time;
    let floor = many_planes::ON_TIME_SHARE * f64::from(many_planes::RATE);
    vec![
        JudgedGoal::new(
            m.estimator,
            format!(
                "many planes: CPU per body-tick ≤ 1.10 × one plane of {} bodies",
                m.one.bodies_per_plane
            ),
            format!(
                "{:.2}× ({:.1} against {:.1} ns; minima {:.2}×)",
                m.cpu_ratio,
                m.many.cpu_ns_per_body_tick,
                m.one.cpu_ns_per_body_tick,
                m.cpu_ratio_min
            ),
            Some(m.cpu_ratio <= 1.10),
        ),
        JudgedGoal::new(
            m.estimator,
            format!(
                "many planes: cores {} planes × {} bodies at 60 Hz need (CPU per body-tick × \
                 {} × 60; no goal)",
                m.many.planes,
                m.many.bodies_per_plane,
                m.many.planes * m.many.bodies_per_plane
            ),
            format!(
                "{:.2} cores ({:.1} ns per body-tick; this machine has {})",
                m.cores_needed,
                m.many.cpu_ns_per_body_tick,
                std::thread::available_parallelism().map_or(1, |n| n.get())
            ),
            None,
        ),
        JudgedGoal::new(
            m.on_time_estimator,
            format!(
                "many planes: {} planes × {} bodies at 60 Hz on time: the slowest plane's \
                 ticks/s ≥ {:.0} % of 60 in a block (median of {} blocks of {:.1} s)",
                on_time.planes,
                on_time.bodies_per_plane,
                many_planes::ON_TIME_SHARE * 100.0,
                on_time.blocks,
                on_time.block_s
            ),
            format!(
                "{:.1} ticks/s (floor {floor:.0}; mean plane {:.1}; lateness p99 {:.2} ms)",
                on_time.slowest_ticks_per_s, on_time.ticks_per_s, on_time.lateness_ms.p99
            ),
            Some(on_time.slowest_ticks_per_s >= floor),
        ),
        JudgedGoal::new(
            Estimator::WallP99OfSamples,
            format!(
                "many planes: {} planes × {} bodies, tick lateness (no goal)",
                m.many.planes, m.many.bodies_per_plane
            ),
            format!(
                "p99 {:.2} ms (p50 {:.2}, max {:.2}; {:.1} ticks/s a plane, slowest {:.1})",
                m.many.lateness_ms.p99,
                m.many.lateness_ms.p50,
                m.many.lateness_ms.max,
                m.many.ticks_per_s,
                m.many.slowest_ticks_per_s
            ),
            None,
        ),
    ]
}

/// `ipc --many-planes-only`: the many-planes row alone.
fn many_planes_only(args: &IpcArgs, plan: &Plan) -> BenchResult<()> {
    let m = many_planes::run(MANY_PLANES, MANY_PLANES_BODIES, plan.many_planes_s)?;
    eprintln!("{}", many_planes_note(&m));
    #[derive(serde::Serialize)]
    struct Only<'a> {
        many_planes: &'a ManyPlanes,
        goals: Vec<JudgedGoal>,
        estimators: BTreeMap<&'static str, &'static str>,
    }
    let goals = many_planes_goals(&m);
    let md = format!(
        "# physics-bench ipc --many-planes-only\n\n{}",
        markdown::many_planes(&m)
    );
    let only = Only {
        many_planes: &m,
        goals,
        estimators: estimator::glossary(),
    };
    let (json, md_path) = report::write(&args.out, "ipc-many-planes", &only, &md)?;
    report::print(&md_path);
    eprintln!("wrote {} and {}", json.display(), md_path.display());
    Ok(())
}

fn goals(r: &IpcReport) -> Vec<JudgedGoal> {
    let mut goals = Vec::new();
    let at_goal = r.scenes.iter().find(|s| s.bodies == GOAL_BODIES);
    for kind in [Kind::Pile, Kind::Free] {
        let ticks = at_goal.and_then(|s| s.ticks.get(&kind));
        let ratio = ticks.map(|o| o.overhead_ratio);
        goals.push(JudgedGoal::new(
            scene_run::OVERHEAD_ESTIMATOR,
            format!("overhead_ratio ≤ 1.05 at 10,000 bodies ({})", kind.name()),
            match ticks {
                Some(o) => format!(
                    "{} (wall medians {:.3}; CPU of both processes {:.3} min, {:.3} median)",
                    report::num(ratio),
                    o.ratios.wall_median,
                    o.ratios.cpu_min,
                    o.ratios.cpu_median
                ),
                None => report::num(None),
            },
            ratio.map(|v| v <= 1.05),
        ));
    }
    // Sleeping readers include the scheduler's wake-up; polling readers show the data path.
    for (mode, polled) in [("sleeping readers", false), ("polling readers", true)] {
        for kind in [Kind::Pile, Kind::Free] {
            let speedup = at_goal.and_then(|s| s.delivery.get(&kind)).map(|d| {
                if polled {
                    d.speedup_poll
                } else {
                    d.speedup
                }
            });
            goals.push(JudgedGoal::new(
                Estimator::WallMedianOfSamples,
                format!(
                    "delivery speedup ≥ 20× at 10,000 bodies ({}, {mode})",
                    kind.name()
                ),
                format!("{}×", report::num(speedup)),
                speedup.map(|v| v >= 20.0),
            ));
        }
        for kind in [Kind::Pile, Kind::Free] {
            let handover: Vec<(usize, f64)> = r
                .scenes
                .iter()
                .filter_map(|s| {
                    let d = s.delivery.get(&kind)?;
                    Some((
                        s.bodies,
                        if polled {
                            d.handover_poll_us
                        } else {
                            d.handover_us
                        },
                    ))
                })
                .collect();
            let (value, met) = match (handover.first(), handover.last()) {
                (Some(a), Some(b)) if handover.len() > 1 => (
                    format!(
                        "{} µs at {} → {} µs at {} bodies",
                        report::num(Some(a.1)),
                        a.0,
                        report::num(Some(b.1)),
                        b.0
                    ),
                    // Flat: the largest scene's hand-over within 2× of the smallest's (+5 µs
                    // of timer noise).
                    Some(b.1 <= 2.0 * a.1 + 5.0),
                ),
                _ => ("one size only".to_string(), None),
            };
            goals.push(JudgedGoal::new(
                Estimator::WallMedianOfSamples,
                format!(
                    "zero-copy hand-over flat in body count ({}, {mode})",
                    kind.name()
                ),
                value,
                met,
            ));
        }
    }
    let idle = &r.idle_cpu_percent;
    for (what, v) in [
        ("no clients", idle.no_clients),
        ("one idle manual plane", idle.idle_manual_plane),
    ] {
        goals.push(JudgedGoal::new(
            Estimator::CpuOverWindow,
            format!("idle CPU ≤ 0.1 % ({what})"),
            format!("{v:.3} %"),
            Some(v <= 0.1),
        ));
    }
    for t in &r.threads {
        if t.scene.has_goal() {
            goals.push(JudgedGoal::new(
                t.estimator,
                format!(
                    "Threads = 2 against 1 ≥ 1.6× on a scene whose step takes ≥ 5 ms ({}; the \
                     plane's step in process)",
                    t.scene.describe()
                ),
                format!(
                    "{:.2}× (step {:.0} µs with 1, {:.0} µs with 2; medians {:.2}×)",
                    t.speedup, t.threads1_step_us, t.threads2_step_us, t.speedup_median
                ),
                (t.threads1_step_us >= 5_000.0).then_some(t.speedup >= 1.6),
            ));
        }
        let d = &t.daemon;
        goals.push(JudgedGoal::new(
            d.estimator,
            format!(
                "Threads = 2 against 1 in a daemon stepped by this process ({}; no goal)",
                t.scene.describe()
            ),
            format!(
                "{:.2}× (step {:.0} µs with 1, {:.0} µs with 2)",
                d.speedup, d.threads1_step_us, d.threads2_step_us
            ),
            None,
        ));
    }
    let h = &r.head_of_line;
    goals.push(JudgedGoal::new(
        h.estimator,
        format!(
            "head-of-line: small-plane round trip p99 beside a {}-body plane at {} Hz ≤ 2× alone",
            h.busy_bodies, h.busy_tick_rate
        ),
        format!(
            "{:.2}× (medians of blocks {:.2}×; all round trips p50/p99/max {:.0}/{:.0}/{:.0} µs \
             alone, {:.0}/{:.0}/{:.0} µs beside)",
            h.p99_ratio,
            h.p99_ratio_median,
            h.alone_us.p50,
            h.alone_us.p99,
            h.alone_us.max,
            h.beside_busy_us.p50,
            h.beside_busy_us.p99,
            h.beside_busy_us.max
        ),
        Some(h.p99_ratio <= 2.0),
    ));
    let m = &r.multi_plane;
    goals.push(JudgedGoal::new(
        m.estimator,
        format!(
            "multi-plane: two {}-body planes ≥ 1.7× the ticks/s of one",
            m.bodies
        ),
        format!(
            "{:.2}× ({:.1} → {:.1} ticks/s; medians of blocks {:.2}×; CPU of both processes \
             {:.0} → {:.0} µs a tick)",
            m.ratio,
            m.one_plane_ticks_per_s,
            m.two_planes_ticks_per_s,
            m.ratio_median,
            m.one_plane_cpu_us,
            m.two_planes_cpu_us
        ),
        Some(m.ratio >= 1.7),
    ));
    let l = &r.lua;
    let lua = Estimator::WallMedianOfSamples;
    goals.push(JudgedGoal::new(
        lua,
        "Lua: 1,000 part.CFrame reads per frame ≤ 0.2 ms",
        format!("{:.3} ms", l.cframe_x1000_us / 1000.0),
        Some(l.cframe_x1000_us <= 200.0),
    ));
    goals.push(JudgedGoal::new(
        lua,
        "Lua: one obj.Weight read ≤ 1 µs",
        format!(
            "{:.3} µs (plane.LinearDamping {:.3} µs)",
            l.weight_read_us, l.linear_damping_read_us
        ),
        Some(l.weight_read_us <= 1.0),
    ));
    goals.push(JudgedGoal::new(
        lua,
        "Lua: one read of a value the daemon derives each tick ≤ 1 µs",
        format!(
            "plane.ObjectCount {:.3} µs, obj.Sleeping {:.3} µs",
            l.object_count_read_us, l.sleeping_read_us
        ),
        Some(l.object_count_read_us.max(l.sleeping_read_us) <= 1.0),
    ));
    // Side by side in one frame of one script: the part reads against plain table reads.
    let ratio = l.cframe_x1000_us / l.table_x1000_us;
    goals.push(JudgedGoal::new(
        lua,
        "Lua: 1,000 part.CFrame reads ≤ 5× 1,000 plain table-field reads (same frame)",
        format!(
            "{ratio:.1}× ({:.1} µs against {:.1} µs; second read {:.1} µs)",
            l.cframe_x1000_us, l.table_x1000_us, l.cframe_x1000_second_read_us
        ),
        Some(ratio <= 5.0),
    ));
    goals.extend(many_planes_goals(&r.many_planes));
    goals
}

//! `physics-bench`: measures the physics service against in-process physics.
//!
//! `physics-bench ipc [--quick] [--out DIR]` writes DIR/ipc.json and DIR/ipc.md. It starts
//! real `physics-daemon` processes (the binary next to this one) in throw-away domains.
//!
//! `physics-bench accuracy [--quick] [--out DIR]` writes DIR/accuracy.json, DIR/accuracy.md
//! and DIR/accuracy-*.svg: error against cost of reference scenes, in process.
//! `physics-bench stability [--out DIR]` writes DIR/stability.json and DIR/stability.md.
//! `physics-bench queries [--quick] [--out DIR]` writes DIR/queries.json and DIR/queries.md.
//! `physics-bench controllers [--quick] [--out DIR]` writes DIR/controllers.json and .md.
//! `physics-bench gpu [--quick] [--out DIR]` writes DIR/gpu.json and DIR/gpu.md.
//! `physics-bench hostile [--out DIR]` writes DIR/hostile.json and DIR/hostile.md.
//! `physics-bench frame [--out DIR]` writes DIR/frame.json and DIR/frame.md.
//! `physics-bench envelope [--seed N] [--minutes M | --cases N] [--out DIR] [--docs FILE]`
//! writes DIR/envelope.json, DIR/envelope.md and the failures' Luau repros (the physics
//! fuzzer, crate `physics-envelope`); `--docs` replaces FILE's envelope section.
//! `physics-bench render [--to DIR] FILE.json...` renders report pages from their JSON into
//! DIR (default docs/reports) with an index, without rerunning.
//!
//! Every page has a header (machine, date, build, command line) and the goals table, both
//! rendered from the report's JSON (see [`report`]).
//!
//! Its parts, shared by the subcommands:
//!
//! - [`daemon`]: real daemon processes in throw-away domains.
//! - [`procfs`]: CPU time, RSS and shared-memory size of a process / domain.
//! - [`scene`]: the benchmark scenes, built identically in the daemon and in process.
//! - [`stats`]: medians and percentiles.
//! - [`progress`]: the progress bar and its log lines.
//! - [`report`]: writing the JSON reports and rendering their pages.
//! - [`render`]: the `render` subcommand (pages and their index from stored JSON).
//! - [`ipc`]: the `ipc` subcommand (daemon overhead, delivery, requests, idle, memory).
//! - [`sim`]: an in-process plane stepped at a fixed dt with its step time accumulated.
//! - [`accuracy`]: the `accuracy` subcommand (error against run time).
//! - [`stability`]: the `stability` subcommand (stiff and extreme scenes, pass/fail).

mod accuracy;
mod cluster;
mod controllers;
mod counts;
mod daemon;
mod envelope;
mod error;
mod estimator;
mod frame;
mod fuzz;
mod gpu;
mod hostile;
mod ipc;
mod load;
mod maps;
mod peers;
mod persist;
mod procfs;
mod progress;
mod queries;
mod recording_cost;
mod render;
mod report;
mod scene;
mod sim;
mod snapshot;
mod soak;
mod stability;
mod stats;
mod validate;

use std::process::ExitCode;

use clap::{Parser, Subcommand};

#[derive(Parser)]
#[command(version, about = "Benchmarks of the physics service")]
struct Cli {
    #[command(subcommand)]
    command: Bench,
}

#[derive(Subcommand)]
enum Bench {
    /// Daemon overhead over in-process rapier, zero-copy vs socket delivery, request round
    /// trips, threads, idle CPU and memory.
    Ipc(ipc::IpcArgs),
    /// Error against run time on reference scenes with exact answers, swept over TickRate,
    /// SolverIterations / LoopSolver and HitBoxQuality.
    Accuracy(accuracy::AccuracyArgs),
    /// Stress scenes (tall stacks, mass ratios, fast bodies, overlap, far from the origin,
    /// tiny objects, extreme forces and tick rates), each with a pass criterion.
    Stability(stability::StabilityArgs),
    /// Fuzzes the daemon's request decoder and command executor through a real daemon:
    /// structured, raw and quota-exceeding frames; fails on any crash.
    Fuzz(fuzz::FuzzArgs),
    /// 16 clients × 100,000 commands against one daemon: none lost, commands/s.
    Load(load::LoadArgs),
    /// Rays per second of RaycastMany batches (1, 64, 4,096 rays) against a 10,000-body
    /// plane, next to the same rays cast in process.
    Queries(queries::QueriesArgs),
    /// Character controllers' cost per tick: 1, 100 and 1,000 controllers walking waypoints
    /// among obstacles, in process on one core.
    Controllers(controllers::ControllersArgs),
    /// A generated ~1M-triangle map: load time, daemon memory, and the step cost of 1,000
    /// boxes resting on it.
    Maps(maps::MapsArgs),
    /// A game's load for N minutes (4 planes × 1,000 bodies at 60 Hz; writes, churn,
    /// queries, controllers, joints, Touched, planes and clients coming and going): daemon
    /// RSS and shared memory sampled every 6 s, flat within 1 MiB after the warm-up.
    Soak(soak::SoakArgs),
    /// The GPU path (DeferGpu) against the CPU: time per tick of 1k to 1M bodies falling
    /// into a container (spatial hash, every pair, rapier), scaling ratios, the adapter.
    Gpu(gpu::GpuArgs),
    /// Hostile clients at scale against real daemons: one verdict row per attack (reply
    /// amplification, queries beside steps, quota race, paths, slow planes, Threads, empty
    /// planes' memory, CPU shares).
    Hostile(hostile::HostileArgs),
    /// Plane snapshots: Snapshot / Restore time and size (1k and 10k bodies, settled and
    /// awake), Rewind(8) + 8 ticks against 8 ticks, the cost of keeping RollbackTicks = 8.
    Snapshot(snapshot::SnapshotArgs),
    /// Persistent planes: a plane's tick with its periodic writes (--state-dir,
    /// --snapshot-every) against a plain plane's, side by side.
    Persist(persist::PersistArgs),
    /// A cluster on loopback: a remote reader beside a local one (delivery latency p50/p99,
    /// bytes of a tick's frame, same StateHash), 1k and 10k bodies, settled and awake.
    Cluster(cluster::ClusterArgs),
    /// Physics for free: a game loop's frame time with the daemon simulating 10,000 bodies
    /// on the other core, against no physics and against physics stepped in the frame.
    Frame(frame::FrameArgs),
    /// The physics fuzzer: scenes drawn over parameter spaces (stacks, chains, projectiles,
    /// drops, springs, piles) judged by physical-law oracles, failures shrunk to Luau
    /// repros, and each family's critical value at the defaults and a strong setting.
    Envelope(envelope::EnvelopeArgs),
    /// Renders report pages from the JSON a bench wrote (header: machine, date, build,
    /// command; the goals; the bench's tables) into a folder, docs/reports by default, with
    /// its index README.md, without rerunning the bench.
    Render(render::RenderArgs),
    /// Scenes other engines publish figures for (Jolt's PerformanceTest Pyramid, Box2D v3's
    /// large_pyramid), measured here with the defaults, beside the peers' published setups.
    Peers(peers::PeersArgs),
    /// The instruction counts of benches/instructions (gungraun over Valgrind's Callgrind,
    /// run by .ci/instructions) against their baselines: fails when one moves more than 2 %.
    Counts(counts::CountsArgs),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    // The daemons it starts inherit this: warnings only, so their logs stay out of the
    // progress display.
    if std::env::var_os("PHYSICS_LOG").is_none() {
        std::env::set_var("PHYSICS_LOG", "warn");
    }
    // In-process planes with Threads = 1 run on rayon's global pool: one worker, as in the
    // daemon, so both sides of a comparison use one core.
    let _ = rapier3d::rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build_global();
    let result = match &cli.command {
        Bench::Ipc(args) => ipc::run(args),
        Bench::Accuracy(args) => accuracy::run(args),
        Bench::Stability(args) => stability::run(args),
        Bench::Fuzz(args) => fuzz::run(args),
        Bench::Load(args) => load::run(args),
        Bench::Soak(args) => soak::run(args),
        Bench::Queries(args) => queries::run(args),
        Bench::Controllers(args) => controllers::run(args),
        Bench::Maps(args) => maps::run(args),
        Bench::Gpu(args) => gpu::run(args),
        Bench::Hostile(args) => hostile::run(args),
        Bench::Snapshot(args) => snapshot::run(args),
        Bench::Persist(args) => persist::run(args),
        Bench::Cluster(args) => cluster::run(args),
        Bench::Frame(args) => frame::run(args),
        Bench::Envelope(args) => envelope::run(args),
        Bench::Render(args) => render::run(args),
        Bench::Peers(args) => peers::run(args),
        Bench::Counts(args) => counts::run(args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("physics-bench: {e}");
            ExitCode::FAILURE
        }
    }
}

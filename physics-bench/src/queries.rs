//! `physics-bench queries`: rays per second of `RaycastMany` batches (1, 64 and 4,096 rays)
//! against a 10,000-body plane in a real daemon, next to the same rays cast in process on
//! the same scene with the daemon's own plane code. Both sides cast identical rays and must
//! report identical hits; the goal is batched rays within 2× of in-process throughput.

use std::fmt::Write as _;
use std::path::PathBuf;
use std::time::{Duration, Instant};

use client_sdk::{Hit, Ray};
use shm_layout::{QueryFilter, QueryOp, Reply};

use super::daemon::DaemonProcess;
use super::error::{BenchError, BenchResult};
use super::report::{self, num, Goal};
use super::scene::{Kind, Scene};

/// Options of the `queries` subcommand.
#[derive(Debug, Clone, clap::Args)]
pub struct QueriesArgs {
    /// Shorter measurements (about a second per row instead of three).
    #[arg(long)]
    pub quick: bool,
    /// Bodies in the plane.
    #[arg(long, default_value_t = 10_000)]
    pub bodies: usize,
    /// Folder receiving queries.json and queries.md.
    #[arg(long, default_value = "bench-out")]
    pub out: PathBuf,
}

/// Batch sizes measured.
const BATCHES: [usize; 3] = [1, 64, 4_096];
/// Batched throughput must be at least 1 / this of in-process throughput...
const GOAL_RATIO: f64 = 2.0;
/// ...for batches of this many rays.
const GOAL_BATCH: usize = 4_096;

#[derive(Debug, Clone, serde::Serialize)]
pub struct Row {
    pub batch: usize,
    pub daemon_rays_per_s: f64,
    pub in_process_rays_per_s: f64,
    /// In-process throughput over daemon throughput (1 = no cost for crossing processes).
    pub ratio: f64,
    pub daemon_round_trip_us: f64,
    /// Share of rays that hit something.
    pub hit_fraction: f64,
}

#[derive(Debug, Clone, serde::Serialize)]
pub struct QueriesReport {
    pub bodies: usize,
    pub rows: Vec<Row>,
    pub goals: Vec<Goal>,
}

/// Deterministic rays through the scene's box: from a random point, a random direction,
/// long enough to cross a good part of it.
fn rays(n: usize, extent: f32, seed: u64) -> Vec<Ray> {
    let mut s = seed | 1;
    let mut unit = move || {
        s ^= s >> 12;
        s ^= s << 25;
        s ^= s >> 27;
        ((s.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 40) as f32 / (1u64 << 24) as f32) * 2.0 - 1.0
    };
    (0..n)
        .map(|_| {
            let origin = [0; 3].map(|_| (unit() * 0.5 + 0.5) * extent);
            let mut d = [unit(), unit(), unit()];
            let len = d.iter().map(|c| c * c).sum::<f32>().sqrt().max(1e-3);
            d = d.map(|c| c / len * extent * 0.5);
            Ray {
                origin,
                direction: d,
            }
        })
        .collect()
}

/// Runs `f` (which casts `batch` rays) until `budget` has passed; returns rays per second and
/// the mean time per call.
fn measure(
    batch: usize,
    budget: Duration,
    mut f: impl FnMut() -> BenchResult<()>,
) -> BenchResult<(f64, f64)> {
    // Warm up: caches, allocations, the daemon's first refresh.
    for _ in 0..3 {
        f()?;
    }
    let started = Instant::now();
    let mut calls = 0u64;
    while started.elapsed() < budget || calls < 5 {
        f()?;
        calls += 1;
    }
    let s = started.elapsed().as_secs_f64();
    Ok(((calls as f64 * batch as f64) / s, s / calls as f64 * 1e6))
}

pub fn run(args: &QueriesArgs) -> BenchResult<()> {
    let budget = Duration::from_millis(if args.quick { 700 } else { 3_000 });
    let scene = Scene {
        kind: Kind::Free,
        bodies: args.bodies,
    };
    let side = (args.bodies as f64).cbrt().ceil() as f32;
    let extent = side * 3.0;
    let mut local = scene.build_local(1)?;
    let daemon = DaemonProcess::start("queries")?;
    let client = daemon.connect()?;
    let (plane, _objects) = scene.build_remote(&client, 1)?;
    // One step each: the same poses on both sides (zero gravity, the same velocities).
    local
        .step(super::scene::DT)
        .map_err(|e| BenchError::Failed(e.to_string()))?;
    plane.step(super::scene::DT)?;

    let mut rows = Vec::new();
    for batch in BATCHES {
        let rays = rays(batch, extent, 0x5eed ^ batch as u64);
        let op = QueryOp::Raycast {
            rays: rays.clone(),
            filter: QueryFilter::default(),
        };
        let local_hits = match local.query(op.clone()) {
            Ok(Reply::Hits(h)) => h,
            other => return Err(BenchError::Failed(format!("in-process query: {other:?}"))),
        };
        let remote_hits = plane.raycast_many(&rays, None)?;
        check_same(&local_hits, &remote_hits)?;
        let (in_process, _) = measure(batch, budget, || {
            local
                .query(op.clone())
                .map(|_| ())
                .map_err(|e| BenchError::Failed(e.to_string()))
        })?;
        let (daemon_rate, round_trip) = measure(batch, budget, || {
            plane
                .raycast_many(&rays, None)
                .map(|_| ())
                .map_err(Into::into)
        })?;
        let hits = remote_hits.iter().filter(|h| h.is_some()).count();
        rows.push(Row {
            batch,
            daemon_rays_per_s: daemon_rate,
            in_process_rays_per_s: in_process,
            ratio: in_process / daemon_rate,
            daemon_round_trip_us: round_trip,
            hit_fraction: hits as f64 / batch as f64,
        });
    }
    let report = QueriesReport {
        bodies: args.bodies,
        goals: goals(&rows),
        rows,
    };
    let md = markdown(&report);
    let (json, md_path) = report::write(&args.out, "queries", &report, &md)?;
    report::print(&md_path);
    println!("wrote {} and {}", json.display(), md_path.display());
    Ok(())
}

/// Both sides must agree on what every ray hit (same object, same distance).
fn check_same(local: &[Option<Hit>], remote: &[Option<Hit>]) -> BenchResult<()> {
    for (i, (a, b)) in local.iter().zip(remote).enumerate() {
        let same = match (a, b) {
            (None, None) => true,
            (Some(a), Some(b)) => a.object == b.object && (a.distance - b.distance).abs() < 1e-3,
            _ => false,
        };
        if !same {
            return Err(BenchError::Failed(format!(
                "ray {i}: in process {a:?}, daemon {b:?}"
            )));
        }
    }
    Ok(())
}

/// One goal per batch size, judged on the large batch only.
fn goals(rows: &[Row]) -> Vec<Goal> {
    // The goal is judged on the large batch; smaller ones are dominated by the fixed cost of
    // one round trip (shown in the table) and carry no verdict.
    rows.iter()
        .map(|row| {
            let judged = row.batch == GOAL_BATCH;
            Goal::new(
                format!(
                    "RaycastMany of {} rays within {GOAL_RATIO}× of in-process throughput{}",
                    row.batch,
                    if judged {
                        ""
                    } else {
                        " (reported, not judged)"
                    }
                ),
                format!("{}×", num(Some(row.ratio))),
                judged.then_some(row.ratio <= GOAL_RATIO),
            )
        })
        .collect()
}

fn markdown(r: &QueriesReport) -> String {
    let mut md = String::new();
    let _ = writeln!(
        md,
        "# Scene queries: RaycastMany against {} bodies\n\nSame rays, same scene: the daemon \
         (one request per batch) and the daemon's plane code in process.\n",
        r.bodies
    );
    let mut t = report::Table::new(&[
        "rays per batch",
        "daemon rays/s",
        "in-process rays/s",
        "in-process ÷ daemon",
        "round trip (µs)",
        "hit fraction",
    ]);
    for row in &r.rows {
        t.row(&[
            row.batch.to_string(),
            num(Some(row.daemon_rays_per_s)),
            num(Some(row.in_process_rays_per_s)),
            num(Some(row.ratio)),
            num(Some(row.daemon_round_trip_us)),
            num(Some(row.hit_fraction)),
        ]);
    }
    md.push_str(&t.finish());
    let _ = writeln!(
        md,
        "\nA batch pays one round trip (about {} µs here) however many rays it carries: below a \
         few hundred rays that fixed cost dominates, which is why hitscan for a whole server \
         belongs in one `RaycastMany`.",
        num(r.rows.first().map(|row| row.daemon_round_trip_us))
    );
    md
}

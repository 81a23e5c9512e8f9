//! `physics-bench gpu`: the GPU path (`DeferGpu`) against the CPU path. Free-falling debris
//! (unit cubes in columns 10 high) dropped into an anchored container, in process with the
//! daemon's own plane code, timed per tick (median wall time of `step`, readback of every
//! state included) at 1k to 1M bodies on three paths side by side: the GPU with its spatial
//! hash, the GPU testing every pair (O(N²)), and rapier on one CPU core. The scaling ratio
//! time(4N) / time(N) shows the order of growth: ≤ 4.5 is O(N) (the goal for the hash),
//! ≈ 16 is O(N²). A path whose next size would take too long (its per-tick time
//! extrapolated from the last size, linearly or quadratically) is skipped, and the report
//! says so. A last scene keeps 100,000 bodies in a box for 10 s of simulated time and checks
//! that every body stays finite and inside.

use std::fmt::Write as _;
use std::path::PathBuf;
use std::time::Instant;

use physics_daemon::gpu::PairMode;
use physics_scenes::LocalPlane;
use shm_layout::PlaneProp;

use super::error::{BenchError, BenchResult};
use super::report::{self, num, Goal};
use super::scene::DT;

/// Options of the `gpu` subcommand.
#[derive(Debug, Clone, clap::Args)]
pub struct GpuArgs {
    /// Small sizes only (1k to 40k bodies) and a 1,000-body stay-in-the-box scene.
    #[arg(long)]
    pub quick: bool,
    /// Largest per-tick time (s) a path may be expected to take at a size; above it the
    /// path is skipped there.
    #[arg(long, default_value_t = 2.0)]
    pub max_tick_s: f64,
    /// Diagnosis only: time each stage of a GPU hash tick (upload, forces, count, scan,
    /// scatter, solve, readback, the CPU pass after it) at 10k and 40k bodies (every stage
    /// submitted and waited for on its own), then the hash path's interleaved 10k → 40k
    /// ratio, and stop (no other paths, sizes, containment or accuracy).
    #[arg(long)]
    pub stages: bool,
    /// Folder receiving gpu.json and gpu.md.
    #[arg(long, default_value = "bench-out")]
    pub out: PathBuf,
}

const SIZES: [usize; 7] = [1_000, 4_000, 10_000, 40_000, 100_000, 400_000, 1_000_000];
const QUICK_SIZES: [usize; 4] = [1_000, 4_000, 10_000, 40_000];
/// time(4N) / time(N) at or below this is O(N).
const GOAL_RATIO: f64 = 4.5;

#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
pub enum Path {
    GpuHash,
    GpuBruteForce,
    CpuRapier,
}

impl Path {
    fn name(self) -> &'static str {
        match self {
            Path::GpuHash => "GPU, spatial hash",
            Path::GpuBruteForce => "GPU, every pair",
            Path::CpuRapier => "CPU, rapier (1 core)",
        }
    }

    /// Growth of the per-tick time with the body count.
    fn exponent(self) -> f64 {
        match self {
            Path::GpuBruteForce => 2.0,
            _ => 1.0,
        }
    }
}

#[derive(Debug, Clone, serde::Serialize)]
pub struct Cell {
    pub bodies: usize,
    pub path: Path,
    /// Median per-tick wall time (ms); `None` when skipped.
    pub tick_ms: Option<f64>,
    /// Ticks timed.
    pub ticks: usize,
    /// Why it was skipped.
    pub skipped: Option<String>,
}

#[derive(Debug, Clone, serde::Serialize)]
pub struct Ratio {
    pub path: Path,
    pub from: usize,
    pub to: usize,
    pub ratio: f64,
}

#[derive(Debug, Clone, serde::Serialize)]
pub struct Containment {
    pub bodies: usize,
    pub seconds: f64,
    pub finite: bool,
    pub escaped: usize,
    pub max_penetration: f32,
    pub tick_ms: f64,
}

/// One accuracy scene (`physics-bench accuracy`'s) at the defaults on both paths.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Accuracy {
    pub scene: String,
    pub measures: String,
    pub unit: String,
    pub cpu_error: Option<f64>,
    /// `None` with `gpu_refused` when the GPU path refuses the scene.
    pub gpu_error: Option<f64>,
    pub gpu_refused: Option<String>,
}

/// One stage of a GPU tick at one size (`physics-bench gpu --stages`).
#[derive(Debug, Clone, serde::Serialize)]
pub struct Stage {
    pub bodies: usize,
    pub stage: String,
    /// Median wall time per tick (ms), summed over the substeps.
    pub ms: f64,
}

#[derive(Debug, Clone, serde::Serialize)]
pub struct GpuReport {
    pub adapter: String,
    pub cells: Vec<Cell>,
    pub ratios: Vec<Ratio>,
    pub containment: Option<Containment>,
    pub accuracy: Vec<Accuracy>,
    /// Per-stage times (`--stages`), empty otherwise.
    pub stages: Vec<Stage>,
    pub goals: Vec<Goal>,
}

/// The accuracy report's scenes at the plane defaults (60 Hz, 4 iterations), on the CPU and
/// on the GPU path.
fn accuracy() -> Vec<Accuracy> {
    use super::sim::Config;
    super::accuracy::scenes::SCENES
        .iter()
        .map(|s| {
            let cpu = (s.run)(Config::DEFAULT).ok().map(|o| o.error);
            let gpu = (s.run)(Config {
                gpu: true,
                ..Config::DEFAULT
            });
            let (gpu_error, gpu_refused) = match gpu {
                Ok(o) => (Some(o.error), None),
                Err(e) => (None, Some(e.to_string())),
            };
            Accuracy {
                scene: s.name.into(),
                measures: s.measures.into(),
                unit: s.unit.into(),
                cpu_error: cpu,
                gpu_error,
                gpu_refused,
            }
        })
        .collect()
}

fn err(e: impl std::fmt::Display) -> BenchError {
    BenchError::Failed(e.to_string())
}

/// Columns of the debris scene: `n` cubes in columns about 10 high.
fn per_row(n: usize) -> usize {
    ((n as f64 / 10.0).sqrt().ceil() as usize).max(1)
}

/// The debris scene on `path`.
fn scene(n: usize, path: Path) -> BenchResult<LocalPlane> {
    let mut plane = LocalPlane::new(1, &[PlaneProp::TickRate(0.0)]).map_err(err)?;
    let rows = per_row(n);
    let (_, width) = physics_scenes::debris_layout(n, rows, 2.0);
    physics_scenes::container(&mut plane, width, 20.0)?;
    physics_scenes::debris(&mut plane, n, rows, 2.0, &[])?;
    if path != Path::CpuRapier {
        plane.set(PlaneProp::DeferGpu(true))?;
    }
    if path == Path::GpuBruteForce {
        plane.set_gpu_pair_mode(PairMode::BruteForce);
    }
    Ok(plane)
}

/// Median tick time (ms): 30 ticks of warm-up (the bottom layers land), then up to 40 ticks
/// or 3 s.
fn time(plane: &mut LocalPlane) -> BenchResult<(f64, usize)> {
    for _ in 0..30 {
        plane.step(DT)?;
    }
    let started = Instant::now();
    let mut samples = Vec::new();
    while samples.len() < 40 && (samples.len() < 3 || started.elapsed().as_secs_f64() < 3.0) {
        let t = Instant::now();
        plane.step(DT)?;
        samples.push(t.elapsed().as_secs_f64() * 1e3);
    }
    let n = samples.len();
    Ok((
        super::stats::median(&samples).ok_or_else(|| err("no samples"))?,
        n,
    ))
}

/// time(4N) / time(N) with the two planes' ticks interleaved after 30 ticks each, so a
/// change in the machine's load hits both alike: median of up to 20 rounds or 4 s.
fn interleaved_ratio(path: Path, n: usize) -> BenchResult<f64> {
    let mut small = scene(n, path)?;
    let mut big = scene(4 * n, path)?;
    for _ in 0..30 {
        small.step(DT)?;
        big.step(DT)?;
    }
    let started = Instant::now();
    let (mut a, mut b) = (Vec::new(), Vec::new());
    while a.len() < 20 && (a.len() < 3 || started.elapsed().as_secs_f64() < 4.0) {
        let t = Instant::now();
        small.step(DT)?;
        a.push(t.elapsed().as_secs_f64());
        let t = Instant::now();
        big.step(DT)?;
        b.push(t.elapsed().as_secs_f64());
    }
    let median = |v: &[f64]| super::stats::median(v).ok_or_else(|| err("no samples"));
    Ok(median(&b)? / median(&a)?)
}

/// Median wall time of each stage of a GPU hash tick at 10k and 40k bodies, the two
/// planes' ticks interleaved after the usual 30 warm-up ticks (20 rounds, each a normal
/// tick and a staged tick of both planes), with `plane (CPU)`: the rest of the plane's step
/// (the state hash and the tick's bookkeeping after the read-back), and `tick, one
/// submission`: the normal tick for comparison with the stages' sum.
fn stages() -> BenchResult<Vec<Stage>> {
    const SIZES: [usize; 2] = [10_000, 40_000];
    let mut planes = Vec::new();
    for n in SIZES {
        planes.push(scene(n, Path::GpuHash)?);
    }
    for _ in 0..30 {
        for plane in &mut planes {
            plane.step(DT)?;
        }
    }
    type Samples = Vec<(&'static str, Vec<f64>)>;
    let mut samples: Vec<Samples> = vec![Vec::new(); SIZES.len()];
    let add = |samples: &mut Samples, stage: &'static str, secs: f64| match samples
        .iter_mut()
        .find(|s| s.0 == stage)
    {
        Some(s) => s.1.push(secs * 1e3),
        None => samples.push((stage, vec![secs * 1e3])),
    };
    for _ in 0..20 {
        for (plane, samples) in planes.iter_mut().zip(&mut samples) {
            plane.set_gpu_stage_timing(false);
            let t = Instant::now();
            plane.step(DT)?;
            add(samples, "tick, one submission", t.elapsed().as_secs_f64());
            plane.set_gpu_stage_timing(true);
            let t = Instant::now();
            plane.step(DT)?;
            let total = t.elapsed().as_secs_f64();
            let times = plane
                .gpu_stage_times()
                .ok_or_else(|| err("not on the GPU"))?;
            let gpu: f64 = times.iter().map(|t| t.1).sum();
            for (stage, secs) in times.into_iter().chain([("plane (CPU)", total - gpu)]) {
                add(samples, stage, secs);
            }
        }
    }
    let mut rows = Vec::new();
    for (n, samples) in SIZES.into_iter().zip(samples) {
        for (stage, v) in samples {
            rows.push(Stage {
                bodies: n,
                stage: stage.into(),
                ms: super::stats::median(&v).ok_or_else(|| err("no samples"))?,
            });
        }
    }
    Ok(rows)
}

/// 100,000 (10,000 quick) bodies in the container for 10 s: finite, inside, penetration.
fn containment(n: usize) -> BenchResult<Containment> {
    let mut plane = scene(n, Path::GpuHash)?;
    let rows = per_row(n);
    let (_, width) = physics_scenes::debris_layout(n, rows, 2.0);
    let ticks = (10.0 / DT).round() as usize;
    let started = Instant::now();
    for _ in 0..ticks {
        plane.step(DT)?;
    }
    let tick_ms = started.elapsed().as_secs_f64() * 1e3 / ticks as f64;
    let half = width / 2.0;
    let (mut finite, mut escaped) = (true, 0);
    // Slots 0..5 are the container.
    for slot in 5..plane.slot_count() {
        let s = plane.body_state(slot);
        let [x, y, z] = s.position;
        finite &= x.is_finite() && y.is_finite() && z.is_finite();
        if !(x.abs() < half && z.abs() < half && y > 0.0) {
            escaped += 1;
        }
    }
    Ok(Containment {
        bodies: n,
        seconds: 10.0,
        finite,
        escaped,
        max_penetration: plane.header().max_penetration,
        tick_ms,
    })
}

pub fn run(args: &GpuArgs) -> BenchResult<()> {
    let adapter = physics_daemon::gpu::adapter_name().map_err(err)?;
    println!("GPU adapter: {adapter}");
    if args.stages {
        return run_stages(&adapter, &args.out);
    }
    let sizes: &[usize] = if args.quick { &QUICK_SIZES } else { &SIZES };
    let mut cells = Vec::new();
    for path in [Path::GpuHash, Path::GpuBruteForce, Path::CpuRapier] {
        let mut last: Option<(usize, f64)> = None;
        for &n in sizes {
            let expected = last.map(|(m, ms)| ms * (n as f64 / m as f64).powf(path.exponent()));
            if let Some(e) = expected.filter(|e| *e > args.max_tick_s * 1e3) {
                println!("{:<22} {n:>9} bodies: skipped", path.name());
                cells.push(Cell {
                    bodies: n,
                    path,
                    tick_ms: None,
                    ticks: 0,
                    skipped: Some(format!(
                        "expected {} ms per tick (above --max-tick-s {})",
                        num(Some(e)),
                        args.max_tick_s
                    )),
                });
                continue;
            }
            let mut plane = scene(n, path)?;
            let (ms, ticks) = time(&mut plane)?;
            drop(plane);
            println!(
                "{:<22} {n:>9} bodies: {} ms per tick",
                path.name(),
                num(Some(ms))
            );
            last = Some((n, ms));
            cells.push(Cell {
                bodies: n,
                path,
                tick_ms: Some(ms),
                ticks,
                skipped: None,
            });
        }
    }
    let mut ratios = Vec::new();
    for a in &cells {
        for b in &cells {
            if a.path == b.path
                && b.bodies == 4 * a.bodies
                && a.tick_ms.is_some()
                && b.tick_ms.is_some()
            {
                let ratio = interleaved_ratio(a.path, a.bodies)?;
                println!(
                    "{:<22} {} → {}: ×{}",
                    a.path.name(),
                    a.bodies,
                    b.bodies,
                    num(Some(ratio))
                );
                ratios.push(Ratio {
                    path: a.path,
                    from: a.bodies,
                    to: b.bodies,
                    ratio,
                });
            }
        }
    }
    let containment = containment(if args.quick { 1_000 } else { 100_000 })?;
    let mut report = GpuReport {
        adapter,
        cells,
        ratios,
        containment: Some(containment),
        accuracy: accuracy(),
        stages: Vec::new(),
        goals: Vec::new(),
    };
    report.goals = goals(&report);
    let md = markdown(&report);
    let (json, md_path) = report::write(&args.out, "gpu", &report, &md)?;
    report::print(&md_path);
    println!("wrote {} and {}", json.display(), md_path.display());
    Ok(())
}

/// `--stages`: per-stage times at 10k and 40k and the hash path's 10k → 40k ratio.
fn run_stages(adapter: &str, out: &std::path::Path) -> BenchResult<()> {
    let rows = stages()?;
    let ratio = interleaved_ratio(Path::GpuHash, 10_000)?;
    println!("GPU, spatial hash 10000 → 40000: ×{}", num(Some(ratio)));
    let mut report = GpuReport {
        adapter: adapter.into(),
        cells: Vec::new(),
        ratios: vec![Ratio {
            path: Path::GpuHash,
            from: 10_000,
            to: 40_000,
            ratio,
        }],
        containment: None,
        accuracy: Vec::new(),
        stages: rows,
        goals: Vec::new(),
    };
    report.goals = goals(&report);
    let md = markdown(&report);
    let (json, md_path) = report::write(out, "gpu-stages", &report, &md)?;
    report::print(&md_path);
    println!("wrote {} and {}", json.display(), md_path.display());
    Ok(())
}

/// The goals: O(N) scaling of the hash path, and the container keeping its bodies.
fn goals(r: &GpuReport) -> Vec<Goal> {
    let mut goals = Vec::new();
    if let Some(x) = r
        .ratios
        .iter()
        .filter(|x| x.path == Path::GpuHash)
        .max_by_key(|x| x.to)
    {
        goals.push(Goal::new(
            format!("GPU hash scales as O(N): time(4N)/time(N) ≤ {GOAL_RATIO} at the largest N"),
            format!("{} ({} → {})", num(Some(x.ratio)), x.from, x.to),
            Some(x.ratio <= GOAL_RATIO),
        ));
    }
    if let Some(c) = &r.containment {
        goals.push(Goal::new(
            format!(
                "{} bodies stay finite and inside the box for 10 s",
                c.bodies
            ),
            format!("finite: {}, outside: {}", c.finite, c.escaped),
            Some(c.finite && c.escaped == 0),
        ));
    }
    goals
}

fn markdown(r: &GpuReport) -> String {
    let mut md = String::new();
    let _ = writeln!(
        md,
        "# GPU path (DeferGpu): time per tick\n\nAdapter: **{}**. Free-falling unit cubes in \
         columns 10 high dropped into an anchored container, in process with the daemon's \
         plane code at 60 Hz (4 substeps), median wall time per tick after 30 ticks (the \
         bottom layers have landed); the GPU figures include reading every state back. The \
         CPU path runs rapier on one core.\n",
        r.adapter
    );
    let mut t = report::Table::new(&[
        "bodies",
        "GPU hash (ms)",
        "GPU every pair (ms)",
        "CPU rapier (ms)",
    ]);
    let mut sizes: Vec<usize> = r.cells.iter().map(|c| c.bodies).collect();
    sizes.dedup();
    sizes.sort_unstable();
    sizes.dedup();
    for n in sizes {
        let cell = |p: Path| {
            r.cells
                .iter()
                .find(|c| c.bodies == n && c.path == p)
                .map(|c| match (c.tick_ms, &c.skipped) {
                    (Some(ms), _) => num(Some(ms)),
                    (None, Some(why)) => format!("skipped: {why}"),
                    _ => "—".into(),
                })
                .unwrap_or_else(|| "—".into())
        };
        t.row(&[
            n.to_string(),
            cell(Path::GpuHash),
            cell(Path::GpuBruteForce),
            cell(Path::CpuRapier),
        ]);
    }
    md.push_str(&t.finish());
    let _ = writeln!(
        md,
        "\nScaling, time(4N) / time(N) (O(N): ≤ {GOAL_RATIO}; O(N²): ≈ 16), measured with \
         the two sizes' ticks interleaved (a change of the machine's load hits both):\n"
    );
    let mut t = report::Table::new(&["path", "N → 4N", "ratio"]);
    for x in &r.ratios {
        t.row(&[
            x.path.name().into(),
            format!("{} → {}", x.from, x.to),
            num(Some(x.ratio)),
        ]);
    }
    md.push_str(&t.finish());
    if let Some(c) = &r.containment {
        let _ = writeln!(
            md,
            "\n{} bodies in the container for {} s: finite {}, {} outside, deepest \
             penetration {:.3}, {} ms per tick.",
            c.bodies,
            c.seconds,
            c.finite,
            c.escaped,
            c.max_penetration,
            num(Some(c.tick_ms))
        );
    }
    if !r.stages.is_empty() {
        let _ = writeln!(
            md,
            "\nStages of a GPU hash tick (median ms per tick, each stage submitted and waited \
             for on its own, summed over the substeps; per body in µs):\n"
        );
        let mut t = report::Table::new(&[
            "stage",
            "10k (ms)",
            "40k (ms)",
            "ratio",
            "10k µs/body",
            "40k µs/body",
        ]);
        for s in r.stages.iter().filter(|s| s.bodies == 10_000) {
            let Some(big) = r
                .stages
                .iter()
                .find(|b| b.bodies == 40_000 && b.stage == s.stage)
            else {
                continue;
            };
            t.row(&[
                s.stage.clone(),
                num(Some(s.ms)),
                num(Some(big.ms)),
                format!("{:.2}", big.ms / s.ms),
                format!("{:.3}", s.ms * 1e3 / 10_000.0),
                format!("{:.3}", big.ms * 1e3 / 40_000.0),
            ]);
        }
        md.push_str(&t.finish());
    }
    let _ = writeln!(
        md,
        "\n## Accuracy: the accuracy report's scenes at the defaults (60 Hz, 4 iterations)\n"
    );
    let mut t = report::Table::new(&["scene", "error measured", "unit", "CPU", "GPU"]);
    for a in &r.accuracy {
        t.row(&[
            a.scene.clone(),
            a.measures.clone(),
            a.unit.clone(),
            a.cpu_error.map_or("—".into(), |e| format!("{e:.3e}")),
            match (&a.gpu_error, &a.gpu_refused) {
                (Some(e), _) => format!("{e:.3e}"),
                (None, Some(why)) => format!("refused: {why}"),
                _ => "—".into(),
            },
        ]);
    }
    md.push_str(&t.finish());
    md
}

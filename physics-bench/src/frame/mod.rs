//! `physics-bench frame`: physics for free. A game loop at 60 frames per second does the same
//! fixed work every frame (the Luau game logic of `game.luau` over one entity per body, then
//! reading every body's pose and writing 100 velocities) in four modes, measured side by
//! side in alternating blocks:
//!
//! - **no physics**: the poses are the game's own array (what a game without physics reads),
//!   the velocity writes go into it;
//! - **daemon**: a 60 Hz daemon plane of `--bodies` bodies (half a settled pile, half awake
//!   cubes flying without gravity) steps on the other core; the frame takes the newest
//!   sample (zero-copy), reads every pose from it, queues the writes and flushes them as one
//!   request, connected as the Luau host is (`refusals_at_next_call`: the flush sends the
//!   writes without waiting for the reply, which the next frame collects);
//! - **in process**: the same world stepped by the daemon's own plane code inside the frame,
//!   poses read from it, writes applied to it;
//! - **daemon, stepped after each frame**: the same daemon plane without its timer; the
//!   frame's end queues one step behind its writes (`Plane::queue_step`) and flushes without
//!   waiting, so the daemon steps while the game sleeps and the next frame reads that tick.
//!
//! The frame time is the wall time of one frame's work (the loop sleeps to the next 60 Hz
//! deadline outside it). The goal is the product's promise in one number: the daemon's
//! median frame within 5 % of the frame without physics, judged by
//! [`Estimator::WallMinOfBlocks`]: each block's median frame, the minimum of each mode's
//! blocks (the modes' blocks run in rounds, forward then backward: A B C D D C B A ...). In
//! process shows 1 + step/frame. Beside it, each block's CPU time per frame of this process
//! and the daemon (schedstat ns).
//! While a block of another mode runs, the daemon plane is paused (TickRate 0), so the no
//! physics and in-process blocks have both cores to themselves as a game without the
//! service would.

use std::hint::black_box;
use std::path::PathBuf;
use std::time::{Duration, Instant};

use client_sdk::{BodyState, Handle, ObjectProp, PlaneProp, Pose};
use physics_scenes::{LocalPlane, SceneTarget};

use super::daemon::DaemonProcess;
use super::error::{BenchError, BenchResult};
use super::estimator::{self, Block, CpuClock, Estimator, JudgedGoal, MinMedian};
use super::report::{self, num, Table};
use super::scene::{asleep_fraction, touch, DT};
use super::stats::{percentile, spread, Spread};

/// The game logic every mode runs (plain Luau, no physics).
const GAME: &str = include_str!("game.luau");

/// Options of the `frame` subcommand.
#[derive(Debug, Clone, clap::Args)]
pub struct FrameArgs {
    /// Simulated bodies: half a settled pile, half awake.
    #[arg(long, default_value_t = 10_000)]
    pub bodies: usize,
    /// Velocities the game writes each frame.
    #[arg(long, default_value_t = 100)]
    pub writes: usize,
    /// Frames per block.
    #[arg(long, default_value_t = 300)]
    pub frames: usize,
    /// Blocks per mode (the modes alternate block by block).
    #[arg(long, default_value_t = 4)]
    pub blocks: usize,
    /// Folder receiving frame.json and frame.md.
    #[arg(long, default_value = "bench-out")]
    pub out: PathBuf,
}

/// How the frame gets its physics.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Mode {
    NoPhysics,
    Daemon,
    InProcess,
    /// The daemon's plane stepped once per frame, queued behind the frame's writes
    /// (`Plane::queue_step`): it steps while the game sleeps.
    DaemonFrameStepped,
}

impl Mode {
    const ALL: [Mode; 4] = [
        Mode::NoPhysics,
        Mode::Daemon,
        Mode::InProcess,
        Mode::DaemonFrameStepped,
    ];

    fn label(self) -> &'static str {
        match self {
            Mode::NoPhysics => "no physics",
            Mode::Daemon => "daemon (other core, 60 Hz timer)",
            Mode::InProcess => "in process",
            Mode::DaemonFrameStepped => "daemon (other core, stepped after each frame)",
        }
    }
}

/// The parts of a frame (medians, ms).
#[derive(Debug, Clone, Copy, serde::Serialize)]
pub struct Phases {
    /// Stepping the physics (in process) or starting the frame (daemon).
    pub step: f64,
    /// The Luau game logic.
    pub game_work: f64,
    /// Reading every pose.
    pub read_poses: f64,
    /// Writing the velocities (the daemon: checked and queued).
    pub write_velocities: f64,
    /// Ending the frame (the daemon: the one request with the frame's writes, until its
    /// reply).
    pub end: f64,
}

/// One mode's frame times.
#[derive(Debug, Clone, serde::Serialize)]
pub struct ModeRow {
    pub mode: Mode,
    pub frames: usize,
    /// Frame time, ms, all blocks together.
    pub frame_ms: Spread,
    /// Medians of the frame's parts, ms.
    pub phases_p50_ms: Phases,
    /// Each block's median frame (wall) and CPU per frame of this process and the daemon,
    /// µs.
    pub blocks: estimator::Side,
    /// What judges `ratio_p50`: [`Estimator::WallMinOfBlocks`].
    pub estimator: Estimator,
    /// This mode's median frame over the no-physics one's: the minima of the blocks'
    /// medians.
    pub ratio_p50: f64,
    /// The same of the medians of the blocks' medians.
    pub ratio_p50_median_of_blocks: f64,
    /// The same of the medians of all frames together.
    pub ratio_p50_pooled: f64,
    /// The same at p99, all frames together ([`Estimator::WallP99OfSamples`]).
    pub ratio_p99: f64,
}

#[derive(Debug, Clone, serde::Serialize)]
pub struct FrameReport {
    pub bodies: usize,
    pub writes: usize,
    pub frames_per_block: usize,
    pub blocks: usize,
    /// Median game work alone (Luau), ms, in the no-physics mode.
    pub game_work_ms: f64,
    /// Median step time of the daemon's plane as its tick headers report it, ms.
    pub daemon_step_ms: f64,
    /// The same while it is stepped after each frame.
    pub frame_stepped_step_ms: f64,
    /// Share of the simulated bodies asleep at the end (the pile's half).
    pub asleep_fraction: f64,
    /// Load average (1 min) at the start and the end of the run.
    pub load_average: [f64; 2],
    pub modes: Vec<ModeRow>,
    pub goals: Vec<JudgedGoal>,
    /// Every estimator's name and meaning.
    pub estimators: std::collections::BTreeMap<&'static str, &'static str>,
}

/// The world of every mode: a settled pile of `settled` cubes on a floor, and `awake` cubes
/// beside it on a grid of spacing 3, without gravity, each flying at 2 units/s in its own
/// fixed direction. Returns the awake cubes.
pub fn world<T: SceneTarget>(
    target: &mut T,
    settled: usize,
    awake: usize,
) -> Result<Vec<T::Handle>, T::Error> {
    physics_scenes::pile(target, settled)?;
    let side = (awake as f64).cbrt().ceil() as usize;
    (0..awake)
        .map(|i| {
            let (x, y, z) = (i % side, (i / side) % side, i / (side * side));
            let at = [-20.0 - x as f32 * 3.0, 2.0 + y as f32 * 3.0, z as f32 * 3.0];
            target.add(
                physics_scenes::cube(1.0),
                Pose::at(at),
                &[
                    ObjectProp::GravityScale(0.0),
                    ObjectProp::Velocity(heading(i, 0)),
                ],
            )
        })
        .collect()
}

/// A fixed direction at 2 units/s for awake body `i` at frame `frame`.
fn heading(i: usize, frame: usize) -> [f32; 3] {
    let a = (i * 37 + frame) as f32 * 0.618;
    let b = (i * 11) as f32 * 0.377;
    [
        2.0 * a.cos() * b.cos(),
        2.0 * b.sin(),
        2.0 * a.sin() * b.cos(),
    ]
}

/// Plane settings of every mode: manual while building, no damping (the awake half keeps
/// its speed).
pub fn plane_props() -> Vec<PlaneProp> {
    vec![
        PlaneProp::TickRate(0.0),
        PlaneProp::LinearDamping(0.0),
        PlaneProp::AngularDamping(0.0),
    ]
}

/// Ticks to settle the pile after building (rapier sleeps a body after 2 s of rest).
pub const SETTLE_TICKS: usize = 180;

/// The game's side of a frame in one mode.
trait Physics {
    /// Advances the physics for this frame (only in process).
    fn step(&mut self) -> BenchResult<()>;
    /// Reads every pose; returns something the optimiser must keep.
    fn read(&mut self) -> BenchResult<f32>;
    /// Writes velocity `v` of awake body `k`.
    fn write(&mut self, k: usize, v: [f32; 3]) -> BenchResult<()>;
    /// Ends the frame (sends the writes).
    fn end(&mut self) -> BenchResult<()>;
    /// Called between blocks: whether the physics runs.
    fn active(&mut self, on: bool) -> BenchResult<()>;
}

struct NoPhysics {
    poses: Vec<BodyState>,
    awake: usize,
}

impl Physics for NoPhysics {
    fn step(&mut self) -> BenchResult<()> {
        Ok(())
    }
    fn read(&mut self) -> BenchResult<f32> {
        Ok(touch(&self.poses))
    }
    fn write(&mut self, k: usize, v: [f32; 3]) -> BenchResult<()> {
        let n = self.poses.len();
        self.poses[n - self.awake + k].linear_velocity = v;
        Ok(())
    }
    fn end(&mut self) -> BenchResult<()> {
        Ok(())
    }
    fn active(&mut self, _: bool) -> BenchResult<()> {
        Ok(())
    }
}

struct Daemon {
    client: client_sdk::Client,
    plane: client_sdk::Plane,
    awake: Vec<client_sdk::Object>,
    step_us: Vec<f64>,
    last_tick: u64,
    /// The frame's end queues the plane's step behind its writes instead of the plane
    /// ticking on its own timer.
    frame_steps: bool,
}

impl Physics for Daemon {
    fn step(&mut self) -> BenchResult<()> {
        self.client.begin_frame();
        Ok(())
    }
    fn read(&mut self) -> BenchResult<f32> {
        let snapshot = self.plane.snapshot()?;
        let header = snapshot.header();
        if header.tick != self.last_tick {
            self.last_tick = header.tick;
            self.step_us.push(header.step_time_us as f64);
        }
        Ok(touch(snapshot.bodies()))
    }
    fn write(&mut self, k: usize, v: [f32; 3]) -> BenchResult<()> {
        Ok(self.awake[k].set_velocity(v)?)
    }
    fn end(&mut self) -> BenchResult<()> {
        if self.frame_steps {
            self.plane.queue_step(DT)?;
        }
        Ok(self.client.flush()?)
    }
    fn active(&mut self, on: bool) -> BenchResult<()> {
        let rate = if on && !self.frame_steps {
            1.0 / DT
        } else {
            0.0
        };
        Ok(self.plane.set_now(PlaneProp::TickRate(rate))?)
    }
}

struct InProcess {
    plane: LocalPlane,
    awake: Vec<Handle>,
}

impl Physics for InProcess {
    fn step(&mut self) -> BenchResult<()> {
        self.plane.step(DT)?;
        Ok(())
    }
    fn read(&mut self) -> BenchResult<f32> {
        let mut sum = 0.0;
        for i in 0..self.plane.slot_count() {
            let b = self.plane.body_state(i);
            sum += b.position[0] + b.position[1] + b.position[2] + b.rotation[3];
        }
        Ok(sum)
    }
    fn write(&mut self, k: usize, v: [f32; 3]) -> BenchResult<()> {
        Ok(self
            .plane
            .set_object(self.awake[k], ObjectProp::Velocity(v))?)
    }
    fn end(&mut self) -> BenchResult<()> {
        Ok(())
    }
    fn active(&mut self, _: bool) -> BenchResult<()> {
        Ok(())
    }
}

/// The Luau game logic: one VM, the `new(n)` of `game.luau` called once.
fn game(n: usize) -> BenchResult<(mlua::Lua, mlua::Function)> {
    let lua = mlua::Lua::new();
    let failed = |e: mlua::Error| BenchError::Failed(format!("game.luau: {e}"));
    let new: mlua::Function = lua
        .load(GAME)
        .set_name("=game.luau")
        .eval()
        .map_err(failed)?;
    let frame: mlua::Function = new.call(n as f64).map_err(failed)?;
    lua.sandbox(true).map_err(failed)?;
    Ok((lua, frame))
}

fn load_average() -> f64 {
    std::fs::read_to_string("/proc/loadavg")
        .ok()
        .and_then(|s| s.split_whitespace().next()?.parse().ok())
        .unwrap_or(f64::NAN)
}

/// Runs `frames` paced frames of `physics`; returns each frame's time (ms) and its
/// [`Phases`] (ms).
fn block(
    physics: &mut dyn Physics,
    game: &mlua::Function,
    args: &FrameArgs,
    awake: usize,
    first_frame: usize,
) -> BenchResult<(Vec<f64>, Vec<[f64; 5]>)> {
    let period = Duration::from_secs_f32(DT);
    let (mut frames, mut phases) = (Vec::with_capacity(args.frames), Vec::new());
    let mut next = Instant::now();
    for f in first_frame..first_frame + args.frames {
        next += period;
        let started = Instant::now();
        physics.step()?;
        let w = Instant::now();
        let _: f64 = game
            .call(DT as f64)
            .map_err(|e| BenchError::Failed(format!("game.luau: {e}")))?;
        let r = Instant::now();
        black_box(physics.read()?);
        let wr = Instant::now();
        for j in 0..args.writes.min(awake) {
            let k = (f * args.writes + j) % awake;
            physics.write(k, heading(k, f))?;
        }
        let e = Instant::now();
        physics.end()?;
        frames.push(started.elapsed().as_secs_f64() * 1e3);
        let ms = |a: Instant, b: Instant| (b - a).as_secs_f64() * 1e3;
        phases.push([
            ms(started, w),
            ms(w, r),
            ms(r, wr),
            ms(wr, e),
            e.elapsed().as_secs_f64() * 1e3,
        ]);
        let now = Instant::now();
        if next > now {
            std::thread::sleep(next - now);
        } else {
            next = now;
        }
    }
    Ok((frames, phases))
}

pub fn run(args: &FrameArgs) -> BenchResult<()> {
    if args.bodies < 2 || args.frames == 0 || args.blocks == 0 {
        return Err(BenchError::Failed(format!(
            "frame needs --bodies ≥ 2, --frames ≥ 1 and --blocks ≥ 1 (got {}, {}, {})",
            args.bodies, args.frames, args.blocks
        )));
    }
    let load_start = load_average();
    eprintln!(
        "frame: {} bodies, {} writes a frame, {} blocks of {} frames per mode (load {load_start})",
        args.bodies, args.writes, args.blocks, args.frames
    );
    // In process.
    let mut local = LocalPlane::new(1, &plane_props())?;
    let local_awake = world(&mut local, args.bodies / 2, args.bodies - args.bodies / 2)?;
    for _ in 0..SETTLE_TICKS {
        local.step(DT)?;
    }
    let awake = local_awake.len();
    // The same world in the daemon.
    let daemon = DaemonProcess::start("frame")?;
    let client = daemon.connect_as_game()?;
    let mut options = client_sdk::PlaneOptions::manual();
    for p in plane_props() {
        options = options.with(p);
    }
    let plane = client.create_plane(&options)?;
    let remote_awake = world(&mut &plane, args.bodies / 2, args.bodies - args.bodies / 2)?;
    client.flush()?;
    for _ in 0..SETTLE_TICKS {
        plane.step(DT)?;
    }
    // No physics: the game's own poses, as the settled world left them.
    let poses: Vec<BodyState> = plane.snapshot()?.bodies().to_vec();
    let mut no_physics = NoPhysics { poses, awake };
    let mut remote = Daemon {
        client: client.clone(),
        plane: plane.clone(),
        awake: remote_awake.clone(),
        step_us: Vec::new(),
        last_tick: 0,
        frame_steps: false,
    };
    let mut frame_stepped = Daemon {
        client: client.clone(),
        plane: plane.clone(),
        awake: remote_awake,
        step_us: Vec::new(),
        last_tick: 0,
        frame_steps: true,
    };
    let mut in_process = InProcess {
        plane: local,
        awake: local_awake,
    };
    let (_lua, game) = game(args.bodies)?;
    let mut times: Vec<Vec<f64>> = vec![Vec::new(); Mode::ALL.len()];
    let mut phases: Vec<Vec<[f64; 5]>> = vec![Vec::new(); Mode::ALL.len()];
    let mut blocks: Vec<Vec<Block>> = vec![Vec::new(); Mode::ALL.len()];
    let clock = CpuClock::new(&[daemon.pid()]);
    let mut frame = 0;
    for round in 0..args.blocks {
        let mut modes: [(usize, &mut dyn Physics); 4] = [
            (0, &mut no_physics),
            (1, &mut remote),
            (2, &mut in_process),
            (3, &mut frame_stepped),
        ];
        // Forward, then backward: each mode as often early as late in a round.
        if round % 2 == 1 {
            modes.reverse();
        }
        for (m, physics) in modes {
            physics.active(true)?;
            // Let the daemon's timer start and the first ticks land before timing.
            std::thread::sleep(Duration::from_millis(50));
            let cpu0 = clock.read()?;
            let (t, w) = block(physics, &game, args, awake, frame)?;
            let cpu = clock.read()?.used_since(&cpu0);
            physics.active(false)?;
            frame += args.frames;
            blocks[m].push(Block {
                wall_us: percentile(&t, 0.5).unwrap_or(f64::NAN) * 1e3,
                cpu_us: cpu as f64 / 1e3 / t.len().max(1) as f64,
            });
            times[m].extend(t);
            phases[m].extend(w);
        }
    }
    // Connected as the Luau host is, refusals wait for a later call: none may be left.
    let refused = client.take_refused(None);
    if let Some(first) = refused.first() {
        return Err(BenchError::Failed(format!(
            "the daemon refused {} of the frames' writes, first: {}",
            refused.len(),
            first.message
        )));
    }
    let asleep = asleep_fraction(plane.snapshot()?.bodies());
    let step_us = std::mem::take(&mut remote.step_us);
    let frame_step_us = std::mem::take(&mut frame_stepped.step_us);
    drop((remote, frame_stepped, plane, client));
    drop(daemon);
    let base = spread(&times[0]).ok_or_else(|| BenchError::Failed("no frames".into()))?;
    let sides = blocks
        .into_iter()
        .map(|b| estimator::Side::of(b).ok_or_else(|| BenchError::Failed("no block".into())))
        .collect::<BenchResult<Vec<_>>>()?;
    let base_blocks = sides[0].wall_us;
    let rows: Vec<ModeRow> = Mode::ALL
        .iter()
        .zip(&times)
        .zip(&phases)
        .zip(sides)
        .map(|(((&mode, t), p), side)| {
            let s = spread(t).unwrap_or(base);
            let median = |k: usize| {
                let v: Vec<f64> = p.iter().map(|x| x[k]).collect();
                percentile(&v, 0.5).unwrap_or(f64::NAN)
            };
            let MinMedian {
                min,
                median: of_medians,
            } = side.wall_us;
            ModeRow {
                mode,
                frames: t.len(),
                frame_ms: s,
                phases_p50_ms: Phases {
                    step: median(0),
                    game_work: median(1),
                    read_poses: median(2),
                    write_velocities: median(3),
                    end: median(4),
                },
                blocks: side,
                estimator: Estimator::WallMinOfBlocks,
                ratio_p50: min / base_blocks.min,
                ratio_p50_median_of_blocks: of_medians / base_blocks.median,
                ratio_p50_pooled: s.p50 / base.p50,
                ratio_p99: s.p99 / base.p99,
            }
        })
        .collect();
    let daemon_row = &rows[1];
    let stepped_row = &rows[3];
    let judged = |r: &ModeRow| {
        format!(
            "{:.3} (medians of blocks {:.3}, all frames {:.3}; CPU per frame {} against {} µs \
             without physics)",
            r.ratio_p50,
            r.ratio_p50_median_of_blocks,
            r.ratio_p50_pooled,
            num(Some(r.blocks.cpu_us.median)),
            num(Some(rows[0].blocks.cpu_us.median))
        )
    };
    let goals = vec![
        JudgedGoal::new(
            daemon_row.estimator,
            format!(
                "frame with the daemon simulating {} bodies on its 60 Hz timer / frame \
                 without physics (p50) ≤ 1.05",
                args.bodies
            ),
            judged(daemon_row),
            Some(daemon_row.ratio_p50 <= 1.05),
        ),
        JudgedGoal::new(
            Estimator::WallP99OfSamples,
            "the same at p99 (no goal)",
            format!("{:.3}", daemon_row.ratio_p99),
            None,
        ),
        JudgedGoal::new(
            stepped_row.estimator,
            format!(
                "frame with the daemon simulating {} bodies, stepped after each frame \
                 (Plane::queue_step) / frame without physics (p50) ≤ 1.05",
                args.bodies
            ),
            judged(stepped_row),
            Some(stepped_row.ratio_p50 <= 1.05),
        ),
        JudgedGoal::new(
            Estimator::WallP99OfSamples,
            "the same at p99 (no goal)",
            format!("{:.3}", stepped_row.ratio_p99),
            None,
        ),
        JudgedGoal::new(
            rows[2].estimator,
            "in process / no physics (p50; 1 + step/frame, no goal)",
            format!("{:.3}", rows[2].ratio_p50),
            None,
        ),
    ];
    let report = FrameReport {
        bodies: args.bodies,
        writes: args.writes,
        frames_per_block: args.frames,
        blocks: args.blocks,
        game_work_ms: rows[0].phases_p50_ms.game_work,
        daemon_step_ms: percentile(&step_us, 0.5).unwrap_or(f64::NAN) / 1e3,
        frame_stepped_step_ms: percentile(&frame_step_us, 0.5).unwrap_or(f64::NAN) / 1e3,
        asleep_fraction: asleep,
        load_average: [load_start, load_average()],
        modes: rows,
        goals,
        estimators: estimator::glossary(),
    };
    let md = markdown(&report);
    let (json, md_path) = report::write(&args.out, "frame", &report, &md)?;
    report::print(&md_path);
    println!("wrote {} and {}", json.display(), md_path.display());
    Ok(())
}

fn markdown(r: &FrameReport) -> String {
    let mut t = Table::new(&[
        "mode",
        "frames",
        "p50 (ms)",
        "p99 (ms)",
        "max (ms)",
        "block p50s min / median (ms)",
        "p50 / no physics",
        "estimator",
        "p99 / no physics",
        "CPU per frame, median of blocks (µs)",
        "step / work / read / write / end, p50 (ms)",
    ]);
    for m in &r.modes {
        t.row(&[
            m.mode.label().into(),
            m.frames.to_string(),
            format!("{:.3}", m.frame_ms.p50),
            format!("{:.3}", m.frame_ms.p99),
            num(Some(m.frame_ms.max)),
            format!(
                "{:.3} / {:.3}",
                m.blocks.wall_us.min / 1e3,
                m.blocks.wall_us.median / 1e3
            ),
            format!("{:.3}", m.ratio_p50),
            m.estimator.name().into(),
            format!("{:.3}", m.ratio_p99),
            num(Some(m.blocks.cpu_us.median)),
            {
                let p = &m.phases_p50_ms;
                format!(
                    "{:.3} / {:.3} / {:.3} / {:.3} / {:.3}",
                    p.step, p.game_work, p.read_poses, p.write_velocities, p.end
                )
            },
        ]);
    }
    format!(
        "# Physics for free\n\nA 60 fps game loop doing the same work every frame: Luau game \
         logic over {} entities ({} ms alone, median), reading every pose of {} bodies (half \
         a settled pile, {:.0} % asleep at the end) and writing {} velocities. The daemon's \
         plane stepped in {} ms on its timer and {} ms stepped after each frame (median tick \
         headers) on the other core. {} blocks of {} frames per mode, in rounds forward then \
         backward; p50 ratios of the minima of the blocks' medians ({}); load \
         average {:.2} → {:.2}.\n\n{}",
        r.bodies,
        num(Some(r.game_work_ms)),
        r.bodies,
        r.asleep_fraction * 100.0,
        r.writes,
        num(Some(r.daemon_step_ms)),
        num(Some(r.frame_stepped_step_ms)),
        r.blocks,
        r.frames_per_block,
        Estimator::WallMinOfBlocks.name(),
        r.load_average[0],
        r.load_average[1],
        t.finish(),
    )
}

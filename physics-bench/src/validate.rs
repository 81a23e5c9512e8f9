//! `physics-bench snapshot --validate`: is a restored plane's replay exact? An awake pile
//! (and one ball flying alone, object 0) is snapshotted, then runs `--validate-ticks` ticks of a
//! command log (a velocity write every tick), keeping every tick's state hash and body
//! array; the snapshot is restored and the log replayed. The first tick whose hash or
//! bodies differ is reported with the first field that differs ("object 0 linvel.x: 1.25
//! vs 1.2500001 at tick 44"), and the run fails. `--inject-tick T` flips the lowest bit of
//! the ball's velocity write at tick T of the replay, to see the report name it.

use client_sdk::{first_difference, BodyState, Client, Object, Plane, PlaneOptions, PlaneProp};
use client_sdk::{Pose, Shape};

use super::daemon::DaemonProcess;
use super::error::{BenchError, BenchResult};
use super::report;

const DT: f32 = 1.0 / 60.0;

/// What the validation found.
#[derive(Debug, Clone, serde::Serialize)]
pub struct ValidateReport {
    pub bodies: usize,
    pub ticks: u32,
    pub snapshot_tick: u64,
    pub snapshot_bytes: usize,
    /// The tick injected into, if any.
    pub injected_tick: Option<u32>,
    /// The first tick (counted from the snapshot) the replay differs at, if any.
    pub diverged_at: Option<u32>,
    /// The first differing field there ("object 0 linvel.x: 1.25 vs 1.2500001 at tick
    /// 44"), or a note that only the state hash differs.
    pub first_difference: Option<String>,
}

/// The ball's velocity write of tick `t` (it flies alone, so a difference in it shows on
/// the ball first).
fn ball_velocity(t: u32) -> [f32; 3] {
    [1.25 + 0.01 * t as f32, 2.0 - 0.05 * t as f32, -0.75]
}

/// A ball far from everything (slot 0), then a pile of `n` boxes on a floor (awake).
fn scene(client: &Client, n: usize) -> BenchResult<(Plane, Object, Vec<Object>)> {
    let plane = client.create_plane(&PlaneOptions::manual().with(PlaneProp::NeverSleep(true)))?;
    let ball = plane.add(
        Shape::Sphere { radius: 0.5 },
        Pose::at([500.0, 50.0, 500.0]),
        &[],
    )?;
    let mut pile = physics_scenes::pile(&mut &plane, n)?;
    pile.remove(0); // the floor
    for _ in 0..10 {
        plane.step(DT)?;
    }
    Ok((plane, ball, pile))
}

/// One run of the log: each tick's hash and bodies.
fn run_log(
    plane: &Plane,
    ball: &Object,
    pile: &[Object],
    ticks: u32,
    inject: Option<u32>,
) -> BenchResult<Vec<(u64, Vec<BodyState>)>> {
    let mut out = Vec::with_capacity(ticks as usize);
    for t in 1..=ticks {
        let mut v = ball_velocity(t);
        if inject == Some(t) {
            v[0] = f32::from_bits(v[0].to_bits() ^ 1);
        }
        ball.set_velocity(v)?;
        if !pile.is_empty() {
            let k = (t as usize * 37) % pile.len();
            pile[k].set_velocity([0.0, 3.0 + 0.1 * t as f32, 0.0])?;
        }
        plane.step(DT)?;
        let sample = plane.snapshot()?;
        out.push((sample.header().state_hash, sample.bodies().to_vec()));
    }
    Ok(out)
}

/// Compares the replay with the first run: the first tick and field that differ.
fn compare(
    first: &[(u64, Vec<BodyState>)],
    again: &[(u64, Vec<BodyState>)],
) -> Option<(u32, String)> {
    for (i, ((h1, b1), (h2, b2))) in first.iter().zip(again).enumerate() {
        let tick = i as u32 + 1;
        if let Some(d) = first_difference(b1, b2) {
            return Some((tick, format!("{d} at tick {tick}")));
        }
        if h1 != h2 {
            return Some((
                tick,
                format!(
                    "state hash {h1:016x} vs {h2:016x} at tick {tick}, every published field \
                     agrees (the engine's internal state differs)"
                ),
            ));
        }
    }
    None
}

/// Runs the validation; an error when the replay diverged.
pub fn run(
    bodies: usize,
    ticks: u32,
    inject: Option<u32>,
    out: &std::path::Path,
) -> BenchResult<()> {
    let daemon = DaemonProcess::start("validate")?;
    let client = daemon.connect()?;
    let (plane, ball, pile) = scene(&client, bodies)?;
    let snapshot = plane.take_snapshot()?;
    eprintln!(
        "validate: {bodies} bodies, snapshot at tick {} ({} bytes), {ticks} ticks",
        snapshot.tick(),
        snapshot.len()
    );
    let first = run_log(&plane, &ball, &pile, ticks, None)?;
    plane.restore(&snapshot)?;
    let again = run_log(&plane, &ball, &pile, ticks, inject)?;
    let found = compare(&first, &again);
    let report = ValidateReport {
        bodies,
        ticks,
        snapshot_tick: snapshot.tick(),
        snapshot_bytes: snapshot.len(),
        injected_tick: inject,
        diverged_at: found.as_ref().map(|f| f.0),
        first_difference: found.as_ref().map(|f| f.1.clone()),
    };
    let md = match &found {
        None => format!(
            "# Snapshot validation\n\nThe replay after a restore matched the first run on \
             every tick ({ticks} ticks, {bodies} bodies): every state hash and every bit of \
             every body.\n"
        ),
        Some((_, what)) => format!("# Snapshot validation\n\nThe replay diverged: {what}.\n"),
    };
    let (json, md_path) = report::write(out, "snapshot-validate", &report, &md)?;
    report::print(&md_path);
    println!("wrote {} and {}", json.display(), md_path.display());
    match found {
        None => Ok(()),
        Some((_, what)) => Err(BenchError::Failed(format!(
            "snapshot validation: the replay diverged: {what}"
        ))),
    }
}

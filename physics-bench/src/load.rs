//! `physics-bench load`: many clients writing at once to one daemon. Each client (a thread
//! with its own `Client`) owns 1,000 objects of one shared manual plane and sends its
//! commands as `SetObject(Velocity)` writes, 1,000 per flush, each write carrying (client,
//! flush, object) as its value. Afterwards the plane is stepped once (no gravity, no
//! damping, no contacts, so velocities pass through unchanged) and every client reads its
//! objects back from shared memory: each must show that client's last write.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::PathBuf;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Barrier, Mutex};
use std::time::{Duration, Instant};

use client_sdk::{Client, Error, Handle, PlaneOptions, Pose, Shape};

use super::daemon::DaemonProcess;
use super::error::{BenchError, BenchResult};
use super::report::{self, num, Goal};
use super::stats::{self, Spread};

/// Options of the `load` subcommand.
#[derive(Debug, Clone, clap::Args)]
pub struct LoadArgs {
    /// 10,000 commands per client instead of 100,000 (seconds instead of a minute).
    #[arg(long)]
    pub quick: bool,
    /// Clients, each a thread with its own connection.
    #[arg(long, default_value_t = 16)]
    pub clients: usize,
    /// Commands each client sends (default 100,000; 10,000 with --quick).
    #[arg(long)]
    pub commands: Option<usize>,
    /// Commands per flush (and objects per client).
    #[arg(long, default_value_t = 1_000)]
    pub batch: usize,
    /// Folder receiving load.json and load.md.
    #[arg(long, default_value = "bench-out")]
    pub out: PathBuf,
}

/// What one client did.
#[derive(Debug, Clone, Default, serde::Serialize)]
pub struct ClientRun {
    pub sent: u64,
    /// Commands whose result was Ok.
    pub acked: u64,
    /// Commands the daemon refused (each with its own error).
    pub refused: u64,
    /// Commands of flushes that got no reply at all.
    pub unanswered: u64,
    pub seconds: f64,
    pub commands_per_s: f64,
    /// Objects whose published velocity is the client's last write.
    pub verified: u64,
    /// Objects showing another value, or missing.
    pub mismatched: u64,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub error: Option<String>,
    #[serde(skip)]
    flush_ms: Vec<f64>,
    #[serde(skip)]
    window: Option<(Instant, Instant)>,
}

#[derive(Debug, Clone, serde::Serialize)]
pub struct LoadReport {
    pub quick: bool,
    pub clients: usize,
    pub commands_per_client: usize,
    pub batch: usize,
    pub objects: usize,
    pub sent: u64,
    pub acked: u64,
    pub refused: u64,
    pub unanswered: u64,
    /// From the first client's first write to the last client's last reply.
    pub seconds: f64,
    pub commands_per_s: f64,
    pub client_commands_per_s: Option<Spread>,
    pub flush_ms: Option<Spread>,
    pub verified_objects: u64,
    pub mismatched_objects: u64,
    pub per_client: Vec<ClientRun>,
    pub goals: Vec<Goal>,
    pub method: BTreeMap<&'static str, &'static str>,
    pub cpus: usize,
}

/// Ticks per second a game frame loop runs at: the rate the throughput goal is made for.
const FRAME_RATE: f64 = 60.0;

pub fn run(args: &LoadArgs) -> BenchResult<()> {
    let clients = args.clients.max(1);
    let batch = args.batch.max(1);
    let per_client = args
        .commands
        .unwrap_or(if args.quick { 10_000 } else { 100_000 });
    let max_clients = clients.max(16).to_string();
    let daemon = DaemonProcess::start_with(
        "load",
        &["--max-clients-per-process".into(), max_clients],
        None,
    )?;
    eprintln!(
        "load: {clients} clients × {per_client} commands ({batch} per flush) on one shared plane"
    );
    let runs = run_clients(&daemon.domain, clients, per_client, batch);
    drop(daemon);
    let runs = runs?;

    let sum = |f: fn(&ClientRun) -> u64| runs.iter().map(f).sum::<u64>();
    let first = runs.iter().filter_map(|r| r.window.map(|w| w.0)).min();
    let last = runs.iter().filter_map(|r| r.window.map(|w| w.1)).max();
    let seconds = match (first, last) {
        (Some(a), Some(b)) => (b - a).as_secs_f64(),
        _ => 0.0,
    };
    let acked = sum(|r| r.acked);
    let flush_ms: Vec<f64> = runs.iter().flat_map(|r| r.flush_ms.clone()).collect();
    let client_rates: Vec<f64> = runs.iter().map(|r| r.commands_per_s).collect();
    let mut report = LoadReport {
        quick: args.quick,
        clients,
        commands_per_client: per_client,
        batch,
        objects: clients * batch.min(per_client),
        sent: sum(|r| r.sent),
        acked,
        refused: sum(|r| r.refused),
        unanswered: sum(|r| r.unanswered),
        seconds,
        commands_per_s: if seconds > 0.0 {
            acked as f64 / seconds
        } else {
            0.0
        },
        client_commands_per_s: stats::spread(&client_rates),
        flush_ms: stats::spread(&flush_ms),
        verified_objects: sum(|r| r.verified),
        mismatched_objects: sum(|r| r.mismatched),
        per_client: runs,
        goals: Vec::new(),
        method: method(),
        cpus: std::thread::available_parallelism().map_or(1, |n| n.get()),
    };
    report.goals = goals(&report);
    let md = render(&report);
    let (json, md_path) = report::write(&args.out, "load", &report, &md)?;
    report::print(&md_path);
    eprintln!("wrote {} and {}", json.display(), md_path.display());
    let errors: Vec<&str> = report
        .per_client
        .iter()
        .filter_map(|r| r.error.as_deref())
        .collect();
    if errors.is_empty() {
        Ok(())
    } else {
        Err(BenchError::Failed(format!(
            "{} client(s) failed: {}",
            errors.len(),
            errors.join("; ")
        )))
    }
}

/// Runs the clients, each in a thread of its own. Client 0 creates the shared plane and
/// steps it once at the end; barriers keep every phase in step even when one client fails.
fn run_clients(
    domain: &str,
    clients: usize,
    per_client: usize,
    batch: usize,
) -> BenchResult<Vec<ClientRun>> {
    let barrier = Barrier::new(clients);
    let plane_id = Mutex::new(None);
    let stepped = AtomicU64::new(0);
    let runs = std::thread::scope(|s| {
        let handles: Vec<_> = (0..clients)
            .map(|i| {
                let (barrier, plane_id, stepped) = (&barrier, &plane_id, &stepped);
                s.spawn(move || {
                    let mut run = ClientRun::default();
                    let phases = Phases {
                        barrier,
                        plane_id,
                        stepped,
                    };
                    if let Err(e) = client(domain, i, per_client, batch, &phases, &mut run) {
                        run.error = Some(format!("client {i}: {e}"));
                    }
                    run
                })
            })
            .collect();
        handles
            .into_iter()
            .map(|h| h.join())
            .collect::<Result<Vec<_>, _>>()
    });
    runs.map_err(|_| BenchError::Failed("a load client thread panicked".into()))
}

/// What the client threads share to keep their phases in step.
struct Phases<'a> {
    barrier: &'a Barrier,
    plane_id: &'a Mutex<Option<client_sdk::PlaneId>>,
    stepped: &'a AtomicU64,
}

/// The velocity write `k` of flush `f` of client `i` carries: different for every flush
/// (by 0.01 at least, far above f32 rounding), so the value read back names the write that
/// won; below rapier's speed cap (400 units/s) for up to 10,000 flushes.
fn value(i: usize, f: usize, k: usize) -> [f32; 3] {
    [
        i as f32 * 0.25,
        (f % 10_000) as f32 * 0.01,
        (k % 10_000) as f32 * 0.01,
    ]
}

/// One client: connect, (create or) attach the plane, add its objects, send its commands,
/// read its objects back. Every barrier is passed even after an error (the other threads
/// wait at them), so the first error is kept and the remaining phases are skipped.
fn client(
    domain: &str,
    i: usize,
    per_client: usize,
    batch: usize,
    phases: &Phases,
    run: &mut ClientRun,
) -> BenchResult<()> {
    let Phases {
        barrier,
        plane_id,
        stepped,
    } = *phases;
    let mut failure: Option<BenchError> = None;

    // Phase 1: connect; client 0 creates the plane.
    let connected = Client::connect(domain);
    let client = match connected {
        Ok(c) => Some(c),
        Err(e) => {
            keep(Err(e.into()), &mut failure);
            None
        }
    };
    if i == 0 {
        if let Some(c) = &client {
            let created = c.create_plane(&PlaneOptions {
                tick_rate: Some(0.0),
                shared: Some(true),
                gravity: Some([0.0; 3]),
                linear_damping: Some(0.0),
                angular_damping: Some(0.0),
                ..Default::default()
            });
            match created {
                Ok(p) => *plane_id.lock().expect("plane id lock") = Some(p.id()),
                Err(e) => keep(Err(e.into()), &mut failure),
            }
        }
    }
    barrier.wait();

    // Phase 2: attach and add this client's objects.
    let id = *plane_id.lock().expect("plane id lock");
    let objects = batch.min(per_client);
    let setup = || -> BenchResult<(client_sdk::Plane, Vec<client_sdk::Object>)> {
        let c = client
            .as_ref()
            .ok_or_else(|| BenchError::Failed("not connected".into()))?;
        let id = id.ok_or_else(|| BenchError::Failed("no shared plane".into()))?;
        let plane = c.attach_plane(id)?;
        let objects = (0..objects)
            .map(|k| {
                // Unit cubes 2 units apart: no contacts.
                let at = [(k % 40) as f32 * 2.0, (k / 40) as f32 * 2.0, i as f32 * 2.0];
                plane.add(Shape::Cube { size: [1.0; 3] }, Pose::at(at), &[])
            })
            .collect::<Result<Vec<_>, _>>()?;
        Ok((plane, objects))
    };
    let set_up = match setup() {
        Ok(v) => Some(v),
        Err(e) => {
            keep(Err(e), &mut failure);
            None
        }
    };
    barrier.wait();

    // Phase 3: the commands, all clients at once.
    if let (Some(c), Some((_, objects))) = (&client, &set_up) {
        keep(send(c, objects, i, per_client, batch, run), &mut failure);
    }
    barrier.wait();

    // Phase 4: client 0 steps the plane once so the daemon publishes every write.
    if i == 0 {
        if let Some((plane, _)) = &set_up {
            match plane.step(1.0 / 60.0) {
                Ok(tick) => stepped.store(tick, Ordering::SeqCst),
                Err(e) => keep(Err(e.into()), &mut failure),
            }
        }
    }
    barrier.wait();

    // Phase 5: read every object back.
    if let Some((plane, objects)) = &set_up {
        let handles: Vec<Handle> = objects.iter().map(|o| o.handle()).collect();
        let tick = stepped.load(Ordering::SeqCst);
        keep(
            verify(plane, &handles, i, per_client, batch, tick, run),
            &mut failure,
        );
    }
    // The plane's owner keeps it (and its client) until every client has read.
    barrier.wait();
    drop(set_up);
    drop(client);
    failure.map_or(Ok(()), Err)
}

/// Keeps the first error.
fn keep(result: BenchResult<()>, failure: &mut Option<BenchError>) {
    if let Err(e) = result {
        failure.get_or_insert(e);
    }
}

/// Sends `per_client` velocity writes, `batch` per flush.
fn send(
    client: &Client,
    objects: &[client_sdk::Object],
    i: usize,
    per_client: usize,
    batch: usize,
    run: &mut ClientRun,
) -> BenchResult<()> {
    let started = Instant::now();
    let mut f = 0;
    let mut left = per_client;
    while left > 0 {
        let count = left.min(batch);
        for (k, object) in objects.iter().take(count).enumerate() {
            object.set_velocity(value(i, f, k))?;
        }
        let t = Instant::now();
        let flushed = client.flush();
        run.flush_ms.push(t.elapsed().as_secs_f64() * 1e3);
        run.sent += count as u64;
        match flushed {
            Ok(()) => run.acked += count as u64,
            Err(Error::Batch(errors)) => {
                run.refused += errors.len() as u64;
                run.acked += (count - errors.len().min(count)) as u64;
            }
            Err(e) => {
                run.unanswered += count as u64;
                return Err(e.into());
            }
        }
        left -= count;
        f += 1;
    }
    let ended = Instant::now();
    run.window = Some((started, ended));
    run.seconds = (ended - started).as_secs_f64();
    run.commands_per_s = run.acked as f64 / run.seconds.max(1e-9);
    Ok(())
}

/// Reads this client's objects from the first sample at or after `tick` and compares each
/// velocity with the client's last write to it.
fn verify(
    plane: &client_sdk::Plane,
    handles: &[Handle],
    i: usize,
    per_client: usize,
    batch: usize,
    tick: u64,
    run: &mut ClientRun,
) -> BenchResult<()> {
    let deadline = Instant::now() + Duration::from_secs(10);
    let snapshot = loop {
        let s = plane.snapshot()?;
        if s.tick() >= tick {
            break s;
        }
        if Instant::now() > deadline {
            return Err(BenchError::Failed(format!(
                "tick {tick} not visible after 10 s (newest {})",
                s.tick()
            )));
        }
        let _ = plane.wait_tick(Duration::from_millis(100));
    };
    let flushes = per_client.div_ceil(batch);
    for (k, &handle) in handles.iter().enumerate() {
        // The last flush that wrote object k.
        let last = (0..flushes)
            .rev()
            .find(|&f| k < (per_client - f * batch).min(batch));
        let Some(last) = last else { continue };
        let expected = value(i, last, k);
        let ok = snapshot.get(handle).is_some_and(|s| {
            s.linear_velocity
                .iter()
                .zip(expected)
                .all(|(a, b)| (a - b).abs() <= 1e-3)
        });
        if ok {
            run.verified += 1;
        } else {
            run.mismatched += 1;
        }
    }
    Ok(())
}

fn method() -> BTreeMap<&'static str, &'static str> {
    BTreeMap::from([
        (
            "setup",
            "one daemon (defaults, --max-clients-per-process raised to the client count when \
             above 16); client 0 creates a shared manual plane without gravity or damping; \
             every client, a thread with its own Client, attaches it and adds one unit cube \
             per command of a flush, 2 units apart (no contacts).",
        ),
        (
            "commands",
            "all clients start together (a barrier); each queues one SetObject(Velocity) \
             per object and flushes, until it has sent its commands; write k of flush f of \
             client i is (i/4, f/100, k/100) units/s (under rapier's 400 units/s cap). A flush that returns Ok had every command applied \
             (acked); a batch error lists the refused ones; any other error is unanswered.",
        ),
        (
            "commands_per_s",
            "acked commands of all clients / time from the first client's first write to \
             the last client's last reply; per client: its acked commands / its own time. \
             flush_ms: the time of each flush call (request, daemon applies 1,000 writes, \
             reply) under the contention of all clients.",
        ),
        (
            "read back",
            "client 0 steps the plane once (velocities pass through unchanged: no forces, no \
             damping, no contacts); every client reads its objects from that tick's shared \
             memory sample: each must show the client's last write to it.",
        ),
    ])
}

fn goals(r: &LoadReport) -> Vec<Goal> {
    let frame_goal = r.clients as f64 * FRAME_RATE * r.batch as f64;
    vec![
        Goal::new(
            "no command lost: every command answered Ok",
            format!(
                "{} of {} acked ({} refused, {} unanswered)",
                r.acked, r.sent, r.refused, r.unanswered
            ),
            Some(r.sent > 0 && r.acked == r.sent && r.refused == 0 && r.unanswered == 0),
        ),
        Goal::new(
            "every object reads back its client's last write",
            format!(
                "{} of {} objects ({} wrong)",
                r.verified_objects, r.objects, r.mismatched_objects
            ),
            Some(r.verified_objects == r.objects as u64 && r.mismatched_objects == 0),
        ),
        Goal::new(
            format!(
                "≥ {} commands/s: every client can flush {} writes each frame at {FRAME_RATE} Hz",
                num(Some(frame_goal)),
                r.batch
            ),
            format!("{} commands/s", num(Some(r.commands_per_s))),
            Some(r.commands_per_s >= frame_goal),
        ),
    ]
}

fn render(r: &LoadReport) -> String {
    let mut md = String::new();
    let _ = writeln!(
        md,
        "# physics-bench load{}\n\n{} clients × {} commands ({} per flush) against one \
         daemon, {} CPU(s), {:.1} s of commands.\n",
        if r.quick { " --quick" } else { "" },
        r.clients,
        r.commands_per_client,
        r.batch,
        r.cpus,
        r.seconds
    );
    let spread = |s: &Option<Spread>| {
        s.map_or("—".into(), |s| {
            format!(
                "{} / {} / {}",
                num(Some(s.p50)),
                num(Some(s.p99)),
                num(Some(s.max))
            )
        })
    };
    let _ = writeln!(
        md,
        "## Throughput\n\n\
         - commands: {} sent, {} acked, {} refused, {} unanswered\n\
         - all clients: {} commands/s\n\
         - per client (p50 / p99 / max): {} commands/s\n\
         - flush of {} writes (p50 / p99 / max): {} ms\n\
         - read back: {} of {} objects show their last write",
        r.sent,
        r.acked,
        r.refused,
        r.unanswered,
        num(Some(r.commands_per_s)),
        spread(&r.client_commands_per_s),
        r.batch,
        spread(&r.flush_ms),
        r.verified_objects,
        r.objects
    );
    md.push_str("\n## Per client\n\n");
    let mut t = report::Table::new(&[
        "client",
        "sent",
        "acked",
        "commands/s",
        "objects verified",
        "error",
    ]);
    for (i, c) in r.per_client.iter().enumerate() {
        t.row(&[
            i.to_string(),
            c.sent.to_string(),
            c.acked.to_string(),
            num(Some(c.commands_per_s)),
            c.verified.to_string(),
            c.error.clone().unwrap_or_default(),
        ]);
    }
    md.push_str(&t.finish());
    md.push_str("\n## Method\n\n");
    for (name, text) in &r.method {
        let _ = writeln!(md, "- **{name}**: {text}");
    }
    md
}

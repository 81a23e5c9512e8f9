//! A fuzzer for the daemon's request decoder and command executor, run against a real
//! daemon process through several clients (`client_sdk::Client::raw_request`), shared by
//! `physics-bench fuzz` and the integration test `tests/tests/fuzz.rs`.
//!
//! Each batch is one of:
//!
//! - structured ([`gen`]): a well-formed frame carrying 1 to 1,000 commands of every
//!   `Command` / `PlaneOp` / `ObjectOp` variant with every `PlaneProp` / `ObjectProp`, each
//!   drawn valid (on the client's own planes and live objects, realistic values, so steps
//!   and property changes run in the engine) or wild (special floats, bogus handles, unknown
//!   planes, degenerate meshes);
//! - raw ([`raw`]): random bytes, or such a frame truncated, bit-flipped, spliced, with a
//!   wrong magic or a wrong layout version;
//! - a quota round: requests built to exceed one daemon quota (commands and bytes per
//!   request, mesh vertices per object and per client, objects and planes per client).
//!
//! After every frame the daemon must still run (the caller's `alive` check) and answer with
//! a reply that decodes as a `Response` of the shape the frame calls for (one result per
//! command, or the rejection the codec predicts, or the version-neutral reply to a frame of
//! another layout version, followed by a probe that must decode). Replies are counted by
//! kind; what the fuzzer learns from them (planes created, handles added or destroyed) is the
//! only state it keeps, so the input is a function of the seed and of earlier replies: one
//! thread drives all clients in turn, and with manual planes the replies, hence the whole
//! run, repeat for a seed (automatically ticking planes add wall-clock timing).

#![deny(missing_docs)]

pub mod gen;
pub mod raw;
pub mod rng;
pub mod stats;
pub mod world;

use std::time::{Duration, Instant};

use client_sdk::{Client, ConnectOptions, Error};
use shm_layout::codec;
use shm_layout::{Command, PlaneId, PlaneOp, PlaneProp, Reply, Request, Response, Shape};

pub use rng::Rng;
pub use stats::{Finding, FuzzStats, OpCount, QuotaRound};

use gen::Gen;
use raw::Expected;
use world::World;

/// The daemon quotas a fuzz run is made for: pass [`Quotas::daemon_args`] to the daemon.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Quotas {
    /// `--max-planes-per-client`.
    pub planes_per_client: usize,
    /// `--max-objects-per-client`.
    pub objects_per_client: u64,
    /// `--max-mesh-vertices`.
    pub mesh_vertices_per_object: u64,
    /// `--max-mesh-vertices-per-client`.
    pub mesh_vertices_per_client: u64,
    /// `--max-request-bytes`.
    pub request_bytes: usize,
    /// `--max-commands-per-request`.
    pub commands_per_request: usize,
}

impl Quotas {
    /// The daemon's defaults for the per-request quotas and the per-object mesh size; the
    /// per-client totals lowered so a round can reach them in milliseconds (at the defaults,
    /// 250,000 objects, a round would measure rapier's memory, not the daemon's checks).
    pub const FUZZ: Quotas = Quotas {
        planes_per_client: 8,
        objects_per_client: 3_000,
        mesh_vertices_per_object: 16_384,
        mesh_vertices_per_client: 50_000,
        request_bytes: 16 << 20,
        commands_per_request: 262_144,
    };

    /// The daemon flags that set these quotas.
    pub fn daemon_args(&self) -> Vec<String> {
        [
            (
                "--max-planes-per-client",
                self.planes_per_client.to_string(),
            ),
            (
                "--max-objects-per-client",
                self.objects_per_client.to_string(),
            ),
            (
                "--max-mesh-vertices",
                self.mesh_vertices_per_object.to_string(),
            ),
            (
                "--max-mesh-vertices-per-client",
                self.mesh_vertices_per_client.to_string(),
            ),
            ("--max-request-bytes", self.request_bytes.to_string()),
            (
                "--max-commands-per-request",
                self.commands_per_request.to_string(),
            ),
        ]
        .into_iter()
        .flat_map(|(flag, value)| [flag.to_string(), value])
        .collect()
    }
}

/// How a fuzz run goes.
#[derive(Debug, Clone)]
pub struct FuzzConfig {
    /// Seeds every random choice.
    pub seed: u64,
    /// Clients (connections) sending frames, in turn from one thread.
    pub clients: usize,
    /// How long to send batches.
    pub duration: Duration,
    /// The quotas the daemon runs with.
    pub quotas: Quotas,
    /// Every this many batches, a quota round (each round exceeds the next quota in turn).
    pub quota_every: u64,
    /// Longest wait for one reply before the request counts as unanswered.
    pub request_timeout: Duration,
    /// Past `duration`, keep sending (up to twice as long again) until every op of
    /// `stats::all_op_names` but Goodbye went out at least once: a short run on a loaded
    /// machine then still covers every op.
    pub until_covered: bool,
}

impl FuzzConfig {
    /// Four clients, [`Quotas::FUZZ`], a quota round every 150 batches.
    pub fn new(seed: u64, duration: Duration) -> FuzzConfig {
        FuzzConfig {
            seed,
            clients: 4,
            duration,
            quotas: Quotas::FUZZ,
            quota_every: 150,
            request_timeout: Duration::from_secs(20),
            until_covered: false,
        }
    }
}

/// The quotas a round can exceed, in the order rounds take them.
pub const QUOTA_FLAGS: [&str; 6] = [
    "--max-commands-per-request",
    "--max-request-bytes",
    "--max-mesh-vertices",
    "--max-objects-per-client",
    "--max-planes-per-client",
    "--max-mesh-vertices-per-client",
];

/// Runs the fuzzer against the daemon of `domain` for `config.duration`. `alive` says
/// whether the daemon process still runs (checked after every frame); `progress` gets the
/// counters about once a second. Fails only when the clients cannot connect; every failure
/// of the daemon is counted in the returned stats.
pub fn run(
    domain: &str,
    config: &FuzzConfig,
    alive: &mut dyn FnMut() -> bool,
    progress: &mut dyn FnMut(&FuzzStats),
) -> Result<FuzzStats, Error> {
    let options = ConnectOptions {
        request_timeout: config.request_timeout,
        ..ConnectOptions::new(domain)
    };
    let clients = (0..config.clients.max(1))
        .map(|_| Client::connect_with(options.clone()))
        .collect::<Result<Vec<_>, _>>()?;
    let mut engine = Engine {
        world: World::new(clients.len()),
        stats: FuzzStats {
            seed: config.seed,
            clients: clients.len(),
            ..FuzzStats::default()
        },
        clients,
        rng: Rng::new(config.seed),
        config,
        alive,
        stop: false,
    };
    let started = Instant::now();
    let mut last_progress = started;
    let more = |stats: &FuzzStats, elapsed: Duration| {
        elapsed < config.duration
            || (config.until_covered
                && elapsed < config.duration * 3
                && stats.ops_not_sent().iter().any(|op| op != "Goodbye"))
    };
    while more(&engine.stats, started.elapsed()) && !engine.stop {
        engine.batch();
        if last_progress.elapsed() >= Duration::from_secs(1) {
            engine.stats.seconds = started.elapsed().as_secs_f64();
            progress(&engine.stats);
            last_progress = Instant::now();
        }
    }
    engine.stats.seconds = started.elapsed().as_secs_f64();
    Ok(engine.stats)
}

/// Where a frame came from, for the counters.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Source {
    Structured,
    Raw,
    Quota,
    Probe,
}

struct Engine<'a> {
    clients: Vec<Client>,
    world: World,
    rng: Rng,
    stats: FuzzStats,
    config: &'a FuzzConfig,
    alive: &'a mut dyn FnMut() -> bool,
    stop: bool,
}

impl Engine<'_> {
    fn batch(&mut self) {
        let c = self.rng.below(self.clients.len());
        let every = self.config.quota_every.max(1);
        let n = self.stats.batches;
        if n % every == every - 1 {
            let flag = QUOTA_FLAGS[(n / every) as usize % QUOTA_FLAGS.len()];
            self.quota_round(c, flag);
        } else if self.world.connected[c] && self.rng.chance(0.25) {
            let base = self.generate(c);
            let valid = codec::encode_request(&Request { commands: base });
            let bytes = raw::frame(&mut self.rng, &valid);
            self.send(c, &bytes, None, Source::Raw);
        } else {
            let commands = self.generate(c);
            self.send_commands(c, commands, Source::Structured);
        }
        self.stats.batches += 1;
    }

    fn generate(&mut self, c: usize) -> Vec<Command> {
        Gen::new(&mut self.rng, &self.world, c).batch()
    }

    fn send_commands(&mut self, c: usize, commands: Vec<Command>, source: Source) -> Vec<Reply> {
        let request = Request { commands };
        let bytes = codec::encode_request(&request);
        match self.send(c, &bytes, Some(&request.commands), source) {
            Some(Response::Results(results)) => {
                results.into_iter().filter_map(Result::ok).collect()
            }
            _ => Vec::new(),
        }
    }

    /// Sends one frame from client `c` and checks the answer. `commands`: the frame's
    /// commands when the caller has them (else they are decoded here, when they decode).
    fn send(
        &mut self,
        c: usize,
        bytes: &[u8],
        commands: Option<&[Command]>,
        source: Source,
    ) -> Option<Response> {
        if self.stop {
            return None;
        }
        self.stats.frames += 1;
        match source {
            Source::Structured => self.stats.structured_frames += 1,
            Source::Raw => self.stats.raw_frames += 1,
            Source::Quota => self.stats.quota_frames += 1,
            Source::Probe => self.stats.probe_frames += 1,
        }
        let q = &self.config.quotas;
        let expected = raw::expected(bytes, q.request_bytes, q.commands_per_request);
        let decoded;
        let commands = match commands {
            Some(c) => Some(c),
            None if matches!(expected, Expected::Results(_)) => {
                decoded = codec::decode_request(bytes).ok();
                decoded.as_ref().map(|r| &r.commands[..])
            }
            None => None,
        };
        let batch = self.stats.batches;
        let reply = match self.clients[c].raw_request(bytes) {
            Ok(reply) => reply,
            Err(e) => {
                if (self.alive)() {
                    self.stats
                        .finding("unanswered", batch, c, e.to_string(), bytes);
                    if matches!(
                        e,
                        Error::Timeout(_) | Error::Stalled { .. } | Error::DaemonGone { .. }
                    ) {
                        self.stop = true;
                    }
                } else {
                    self.daemon_exited(c, bytes, &e.to_string());
                }
                return None;
            }
        };
        let answer = match codec::decode_response(&reply) {
            Ok(response) => {
                let panics = self.stats.plane_panics;
                let fuzzed = matches!(source, Source::Structured | Source::Raw);
                self.stats
                    .count_response(&response, commands.filter(|_| fuzzed));
                if self.stats.plane_panics > panics {
                    let detail = panic_detail(&response, commands);
                    self.stats.finding("plane panic", batch, c, detail, bytes);
                }
                let shape_ok = match (&expected, &response) {
                    (Expected::Results(n), Response::Results(r)) => r.len() == *n,
                    (Expected::Rejected(kind), Response::Rejected(e)) => e.kind == *kind,
                    _ => false,
                };
                if !shape_ok {
                    let detail = format!("expected {expected:?}, got {}", summarise(&response));
                    self.stats.finding("protocol", batch, c, detail, bytes);
                }
                if let (Some(commands), Response::Results(results)) = (commands, &response) {
                    self.world.learn(c, commands, results);
                }
                Some(response)
            }
            // The version-neutral reply carries the daemon's own version, so it parses as a
            // frame of ours with a body that is no Response.
            Err(_) if expected == Expected::VersionReply && reply == version_reply() => {
                self.stats.version_replies += 1;
                None
            }
            Err(e) => {
                let detail = format!("undecodable reply ({} bytes): {e}", reply.len());
                self.stats.finding("crash", batch, c, detail, bytes);
                None
            }
        };
        if !(self.alive)() {
            self.daemon_exited(c, bytes, "after the reply");
            return answer;
        }
        if answer.is_none() && source != Source::Probe && !self.stop {
            // No Response came back: make sure the daemon still answers one.
            let probe = codec::encode_request(&Request { commands: vec![] });
            self.send(c, &probe, Some(&[]), Source::Probe);
        }
        answer
    }

    fn daemon_exited(&mut self, c: usize, bytes: &[u8], what: &str) {
        let batch = self.stats.batches;
        self.stats.finding(
            "crash",
            batch,
            c,
            format!("the daemon process exited ({what})"),
            bytes,
        );
        self.stop = true;
    }

    /// Requests built to exceed `flag`'s quota; counted as hit when the daemon refused with
    /// that quota's error.
    fn quota_round(&mut self, c: usize, flag: &'static str) {
        if !self.world.connected[c] {
            self.send_commands(c, vec![gen::hello()], Source::Quota);
        }
        let before = self.stats.quota_hits.get(flag).copied().unwrap_or(0);
        let q = self.config.quotas;
        match flag {
            "--max-commands-per-request" => {
                let plane = self.any_plane(c);
                let commands =
                    vec![Command::plane(plane, PlaneOp::Info); q.commands_per_request + 1];
                self.send_commands(c, commands, Source::Quota);
            }
            "--max-request-bytes" => {
                let command = if self.rng.chance(0.5) {
                    Command::Hello {
                        crate_version: "x".repeat(q.request_bytes + 1),
                        pid: 0,
                    }
                } else {
                    Command::plane(
                        self.any_plane(c),
                        PlaneOp::AddObject {
                            shape: Shape::Mesh {
                                vertices: vec![[0.5; 3]; q.request_bytes / 12 + 1],
                                triangles: vec![],
                            },
                            pose: Default::default(),
                            props: vec![],
                        },
                    )
                };
                self.send_commands(c, vec![command], Source::Quota);
            }
            "--max-mesh-vertices" => {
                if let Some(plane) = self.fresh_plane(c) {
                    let n = q.mesh_vertices_per_object as usize + 1;
                    let add = PlaneOp::AddObject {
                        shape: Shape::Mesh {
                            vertices: gen::sphere_points(n),
                            triangles: vec![],
                        },
                        pose: Default::default(),
                        props: vec![],
                    };
                    self.send_commands(
                        c,
                        vec![
                            Command::plane(plane, add),
                            Command::plane(plane, PlaneOp::Destroy),
                        ],
                        Source::Quota,
                    );
                }
            }
            "--max-objects-per-client" => {
                if let Some(plane) = self.fresh_plane(c) {
                    let n = q.objects_per_client as usize + 1;
                    let mut commands: Vec<Command> = (0..n)
                        .map(|i| {
                            let at = [(i % 100) as f32, 0.0, (i / 100) as f32];
                            Command::plane(plane, gen::small_cube(at))
                        })
                        .collect();
                    commands.push(Command::plane(plane, PlaneOp::Destroy));
                    self.send_commands(c, commands, Source::Quota);
                }
            }
            "--max-planes-per-client" => {
                let create = Command::CreatePlane {
                    kind: Default::default(),
                    props: vec![PlaneProp::TickRate(0.0)],
                };
                let created =
                    self.send_commands(c, vec![create; q.planes_per_client + 1], Source::Quota);
                let destroy: Vec<Command> = created
                    .iter()
                    .filter_map(|r| match r {
                        Reply::Plane(info) => Some(Command::plane(info.id, PlaneOp::Destroy)),
                        _ => None,
                    })
                    .collect();
                if !destroy.is_empty() {
                    self.send_commands(c, destroy, Source::Quota);
                }
            }
            _ => {
                if let Some(plane) = self.fresh_plane(c) {
                    let per = q.mesh_vertices_per_object.min(q.mesh_vertices_per_client) as usize;
                    let parts = (q.mesh_vertices_per_client as usize / per.max(1)) + 1;
                    let mut commands = Vec::new();
                    for i in 0..parts {
                        let vertices = (0..per)
                            .map(|_| [0; 3].map(|_| self.rng.f32_in(-1.0, 1.0)))
                            .collect();
                        let add = PlaneOp::AddObject {
                            shape: Shape::Mesh {
                                vertices,
                                triangles: vec![],
                            },
                            pose: shm_layout::Pose::at([3.0 * i as f32, 0.0, 0.0]),
                            props: vec![shm_layout::ObjectProp::Anchored(true)],
                        };
                        commands.push(Command::plane(plane, add));
                    }
                    commands.push(Command::plane(plane, PlaneOp::Destroy));
                    self.send_commands(c, commands, Source::Quota);
                }
            }
        }
        let after = self.stats.quota_hits.get(flag).copied().unwrap_or(0);
        let round = self.stats.quota_rounds.entry(flag.to_string()).or_default();
        round.runs += 1;
        round.hit += (after > before) as u64;
    }

    /// One of the client's planes, or any id (per-request quotas are checked before it).
    fn any_plane(&mut self, c: usize) -> PlaneId {
        let own = self.world.own_planes(c);
        if own.is_empty() {
            1
        } else {
            *self.rng.pick(&own)
        }
    }

    /// A new empty manual plane of client `c`, made room for by destroying the client's
    /// other planes but two (so the new plane's objects meet the client's quota alone, as
    /// far as these two allow).
    fn fresh_plane(&mut self, c: usize) -> Option<PlaneId> {
        let mut commands: Vec<Command> = self
            .world
            .own_planes(c)
            .into_iter()
            .skip(2)
            .map(|id| Command::plane(id, PlaneOp::Destroy))
            .collect();
        for id in self.world.own_planes(c).into_iter().take(2) {
            if self.world.planes[&id].live.len() > 20 {
                commands.push(Command::plane(id, PlaneOp::Destroy));
            }
        }
        let create = Command::CreatePlane {
            kind: Default::default(),
            props: vec![PlaneProp::TickRate(0.0)],
        };
        commands.push(create.clone());
        if let Some(Reply::Plane(info)) = self.send_commands(c, commands, Source::Quota).last() {
            return Some(info.id);
        }
        // Quotas count per process and every fuzzing client shares this one: make room by
        // letting every client destroy its planes, then try once more.
        for k in 0..self.clients.len() {
            let destroy: Vec<Command> = self
                .world
                .own_planes(k)
                .into_iter()
                .map(|id| Command::plane(id, PlaneOp::Destroy))
                .collect();
            if !destroy.is_empty() {
                self.send_commands(k, destroy, Source::Quota);
            }
        }
        match self.send_commands(c, vec![create], Source::Quota).last() {
            Some(Reply::Plane(info)) => Some(info.id),
            _ => None,
        }
    }
}

/// The message of the first plane failure in `response`, and the command that met it.
fn panic_detail(response: &Response, commands: Option<&[Command]>) -> String {
    let Response::Results(results) = response else {
        return String::new();
    };
    let Some((i, e)) = results.iter().enumerate().find_map(|(i, r)| match r {
        Err(e) if e.message.contains("failed and was removed") => Some((i, e)),
        _ => None,
    }) else {
        return String::new();
    };
    let mut command = commands
        .and_then(|c| c.get(i))
        .map_or_else(|| "?".to_string(), |c| format!("{c:?}"));
    if command.len() > 600 {
        let cut = (0..=600)
            .rev()
            .find(|&k| command.is_char_boundary(k))
            .unwrap_or(0);
        command.truncate(cut);
        command.push_str(" …");
    }
    format!("{} (command {i}: {command})", e.message)
}

/// What the daemon answers to a frame of another layout version.
fn version_reply() -> &'static [u8] {
    static REPLY: std::sync::OnceLock<Vec<u8>> = std::sync::OnceLock::new();
    REPLY.get_or_init(codec::encode_version_mismatch)
}

/// A short description of a response.
fn summarise(response: &Response) -> String {
    match response {
        Response::Results(r) => format!("{} results", r.len()),
        Response::Rejected(e) => format!("rejected: {e}"),
    }
}

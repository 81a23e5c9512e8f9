//! The viewer's one client of the daemon. `Client` and its ports are not `Send`, so they
//! live on this thread alone: it lists the domain's planes, samples each plane's newest tick
//! header a few times a second (the plane list and the plots), and answers the web server's
//! jobs (a plane's bodies, a body's properties, controls) from the newest published tick.
//! It only reads shared memory and asks read-only questions, except for the controls, which
//! the server refuses unless `--allow-control` was given. With `--replay FILE` it also owns
//! the replay ([`crate::replay::Player`]): the plane it plays into is one of its client's,
//! so the replay lives on this thread too and advances between jobs.

use std::collections::{BTreeMap, HashMap, VecDeque};
use std::sync::mpsc::{Receiver, RecvTimeoutError};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use client_sdk::{
    Client, Contact, Error, Handle, Plane, PlaneId, PlaneInfo, PlaneKind, PlaneProp, FLAG_ON_GROUND,
};
use serde::Serialize;
use serde_json::{json, Value};
use shm_layout::FLAG_CONTROLLER;
use tokio::sync::oneshot;

use crate::describe::{bodies_of, body_json, describe, to_json};
use crate::joints::{self, JointCache, PoseOf};
use crate::replay::{Player, Refusal, ReplayRequest};

/// How often tick headers are sampled for the plane list and the plots.
pub const SAMPLE_PERIOD: Duration = Duration::from_millis(100);
/// How often the plane list and each plane's options are asked for again.
const LIST_PERIOD: Duration = Duration::from_secs(1);
/// How often a lost daemon is looked for again.
const RECONNECT_PERIOD: Duration = Duration::from_secs(1);
/// Shapes and sizes of bodies are asked for again after this long (Size can change).
const SHAPE_REFRESH: Duration = Duration::from_secs(2);
/// Most object descriptions fetched for one snapshot (a plane of 50,000 new bodies is
/// described over several frames instead of stalling one).
const SHAPE_FETCHES_PER_SNAPSHOT: usize = 500;
/// Most contacts kept per plane for the overlay.
const MAX_CONTACTS: usize = 4096;

/// What the web server asks of the sampler; each job carries its answer's channel.
pub enum Job {
    /// Every live body of a plane at its newest tick, with shapes and overlays.
    Snapshot {
        /// The plane.
        plane: PlaneId,
        /// The answer.
        reply: oneshot::Sender<Result<Value, String>>,
    },
    /// Every property of one body.
    Body {
        /// The plane.
        plane: PlaneId,
        /// The body's slot.
        slot: u32,
        /// The answer.
        reply: oneshot::Sender<Result<Value, String>>,
    },
    /// Pause, step or resume a plane.
    Control {
        /// The plane.
        plane: PlaneId,
        /// What to do.
        action: Action,
        /// The answer.
        reply: oneshot::Sender<Result<Value, String>>,
    },
    /// Say goodbye to the daemon and exit the process.
    Shutdown,
    /// A plane's whole state as a snapshot file's bytes (`PlaneSnapshot`), for "download
    /// snapshot": its tick and bytes.
    Download {
        /// The plane.
        plane: PlaneId,
        /// The answer.
        reply: oneshot::Sender<Result<(u64, Vec<u8>), String>>,
    },
    /// The replay's timeline: its state (`request` `None`) or a play, pause, step, seek or
    /// speed change, answered with the state after it.
    Replay {
        /// What to do, if anything.
        request: Option<ReplayRequest>,
        /// The answer, or an HTTP status and why not.
        reply: oneshot::Sender<Result<Value, (u16, String)>>,
    },
}

/// A control of the page.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Action {
    /// `Enabled = false`.
    Pause,
    /// `Enabled = true`.
    Resume,
    /// One `Step(1 / TickRate)` (1/60 s for a manual plane).
    Step,
}

impl Action {
    /// The action named in a URL.
    pub fn parse(name: &str) -> Option<Action> {
        match name {
            "pause" => Some(Action::Pause),
            "resume" => Some(Action::Resume),
            "step" => Some(Action::Step),
            _ => None,
        }
    }
}

/// One row of the plane list.
#[derive(Debug, Clone, Serialize)]
pub struct PlaneSummary {
    /// The plane's id.
    pub id: PlaneId,
    /// `Rapier3d` or `Gui2d`.
    pub kind: &'static str,
    /// Live bodies at the newest tick.
    pub body_count: u32,
    /// The newest tick.
    pub tick: u64,
    /// Simulated seconds.
    pub sim_time: f64,
    /// `TickRate` (0: manual).
    pub tick_rate: f32,
    /// `Enabled`.
    pub enabled: bool,
    /// Wall time of the last step (µs).
    pub step_time_us: f32,
    /// Deepest contact penetration of the last step.
    pub max_penetration: f32,
    /// Contact pairs after the last step.
    pub contact_pairs: u32,
    /// Largest joint error after the last step.
    pub max_joint_error: f32,
    /// The plane plays the recording of `--replay`.
    pub replay: bool,
}

/// The last minutes of one plane's tick-header figures, one point per sampled tick.
#[derive(Debug, Clone, Default, Serialize)]
pub struct History {
    /// Simulated time of each point (s).
    pub sim_time: VecDeque<f64>,
    /// `step_time_us`.
    pub step_time_us: VecDeque<f32>,
    /// `max_penetration`.
    pub max_penetration: VecDeque<f32>,
    /// `contact_pairs`.
    pub contact_pairs: VecDeque<u32>,
    /// `max_joint_error`.
    pub max_joint_error: VecDeque<f32>,
}

impl History {
    fn push(&mut self, h: &shm_layout::TickHeader, keep: usize) {
        self.sim_time.push_back(h.sim_time);
        self.step_time_us.push_back(h.step_time_us);
        self.max_penetration.push_back(h.max_penetration);
        self.contact_pairs.push_back(h.contact_pairs);
        self.max_joint_error.push_back(h.max_joint_error);
        while self.sim_time.len() > keep {
            self.sim_time.pop_front();
            self.step_time_us.pop_front();
            self.max_penetration.pop_front();
            self.contact_pairs.pop_front();
            self.max_joint_error.pop_front();
        }
    }
}

/// What the sampler publishes for the web server: read under a short lock, never waiting
/// for the daemon.
#[derive(Debug, Default)]
pub struct Overview {
    /// Connected to a live daemon.
    pub connected: bool,
    /// Why not, when not.
    pub error: Option<String>,
    /// The daemon's process id (0 when not connected).
    pub daemon_pid: u32,
    /// Every plane, by id.
    pub planes: Vec<PlaneSummary>,
    /// Figures over time, by plane.
    pub histories: HashMap<PlaneId, History>,
    /// The recording played (`--replay FILE`).
    pub replay_file: Option<String>,
    /// The plane it plays into, while a daemon runs it.
    pub replay_plane: Option<PlaneId>,
}

/// A body's shape as drawn, and what else its description adds (controllers, GUI).
struct Known {
    generation: u32,
    fetched: Instant,
    view: Value,
}

/// A contact reported by the event stream and not ended yet.
#[derive(Clone, Copy)]
struct Touch {
    position: [f32; 3],
    normal: [f32; 3],
    impulse: f32,
    tick: u64,
}

/// A plane the viewer reads.
struct Watched {
    plane: Plane,
    info: PlaneInfo,
    shapes: HashMap<u32, Known>,
    contacts: HashMap<(Handle, Handle), Touch>,
    last_tick: Option<u64>,
    /// The plane's joints as last listed (a 3D plane's; GUI planes have none).
    joints: JointCache,
}

/// The sampler's state (lives on its own thread).
struct Sampler {
    domain: String,
    client: Option<Client>,
    planes: BTreeMap<PlaneId, Watched>,
    shared: Arc<Mutex<Overview>>,
    history_points: usize,
    last_list: Option<Instant>,
    last_connect: Option<Instant>,
    /// The replay of `--replay FILE`.
    player: Option<Player>,
    /// The daemon this viewer started for its replay (none ran); stopped when it exits.
    daemon: Option<client_sdk::DaemonChild>,
}

/// A replay to start before anything else, and where to say whether it started (its
/// plane) or why not.
pub struct ReplayStart {
    /// The file, as named.
    pub path: String,
    /// Its recording, read and checked.
    pub recording: Arc<client_sdk::Recording>,
    /// The answer.
    pub ready: std::sync::mpsc::Sender<Result<PlaneId, String>>,
}

/// Runs the sampler until the job channel closes or a `Shutdown` job arrives. With a
/// replay, it first connects (starting a daemon for the domain when none runs) and starts
/// the replay; when that fails it says why on `ready` and returns.
pub fn run(
    domain: String,
    shared: Arc<Mutex<Overview>>,
    jobs: Receiver<Job>,
    history_seconds: f64,
    replay: Option<ReplayStart>,
) {
    let history_points =
        ((history_seconds / SAMPLE_PERIOD.as_secs_f64()).ceil() as usize).clamp(10, 1_000_000);
    let mut sampler = Sampler {
        domain,
        client: None,
        planes: BTreeMap::new(),
        shared,
        history_points,
        last_list: None,
        last_connect: None,
        player: None,
        daemon: None,
    };
    if let Some(ReplayStart {
        path,
        recording,
        ready,
    }) = replay
    {
        let player = Player::new(path, recording);
        {
            let mut o = sampler.shared.lock().expect("overview lock");
            o.replay_file = Some(player.path().to_string());
        }
        sampler.player = Some(player);
        sampler.last_connect = Some(Instant::now());
        let started = sampler.connect_now();
        let failed = started.is_err();
        let started = started.map(|()| sampler.replay_plane().unwrap_or_default());
        let _ = ready.send(started.map_err(|e| e.to_string()));
        if failed {
            sampler.stop();
            return;
        }
    }
    let mut next = Instant::now();
    loop {
        if Instant::now() >= next {
            sampler.housekeeping();
            next = Instant::now() + SAMPLE_PERIOD;
        }
        sampler.pump();
        let wake = sampler
            .player
            .as_ref()
            .and_then(Player::due)
            .map_or(next, |due| due.min(next));
        match jobs.recv_timeout(wake.saturating_duration_since(Instant::now())) {
            Ok(Job::Shutdown) => {
                sampler.stop();
                std::process::exit(0);
            }
            Ok(job) => sampler.handle(job),
            Err(RecvTimeoutError::Timeout) => {}
            Err(RecvTimeoutError::Disconnected) => return,
        }
    }
}

/// Whether an error means the daemon is gone (then the client is dropped and a new daemon
/// of the domain is looked for), rather than one plane or body being gone (a plane's
/// services vanish when it is destroyed: those are `Ipc` errors, and a daemon that died
/// shows up as `DaemonGone` at the next request).
fn daemon_lost(e: &Error) -> bool {
    matches!(
        e,
        Error::NoDaemon { .. }
            | Error::DaemonGone { .. }
            | Error::Stalled { .. }
            | Error::Timeout(_)
    )
}

fn kind_name(kind: PlaneKind) -> &'static str {
    match kind {
        PlaneKind::Rapier3d => "Rapier3d",
        PlaneKind::Gui2d => "Gui2d",
    }
}

impl Sampler {
    fn housekeeping(&mut self) {
        if self.client.is_none() {
            if self
                .last_connect
                .is_some_and(|t| t.elapsed() < RECONNECT_PERIOD)
            {
                return;
            }
            self.last_connect = Some(Instant::now());
            if let Err(e) = self.connect_now() {
                let mut o = self.shared.lock().expect("overview lock");
                o.connected = false;
                o.error = Some(e.to_string());
                return;
            }
        }
        if let Err(e) = self.sample() {
            self.check(&e);
        }
    }

    /// Connects to the domain's daemon (with a replay: starting one when none runs) and
    /// starts the replay in it.
    fn connect_now(&mut self) -> Result<(), Error> {
        let client = match Client::connect(&self.domain) {
            Ok(client) => client,
            Err(Error::NoDaemon { .. }) if self.player.is_some() => self.start_daemon()?,
            Err(e) => return Err(e),
        };
        tracing::info!(domain = self.domain, pid = client.daemon_pid(), "connected");
        {
            let mut o = self.shared.lock().expect("overview lock");
            o.connected = true;
            o.error = None;
            o.daemon_pid = client.daemon_pid();
        }
        self.client = Some(client.clone());
        self.last_list = None;
        let Some(player) = self.player.as_mut() else {
            return Ok(());
        };
        let id = match player.start(&client) {
            Ok(id) => id,
            Err(e) => {
                player.lost(&e.to_string());
                return Err(e);
            }
        };
        let (first, last) = player.range();
        // The camera's framing: the bodies as the recording starts and as it ends (the
        // way there restores the last keyframe before the end: at most one keyframe
        // interval of steps), then back to the start.
        let mut fit = bodies_of(self.snapshot(id)?);
        if last > first {
            if let Some(player) = self.player.as_mut() {
                player.jump(last)?;
            }
            fit.extend(bodies_of(self.snapshot(id)?));
            if let Some(player) = self.player.as_mut() {
                player.jump(first)?;
            }
        }
        if let Some(player) = self.player.as_mut() {
            player.set_fit(&fit);
        }
        self.shared.lock().expect("overview lock").replay_plane = Some(id);
        Ok(())
    }

    /// Starts a daemon for the domain (its log in a file of the temporary folder), as
    /// `physics-lua` does when none runs; it exits with this process.
    fn start_daemon(&mut self) -> Result<Client, Error> {
        // One that died is reaped first.
        self.daemon = None;
        let log = std::env::temp_dir().join(format!("physics-daemon-{}.log", self.domain));
        let stderr = std::fs::File::create(&log)
            .map(std::process::Stdio::from)
            .unwrap_or_else(|_| std::process::Stdio::inherit());
        let (child, client) = client_sdk::start_daemon_with(&self.domain, &[], stderr)?;
        eprintln!(
            "physics-view: no daemon served domain {}: started one (pid {}, log {})",
            self.domain,
            child.pid(),
            log.display()
        );
        self.daemon = Some(child);
        Ok(client)
    }

    /// Says goodbye to the daemon (the replay's plane goes with the client) and stops the
    /// daemon this viewer started, if it did.
    fn stop(&mut self) {
        self.player = None;
        self.planes.clear();
        self.client = None;
        self.daemon = None;
    }

    /// Advances the replay's ticks that are due.
    fn pump(&mut self) {
        let Some(player) = self.player.as_mut() else {
            return;
        };
        if player.due().is_some_and(|due| due <= Instant::now()) {
            if let Err(e) = player.pump() {
                self.check(&e);
            }
        }
    }

    /// The plane the replay plays into.
    fn replay_plane(&self) -> Option<PlaneId> {
        self.player.as_ref().and_then(Player::plane_id)
    }

    /// Drops the client when `e` says the daemon is gone.
    fn check(&mut self, e: &Error) {
        if daemon_lost(e) {
            tracing::warn!("daemon lost: {e}");
            self.planes.clear();
            self.client = None;
            if let Some(player) = self.player.as_mut() {
                player.lost(&e.to_string());
            }
            let mut o = self.shared.lock().expect("overview lock");
            o.connected = false;
            o.daemon_pid = 0;
            o.error = Some(e.to_string());
            o.planes.clear();
            o.replay_plane = None;
        }
    }

    /// Lists planes (once a second) and samples every plane's newest header.
    fn sample(&mut self) -> Result<(), Error> {
        let Some(client) = self.client.clone() else {
            return Ok(());
        };
        if self.last_list.is_none_or(|t| t.elapsed() >= LIST_PERIOD) {
            self.last_list = Some(Instant::now());
            let ids = client.plane_ids()?;
            let gone: Vec<PlaneId> = self
                .planes
                .keys()
                .filter(|id| !ids.contains(id))
                .copied()
                .collect();
            for id in gone {
                self.planes.remove(&id);
                client.detach_plane(id);
            }
            for id in ids {
                match self.planes.get_mut(&id) {
                    Some(w) => match w.plane.info() {
                        Ok(info) => w.info = info,
                        Err(e) if daemon_lost(&e) => return Err(e),
                        Err(_) => {
                            self.planes.remove(&id);
                            client.detach_plane(id);
                        }
                    },
                    None => match Self::attach(&client, id) {
                        Ok(w) => {
                            self.planes.insert(id, w);
                        }
                        Err(e) if daemon_lost(&e) => return Err(e),
                        // Destroyed between the list and the attach: gone already.
                        Err(_) => {}
                    },
                }
            }
        }
        let mut summaries = Vec::with_capacity(self.planes.len());
        let mut fresh = Vec::new();
        let replay = self.replay_plane();
        for (id, w) in &mut self.planes {
            let Ok(snap) = w.plane.snapshot() else {
                continue;
            };
            let h = *snap.header();
            drain_contacts(w)?;
            summaries.push(PlaneSummary {
                id: *id,
                kind: kind_name(w.info.kind),
                body_count: h.body_count,
                tick: h.tick,
                sim_time: h.sim_time,
                tick_rate: w.info.tick_rate,
                enabled: w.info.enabled,
                step_time_us: h.step_time_us,
                max_penetration: h.max_penetration,
                contact_pairs: h.contact_pairs,
                max_joint_error: h.max_joint_error,
                replay: replay == Some(*id),
            });
            if w.last_tick != Some(h.tick) {
                w.last_tick = Some(h.tick);
                fresh.push((*id, h));
            }
        }
        let mut o = self.shared.lock().expect("overview lock");
        o.planes = summaries;
        let live: Vec<PlaneId> = self.planes.keys().copied().collect();
        o.histories.retain(|id, _| live.contains(id));
        for (id, h) in fresh {
            o.histories
                .entry(id)
                .or_default()
                .push(&h, self.history_points);
        }
        Ok(())
    }

    fn attach(client: &Client, id: PlaneId) -> Result<Watched, Error> {
        let plane = client.attach_plane(id)?;
        let info = plane.info()?;
        // Contact events (of objects that report them) feed the contact overlay.
        plane.subscribe_events()?;
        Ok(Watched {
            plane,
            info,
            shapes: HashMap::new(),
            contacts: HashMap::new(),
            last_tick: None,
            joints: JointCache::default(),
        })
    }

    /// The plane `id`, attached now if the list has not caught up with it yet.
    fn watched(&mut self, id: PlaneId) -> Result<&mut Watched, Error> {
        let client = self.client.clone().ok_or_else(|| Error::NoDaemon {
            domain: self.domain.clone(),
            detail: "not connected".into(),
        })?;
        match self.planes.entry(id) {
            std::collections::btree_map::Entry::Occupied(e) => Ok(e.into_mut()),
            std::collections::btree_map::Entry::Vacant(e) => {
                Ok(e.insert(Self::attach(&client, id)?))
            }
        }
    }

    fn handle(&mut self, job: Job) {
        let (result, reply) = match job {
            Job::Snapshot { plane, reply } => (self.snapshot(plane), reply),
            Job::Body { plane, slot, reply } => (self.body(plane, slot), reply),
            Job::Control {
                plane,
                action,
                reply,
            } => (self.control(plane, action), reply),
            Job::Shutdown => unreachable!("handled by run"),
            Job::Download { plane, reply } => {
                let result = self.download(plane).map_err(|e| {
                    let message = e.to_string();
                    self.check(&e);
                    message
                });
                let _ = reply.send(result);
                return;
            }
            Job::Replay { request, reply } => {
                let _ = reply.send(self.replay(request));
                return;
            }
        };
        let result = result.map_err(|e| {
            let message = e.to_string();
            self.check(&e);
            message
        });
        let _ = reply.send(result);
    }

    /// The replay's state, after `request` if any.
    fn replay(&mut self, request: Option<ReplayRequest>) -> Result<Value, (u16, String)> {
        let Some(player) = self.player.as_mut() else {
            return Err((
                404,
                "not replaying: start physics-view with --replay FILE".to_string(),
            ));
        };
        let Some(request) = request else {
            return Ok(player.status());
        };
        match player.act(request) {
            Ok(v) => Ok(v),
            Err(Refusal::Conflict(message)) => Err((409, message)),
            Err(Refusal::Daemon(e)) => {
                let message = e.to_string();
                self.check(&e);
                Err((503, message))
            }
        }
    }

    fn snapshot(&mut self, id: PlaneId) -> Result<Value, Error> {
        let replayed = self.replay_plane() == Some(id);
        let w = self.watched(id)?;
        let snap = w.plane.snapshot()?;
        drain_contacts(w)?;
        let h = *snap.header();
        let gui = w.info.kind == PlaneKind::Gui2d;
        let mut fetches = 0;
        let mut bodies = Vec::with_capacity(h.body_count as usize);
        let mut controllers = Vec::new();
        let mut live = Vec::new();
        let mut poses: HashMap<u32, PoseOf> = HashMap::new();
        for (slot, b) in snap.bodies().iter().enumerate() {
            let slot = slot as u32;
            if !b.is_alive() {
                w.shapes.remove(&slot);
                continue;
            }
            if replayed {
                live.push((slot, b.generation, b.position, b.flags));
            }
            if !gui {
                poses.insert(slot, (b.generation, b.position, b.rotation));
            }
            let stale = w.shapes.get(&slot).is_none_or(|k| {
                k.generation != b.generation || k.fetched.elapsed() > SHAPE_REFRESH
            });
            if stale && fetches < SHAPE_FETCHES_PER_SNAPSHOT {
                fetches += 1;
                let handle = Handle {
                    slot,
                    generation: b.generation,
                };
                match describe(&w.plane, handle, b, gui) {
                    Ok(view) => {
                        w.shapes.insert(
                            slot,
                            Known {
                                generation: b.generation,
                                fetched: Instant::now(),
                                view,
                            },
                        );
                    }
                    Err(e) if daemon_lost(&e) => return Err(e),
                    // Destroyed since the tick: drawn from the tick, as an unknown shape.
                    Err(_) => {}
                }
            }
            let view = w
                .shapes
                .get(&slot)
                .filter(|k| k.generation == b.generation)
                .map(|k| k.view.clone())
                .unwrap_or_else(|| json!({"shape": "Unknown", "size": [1.0, 1.0, 1.0]}));
            if b.flags & FLAG_CONTROLLER != 0 || view.get("controller").is_some() {
                controllers.push(json!({
                    "slot": slot,
                    "position": b.position,
                    "velocity": b.linear_velocity,
                    "on_ground": b.flags & FLAG_ON_GROUND != 0,
                    "controller": view.get("controller").cloned().unwrap_or(Value::Null),
                }));
            }
            let mut body = body_json(slot, b);
            if let (Value::Object(body), Value::Object(view)) = (&mut body, view) {
                for (k, v) in view {
                    if k != "controller" {
                        body.insert(k, v);
                    }
                }
            }
            bodies.push(body);
        }
        let contacts: Vec<Value> = w
            .contacts
            .values()
            .map(|t| {
                json!({"position": t.position, "normal": t.normal, "impulse": t.impulse,
                       "tick": t.tick})
            })
            .collect();
        // Joints: listed again once a second (live) or once per tick drawn (replay), their
        // anchors placed with this tick's poses.
        let joint_lines = if gui {
            Vec::new()
        } else {
            w.joints.refresh(&w.plane, h.tick, replayed)?;
            joints::lines(w.joints.joints(), &poses)
        };
        let joint_count = w.joints.joints().len();
        let mut out = json!({
            "id": id,
            "kind": kind_name(w.info.kind),
            "tick": h.tick,
            "sim_time": h.sim_time,
            "dt": h.dt,
            "step_time_us": h.step_time_us,
            "slot_count": h.slot_count,
            "body_count": h.body_count,
            "max_penetration": h.max_penetration,
            "max_joint_error": h.max_joint_error,
            "contact_pairs": h.contact_pairs,
            "tick_rate": w.info.tick_rate,
            "enabled": w.info.enabled,
            "gravity": w.info.gravity,
            "object_count": w.info.object_count,
            "bodies": bodies,
            "contacts": contacts,
            "controllers": controllers,
            "joints": joint_lines,
            "joint_count": joint_count,
            "described": fetches < SHAPE_FETCHES_PER_SNAPSHOT,
        });
        if replayed {
            let gui = w.info.kind == PlaneKind::Gui2d;
            if let Some(player) = self.player.as_mut() {
                if let Value::Object(extra) = player.overlay(&live)? {
                    for (k, v) in extra {
                        // A GUI plane's contacts come from its events, as for a live plane.
                        if !(gui && k == "contacts") {
                            out[k] = v;
                        }
                    }
                }
            }
        }
        Ok(out)
    }

    fn body(&mut self, id: PlaneId, slot: u32) -> Result<Value, Error> {
        let w = self.watched(id)?;
        let snap = w.plane.snapshot()?;
        let Some(b) = snap.bodies().get(slot as usize).filter(|b| b.is_alive()) else {
            return Err(Error::Invalid {
                field: "slot".into(),
                message: format!("plane {id} has no live body in slot {slot}"),
            });
        };
        let handle = Handle {
            slot,
            generation: b.generation,
        };
        let mut out = json!({ "plane": id, "tick": snap.tick(), "state": body_json(slot, b) });
        if w.info.kind == PlaneKind::Gui2d {
            out["info"] = to_json(&w.plane.gui_object_info(handle)?);
        } else {
            out["info"] = to_json(&w.plane.object_info(handle)?);
            if b.flags & FLAG_CONTROLLER != 0 {
                out["controller"] = to_json(&w.plane.controller_info(handle)?);
            }
        }
        Ok(out)
    }

    /// The plane's snapshot (a read: any client may take one): its tick and file bytes.
    fn download(&mut self, id: PlaneId) -> Result<(u64, Vec<u8>), Error> {
        let w = self.watched(id)?;
        let snapshot = w.plane.take_snapshot()?;
        Ok((snapshot.tick(), snapshot.bytes().to_vec()))
    }

    fn control(&mut self, id: PlaneId, action: Action) -> Result<Value, Error> {
        if self.replay_plane() == Some(id) {
            return Err(Error::Invalid {
                field: "plane".into(),
                message: format!(
                    "plane {id} plays the recording: its timeline drives it (POST /api/replay)"
                ),
            });
        }
        let w = self.watched(id)?;
        let plane = w.plane.clone();
        let tick = match action {
            Action::Pause | Action::Resume => {
                plane.set(PlaneProp::Enabled(action == Action::Resume))?;
                plane.client().flush()?;
                plane.snapshot().map(|s| s.tick()).unwrap_or(0)
            }
            Action::Step => {
                let rate = w.info.tick_rate;
                plane.step(if rate > 0.0 { 1.0 / rate } else { 1.0 / 60.0 })?
            }
        };
        w.info = plane.info()?;
        Ok(json!({"plane": id, "tick": tick, "enabled": w.info.enabled}))
    }
}

/// Takes the plane's new contact events into its set of touching pairs.
fn drain_contacts(w: &mut Watched) -> Result<(), Error> {
    let events = w.plane.events()?;
    for r in &events.records {
        match Contact::from_record(r) {
            Some(Contact::Started {
                a,
                b,
                position,
                normal,
                impulse,
                tick,
            }) if w.contacts.len() < MAX_CONTACTS => {
                w.contacts.insert(
                    (a, b),
                    Touch {
                        position,
                        normal,
                        impulse,
                        tick,
                    },
                );
            }
            Some(Contact::Ended { a, b, .. }) => {
                w.contacts.remove(&(a, b));
                w.contacts.remove(&(b, a));
            }
            Some(Contact::Started { .. }) | None => {}
        }
    }
    Ok(())
}

//! The soak's load: what a game does to the daemon over an hour, one frame per tick.
//!
//! Each long-lived plane holds a settled pile of cubes (the level), a floor beside it where
//! character controllers walk looping paths, and an anchored platform the client moves by
//! CFrame every frame. Every frame the client kicks a few cubes (Velocity), moves the
//! platform (CFrame), reads the plane's events (Touched: the churned cubes report contacts)
//! and casts rays; every few frames it overlaps and sweeps, replaces a cube (destroy + add),
//! and makes and breaks joints and replaces a controller. Besides the long-lived planes a
//! plane is created and destroyed every cycle, and a second client (its own thread and
//! connection) connects, builds and steps a plane, and disconnects every cycle.

use std::sync::mpsc;
use std::thread::JoinHandle;
use std::time::Duration;

use client_sdk::{
    Client, Contact, Controller, Error, Joint, JointBroke, JointKind, JointProp, Object,
    ObjectProp, Plane, PlaneOptions, Pose, Ray, Shape, EVENT_PATH_FINISHED,
};

use crate::error::BenchResult;

/// Bodies per plane the client kicks (a game's few active objects; the rest of the level
/// rests and sleeps).
const ACTIVE: usize = 10;
/// Velocity writes per plane per frame, on the active bodies in turn.
const WRITES_PER_PLANE: usize = 2;
/// Every this many frames a plane has one cube destroyed and a new one added (staggered).
pub const CHURN_EVERY: u64 = 30;
/// Every this many frames a plane's joints and one controller are remade (staggered).
pub const JOINT_EVERY: u64 = 120;
/// Every this many query turns of a plane, an overlap and a sweep are asked too.
const OVERLAP_EVERY: u64 = 10;
/// Rays per frame (one batch, on one plane in turn).
const RAYS: usize = 16;
/// Controllers walking on each long-lived plane.
const CONTROLLERS: usize = 3;
/// A controller's full size (capsule radius 1, height 5) and its standing height.
const CONTROLLER_SIZE: [f32; 3] = [2.0, 5.0, 2.0];
const CONTROLLER_Y: f32 = 2.51;
/// The walking floor beside the pile: top face at y = 0, centred here, this wide.
const WALK_CENTRE: [f32; 3] = [-20.0, 0.0, 10.0];
const WALK_WIDTH: f32 = 26.0;
/// The loop the controllers walk (corners of a square on the walking floor).
const PATH: [[f32; 3]; 4] = [
    [-29.0, 0.0, 1.0],
    [-11.0, 0.0, 1.0],
    [-11.0, 0.0, 19.0],
    [-29.0, 0.0, 19.0],
];
/// A joint that breaks under its own body's weight (a unit cube weighs far more).
const FRAGILE: f32 = 1.0;

/// How many of each thing the load did.
#[derive(Debug, Clone, Default, serde::Serialize)]
pub struct Counts {
    pub frames: u64,
    pub velocity_writes: u64,
    pub cframe_writes: u64,
    pub bodies_replaced: u64,
    pub rays: u64,
    pub overlaps: u64,
    pub sweeps: u64,
    pub contacts_started: u64,
    pub contacts_ended: u64,
    pub events_lost: u64,
    pub paths_finished: u64,
    pub paths_set: u64,
    pub controllers_replaced: u64,
    pub joints_made: u64,
    pub joints_broken: u64,
    pub joints_destroyed: u64,
    pub planes_cycled: u64,
    pub clients_cycled: u64,
    pub errors: u64,
    pub first_error: Option<String>,
}

impl Counts {
    /// Total property writes (velocity and CFrame).
    pub fn writes(&self) -> u64 {
        self.velocity_writes + self.cframe_writes
    }

    /// Counts an error of `what`, keeping the first one's text.
    pub fn error_of(&mut self, what: &str, e: impl std::fmt::Display) {
        self.errors += 1;
        self.first_error
            .get_or_insert_with(|| format!("{what}: {e}"));
    }
}

/// One long-lived plane and what the client keeps of it.
pub struct SoakPlane {
    pub plane: Plane,
    bodies: Vec<Object>,
    /// Where each cube's column stands (x, z): its replacement drops onto it.
    spots: Vec<[f32; 2]>,
    next: usize,
    platform: Object,
    controllers: Vec<Controller>,
    next_controller: usize,
    /// Bodies and the joint of the current joint round (destroyed by the next one).
    rig: Vec<Object>,
    hinge: Option<Joint>,
    rounds: u64,
    /// Centre of the pile (rays and overlaps aim there).
    centre: [f32; 2],
}

/// A plane at 60 Hz with a settled pile of `bodies` unit cubes, a walking floor with
/// [`CONTROLLERS`] controllers on their path, and a platform.
pub fn build(client: &Client, bodies: usize) -> BenchResult<SoakPlane> {
    let plane = client.create_plane(&PlaneOptions::default())?;
    let mut all = physics_scenes::pile(&mut &plane, bodies)?;
    let bodies: Vec<Object> = all.drain(1..).collect();
    let spots = bodies
        .iter()
        .map(|b| b.position().map(|p| [p[0], p[2]]))
        .collect::<Result<Vec<_>, _>>()?;
    let (lo, hi) = spots
        .iter()
        .fold(([f32::MAX; 2], [f32::MIN; 2]), |(lo, hi), s| {
            (
                [lo[0].min(s[0]), lo[1].min(s[1])],
                [hi[0].max(s[0]), hi[1].max(s[1])],
            )
        });
    physics_scenes::slab(&mut &plane, WALK_CENTRE, [WALK_WIDTH, 1.0, WALK_WIDTH], &[])?;
    let platform = plane.add(
        Shape::Cube {
            size: [4.0, 0.5, 4.0],
        },
        Pose::at([0.0, 20.0, 0.0]),
        &[ObjectProp::Anchored(true)],
    )?;
    let mut soak = SoakPlane {
        plane,
        bodies,
        spots,
        next: 0,
        platform,
        controllers: Vec::new(),
        next_controller: 0,
        rig: Vec::new(),
        hinge: None,
        rounds: 0,
        centre: [(lo[0] + hi[0]) / 2.0, (lo[1] + hi[1]) / 2.0],
    };
    for k in 0..CONTROLLERS {
        let c = walker(&soak.plane, k)?;
        soak.controllers.push(c);
    }
    soak.plane.subscribe_events()?;
    Ok(soak)
}

/// A controller at corner `k` of the path, walking it from there.
fn walker(plane: &Plane, k: usize) -> Result<Controller, Error> {
    let [x, _, z] = PATH[k % PATH.len()];
    let c = plane.new_controller(Pose::at([x, CONTROLLER_Y, z]), CONTROLLER_SIZE, false, &[])?;
    walk(&c, k)?;
    Ok(c)
}

/// Sets the loop from corner `k + 1` round to corner `k`.
fn walk(c: &Controller, k: usize) -> Result<(), Error> {
    let path: Vec<[f32; 3]> = (1..=PATH.len())
        .map(|i| PATH[(k + i) % PATH.len()])
        .collect();
    c.compute_path(&path).map(|_| ())
}

/// One frame of the load on every long-lived plane, then one flush. Errors are counted,
/// not returned, except a daemon that is gone or stalled.
pub fn frame(
    client: &Client,
    planes: &mut [SoakPlane],
    n: u64,
    counts: &mut Counts,
) -> Result<(), Error> {
    let count = planes.len() as u64;
    for (p, soak) in planes.iter_mut().enumerate() {
        let p = p as u64;
        let results = [
            ("writes", writes(soak, n, counts)),
            ("events", events(soak, counts)),
            (
                "churn",
                if n % CHURN_EVERY == p % CHURN_EVERY {
                    churn(soak, counts)
                } else {
                    Ok(())
                },
            ),
            (
                "joints",
                if n % JOINT_EVERY == (p * JOINT_EVERY / count.max(1)) % JOINT_EVERY {
                    joints(soak, counts)
                } else {
                    Ok(())
                },
            ),
            (
                "queries",
                if n % count == p {
                    queries(soak, n / count, counts)
                } else {
                    Ok(())
                },
            ),
        ];
        for (what, r) in results {
            if let Err(e) = r {
                if fatal(&e) {
                    return Err(e);
                }
                counts.error_of(what, e);
            }
        }
    }
    if let Err(e) = client.flush() {
        if fatal(&e) {
            return Err(e);
        }
        counts.error_of("flush", e);
    }
    counts.frames += 1;
    Ok(())
}

/// Whether an error ends the run (the daemon is gone or stalled).
fn fatal(e: &Error) -> bool {
    matches!(e, Error::DaemonGone { .. } | Error::Stalled { .. })
}

/// Velocity kicks on the active cubes (the tops of the first columns) and the platform
/// moved one step round its circle by CFrame.
fn writes(soak: &mut SoakPlane, n: u64, counts: &mut Counts) -> Result<(), Error> {
    let len = soak.bodies.len();
    if len > 0 {
        for k in 0..WRITES_PER_PLANE {
            let m = (n as usize * WRITES_PER_PLANE + k) % ACTIVE;
            let i = (m * 5 + 4).min(len - 1);
            let s = ((n as usize + k) % 5) as f32 * 0.5 - 1.0;
            soak.bodies[i].set_velocity([s, 2.0, -s])?;
            counts.velocity_writes += 1;
        }
    }
    let a = n as f32 * 0.02;
    soak.platform.set_pose(Pose::at([
        soak.centre[0] + 6.0 * a.cos(),
        20.0,
        soak.centre[1] + 6.0 * a.sin(),
    ]))?;
    counts.cframe_writes += 1;
    Ok(())
}

/// Drains the plane's events: Touched (contact started / ended), joint breaks, finished
/// paths (the controller is sent round again).
fn events(soak: &mut SoakPlane, counts: &mut Counts) -> Result<(), Error> {
    let events = soak.plane.events()?;
    counts.events_lost += events.lost;
    for r in &events.records {
        match Contact::from_record(r) {
            Some(Contact::Started { .. }) => counts.contacts_started += 1,
            Some(Contact::Ended { .. }) => counts.contacts_ended += 1,
            None => {}
        }
        if JointBroke::from_record(r).is_some() {
            counts.joints_broken += 1;
        }
        if r.kind == EVENT_PATH_FINISHED {
            counts.paths_finished += 1;
            if let Some((k, c)) = soak
                .controllers
                .iter()
                .enumerate()
                .find(|(_, c)| c.handle() == r.a())
            {
                walk(c, k)?;
                counts.paths_set += 1;
            }
        }
    }
    Ok(())
}

/// One cube destroyed and a new one (reporting contacts: Touched) dropped onto its column.
fn churn(soak: &mut SoakPlane, counts: &mut Counts) -> Result<(), Error> {
    let len = soak.bodies.len();
    if len == 0 {
        return Ok(());
    }
    let i = soak.next % len;
    soak.next += 1;
    soak.bodies[i].destroy();
    let [x, z] = soak.spots[i];
    soak.bodies[i] = soak.plane.add(
        Shape::Cube { size: [1.0; 3] },
        Pose::at([x, 8.0, z]),
        &[ObjectProp::ReportContacts(true)],
    )?;
    counts.bodies_replaced += 1;
    Ok(())
}

/// A joint round: the previous round's hinge destroyed (or left to go with its bodies, every
/// other round) and its bodies destroyed; a lamp hung from the world by a joint too weak
/// for it (it breaks: an event), two cubes hinged together over the walking floor, and one
/// controller replaced by a new one.
fn joints(soak: &mut SoakPlane, counts: &mut Counts) -> Result<(), Error> {
    soak.rounds += 1;
    if let Some(h) = soak.hinge.take() {
        if soak.rounds.is_multiple_of(2) {
            h.destroy()?;
            counts.joints_destroyed += 1;
        }
    }
    for b in soak.rig.drain(..) {
        b.destroy();
    }
    let [x, _, z] = WALK_CENTRE;
    let cube = Shape::Cube { size: [1.0; 3] };
    let lamp = soak.plane.add(
        Shape::Sphere { radius: 0.5 },
        Pose::at([x, 12.0, z]),
        &[ObjectProp::ReportContacts(true)],
    )?;
    soak.rig.push(lamp.clone());
    soak.plane.joint(
        JointKind::Ball,
        &lamp,
        None,
        &[
            JointProp::AnchorA([0.0, 1.0, 0.0]),
            JointProp::AnchorB([x, 13.0, z]),
            JointProp::BreakForce(FRAGILE),
        ],
    )?;
    let a = soak
        .plane
        .add(cube.clone(), Pose::at([x + 3.0, 6.0, z]), &[])?;
    let b = soak.plane.add(cube, Pose::at([x + 4.5, 6.0, z]), &[])?;
    soak.rig.extend([a.clone(), b.clone()]);
    soak.hinge = Some(soak.plane.joint(
        JointKind::Hinge,
        &a,
        Some(&b),
        &[
            JointProp::AnchorA([0.75, 0.0, 0.0]),
            JointProp::AnchorB([-0.75, 0.0, 0.0]),
            JointProp::Axis([0.0, 0.0, 1.0]),
        ],
    )?);
    counts.joints_made += 2;
    let k = soak.next_controller % CONTROLLERS;
    soak.next_controller += 1;
    if let Some(old) = soak.controllers.get(k) {
        old.destroy();
        soak.controllers[k] = walker(&soak.plane, k)?;
        counts.controllers_replaced += 1;
    }
    Ok(())
}

/// The plane's `round`-th query turn (planes take turns, one per frame): a batch of rays
/// down onto the pile, and every [`OVERLAP_EVERY`] turns an overlap (objects in a radius)
/// and a sphere sweep.
fn queries(soak: &mut SoakPlane, round: u64, counts: &mut Counts) -> Result<(), Error> {
    let n = round;
    let [cx, cz] = soak.centre;
    let rays: Vec<Ray> = (0..RAYS)
        .map(|i| {
            let a = (n as usize * RAYS + i) as f32 * 0.37;
            Ray {
                origin: [cx + 8.0 * a.cos(), 15.0, cz + 8.0 * a.sin()],
                direction: [0.0, -30.0, 0.0],
            }
        })
        .collect();
    soak.plane.raycast_many(&rays, None)?;
    counts.rays += RAYS as u64;
    if round.is_multiple_of(OVERLAP_EVERY) {
        soak.plane.bounds_in_radius([cx, 3.0, cz], 4.0, None)?;
        counts.overlaps += 1;
        soak.plane
            .spherecast([cx - 12.0, 3.0, cz], 1.0, [24.0, 0.0, 0.0], None)?;
        counts.sweeps += 1;
    }
    Ok(())
}

/// A plane made and destroyed within one cycle: a small pile, a controller on its path,
/// a joint, events subscribed.
pub struct PassingPlane {
    plane: Plane,
}

impl PassingPlane {
    /// Creates it (60 Hz, the defaults).
    pub fn create(client: &Client) -> BenchResult<PassingPlane> {
        let plane = client.create_plane(&PlaneOptions::default())?;
        let all = physics_scenes::pile(&mut &plane, 100)?;
        physics_scenes::slab(&mut &plane, WALK_CENTRE, [WALK_WIDTH, 1.0, WALK_WIDTH], &[])?;
        walker(&plane, 0)?;
        if let [_, a, b, ..] = all.as_slice() {
            plane.joint(JointKind::Ball, a, Some(b), &[])?;
        }
        plane.subscribe_events()?;
        Ok(PassingPlane { plane })
    }

    /// Destroys it.
    pub fn destroy(self) -> BenchResult<()> {
        Ok(self.plane.destroy()?)
    }
}

/// The second client: a thread that, when told, connects its own client to the domain,
/// builds a manual plane, steps it, asks a query, reads events and disconnects (every other
/// time destroying its plane first, otherwise leaving it to the daemon's cleanup).
pub struct VisitingClient {
    go: Option<mpsc::Sender<u64>>,
    done: mpsc::Receiver<Result<(), String>>,
    thread: Option<JoinHandle<()>>,
    busy: bool,
}

impl VisitingClient {
    /// Starts the thread (idle until [`VisitingClient::visit`]).
    pub fn start(domain: &str) -> VisitingClient {
        let (go, rx) = mpsc::channel::<u64>();
        let (tx, done) = mpsc::channel();
        let domain = domain.to_string();
        let thread = std::thread::spawn(move || {
            while let Ok(n) = rx.recv() {
                let _ = tx.send(visit(&domain, n).map_err(|e| e.to_string()));
            }
        });
        VisitingClient {
            go: Some(go),
            done,
            thread: Some(thread),
            busy: false,
        }
    }

    /// Starts visit number `n` (ignored while one runs).
    pub fn visit(&mut self, n: u64) {
        if !self.busy {
            if let Some(go) = &self.go {
                self.busy = go.send(n).is_ok();
            }
        }
    }

    /// Whether a visit is under way; a finished one is counted into `counts`.
    pub fn busy(&mut self, counts: &mut Counts) -> bool {
        if self.busy {
            if let Ok(result) = self.done.try_recv() {
                self.busy = false;
                counts.clients_cycled += 1;
                if let Err(e) = result {
                    counts.error_of("visiting client", e);
                }
            }
        }
        self.busy
    }

    /// Waits up to `timeout` for the visit under way.
    pub fn wait(&mut self, timeout: Duration, counts: &mut Counts) {
        if self.busy {
            if let Ok(result) = self.done.recv_timeout(timeout) {
                self.busy = false;
                counts.clients_cycled += 1;
                if let Err(e) = result {
                    counts.error_of("visiting client", e);
                }
            }
        }
    }
}

impl Drop for VisitingClient {
    fn drop(&mut self) {
        drop(self.go.take());
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

fn visit(domain: &str, n: u64) -> Result<(), Error> {
    let client = Client::connect(domain)?;
    let plane = client.create_plane(&PlaneOptions::manual())?;
    let cubes = physics_scenes::pile(&mut &plane, 50)?;
    plane.subscribe_events()?;
    for _ in 0..30 {
        plane.step(1.0 / 60.0)?;
    }
    plane.raycast([0.5, 20.0, 0.5], [0.0, -40.0, 0.0], None)?;
    let _ = plane.events()?;
    if let Some(c) = cubes.last() {
        c.set_velocity([0.0, 5.0, 0.0])?;
    }
    client.flush()?;
    if n.is_multiple_of(2) {
        plane.destroy()?;
    }
    Ok(())
}

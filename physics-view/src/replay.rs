//! `physics-view --replay FILE`: a recording played into a plane of the viewer's own client
//! ([`client_sdk::Replay`]: the start keyframe restored into a new manual plane, the
//! recorded batches re-applied tick by tick, every tick's state hash checked). The plane is
//! listed and drawn like any live plane; this module is its timeline: play at a speed
//! relative to the recording's tick rate, pause, step one tick, jump to a tick. It lives on
//! the sampler's thread (the client is not `Send`), which calls [`Player::pump`] between
//! jobs to advance the ticks that are due.

use std::collections::HashSet;
use std::sync::Arc;
use std::time::{Duration, Instant};

use client_sdk::{Advanced, Client, Error, Object, PlaneId, Recording, Replay};
use serde_json::{json, Value};
use shm_layout::{PlaneOp, QueryOp, FLAG_ANCHORED};

/// The speeds the page offers (times the recording's tick rate).
pub const SPEEDS: [f64; 5] = [0.25, 0.5, 1.0, 2.0, 4.0];
/// Slowest and fastest speed the API takes.
pub const SPEED_RANGE: (f64, f64) = (1.0 / 16.0, 16.0);
/// Most ticks stepped in one turn of the sampler's loop while playing: it answers the page
/// in between, and a replay slower than its speed plays as fast as it can instead of
/// bursting to catch up.
const MAX_TICKS_PER_PUMP: u32 = 4;
/// Most bodies whose contacts are asked for at one tick (one round trip each).
const MAX_CONTACT_QUERIES: usize = 256;
/// Most contacts drawn (as the live overlay).
const MAX_CONTACTS: usize = 4096;
/// Most ray segments drawn at one tick.
const MAX_RAYS: usize = 4096;

/// What the page asks of the timeline.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ReplayAction {
    /// Play from the current tick at the current (or given) speed.
    Play,
    /// Stop advancing.
    Pause,
    /// Pause, then advance exactly one tick.
    Step,
    /// Pause, then go to this tick (restoring a keyframe when it lies behind).
    Seek(u64),
    /// Only change the speed.
    Speed,
}

/// A request of `POST /api/replay`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ReplayRequest {
    /// What to do.
    pub action: ReplayAction,
    /// A new speed, applied first.
    pub speed: Option<f64>,
}

impl ReplayRequest {
    /// Reads `{"action": "play"|"pause"|"step"|"seek"|"speed", "tick"?: N, "speed"?: X}`.
    pub fn parse(body: &[u8]) -> Result<ReplayRequest, String> {
        let v: Value = serde_json::from_slice(body)
            .map_err(|e| format!("the body must be a JSON object: {e}"))?;
        let speed = match v.get("speed") {
            None | Some(Value::Null) => None,
            Some(s) => Some(
                s.as_f64()
                    .ok_or_else(|| format!("speed must be a number, got {s}"))?,
            ),
        };
        let tick = match v.get("tick") {
            None | Some(Value::Null) => None,
            Some(t) => Some(
                t.as_u64()
                    .ok_or_else(|| format!("tick must be a whole number ≥ 0, got {t}"))?,
            ),
        };
        let action = match v.get("action").and_then(Value::as_str) {
            Some("play") => ReplayAction::Play,
            Some("pause") => ReplayAction::Pause,
            Some("step") => ReplayAction::Step,
            Some("seek") => ReplayAction::Seek(
                tick.ok_or("seek needs a tick (e.g. {\"action\":\"seek\",\"tick\":60})")?,
            ),
            Some("speed") if speed.is_some() => ReplayAction::Speed,
            Some("speed") => return Err("speed needs a speed (e.g. 0.5)".into()),
            _ => {
                return Err(format!(
                    "action must be one of play, pause, step, seek, speed; got {}",
                    v.get("action").unwrap_or(&Value::Null)
                ))
            }
        };
        if let Some(s) = speed {
            if !(s.is_finite() && (SPEED_RANGE.0..=SPEED_RANGE.1).contains(&s)) {
                return Err(format!(
                    "speed must be between {} and {} (times the recording's tick rate), got {s}",
                    SPEED_RANGE.0, SPEED_RANGE.1
                ));
            }
        }
        Ok(ReplayRequest { action, speed })
    }
}

/// Why a request was not done: the page's mistake (a tick outside the recording, a step
/// after a divergence) or the daemon's.
pub enum Refusal {
    /// The request does not fit the replay's state (409).
    Conflict(String),
    /// The daemon failed (its message; the sampler checks whether it is gone).
    Daemon(Error),
}

impl From<Error> for Refusal {
    fn from(e: Error) -> Refusal {
        Refusal::Daemon(e)
    }
}

/// The timeline of one recording.
pub struct Player {
    path: String,
    recording: Arc<Recording>,
    /// `None` while no daemon is connected (the replay starts again on the next one).
    replay: Option<Replay>,
    playing: bool,
    speed: f64,
    /// Seconds of one recorded tick (1× plays one tick per this).
    tick_dt: f64,
    /// When the next tick is due while playing.
    due: Instant,
    diverged: Option<(u64, String)>,
    error: Option<String>,
    /// The camera's framing: every body at the first and at the last tick (position and
    /// size), so the view holds the whole recording and keeps its place whatever tick the
    /// page is opened at.
    fit: Value,
    /// Contacts of the current tick, asked for once per tick.
    contacts: Option<(u64, Value)>,
}

impl Player {
    /// A timeline for `recording` (read from `path`); not started until [`Player::start`].
    pub fn new(path: String, recording: Arc<Recording>) -> Player {
        let tick_dt = recording
            .events
            .iter()
            .find_map(|e| match e {
                shm_layout::recording::Event::Tick { dt, .. } => Some(*dt as f64),
                _ => None,
            })
            .filter(|dt| dt.is_finite() && *dt > 0.0)
            .unwrap_or(1.0 / 60.0)
            .clamp(1e-4, 1.0);
        Player {
            path,
            recording,
            replay: None,
            playing: false,
            speed: 1.0,
            tick_dt,
            due: Instant::now(),
            diverged: None,
            error: None,
            fit: Value::Array(Vec::new()),
            contacts: None,
        }
    }

    /// Restores the start keyframe into a new plane of `client` (paused at the first tick).
    pub fn start(&mut self, client: &Client) -> Result<PlaneId, Error> {
        self.replay = None;
        self.playing = false;
        self.diverged = None;
        self.contacts = None;
        let replay = Replay::start(client, self.recording.clone())?;
        let id = replay.plane().id();
        self.replay = Some(replay);
        self.error = None;
        Ok(id)
    }

    /// The recording's first and last tick.
    pub fn range(&self) -> (u64, u64) {
        (self.recording.first_tick(), self.recording.last_tick())
    }

    /// Goes to `tick` without changing the timeline's state (a divergence on the way is
    /// found again when played): for looking at the recording's extent.
    pub fn jump(&mut self, tick: u64) -> Result<(), Error> {
        if let Some(replay) = self.replay.as_mut() {
            replay.seek(tick)?;
        }
        Ok(())
    }

    /// Keeps `bodies` (of the first and the last tick) for the camera's framing.
    pub fn set_fit(&mut self, bodies: &[Value]) {
        let fit = bodies
            .iter()
            .map(|b| json!({"position": b["position"], "size": b["size"]}))
            .collect();
        self.fit = Value::Array(fit);
    }

    /// The daemon went away: the replay's plane with it.
    pub fn lost(&mut self, why: &str) {
        self.replay = None;
        self.playing = false;
        self.contacts = None;
        self.error = Some(why.to_string());
    }

    /// The plane the replay drives.
    pub fn plane_id(&self) -> Option<PlaneId> {
        self.replay.as_ref().map(|r| r.plane().id())
    }

    /// The file played.
    pub fn path(&self) -> &str {
        &self.path
    }

    /// When the sampler must call [`Player::pump`] next (`None`: not playing).
    pub fn due(&self) -> Option<Instant> {
        (self.playing && self.replay.is_some()).then_some(self.due)
    }

    fn interval(&self) -> Duration {
        Duration::from_secs_f64(self.tick_dt / self.speed)
    }

    /// Advances the ticks that are due while playing.
    pub fn pump(&mut self) -> Result<(), Error> {
        let now = Instant::now();
        let mut n = 0;
        while self.playing && self.due <= now && n < MAX_TICKS_PER_PUMP {
            self.advance()?;
            self.due += self.interval();
            n += 1;
        }
        if self.due + self.interval() < now {
            // Behind (the steps take longer than the speed allows): no burst to catch up.
            self.due = now;
        }
        Ok(())
    }

    /// One tick; a divergence or the end stops playing.
    fn advance(&mut self) -> Result<(), Error> {
        let Some(replay) = self.replay.as_mut() else {
            self.playing = false;
            return Ok(());
        };
        let result = replay.advance();
        self.settle(result)
    }

    /// Takes what an advance or a seek did into the timeline's state.
    fn settle(&mut self, result: Result<Advanced, Error>) -> Result<(), Error> {
        match result {
            Ok(Advanced::Tick(_)) => {}
            Ok(Advanced::End) => self.playing = false,
            Ok(Advanced::Diverged(d)) => {
                self.playing = false;
                self.diverged = Some((d.tick, d.to_string()));
            }
            Err(e) => {
                self.playing = false;
                self.error = Some(e.to_string());
                return Err(e);
            }
        }
        Ok(())
    }

    /// Does what the page asked; answers the timeline's state.
    pub fn act(&mut self, request: ReplayRequest) -> Result<Value, Refusal> {
        if self.replay.is_none() {
            return Err(Refusal::Conflict(format!(
                "the replay is not running: {}",
                self.error.as_deref().unwrap_or("no daemon")
            )));
        }
        if let Some(speed) = request.speed {
            self.speed = speed;
            self.due = Instant::now() + self.interval();
        }
        let (first, last) = (self.recording.first_tick(), self.recording.last_tick());
        match request.action {
            ReplayAction::Speed => {}
            ReplayAction::Pause => self.playing = false,
            ReplayAction::Play | ReplayAction::Step => {
                if let Some((tick, message)) = &self.diverged {
                    return Err(Refusal::Conflict(format!(
                        "{message} (seek to a tick before {tick} to go on)"
                    )));
                }
                if request.action == ReplayAction::Step {
                    self.playing = false;
                    self.advance()?;
                } else if !self.at_end() {
                    self.playing = true;
                    self.due = Instant::now();
                }
            }
            ReplayAction::Seek(tick) => {
                if !(first..=last).contains(&tick) {
                    return Err(Refusal::Conflict(format!(
                        "tick {tick} is outside the recording (ticks {first} to {last})"
                    )));
                }
                if let Some((at, message)) = &self.diverged {
                    if tick >= *at {
                        return Err(Refusal::Conflict(format!(
                            "{message} (seek to a tick before {at} to go on)"
                        )));
                    }
                }
                self.playing = false;
                self.diverged = None;
                let result = self
                    .replay
                    .as_mut()
                    .map(|r| r.seek(tick))
                    .unwrap_or(Ok(Advanced::End));
                self.settle(result)?;
            }
        }
        Ok(self.status())
    }

    fn at_end(&self) -> bool {
        self.replay
            .as_ref()
            .is_none_or(|r| r.at_end() || r.tick() >= self.recording.last_tick())
    }

    /// The timeline's state (what `GET /api/replay` answers).
    pub fn status(&self) -> Value {
        let replay = self.replay.as_ref();
        json!({
            "file": self.path,
            "plane": replay.map(|r| r.plane().id()),
            "first": self.recording.first_tick(),
            "last": self.recording.last_tick(),
            "ticks": self.recording.tick_count(),
            "tick": replay.map(|r| r.tick()),
            "playing": self.playing,
            "speed": self.speed,
            "speeds": SPEEDS,
            "rate_hz": 1.0 / self.tick_dt,
            "at_end": self.at_end(),
            "diverged": self.diverged.as_ref().map(|(_, m)| m),
            "error": self.error,
            "ended_because": self.recording.end,
        })
    }

    /// What the page draws over the replay plane at its current tick: the timeline's state,
    /// the recorded rays applied at this tick, the camera's framing and the contacts (every
    /// pair a moving body touches now, asked for once per tick).
    pub fn overlay(&mut self, bodies: &[(u32, u32, [f32; 3], u32)]) -> Result<Value, Error> {
        let Some(replay) = self.replay.as_ref() else {
            return Ok(json!({ "replay": self.status() }));
        };
        let tick = replay.tick();
        let positions: std::collections::HashMap<u32, [f32; 3]> =
            bodies.iter().map(|(slot, _, p, _)| (*slot, *p)).collect();
        let rays = rays_of(&replay.ops_at(tick), &positions);
        if self.contacts.as_ref().is_none_or(|(t, _)| *t != tick) {
            let contacts = contacts_of(replay, bodies, tick)?;
            self.contacts = Some((tick, contacts));
        }
        let contacts = self
            .contacts
            .as_ref()
            .map_or(Value::Array(Vec::new()), |(_, c)| c.clone());
        Ok(json!({
            "replay": self.status(),
            "rays": rays,
            "fit": self.fit,
            "contacts": contacts,
        }))
    }
}

/// Every pair a moving body of the plane touches now (`ObjectOp::Contacts` of each body
/// that is not anchored, at most [`MAX_CONTACT_QUERIES`]), once per pair, as the live
/// overlay draws them: the deepest point, its normal, the pair's impulse.
fn contacts_of(
    replay: &Replay,
    bodies: &[(u32, u32, [f32; 3], u32)],
    tick: u64,
) -> Result<Value, Error> {
    let plane = replay.plane();
    let mut seen = HashSet::new();
    let mut out = Vec::new();
    for (slot, generation, _, _) in bodies
        .iter()
        .filter(|b| b.3 & FLAG_ANCHORED == 0)
        .take(MAX_CONTACT_QUERIES)
    {
        let handle = client_sdk::Handle {
            slot: *slot,
            generation: *generation,
        };
        let list = match Object::from_handle(plane, handle).contacts() {
            Ok(list) => list,
            Err(Error::Command(_)) => continue,
            Err(e) => return Err(e),
        };
        for c in list {
            let key = if c.other.slot < *slot {
                (c.other.slot, *slot)
            } else {
                (*slot, c.other.slot)
            };
            if out.len() < MAX_CONTACTS && seen.insert(key) {
                out.push(json!({
                    "position": c.position, "normal": c.normal, "impulse": c.impulse,
                    "tick": tick,
                }));
            }
        }
    }
    Ok(Value::Array(out))
}

/// The segments of the recorded queries that travel along a line: rays (origin to origin +
/// direction), sphere, box and shape casts (from their start along the direction) and ground
/// probes (straight down by their reach).
fn rays_of(ops: &[PlaneOp], positions: &std::collections::HashMap<u32, [f32; 3]>) -> Value {
    let add = |a: [f32; 3], d: [f32; 3]| [a[0] + d[0], a[1] + d[1], a[2] + d[2]];
    let mut out = Vec::new();
    let mut push = |kind: &str, from: [f32; 3], to: [f32; 3]| {
        if out.len() < MAX_RAYS {
            out.push(json!({ "kind": kind, "from": from, "to": to }));
        }
    };
    for op in ops {
        let PlaneOp::Query(q) = op else { continue };
        match q {
            QueryOp::Raycast { rays, .. } => {
                for r in rays {
                    push("Raycast", r.origin, add(r.origin, r.direction));
                }
            }
            QueryOp::Spherecast {
                origin, direction, ..
            } => push("Spherecast", *origin, add(*origin, *direction)),
            QueryOp::Blockcast {
                pose, direction, ..
            } => push("Blockcast", pose.position, add(pose.position, *direction)),
            QueryOp::Shapecast {
                object, direction, ..
            } => {
                if let Some(p) = positions.get(&object.slot) {
                    push("Shapecast", *p, add(*p, *direction));
                }
            }
            QueryOp::ProbeGround {
                position,
                max_distance,
                ..
            } => push(
                "ProbeGround",
                *position,
                add(*position, [0.0, -max_distance, 0.0]),
            ),
            _ => {}
        }
    }
    Value::Array(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use shm_layout::geometry::Pose;
    use shm_layout::{QueryFilter, Ray};

    #[test]
    fn requests_are_parsed_and_checked() {
        let r = ReplayRequest::parse(br#"{"action":"seek","tick":60}"#).unwrap();
        assert_eq!(r.action, ReplayAction::Seek(60));
        let r = ReplayRequest::parse(br#"{"action":"play","speed":0.25}"#).unwrap();
        assert_eq!((r.action, r.speed), (ReplayAction::Play, Some(0.25)));
        assert_eq!(
            ReplayRequest::parse(br#"{"action":"step"}"#)
                .unwrap()
                .action,
            ReplayAction::Step
        );
        for (body, says) in [
            (&br#"{"action":"seek"}"#[..], "needs a tick"),
            (br#"{"action":"seek","tick":-1}"#, "whole number"),
            (br#"{"action":"jump"}"#, "one of play"),
            (br#"{"action":"play","speed":0}"#, "between"),
            (br#"{"action":"play","speed":"fast"}"#, "must be a number"),
            (br#"{"action":"speed"}"#, "needs a speed"),
            (b"not json", "JSON object"),
        ] {
            let e = ReplayRequest::parse(body).unwrap_err();
            assert!(e.contains(says), "{e}");
        }
    }

    #[test]
    fn rays_are_drawn_from_their_origin_along_their_reach() {
        let filter = QueryFilter::default();
        let ops = vec![
            PlaneOp::Query(QueryOp::Raycast {
                rays: vec![
                    Ray {
                        origin: [0.0, 5.0, 0.0],
                        direction: [0.0, -10.0, 0.0],
                    },
                    Ray {
                        origin: [1.0, 1.0, 1.0],
                        direction: [2.0, 0.0, 0.0],
                    },
                ],
                filter: filter.clone(),
            }),
            PlaneOp::Query(QueryOp::Blockcast {
                pose: Pose::at([3.0, 0.0, 0.0]),
                size: [1.0, 1.0, 1.0],
                direction: [0.0, 0.0, 4.0],
                filter: filter.clone(),
            }),
            PlaneOp::Query(QueryOp::ProbeGround {
                position: [0.0, 2.0, 0.0],
                radius: 0.5,
                max_distance: 3.0,
                max_slope: 45.0,
                filter,
            }),
            PlaneOp::Info,
        ];
        let v = rays_of(&ops, &Default::default());
        assert_eq!(
            v,
            json!([
                {"kind": "Raycast", "from": [0.0, 5.0, 0.0], "to": [0.0, -5.0, 0.0]},
                {"kind": "Raycast", "from": [1.0, 1.0, 1.0], "to": [3.0, 1.0, 1.0]},
                {"kind": "Blockcast", "from": [3.0, 0.0, 0.0], "to": [3.0, 0.0, 4.0]},
                {"kind": "ProbeGround", "from": [0.0, 2.0, 0.0], "to": [0.0, -1.0, 0.0]},
            ])
        );
    }
}

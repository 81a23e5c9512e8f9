//! Recording a plane and replaying the file: [`Plane::start_recording`] /
//! [`Plane::stop_recording`] ask the daemon to write the plane's session file
//! ([`shm_layout::recording`]: a keyframe at the start, every batch of ops with the tick it
//! was applied at, each tick's state hash, a keyframe every so many ticks); [`Replay`]
//! restores it into a new manual plane of this client and re-applies the batches tick by
//! tick, checking every tick's hash. The first divergence stops it naming the tick and the
//! batch before it ([`Divergence`]).

use std::path::{Path, PathBuf};
use std::sync::Arc;

use shm_layout::recording::{Event, KeyframeWhy};
use shm_layout::{Command, PlaneOp, PlaneProp, RecordOp, RecordingInfo, Reply};

pub use shm_layout::recording::Recording;

use crate::{client::Client, error::Error, plane::Plane, plane_snapshot::PlaneSnapshot};

impl Plane {
    /// Starts recording the plane into a new file at `path` on the daemon's machine
    /// (relative paths are taken from this process's working directory); `None`: the daemon
    /// names a file in its `--record` folder or in `physics-recordings` under the temporary
    /// folder. Refused when the file exists or the plane records already. Returns the file.
    pub fn start_recording(&self, path: Option<&Path>) -> Result<PathBuf, Error> {
        let path = match path {
            None => String::new(),
            Some(p) => {
                let absolute = std::path::absolute(p).map_err(|e| Error::Invalid {
                    field: "path".into(),
                    message: format!("cannot resolve {}: {e}", p.display()),
                })?;
                absolute
                    .to_str()
                    .map(str::to_owned)
                    .ok_or_else(|| Error::Invalid {
                        field: "path".into(),
                        message: format!("{} is not valid UTF-8", absolute.display()),
                    })?
            }
        };
        let op = PlaneOp::Record(RecordOp::Start { path });
        match self.client().call(Command::plane(self.id(), op))? {
            Reply::Recording(info) => Ok(PathBuf::from(info.path)),
            other => Err(Error::Protocol(format!("unexpected reply {other:?}"))),
        }
    }

    /// Stops recording (the queued writes first, so they are in the file): the file is
    /// complete when this returns. `None` when the plane was not recording.
    pub fn stop_recording(&self) -> Result<Option<RecordingInfo>, Error> {
        let op = PlaneOp::Record(RecordOp::Stop);
        match self.client().call(Command::plane(self.id(), op))? {
            Reply::Recording(info) => Ok(Some(info)),
            Reply::Done => Ok(None),
            other => Err(Error::Protocol(format!("unexpected reply {other:?}"))),
        }
    }
}

/// Reads and checks a recording file (a damaged one is refused naming the byte offset).
pub fn load_recording(path: impl AsRef<Path>) -> Result<Recording, Error> {
    let path = path.as_ref();
    let bytes = std::fs::read(path).map_err(|e| Error::Invalid {
        field: "path".into(),
        message: format!("cannot read recording {}: {e}", path.display()),
    })?;
    Recording::parse(bytes).map_err(|mut e| {
        e.message = format!("{}: {}", path.display(), e.message);
        Error::Command(e)
    })
}

/// Where a replay left the recording: the tick whose hash differs, both hashes, and the
/// batch of ops applied before that tick.
#[derive(Debug, Clone, PartialEq)]
pub struct Divergence {
    /// The tick whose state hash differs.
    pub tick: u64,
    /// The hash the recording holds.
    pub recorded: u64,
    /// The hash the replay got.
    pub replayed: u64,
    /// The batch applied before that tick: its byte offset in the file, the tick it was
    /// applied at and a short list of its ops; `None` when no op came before the tick.
    pub batch: Option<String>,
}

impl std::fmt::Display for Divergence {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "the replay diverged at tick {}: state hash {:016x}, the recording has {:016x}",
            self.tick, self.replayed, self.recorded
        )?;
        match &self.batch {
            Some(b) => write!(f, "; the batch before it: {b}"),
            None => write!(f, "; no op was applied since the tick before"),
        }
    }
}

/// What [`Replay::advance`] did.
#[derive(Debug, Clone, PartialEq)]
pub enum Advanced {
    /// A tick was stepped and its hash agrees with the recording.
    Tick(u64),
    /// The recording ends here.
    End,
    /// The tick's hash differs; the replay stays at that tick.
    Diverged(Divergence),
}

/// A recording being replayed into a plane of this client.
pub struct Replay {
    recording: Arc<Recording>,
    plane: Plane,
    /// The next event to apply.
    next: usize,
    /// The batch applied since the last tick (its event index).
    batch: Option<usize>,
    tick: u64,
    /// The batch events of each tick, by event index ([`Replay::ops_at`] is asked every
    /// tick a viewer shows: one pass over the file at the start, not one a tick).
    batches: std::collections::BTreeMap<u64, Vec<usize>>,
}

/// Options every replayed plane gets on top of its snapshot: it advances only when the
/// replay steps it.
fn replay_overrides() -> Vec<PlaneProp> {
    vec![PlaneProp::TickRate(0.0)]
}

/// Most bytes of recorded ops one replay request carries (a quarter of the daemon's
/// default request limit).
const MAX_REQUEST_BYTES: usize = 4 << 20;
/// Most recorded ops one replay request carries.
const MAX_REQUEST_OPS: usize = 16_384;

impl Replay {
    /// Restores the recording's start keyframe into a new manual plane of `client`.
    pub fn start(client: &Client, recording: Arc<Recording>) -> Result<Replay, Error> {
        let Some(Event::Keyframe { range, tick, .. }) = recording.events.first() else {
            return Err(Error::Protocol(
                "a recording without its start keyframe".into(),
            ));
        };
        let snapshot = PlaneSnapshot::from_bytes(recording.snapshot(range).to_vec())?;
        let tick = *tick;
        let plane = client.plane_from_snapshot(&snapshot, &replay_overrides())?;
        let mut batches = std::collections::BTreeMap::<u64, Vec<usize>>::new();
        for (i, e) in recording.events.iter().enumerate() {
            if let Event::Batch { tick, .. } = e {
                batches.entry(*tick).or_default().push(i);
            }
        }
        Ok(Replay {
            recording,
            plane,
            next: 1,
            batch: None,
            tick,
            batches,
        })
    }

    /// The recording.
    pub fn recording(&self) -> &Arc<Recording> {
        &self.recording
    }

    /// The plane the replay drives.
    pub fn plane(&self) -> &Plane {
        &self.plane
    }

    /// The plane, handed over (it stays manual: step it yourself).
    pub fn into_plane(self) -> Plane {
        self.plane
    }

    /// The tick the plane is at.
    pub fn tick(&self) -> u64 {
        self.tick
    }

    /// Whether every event was applied.
    pub fn at_end(&self) -> bool {
        self.next >= self.recording.events.len()
    }

    /// The ops of the batch applied at `tick` (before tick + 1), as recorded: what a
    /// viewer draws (rays of queries) at that tick. Empty when none was.
    pub fn ops_at(&self, tick: u64) -> Vec<PlaneOp> {
        let events = self.batches.get(&tick).map_or(&[][..], Vec::as_slice);
        events
            .iter()
            .flat_map(|&i| {
                self.recording
                    .ops(&self.recording.events[i])
                    .unwrap_or_default()
            })
            .collect()
    }

    /// Applies the recorded events up to and including the next tick: the batch before it
    /// (its ops sent as recorded, all in one request; refused ops are refused again, as
    /// when recorded), a keyframe written after a Restore or Rewind (restored), then the
    /// step with the recorded dt, whose state hash must equal the recorded one.
    pub fn advance(&mut self) -> Result<Advanced, Error> {
        while let Some(event) = self.recording.events.get(self.next).cloned() {
            self.next += 1;
            match event {
                Event::Batch { .. } => {
                    self.send_batch(&event)?;
                    self.batch = Some(self.next - 1);
                }
                Event::Keyframe {
                    why: KeyframeWhy::Jump,
                    range,
                    tick,
                    state_hash,
                } => {
                    // The Restore or Rewind before it was repeated with its batch; the
                    // keyframe is the state it made. Restored only where the repeat did not
                    // get there (a Rewind reaching past where the replay started).
                    let here = self.plane.snapshot()?.header().state_hash;
                    if self.plane_tick()? != tick || here != state_hash {
                        let snapshot =
                            PlaneSnapshot::from_bytes(self.recording.snapshot(&range).to_vec())?;
                        self.plane.restore_with(&snapshot, &replay_overrides())?;
                    }
                    self.tick = tick;
                }
                Event::Keyframe { .. } => {}
                Event::Tick {
                    tick,
                    dt,
                    state_hash,
                } => {
                    let stepped = self.plane.step(dt)?;
                    self.tick = stepped;
                    let replayed = self.plane.snapshot()?.header().state_hash;
                    let batch = self.batch.take();
                    if stepped != tick || replayed != state_hash {
                        return Ok(Advanced::Diverged(Divergence {
                            tick,
                            recorded: state_hash,
                            replayed,
                            batch: batch.map(|i| self.describe_batch(i)),
                        }));
                    }
                    return Ok(Advanced::Tick(tick));
                }
            }
        }
        Ok(Advanced::End)
    }

    /// Advances until the plane is at `tick` (or the recording ends). Going backwards, or
    /// far forwards, restores the last keyframe at or before `tick` first.
    pub fn seek(&mut self, tick: u64) -> Result<Advanced, Error> {
        let keyframe = self.recording.keyframe_for(tick);
        let Event::Keyframe {
            tick: key_tick,
            range,
            ..
        } = self.recording.events[keyframe].clone()
        else {
            return Err(Error::Protocol("keyframe_for gave no keyframe".into()));
        };
        if tick < self.tick || (key_tick > self.tick && keyframe >= self.next) {
            let snapshot = PlaneSnapshot::from_bytes(self.recording.snapshot(&range).to_vec())?;
            self.plane.restore_with(&snapshot, &replay_overrides())?;
            self.tick = key_tick;
            self.next = keyframe + 1;
            self.batch = None;
        }
        let mut last = Advanced::Tick(self.tick);
        while self.tick < tick {
            last = self.advance()?;
            if !matches!(last, Advanced::Tick(_)) {
                break;
            }
        }
        Ok(last)
    }

    /// Replays to the end (or to `until`); the first divergence stops it.
    pub fn run(&mut self, until: Option<u64>) -> Result<Advanced, Error> {
        loop {
            if until.is_some_and(|u| self.tick >= u) {
                return Ok(Advanced::Tick(self.tick));
            }
            match self.advance()? {
                Advanced::Tick(_) => {}
                other => return Ok(other),
            }
        }
    }

    /// The tick the plane's newest sample shows.
    fn plane_tick(&self) -> Result<u64, Error> {
        Ok(self.plane.snapshot()?.tick())
    }

    /// Sends a batch's ops as recorded, in requests of bounded size (a batch gathers every
    /// request applied between two ticks). Per-op refusals are part of what happened (the
    /// recorded plane refused them too); only a lost request stops the replay.
    fn send_batch(&self, event: &Event) -> Result<(), Error> {
        let id = self.plane.id();
        let mut commands = Vec::new();
        let mut bytes = 0;
        for (op, size) in self.recording.sized_ops(event)? {
            // The replay drives the plane's ticks itself.
            if matches!(
                op,
                PlaneOp::Set(PlaneProp::TickRate(_)) | PlaneOp::Record(_)
            ) {
                continue;
            }
            if !commands.is_empty()
                && (bytes + size > MAX_REQUEST_BYTES || commands.len() >= MAX_REQUEST_OPS)
            {
                self.plane.client().send(std::mem::take(&mut commands))?;
                bytes = 0;
            }
            bytes += size;
            commands.push(Command::plane(id, op));
        }
        if !commands.is_empty() {
            self.plane.client().send(commands)?;
        }
        Ok(())
    }

    fn describe_batch(&self, index: usize) -> String {
        let event = &self.recording.events[index];
        let Event::Batch {
            tick,
            count,
            offset,
            ..
        } = event
        else {
            return String::new();
        };
        let ops = self.recording.ops(event).unwrap_or_default();
        let mut names: Vec<String> = ops.iter().take(8).map(op_words).collect();
        if ops.len() > 8 {
            names.push(format!("… {} more", ops.len() - 8));
        }
        format!(
            "{count} op(s) applied at tick {tick} (entry at byte offset {offset}): {}",
            names.join(", ")
        )
    }
}

/// A short description of an op (its variant and the object it touches, never a payload).
fn op_words(op: &PlaneOp) -> String {
    let text = format!("{op:?}");
    let short: String = text.chars().take(60).collect();
    match short.len() < text.len() {
        true => format!("{short}…"),
        false => short,
    }
}

//! Recording planes: a session file that reproduces a plane bit for bit
//! ([`shm_layout::recording`]). Every plane the server creates is a [`Recorded`]: a
//! [`Backend`] around the plane kind's own that passes everything through and, while a
//! recording runs, writes what the plane does in the order it happens: a keyframe of the
//! state it starts from (a snapshot holds the ops applied since the last step too), the
//! ops of each run (encoded as they are applied, one batch entry per tick), each tick's dt
//! and state hash, a keyframe every `--record-keyframe-every` ticks, and after every
//! Restore or Rewind the op and a keyframe of the state it made. It starts with
//! `PlaneOp::Record(Start)` (owner only) or, for every plane of the daemon, `--record DIR`;
//! it ends with `Stop`, or when the plane goes (destroyed, moved to another daemon, the
//! daemon stopping): the end entry says which. Nothing is written, and nothing paid beyond
//! one branch per op and step, unless asked.

#[cfg(test)]
mod tests;
mod writer;

use std::mem::MaybeUninit;
use std::path::{Path, PathBuf};
use std::sync::atomic::Ordering;
use std::time::{SystemTime, UNIX_EPOCH};

use shm_layout::recording::{
    preamble, push_keyframe, push_start, push_tick, BatchWriter, KeyframeWhy, RecordingStart,
    DEFAULT_KEYFRAME_EVERY,
};
use shm_layout::{
    BodyState, CommandError, CommandResult, ErrorKind, EventRecord, PlaneId, PlaneKind, PlaneOp,
    RecordOp, RecordingInfo, Reply, TickHeader,
};

use crate::backend::{Backend, SlotFilter, SnapshotJob, Usage};
use writer::{Chunk, Writer};

/// The daemon's recording flags.
#[derive(Debug, Clone, PartialEq, clap::Args)]
pub struct RecordArgs {
    /// Record every plane this daemon creates or receives into DIR (one file per plane,
    /// `plane-<id>-<unix ms>.physrec`); also where `Record = true` / `StartRecording()`
    /// without a path write. Without it those go to `physics-recordings` under the system's
    /// temporary folder.
    #[arg(long = "record", value_name = "DIR")]
    pub record: Option<PathBuf>,
    /// Most bytes one recording file may hold: past it the recording ends (its end entry
    /// says so). Default 4 GiB.
    #[arg(long = "record-max-bytes", value_name = "BYTES", default_value_t = DEFAULT_MAX_BYTES)]
    pub max_bytes: u64,
    /// Ticks between the keyframes of a recording (a full snapshot, where a replay or the
    /// viewer can enter it). Within [1, 1000000].
    #[arg(long = "record-keyframe-every", value_name = "TICKS",
          default_value_t = DEFAULT_KEYFRAME_EVERY, value_parser = parse_every)]
    pub keyframe_every: u32,
}

fn parse_every(s: &str) -> Result<u32, String> {
    let v: u32 = s
        .parse()
        .map_err(|_| format!("--record-keyframe-every takes a number of ticks, got {s:?}"))?;
    if !(1..=1_000_000).contains(&v) {
        return Err(format!(
            "--record-keyframe-every must be within [1, 1000000] ticks, got {v}"
        ));
    }
    Ok(v)
}

/// Default `--record-max-bytes`: 4 GiB.
pub const DEFAULT_MAX_BYTES: u64 = 4 << 30;

/// How the daemon's planes record.
#[derive(Debug, Clone)]
pub struct RecordSettings {
    /// Most bytes of one recording file.
    pub max_bytes: u64,
    /// `--record DIR`: every plane records there from its creation.
    pub all_into: Option<PathBuf>,
    /// Ticks between keyframes.
    pub keyframe_every: u32,
    /// Named in each file's start entry (the domain, or the cluster member's name).
    pub daemon: String,
}

impl Default for RecordSettings {
    fn default() -> Self {
        RecordSettings {
            all_into: None,
            keyframe_every: DEFAULT_KEYFRAME_EVERY,
            daemon: String::new(),
            max_bytes: DEFAULT_MAX_BYTES,
        }
    }
}

impl RecordSettings {
    /// The settings of `args` for a daemon called `daemon`.
    pub fn new(args: &RecordArgs, daemon: &str) -> RecordSettings {
        RecordSettings {
            all_into: args.record.clone(),
            keyframe_every: args.keyframe_every,
            daemon: daemon.to_owned(),
            max_bytes: args.max_bytes,
        }
    }

    /// The folder a recording without a path goes to.
    fn folder(&self) -> PathBuf {
        self.all_into
            .clone()
            .unwrap_or_else(|| std::env::temp_dir().join("physics-recordings"))
    }
}

/// Bytes of entries a recording gathers before handing them to its writer.
const HAND_OVER_BYTES: usize = 64 * 1024;
/// Ticks a recording gathers before handing their entries to its writer: the writer wakes
/// once per this many ticks, not every tick (a daemon killed loses at most these).
const HAND_OVER_TICKS: u32 = 16;

/// A recording running.
struct Recorder {
    writer: Writer,
    path: PathBuf,
    /// Ops applied since the last tick.
    batch: BatchWriter,
    /// Entries not handed to the writer yet, and the ticks among them.
    gathered: Vec<u8>,
    gathered_ticks: u32,
    /// Ticks recorded.
    ticks: u64,
    /// Ticks since the last keyframe.
    since_keyframe: u32,
    keyframe_every: u32,
}

impl Recorder {
    /// Hands the gathered entries (the batch not yet closed by a tick included), then
    /// `then` (a keyframe), to the writer.
    fn hand_over(&mut self, then: Option<Chunk>) {
        self.batch.push_to(&mut self.gathered);
        if !self.gathered.is_empty() {
            let entries = std::mem::replace(&mut self.gathered, Vec::with_capacity(4096));
            self.writer.send(Chunk::Entries(entries));
        }
        self.gathered_ticks = 0;
        if let Some(chunk) = then {
            self.writer.send(chunk);
        }
    }
}

/// A plane that records when asked (see the module's text).
pub struct Recorded {
    inner: Box<dyn Backend>,
    id: PlaneId,
    settings: RecordSettings,
    recorder: Option<Recorder>,
}

fn unix_ms() -> u64 {
    SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map(|d| d.as_millis() as u64)
        .unwrap_or(0)
}

fn refused(message: String) -> CommandError {
    CommandError {
        field: Some("path".into()),
        ..CommandError::new(ErrorKind::InvalidValue, message)
    }
}

impl Recorded {
    /// `inner`, recording nothing yet.
    pub fn new(inner: Box<dyn Backend>, id: PlaneId, settings: RecordSettings) -> Recorded {
        Recorded {
            inner,
            id,
            settings,
            recorder: None,
        }
    }

    /// Starts recording when the daemon records every plane (`--record DIR`), or when the
    /// plane arrived recording from another daemon; a plane that cannot (the folder is not
    /// writable) runs on unrecorded, with the reason logged.
    /// `arrived_recording`: the plane arrived from another daemon where it was recording.
    pub fn record_if_asked(&mut self, arrived_recording: bool) {
        if self.settings.all_into.is_some() || arrived_recording {
            if let Err(e) = self.start(String::new()) {
                tracing::error!(plane = self.id, "--record: {}", e.message);
            }
        }
    }

    fn new_file(&self, path: &str) -> Result<(std::fs::File, PathBuf), CommandError> {
        let open = |p: &Path| {
            std::fs::OpenOptions::new()
                .write(true)
                .create_new(true)
                .open(p)
        };
        if !path.is_empty() {
            let p = PathBuf::from(path);
            if !p.is_absolute() {
                return Err(refused(format!(
                    "StartRecording({path:?}): the path must be absolute (the daemon's working \
                     folder is not the caller's)"
                )));
            }
            return match open(&p) {
                Ok(f) => Ok((f, p)),
                Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => Err(refused(format!(
                    "StartRecording({path:?}): the file exists (a recording never overwrites a \
                     file)"
                ))),
                Err(e) => Err(refused(format!("StartRecording({path:?}): {e}"))),
            };
        }
        let dir = self.settings.folder();
        std::fs::create_dir_all(&dir).map_err(|e| {
            refused(format!(
                "cannot create the recordings folder {}: {e}",
                dir.display()
            ))
        })?;
        let stem = format!("plane-{}-{}", self.id, unix_ms());
        for n in 0..1000u32 {
            let name = match n {
                0 => format!("{stem}.physrec"),
                n => format!("{stem}-{n}.physrec"),
            };
            let p = dir.join(name);
            match open(&p) {
                Ok(f) => return Ok((f, p)),
                Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => continue,
                Err(e) => return Err(refused(format!("cannot create {}: {e}", p.display()))),
            }
        }
        Err(refused(format!(
            "no free file name {stem}*.physrec in {}",
            dir.display()
        )))
    }

    /// A snapshot of the plane as a keyframe chunk: a copy now, encoded by the writer,
    /// when the kind splits its snapshot; encoded here otherwise.
    fn keyframe(&mut self, why: KeyframeWhy) -> Result<Chunk, CommandError> {
        if let Some(job) = self.inner.snapshot_later() {
            return Ok(Chunk::Later(why, job?));
        }
        match self.inner.apply(PlaneOp::Snapshot)? {
            Reply::Snapshot(bytes) => {
                let mut entry = Vec::with_capacity(bytes.len() + 16);
                push_keyframe(&mut entry, why, &bytes);
                Ok(Chunk::Entries(entry))
            }
            other => Err(CommandError::new(
                ErrorKind::Internal,
                format!("plane {}: a snapshot answered {other:?}", self.id),
            )),
        }
    }

    fn start(&mut self, path: String) -> CommandResult {
        if let Some(r) = &self.recorder {
            return Err(CommandError::new(
                ErrorKind::InvalidValue,
                format!(
                    "plane {} records already (into {}): StopRecording first",
                    self.id,
                    r.path.display()
                ),
            ));
        }
        let (file, path) = self.new_file(&path)?;
        let writer = Writer::start(file, path.clone(), self.id, self.settings.max_bytes)?;
        let mut head = preamble().to_vec();
        push_start(
            &mut head,
            &RecordingStart {
                kind: self.inner.kind(),
                plane: self.id,
                tick: self.inner.tick(),
                keyframe_every: self.settings.keyframe_every,
                daemon: self.settings.daemon.clone(),
                started_unix_ms: unix_ms(),
            },
        );
        writer.send(Chunk::Entries(head));
        writer.send(self.keyframe(KeyframeWhy::Start)?);
        tracing::info!(plane = self.id, path = %path.display(), "recording started");
        let info = RecordingInfo {
            path: path.display().to_string(),
            ticks: 0,
            bytes: 0,
        };
        self.recorder = Some(Recorder {
            writer,
            path,
            batch: BatchWriter::default(),
            ticks: 0,
            since_keyframe: 0,
            keyframe_every: self.settings.keyframe_every,
            gathered: Vec::new(),
            gathered_ticks: 0,
        });
        Ok(Reply::Recording(info))
    }

    /// Ends the recording (if one runs) with `reason`; what it wrote.
    fn stop(&mut self, reason: &str) -> Option<Result<RecordingInfo, CommandError>> {
        let mut r = self.recorder.take()?;
        r.hand_over(None);
        let path = r.path.display().to_string();
        let ticks = r.ticks;
        let result = r.writer.finish(reason).map(|bytes| RecordingInfo {
            path: path.clone(),
            ticks,
            bytes,
        });
        match &result {
            Ok(info) => tracing::info!(
                plane = self.id,
                path,
                ticks,
                bytes = info.bytes,
                reason,
                "recording ended"
            ),
            Err(e) => tracing::error!(plane = self.id, path, "recording failed: {}", e.message),
        }
        Some(result)
    }

    /// Whether `op` goes into the recording: everything that may change the plane, and
    /// scene queries (drawn by the viewer, and they refresh the query tree).
    fn recorded(op: &PlaneOp) -> bool {
        !matches!(op, PlaneOp::Record(_)) && (!op.is_read_only() || matches!(op, PlaneOp::Query(_)))
    }

    fn jump(&mut self) {
        match self.keyframe(KeyframeWhy::Jump) {
            Ok(chunk) => {
                if let Some(r) = &mut self.recorder {
                    r.hand_over(Some(chunk));
                    r.since_keyframe = 0;
                }
            }
            Err(e) => {
                let reason = format!(
                    "the plane's state after a restore could not be kept: {}",
                    e.message
                );
                let _ = self.stop(&reason);
            }
        }
    }
}

impl Drop for Recorded {
    fn drop(&mut self) {
        let _ =
            self.stop("the plane was removed (destroyed, its owner left, or the daemon stopped)");
    }
}

impl Backend for Recorded {
    fn kind(&self) -> PlaneKind {
        self.inner.kind()
    }

    fn apply(&mut self, op: PlaneOp) -> CommandResult {
        if let PlaneOp::Record(op) = op {
            return match op {
                RecordOp::Start { path } => self.start(path),
                RecordOp::Stop => match self.stop("stopped") {
                    Some(result) => result.map(Reply::Recording),
                    None => Ok(Reply::Done),
                },
            };
        }
        let Some(r) = &mut self.recorder else {
            return self.inner.apply(op);
        };
        if Recorded::recorded(&op) {
            r.batch.add(self.inner.tick(), &op);
        }
        // A Restore or Rewind goes in as an op (a replay repeats it on the same state), and
        // the state it made as a keyframe: the replay checks it, and restores it where the
        // op cannot be repeated (a Rewind past the recording's start).
        let jumps = matches!(op, PlaneOp::Restore { .. } | PlaneOp::Rewind(_));
        let result = self.inner.apply(op);
        if jumps && result.is_ok() {
            self.jump();
        }
        result
    }

    fn step(&mut self, dt: f32) -> Result<bool, CommandError> {
        let Some(r) = &mut self.recorder else {
            return self.inner.step(dt);
        };
        let before = self.inner.tick();
        r.batch.push_to(&mut r.gathered);
        let stepped = self.inner.step(dt);
        let tick = self.inner.tick();
        if tick == before + 1 {
            push_tick(&mut r.gathered, tick, dt, self.inner.header().state_hash);
            r.ticks += 1;
            r.since_keyframe += 1;
            r.gathered_ticks += 1;
        }
        if r.gathered.len() >= HAND_OVER_BYTES || r.gathered_ticks >= HAND_OVER_TICKS {
            r.hand_over(None);
        }
        if r.writer.failed.load(Ordering::Relaxed) {
            // The writer says why when the recording is stopped.
            let _ = self.stop("writing failed");
            return stepped;
        }
        if r.writer.full.load(Ordering::Relaxed) {
            let reason = format!(
                "the file reached --record-max-bytes ({} bytes)",
                self.settings.max_bytes
            );
            let _ = self.stop(&reason);
            return stepped;
        }
        if r.since_keyframe >= r.keyframe_every {
            r.since_keyframe = 0;
            match self.keyframe(KeyframeWhy::Periodic) {
                Ok(chunk) => {
                    if let Some(r) = &mut self.recorder {
                        r.hand_over(Some(chunk));
                    }
                }
                Err(e) => {
                    let reason = format!("a keyframe could not be taken: {}", e.message);
                    let _ = self.stop(&reason);
                }
            }
        }
        stepped
    }

    fn tick_rate(&self) -> f32 {
        self.inner.tick_rate()
    }

    fn enabled(&self) -> bool {
        self.inner.enabled()
    }

    fn tick(&self) -> u64 {
        self.inner.tick()
    }

    fn header(&self) -> TickHeader {
        self.inner.header()
    }

    fn slot_count(&self) -> usize {
        self.inner.slot_count()
    }

    fn awake_count(&self) -> usize {
        self.inner.awake_count()
    }

    fn for_each_awake(&self, f: &mut dyn FnMut(usize)) {
        self.inner.for_each_awake(f)
    }

    fn drain_dirty(&mut self, into: &mut Vec<u32>) -> bool {
        self.inner.drain_dirty(into)
    }

    fn body_state(&self, i: usize) -> BodyState {
        self.inner.body_state(i)
    }

    fn write_states(&self, out: &mut [MaybeUninit<BodyState>], filter: SlotFilter<'_>) {
        self.inner.write_states(out, filter)
    }

    fn events(&self) -> &[EventRecord] {
        self.inner.events()
    }

    fn usage(&self) -> Usage {
        self.inner.usage()
    }

    fn snapshot_later(&self) -> Option<Result<SnapshotJob, CommandError>> {
        self.inner.snapshot_later()
    }

    fn idle_work(&mut self) -> Result<(), CommandError> {
        self.inner.idle_work()
    }

    fn has_idle_work(&self) -> bool {
        self.inner.has_idle_work()
    }

    fn recording(&self) -> bool {
        self.recorder.is_some()
    }

    fn leaving(&mut self, why: &str) {
        let _ = self.stop(why);
    }
}

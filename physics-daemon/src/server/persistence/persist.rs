//! Persistent planes (`Persistent = true`, `--state-dir DIR`, `--snapshot-every SECONDS`):
//! each one's worker copies the plane's state (`Backend::snapshot_later`, what Rewind keeps)
//! every period when the plane changed, on `Save` and at a clean shutdown, and hands it to one
//! writer thread per daemon, which encodes it (the plane's own snapshot encoder, off the
//! tick) and writes `DIR/<domain>/<name>.physnap` atomically (a temporary file in the
//! same directory, written, fsynced, renamed over the old file, then the directory fsynced):
//! a crash at any point leaves the previous file or the new one, never half of one. The
//! worker never waits for the disk (except for an explicit `Save`, whose reply says the file
//! is there).
//!
//! The writer also records each persistent plane's tick in `<name>.tick` (8 bytes, written
//! in place every [`TICK_RECORD_PERIOD`] while the tick moves; no fsync: a killed daemon's
//! writes are in the page cache all the same). The next daemon reads it to tell a restored
//! plane's opener how many ticks were lost (`Recovered(lostTicks)`).
//!
//! At start the daemon loads every `.physnap` of its domain's directory ([`load`]): a file
//! whose name is not a plane name, or that fails the snapshot checks (truncated, corrupted,
//! another format or engine) is skipped with an error naming the file and why; leftover
//! temporary files are removed.

use std::collections::{HashMap, HashSet};
use std::fs::File;
use std::io::Write as _;
use std::os::unix::fs::FileExt as _;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::mpsc::{self, Receiver, RecvTimeoutError, Sender};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use shm_layout::{
    snapshot, CommandError, ErrorKind, PlaneId, PlaneKind, PlaneName, PlaneOp, Reply,
};

use crate::backend::Backend;

/// File name ending of a plane's snapshot.
pub const EXTENSION: &str = "physnap";
/// How often the writer records the ticks of persistent planes that moved.
pub const TICK_RECORD_PERIOD: Duration = Duration::from_millis(100);
/// The state folder of a daemon given `--replicate-every` without `--state-dir`, under the
/// system's temporary directory (each domain has its own folder in it, mode 0700).
pub const REPLICA_DIR: &str = "physics-replicated-planes";
/// Default `--snapshot-every`, in seconds.
pub const DEFAULT_EVERY: f64 = 5.0;

/// The persistence flags of the daemon.
#[derive(Debug, Clone, PartialEq, clap::Args)]
pub struct PersistArgs {
    /// Directory for persistent planes: each is written to `DIR/<domain>/<name>.physnap`
    /// and restored from there by the next daemon of the domain. Without it, `Persistent =
    /// true` is refused.
    #[arg(long = "state-dir")]
    pub state_dir: Option<PathBuf>,
    /// Seconds between two writes of a persistent plane that changed (also written on
    /// `Save` and at a clean shutdown). Within [0.05, 86400].
    #[arg(long = "snapshot-every", default_value_t = DEFAULT_EVERY, value_parser = parse_every)]
    pub snapshot_every: f64,
    /// In a cluster: a persistent plane that changed is also written (and so replicated to
    /// the other members, docs/cluster.md "Failover") every TICKS of its own ticks. Without
    /// `--state-dir` the daemon keeps its planes' files in a folder of its own under the
    /// system's temporary directory. Within [1, 1000000].
    #[arg(long = "replicate-every", value_name = "TICKS", value_parser = parse_ticks)]
    pub replicate_every: Option<u64>,
}

fn parse_ticks(s: &str) -> Result<u64, String> {
    let v: u64 = s
        .parse()
        .map_err(|_| format!("--replicate-every takes a number of ticks, got {s:?}"))?;
    if !(1..=1_000_000).contains(&v) {
        return Err(format!(
            "--replicate-every must be within [1, 1000000] ticks, got {v}"
        ));
    }
    Ok(v)
}

fn parse_every(s: &str) -> Result<f64, String> {
    let v: f64 = s
        .parse()
        .map_err(|_| format!("--snapshot-every takes seconds, got {s:?}"))?;
    if !(0.05..=86_400.0).contains(&v) {
        return Err(format!(
            "--snapshot-every must be within [0.05, 86400] seconds, got {v}"
        ));
    }
    Ok(v)
}

/// Where and how often a daemon writes its persistent planes.
#[derive(Debug, Clone, PartialEq)]
pub struct Persistence {
    /// The state directory (the domain's folder goes under it).
    pub dir: PathBuf,
    /// Time between two writes of a plane that changed.
    pub every: Duration,
    /// Ticks of a plane between two writes when it changed (`--replicate-every`), besides
    /// `every`.
    pub every_ticks: Option<u64>,
}

impl PersistArgs {
    /// The daemon's persistence, when `--state-dir` (or `--replicate-every`) is given.
    pub fn persistence(&self) -> Option<Persistence> {
        let dir = match (&self.state_dir, self.replicate_every) {
            (Some(dir), _) => dir.clone(),
            (None, Some(_)) => std::env::temp_dir().join(REPLICA_DIR),
            (None, None) => return None,
        };
        Some(Persistence {
            dir,
            every: Duration::from_secs_f64(self.snapshot_every),
            every_ticks: self.replicate_every,
        })
    }
}

/// The domain's folder of the state directory `dir`.
pub fn domain_dir(dir: &Path, domain: &str) -> PathBuf {
    dir.join(domain)
}

/// The snapshot file of plane `name` in the domain folder `dir`.
pub fn file_of(dir: &Path, name: &str) -> PathBuf {
    dir.join(format!("{name}.{EXTENSION}"))
}

fn tick_file_of(dir: &Path, name: &str) -> PathBuf {
    dir.join(format!("{name}.tick"))
}

fn temp_of(dir: &Path, name: &str) -> PathBuf {
    dir.join(format!(".{name}.{EXTENSION}.tmp"))
}

/// What a plane's worker and the request loop share about its life beyond the engine.
#[derive(Debug, Default)]
pub struct Marks {
    /// The tick the plane reached (`ListPlanes`, the tick record).
    pub tick: Arc<AtomicU64>,
    /// Something changed since the last write (an op that is not a read, a tick).
    pub changed: AtomicBool,
    /// A restored plane waits for its first `Open` before it ticks on its own.
    pub held: AtomicBool,
    /// Destroyed by its owner: the file goes with it.
    pub destroyed: AtomicBool,
}

/// What the writer thread is asked to do.
enum Write {
    /// Write `bytes` as plane `name`'s file; `done` hears the outcome.
    File {
        name: String,
        plane: PlaneId,
        tick: u64,
        bytes: Bytes,
        done: Option<Sender<Result<(), String>>>,
    },
    /// Record the tick of plane `name` from now on.
    Track {
        name: String,
        plane: PlaneId,
        tick: Arc<AtomicU64>,
        recorded: Option<u64>,
    },
    /// Plane `plane`, named `name`, was destroyed: stop recording, remove its files, and
    /// ignore the writes of it still on their way.
    Delete { name: String, plane: PlaneId },
}

/// The writer thread of a daemon, and the way to it.
pub struct Writer {
    dir: PathBuf,
    every: Duration,
    every_ticks: Option<u64>,
    jobs: Option<Sender<Write>>,
    thread: Option<JoinHandle<()>>,
}

impl Writer {
    /// Creates the domain's folder under the state directory (mode 0700) and starts the
    /// writer thread.
    pub fn start(persistence: &Persistence, domain: &str) -> std::io::Result<Writer> {
        use std::os::unix::fs::DirBuilderExt as _;
        let dir = domain_dir(&persistence.dir, domain);
        std::fs::DirBuilder::new()
            .recursive(true)
            .mode(0o700)
            .create(&dir)?;
        let (jobs, receiver) = mpsc::channel();
        let thread_dir = dir.clone();
        let thread = std::thread::Builder::new()
            .name("plane-writer".into())
            .spawn(move || write_loop(&thread_dir, receiver))?;
        Ok(Writer {
            dir,
            every: persistence.every,
            every_ticks: persistence.every_ticks,
            jobs: Some(jobs),
            thread: Some(thread),
        })
    }

    /// The domain's folder.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// The saver a persistent plane's worker uses. `restored`: the tick of the snapshot a
    /// restored plane starts from (its tick record is left alone until it moves past it, so
    /// the old daemon's record survives a second crash before anyone opens the plane).
    pub(crate) fn plane_file(
        &self,
        id: PlaneId,
        name: &str,
        marks: &Marks,
        restored: Option<u64>,
    ) -> Option<PlaneFile> {
        let jobs = self.jobs.clone()?;
        let _ = jobs.send(Write::Track {
            name: name.to_string(),
            plane: id,
            tick: marks.tick.clone(),
            recorded: restored,
        });
        Some(PlaneFile {
            id,
            name: name.to_string(),
            jobs,
            every: self.every,
            every_ticks: self.every_ticks,
            // The first write comes at once: a plane is on disk from its creation on.
            next_save: Instant::now(),
            saved_tick: 0,
        })
    }

    /// Plane `id`, named `name`, was destroyed by its owner: its files go (sent by the
    /// request loop before the name is free again, so a new plane of the same name is
    /// written after the removal).
    pub fn delete(&self, id: PlaneId, name: &str) {
        if let Some(jobs) = &self.jobs {
            let _ = jobs.send(Write::Delete {
                name: name.to_string(),
                plane: id,
            });
        }
    }

    /// Writes what is queued, then ends the thread (after every worker has ended).
    pub fn finish(&mut self) {
        self.jobs = None;
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

impl Drop for Writer {
    fn drop(&mut self) {
        self.finish();
    }
}

/// A persistent plane's side of the writer: held by its worker.
pub(crate) struct PlaneFile {
    id: PlaneId,
    name: String,
    jobs: Sender<Write>,
    every: Duration,
    every_ticks: Option<u64>,
    next_save: Instant,
    /// The plane's tick at the last periodic write.
    saved_tick: u64,
}

impl PlaneFile {
    /// When the next periodic write is due (by time; see [`PlaneFile::is_due`]).
    pub fn due(&self) -> Instant {
        self.next_save
    }

    /// Whether the periodic write is due at `now` with the plane at `tick`: its period has
    /// passed, or it ran `--replicate-every` ticks since the last one.
    pub fn is_due(&self, now: Instant, tick: u64) -> bool {
        now >= self.next_save
            || self
                .every_ticks
                .is_some_and(|n| tick >= self.saved_tick.saturating_add(n))
    }

    /// The periodic write: when due and the plane changed, snapshot it and hand the bytes
    /// to the writer (the worker does not wait for the disk).
    pub fn save_if_due(&mut self, plane: &mut dyn Backend, marks: &Marks, now: Instant) {
        let tick = marks.tick.load(Ordering::SeqCst);
        if !self.is_due(now, tick) || marks.destroyed.load(Ordering::SeqCst) {
            return;
        }
        self.next_save = now + self.every;
        self.saved_tick = tick;
        if marks.changed.swap(false, Ordering::SeqCst) {
            if let Err(e) = self.send(plane, None) {
                // Next period tries again.
                marks.changed.store(true, Ordering::SeqCst);
                tracing::warn!(plane = self.name, "cannot write the plane: {e}");
            }
        }
    }

    /// `Save`: writes the plane now and replies once the file is on disk.
    pub fn save_now(
        &mut self,
        plane: &mut dyn Backend,
        marks: &Marks,
    ) -> Result<Reply, CommandError> {
        let (done, outcome) = mpsc::channel();
        marks.changed.store(false, Ordering::SeqCst);
        let tick = self.send(plane, Some(done))?;
        match outcome.recv() {
            Ok(Ok(())) => Ok(Reply::Saved { tick }),
            Ok(Err(e)) => {
                marks.changed.store(true, Ordering::SeqCst);
                Err(CommandError::new(ErrorKind::Internal, e))
            }
            Err(_) => Err(CommandError::new(
                ErrorKind::Internal,
                format!("plane {:?}: the writer thread is gone", self.name),
            )),
        }
    }

    /// The worker ends: a plane not destroyed is written one last time if it changed (a
    /// clean shutdown loses nothing).
    pub fn finish(&mut self, plane: Option<&mut dyn Backend>, marks: &Marks) {
        if marks.destroyed.load(Ordering::SeqCst) {
            return;
        }
        if let Some(plane) = plane {
            if marks.changed.swap(false, Ordering::SeqCst) {
                if let Err(e) = self.send(plane, None) {
                    tracing::error!(plane = self.name, "cannot write the plane at exit: {e}");
                }
            }
        }
    }

    fn send(
        &self,
        plane: &mut dyn Backend,
        done: Option<Sender<Result<(), String>>>,
    ) -> Result<u64, CommandError> {
        // A copy of the state now, encoded by the writer (off the tick), when the kind can
        // split its snapshot; otherwise encoded here.
        let bytes = match plane.snapshot_later() {
            Some(job) => Bytes::Later(job?),
            None => match plane.apply(PlaneOp::Snapshot)? {
                Reply::Snapshot(bytes) => Bytes::Ready(bytes),
                other => {
                    return Err(CommandError::new(
                        ErrorKind::Internal,
                        format!("a snapshot answered {other:?}"),
                    ))
                }
            },
        };
        let tick = plane.tick();
        self.jobs
            .send(Write::File {
                name: self.name.clone(),
                plane: self.id,
                tick,
                bytes,
                done,
            })
            .map_err(|_| {
                CommandError::new(
                    ErrorKind::Internal,
                    format!("plane {:?}: the writer thread is gone", self.name),
                )
            })?;
        Ok(tick)
    }
}

/// A tracked plane: where its tick is, and the record file.
struct Tracked {
    plane: PlaneId,
    tick: Arc<AtomicU64>,
    recorded: Option<u64>,
    file: Option<File>,
}

/// A write of one batch: the plane's name, tick and bytes, and who waits for the outcome.
type Pending = (String, u64, Bytes, Vec<Sender<Result<(), String>>>);

/// A plane's snapshot as handed to the writer.
enum Bytes {
    /// Encoded already.
    Ready(Vec<u8>),
    /// A copy of the state, encoded by the writer.
    Later(crate::backend::SnapshotJob),
}

fn write_loop(dir: &Path, jobs: Receiver<Write>) {
    let mut tracked: HashMap<String, Tracked> = HashMap::new();
    // Destroyed planes: writes of theirs still on their way are dropped.
    let mut deleted: HashSet<PlaneId> = HashSet::new();
    let mut next_record = Instant::now() + TICK_RECORD_PERIOD;
    loop {
        let first = match jobs.recv_timeout(next_record.saturating_duration_since(Instant::now())) {
            Ok(job) => Some(job),
            Err(RecvTimeoutError::Timeout) => None,
            Err(RecvTimeoutError::Disconnected) => {
                record_ticks(dir, &mut tracked);
                return;
            }
        };
        // Take everything queued; of several writes of one plane only the newest counts.
        let mut batch: Vec<Write> = first.into_iter().collect();
        batch.extend(jobs.try_iter());
        let mut files: Vec<Pending> = Vec::new();
        for job in batch {
            match job {
                Write::Track {
                    name,
                    plane,
                    tick,
                    recorded,
                } => {
                    tracked.insert(
                        name,
                        Tracked {
                            plane,
                            tick,
                            recorded,
                            file: None,
                        },
                    );
                }
                Write::Delete { name, plane } => {
                    deleted.insert(plane);
                    if tracked.get(&name).is_some_and(|t| t.plane == plane) {
                        tracked.remove(&name);
                    }
                    files.retain(|f| f.0 != name);
                    for path in [
                        file_of(dir, &name),
                        tick_file_of(dir, &name),
                        temp_of(dir, &name),
                    ] {
                        let _ = std::fs::remove_file(path);
                    }
                    tracing::info!(
                        plane = name,
                        "persistent plane destroyed: its files removed"
                    );
                }
                Write::File {
                    name, plane, done, ..
                } if deleted.contains(&plane) => {
                    if let Some(d) = done {
                        let _ = d.send(Err(format!("plane {name:?} was destroyed")));
                    }
                }
                Write::File {
                    name,
                    tick,
                    bytes,
                    done,
                    ..
                } => match files.iter_mut().find(|f| f.0 == name) {
                    Some(f) => {
                        f.1 = tick;
                        f.2 = bytes;
                        f.3.extend(done);
                    }
                    None => files.push((name, tick, bytes, done.into_iter().collect())),
                },
            }
        }
        for (name, tick, bytes, done) in files {
            let bytes = match bytes {
                Bytes::Ready(b) => Ok(b),
                Bytes::Later(job) => job().map_err(|e| e.message),
            };
            let outcome = bytes.and_then(|bytes| {
                write_atomically(dir, &name, &bytes)
                    .map(|()| {
                        tracing::debug!(plane = name, tick, bytes = bytes.len(), "plane written")
                    })
                    .map_err(|e| format!("cannot write {}: {e}", file_of(dir, &name).display()))
            });
            if let Err(e) = &outcome {
                tracing::error!(plane = name, "{e}");
            }
            for d in done {
                let _ = d.send(outcome.clone());
            }
        }
        if Instant::now() >= next_record {
            record_ticks(dir, &mut tracked);
            next_record = Instant::now() + TICK_RECORD_PERIOD;
        }
    }
}

/// Records the tick of every tracked plane that moved: 8 bytes written in place.
fn record_ticks(dir: &Path, tracked: &mut HashMap<String, Tracked>) {
    for (name, t) in tracked.iter_mut() {
        let tick = t.tick.load(Ordering::SeqCst);
        // Tick 0: nothing stepped yet (or a restore still on its way): nothing to record.
        if t.recorded == Some(tick) || tick == 0 {
            continue;
        }
        if t.file.is_none() {
            t.file = std::fs::OpenOptions::new()
                .create(true)
                .truncate(false)
                .write(true)
                .open(tick_file_of(dir, name))
                .map_err(|e| tracing::warn!(plane = name, "cannot record the tick: {e}"))
                .ok();
        }
        if let Some(f) = &t.file {
            if f.write_all_at(&tick.to_le_bytes(), 0).is_ok() {
                t.recorded = Some(tick);
            }
        }
    }
}

/// Writes `bytes` as plane `name`'s file: a temporary file in the same directory, written
/// and fsynced, renamed over the old file, then the directory fsynced (the rename itself
/// is on disk).
fn write_atomically(dir: &Path, name: &str, bytes: &[u8]) -> std::io::Result<()> {
    let tmp = temp_of(dir, name);
    let written = (|| {
        let mut f = File::create(&tmp)?;
        f.write_all(bytes)?;
        f.sync_all()?;
        drop(f);
        std::fs::rename(&tmp, file_of(dir, name))?;
        File::open(dir)?.sync_all()
    })();
    if written.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    written
}

/// Planes handed to this daemon at run time (a cluster peer's, on failover): the cluster
/// side pushes, the server loop takes them after its next wake-up.
#[derive(Default)]
pub struct Adoptions(std::sync::Mutex<Vec<Loaded>>);

impl Adoptions {
    /// Queues `plane` (wake the loop after: `crate::wake`).
    pub fn push(&self, plane: Loaded) {
        self.0.lock().unwrap_or_else(|p| p.into_inner()).push(plane);
    }

    /// Everything queued.
    pub fn take(&self) -> Vec<Loaded> {
        std::mem::take(&mut *self.0.lock().unwrap_or_else(|p| p.into_inner()))
    }
}

impl std::fmt::Debug for Adoptions {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("Adoptions")
    }
}

/// A plane file found at start, checked.
pub struct Loaded {
    /// The plane's name (the file's).
    pub name: PlaneName,
    /// The snapshot bytes.
    pub bytes: Vec<u8>,
    /// The kind of plane it holds (3D or GUI).
    pub kind: PlaneKind,
    /// The snapshot's tick.
    pub tick: u64,
    /// The ticks the old daemon reached past the snapshot (its tick record), 0 without one.
    pub lost_ticks: u64,
}

/// Loads every plane file of the domain folder `dir`, in name order: temporary files left
/// by a crash are removed; a file that is not a valid snapshot is skipped with
/// an error naming it and why (the daemon starts all the same).
pub fn load(dir: &Path) -> Vec<Loaded> {
    let entries = match std::fs::read_dir(dir) {
        Ok(e) => e,
        Err(e) => {
            tracing::error!(dir = %dir.display(), "cannot read the state directory: {e}");
            return Vec::new();
        }
    };
    let mut paths: Vec<PathBuf> = entries.filter_map(|e| e.ok().map(|e| e.path())).collect();
    paths.sort();
    let mut loaded = Vec::new();
    for path in paths {
        let Some(file) = path.file_name().and_then(|f| f.to_str()) else {
            continue;
        };
        if file.ends_with(".tmp") {
            match std::fs::remove_file(&path) {
                Ok(()) => tracing::warn!(
                    file = %path.display(),
                    "removed a temporary file left by an interrupted write"
                ),
                Err(e) => tracing::warn!(file = %path.display(), "cannot remove: {e}"),
            }
            continue;
        }
        let Some(stem) = file.strip_suffix(&format!(".{EXTENSION}")) else {
            continue;
        };
        match load_one(dir, &path, stem) {
            Ok(l) => {
                tracing::info!(
                    file = %path.display(),
                    tick = l.tick,
                    lost_ticks = l.lost_ticks,
                    "persistent plane loaded"
                );
                loaded.push(l);
            }
            Err(why) => tracing::error!(
                file = %path.display(),
                "persistent plane file skipped: {why}"
            ),
        }
    }
    loaded
}

impl Loaded {
    /// A plane snapshot from elsewhere (a cluster peer's file): `recorded` is the last tick
    /// its old daemon recorded (its `.tick`), for the lost ticks.
    pub fn from_bytes(name: &str, bytes: Vec<u8>, recorded: Option<u64>) -> Result<Loaded, String> {
        let name = PlaneName::new(name)
            .map_err(|e| format!("its name is not a plane name: {}", e.message))?;
        let (header, _) = snapshot::verify(&bytes).map_err(|e| e.message)?;
        Ok(Loaded {
            name,
            kind: header.kind,
            tick: header.tick,
            lost_ticks: recorded.map_or(0, |r| r.saturating_sub(header.tick)),
            bytes,
        })
    }
}

fn load_one(dir: &Path, path: &Path, stem: &str) -> Result<Loaded, String> {
    let bytes = std::fs::read(path).map_err(|e| format!("cannot read it: {e}"))?;
    let recorded = std::fs::read(tick_file_of(dir, stem))
        .ok()
        .and_then(|b| <[u8; 8]>::try_from(b.get(..8)?).ok())
        .map(u64::from_le_bytes);
    Loaded::from_bytes(stem, bytes, recorded)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn replicate_every_is_bounded() {
        assert_eq!(parse_ticks("10"), Ok(10));
        for bad in ["0", "1000001", "-3", "1.5", "x"] {
            let e = parse_ticks(bad).unwrap_err();
            assert!(e.contains("--replicate-every"), "{e}");
        }
    }

    #[test]
    fn snapshot_every_is_bounded() {
        assert!(parse_every("5").is_ok());
        assert!(parse_every("0.05").is_ok());
        for bad in ["0", "-1", "nan", "inf", "1e9", "x"] {
            let e = parse_every(bad).unwrap_err();
            assert!(e.contains("--snapshot-every"), "{e}");
        }
    }

    #[test]
    fn bad_files_are_skipped_and_temporaries_removed() {
        let dir = std::env::temp_dir().join(format!("physnap-unit-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join(".a.physnap.tmp"), b"half").unwrap();
        std::fs::write(dir.join("b.physnap"), b"PHYSNAP1 truncated").unwrap();
        std::fs::write(dir.join("bad name!.physnap"), b"x").unwrap();
        std::fs::write(dir.join("notes.txt"), b"x").unwrap();
        assert!(load(&dir).is_empty());
        assert!(!dir.join(".a.physnap.tmp").exists());
        assert!(
            dir.join("b.physnap").exists(),
            "a bad file is kept for inspection"
        );
        let _ = std::fs::remove_dir_all(&dir);
    }
}

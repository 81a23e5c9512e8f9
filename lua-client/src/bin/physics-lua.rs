//! `physics-lua SCRIPT.luau`: runs a Luau script against the physics daemon of a domain
//! (starting one for the run when none answers), then keeps running frames while the script
//! has `Heart` handlers, pending waits or change listeners.
//!
//! `physics-lua [SCRIPT] --replay FILE [--until TICK]` first replays a plane recording
//! (`plane:StartRecording()`, `PhysicsService.New{ Record = true }`, `physics-daemon
//! --record`) into a new plane, checking every tick's state hash, and hands the plane it
//! reached to SCRIPT (`PhysicsService.GetStartPlane()`); without SCRIPT the run only replays.
//!
//! The script runs sandboxed (`Lua::sandbox`), under a watchdog that stops it when it runs
//! too long without yielding (`--max-run-ms`), when `--seconds` is up, or on the first
//! SIGINT/SIGTERM, and with a memory limit (`--max-memory-mb`).

use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, AtomicU32, AtomicU8, Ordering};
use std::sync::mpsc::{self, Receiver, RecvTimeoutError};
use std::sync::Arc;
use std::time::{Duration, Instant};

use clap::Parser;
use client_sdk::{Client, ConnectOptions, Session};
use lua_client::{Host, Stop};
use mlua::{Lua, Value, Variadic};

#[derive(Parser, Debug)]
#[command(version, about = "Run a Luau script against the physics service")]
struct Args {
    /// The Luau script to run (optional with `--replay`, which then only replays).
    #[arg(required_unless_present = "replay")]
    script: Option<PathBuf>,
    /// Domain of the daemon to use; one is started for the run when none answers.
    #[arg(long, env = "PHYSICS_DOMAIN", default_value = "physics")]
    domain: String,
    /// End the run after this many seconds, stopping the script if it is running then
    /// (default: run while there is work).
    #[arg(long)]
    seconds: Option<f64>,
    /// Frames per second.
    #[arg(long, default_value_t = 60.0)]
    fps: f64,
    /// Stop the script with an error when it runs this many milliseconds without yielding
    /// back to the host (a `wait`, the end of a handler); 0 turns the limit off.
    #[arg(long, default_value_t = 5000)]
    max_run_ms: u64,
    /// Memory the script's Lua state may use, in MiB; 0 turns the limit off.
    #[arg(long, default_value_t = 1024)]
    max_memory_mb: u64,
    /// Longest wait for one reply of the daemon, in seconds.
    #[arg(long, default_value_t = 30.0)]
    request_timeout: f64,
    /// Start the live browser viewer (`physics-view`, found next to this executable) on the
    /// domain and print its URL. The run then lasts until Ctrl-C (or `--seconds`) even after
    /// the script's work is done, so its planes stay on screen; the viewer stops with it.
    #[arg(long)]
    view: bool,
    /// Port of the viewer started by `--view`; 0 picks a free one.
    #[arg(long, default_value_t = 8080, requires = "view")]
    view_port: u16,
    /// Let the viewer's page pause, step and resume planes (its `--allow-control`).
    #[arg(long, requires = "view")]
    view_allow_control: bool,
    /// A directory `LoadMap` / `LoadProp` may read files under (repeatable). Other paths
    /// are refused with one message that does not tell whether they exist. Default: the
    /// script's directory and the current directory.
    #[arg(long = "asset-root")]
    asset_roots: Vec<PathBuf>,
    /// Start from this plane snapshot file (`snapshot:Save(path)`, a persistent plane's
    /// `.physnap`): it is restored into a new plane before the script runs, and the script
    /// gets that plane with `PhysicsService.GetStartPlane()`.
    #[arg(long)]
    snapshot: Option<PathBuf>,
    /// Replay this plane recording (`plane:StartRecording()`, `New{ Record = true }`,
    /// `physics-daemon --record`) into a new plane before the script runs, checking every
    /// tick's state hash: the first tick that differs ends the run with an error naming it
    /// and the batch of writes before it. The script gets the plane with
    /// `PhysicsService.GetStartPlane()` (manual: it steps it); without a script the run only
    /// replays.
    #[arg(long, value_name = "FILE", conflicts_with = "snapshot")]
    replay: Option<PathBuf>,
    /// With `--replay`: stop the replay once the plane is at this tick (a tick past the
    /// recording's last replays it to its end).
    #[arg(long, value_name = "TICK", requires = "replay")]
    until: Option<u64>,
    /// Run against a daemon of this physics cluster, on this host or another, instead of
    /// this host's domain (docs/cluster.md); no daemon is started. Needs `--connect`.
    #[arg(long, requires = "connect")]
    cluster: Option<String>,
    /// A cluster member's endpoint (`tcp/127.0.0.1:7447`; `tls/HOST:PORT` with the TLS
    /// flags beyond loopback); repeatable.
    #[arg(long, requires = "cluster")]
    connect: Vec<String>,
    /// The cluster daemon to use, by name (default: the least loaded).
    #[arg(long = "daemon", requires = "cluster")]
    cluster_daemon: Option<String>,
    /// For `tls/` endpoints: the authority that signed the members' certificates.
    #[arg(long, requires = "cluster")]
    tls_ca: Option<PathBuf>,
    /// For `tls/` endpoints: this client's certificate.
    #[arg(long, requires = "cluster")]
    tls_cert: Option<PathBuf>,
    /// For `tls/` endpoints: its key.
    #[arg(long, requires = "cluster")]
    tls_key: Option<PathBuf>,
}

/// The asset roots of a run: `--asset-root`, or the script's directory and the current one.
fn asset_roots(args: &Args) -> lua_client::AssetRoots {
    if !args.asset_roots.is_empty() {
        return lua_client::AssetRoots::new(args.asset_roots.iter().cloned());
    }
    let dir = |p: &std::path::Path| match p.as_os_str().is_empty() {
        true => PathBuf::from("."),
        false => p.to_path_buf(),
    };
    let script_dir = args.script.as_deref().and_then(|s| s.parent()).map(dir);
    lua_client::AssetRoots::new(script_dir.into_iter().chain(std::env::current_dir().ok()))
}

/// How long the first signal lets a running script's run end before the runner stops the
/// daemon it started and exits anyway (a call into a stalled daemon cannot be interrupted).
const SIGNAL_GRACE: Duration = Duration::from_secs(2);
/// Exit status after SIGINT or SIGTERM.
const SIGNALLED: u8 = 130;

/// Where the run is, for the signal handler.
const CONNECTING: u8 = 0;
const RUNNING: u8 = 1;
const CLEANING_UP: u8 = 2;

/// What the signal handler shares with the run.
struct Shared {
    /// Set by the first signal: the watchdog stops the script, the frame loop ends.
    stop: Arc<AtomicBool>,
    signals: AtomicU32,
    phase: AtomicU8,
    /// The daemon this run started (0: none), for a forced exit.
    daemon_pid: AtomicU32,
}

impl Shared {
    /// Stops the daemon this run started (unless the run is stopping it already) and exits.
    fn exit_now(&self) -> ! {
        let pid = self.daemon_pid.load(Ordering::SeqCst);
        if pid != 0 && self.phase.load(Ordering::SeqCst) != CLEANING_UP {
            // SAFETY: kill(2) on the daemon this process started; it shuts down cleanly.
            unsafe { libc::kill(pid as libc::pid_t, libc::SIGINT) };
        }
        std::process::exit(SIGNALLED.into());
    }

    /// After the first signal: waits for the run to end; a run still going
    /// [`SIGNAL_GRACE`] after the signal (or after connecting, whichever is later) is ended
    /// by exiting. Connecting is waited for: it is bounded, and the daemon it may be starting
    /// must be known to be stopped.
    fn watch_the_run_end(&self) {
        let mut since = Instant::now();
        loop {
            match self.phase.load(Ordering::SeqCst) {
                CLEANING_UP => return,
                CONNECTING => since = Instant::now(),
                _ if since.elapsed() >= SIGNAL_GRACE => {
                    eprintln!(
                        "physics-lua: the run did not end within {SIGNAL_GRACE:?} of the signal; \
                         exiting"
                    );
                    self.exit_now();
                }
                _ => {}
            }
            std::thread::sleep(Duration::from_millis(10));
        }
    }
}

/// The signal handler's side of the run.
struct Signals {
    shared: Arc<Shared>,
    /// Wakes the frame loop out of its sleep when a signal arrives.
    wake: Receiver<()>,
}

impl Signals {
    /// Installs the SIGINT/SIGTERM handler. The first signal stops the run: the watchdog
    /// interrupts a running script and the frame loop wakes up; a run that still has not
    /// ended [`SIGNAL_GRACE`] later is ended by exiting (see [`Shared::watch_the_run_end`]).
    /// A second signal exits at once. Either way the daemon this run started is stopped.
    fn install() -> Signals {
        let shared = Arc::new(Shared {
            stop: Arc::new(AtomicBool::new(false)),
            signals: AtomicU32::new(0),
            phase: AtomicU8::new(CONNECTING),
            daemon_pid: AtomicU32::new(0),
        });
        let (tx, wake) = mpsc::channel();
        let on_signal = shared.clone();
        let handler = move || {
            on_signal.stop.store(true, Ordering::SeqCst);
            let _ = tx.send(());
            if on_signal.signals.fetch_add(1, Ordering::SeqCst) == 0 {
                let watch = on_signal.clone();
                std::thread::spawn(move || watch.watch_the_run_end());
            } else {
                on_signal.exit_now();
            }
        };
        if let Err(e) = ctrlc::set_handler(handler) {
            eprintln!("physics-lua: cannot install the SIGINT/SIGTERM handler: {e}");
        }
        Signals { shared, wake }
    }

    fn set_phase(&self, phase: u8) {
        self.shared.phase.store(phase, Ordering::SeqCst);
    }

    fn stop_requested(&self) -> bool {
        self.shared.stop.load(Ordering::SeqCst)
    }

    /// Sleeps until `until` or until a signal arrives.
    fn sleep_until(&self, until: Instant) {
        let now = Instant::now();
        if until > now {
            match self.wake.recv_timeout(until - now) {
                Ok(()) | Err(RecvTimeoutError::Timeout) => {}
                // No handler (it could not be installed): plain sleep.
                Err(RecvTimeoutError::Disconnected) => std::thread::sleep(until - now),
            }
        }
    }
}

/// How a run ended without an error.
enum Ended {
    /// No work left (or `--seconds` was up between frames).
    Finished,
    /// `--seconds` was up while the script was running; it was stopped.
    StoppedAtDeadline(String),
    /// A signal stopped the run.
    Signalled,
}

/// `print` writes to stdout, one line per call, flushed so output interleaves sensibly.
fn install_print(lua: &Lua) -> mlua::Result<()> {
    let tostring: mlua::Function = lua.globals().get("tostring")?;
    let print = lua.create_function(move |_, args: Variadic<Value>| {
        let mut line = String::new();
        for (i, v) in args.into_iter().enumerate() {
            if i > 0 {
                line.push('\t');
            }
            line.push_str(&tostring.call::<mlua::String>(v)?.to_string_lossy());
        }
        let mut out = std::io::stdout().lock();
        let _ = writeln!(out, "{line}");
        let _ = out.flush();
        Ok(())
    })?;
    lua.globals().set("print", print)
}

/// Connects to the domain's daemon, starting one when none answers, or with `--cluster` to
/// a daemon of the cluster, with `timeout` as the longest wait for a reply.
fn connect(args: &Args, timeout: Duration) -> Result<Session, client_sdk::Error> {
    let domain = args.domain.as_str();
    let mut options = ConnectOptions::new(domain);
    // The host flushes every frame: writes right after an Add apply before its first step.
    options.hold_adds_until_flush = true;
    // A write refused after its frame was flushed is the next plane call's error (which the
    // script can catch), never the end of the run.
    options.refusals_at_next_call = true;
    options.request_timeout = timeout;
    if let Some(remote) = remote_options(args) {
        return Ok(Session {
            client: Client::connect_cluster_with(&remote, options)?,
            daemon: None,
        });
    }
    match Client::connect_with(options.clone()) {
        Ok(client) => Ok(Session {
            client,
            daemon: None,
        }),
        Err(client_sdk::Error::NoDaemon { .. }) => {
            // The daemon started for the run writes its log to a file, not into the run's
            // output (its transport notes, a GPU driver's probe lines).
            let log = std::env::temp_dir().join(format!("physics-daemon-{domain}.log"));
            let stderr = std::fs::File::create(&log)
                .map(std::process::Stdio::from)
                .unwrap_or_else(|_| std::process::Stdio::inherit());
            let (daemon, started_with) = client_sdk::start_daemon_with(domain, &[], stderr)?;
            drop(started_with);
            Ok(Session {
                client: Client::connect_with(options)?,
                daemon: Some(daemon),
            })
        }
        Err(e) => Err(e),
    }
}

/// The cluster of a `--cluster` run: where the script's client and its placed planes go.
fn remote_options(args: &Args) -> Option<client_sdk::remote::RemoteOptions> {
    Some(client_sdk::remote::RemoteOptions {
        cluster: client_sdk::cluster::ClusterOptions {
            cluster: args.cluster.clone()?,
            endpoints: args.connect.clone(),
            tls_ca: args.tls_ca.clone(),
            tls_cert: args.tls_cert.clone(),
            tls_key: args.tls_key.clone(),
        },
        daemon: args.cluster_daemon.clone(),
    })
}

/// Whether `e` is (or was caused by) the Lua state running out of memory.
fn out_of_memory(e: &mlua::Error) -> bool {
    match e {
        mlua::Error::MemoryError(_) => true,
        mlua::Error::CallbackError { cause, .. } | mlua::Error::WithContext { cause, .. } => {
            out_of_memory(cause)
        }
        _ => false,
    }
}

fn check_args(args: &Args) -> Result<(), String> {
    if !(args.fps.is_finite() && args.fps > 0.0) {
        return Err(format!("--fps must be a positive number, got {}", args.fps));
    }
    if let Some(s) = args.seconds {
        if !(s.is_finite() && s >= 0.0) {
            return Err(format!("--seconds must be a non-negative number, got {s}"));
        }
    }
    if !(args.request_timeout.is_finite() && args.request_timeout > 0.0) {
        return Err(format!(
            "--request-timeout must be a positive number of seconds, got {}",
            args.request_timeout
        ));
    }
    if args.max_memory_mb > (usize::MAX >> 20) as u64 {
        return Err(format!(
            "--max-memory-mb {} is too large",
            args.max_memory_mb
        ));
    }
    Ok(())
}

fn run(args: &Args, signals: &Signals) -> Result<Ended, String> {
    check_args(args)?;
    let source = match &args.script {
        Some(script) => Some(
            std::fs::read_to_string(script)
                .map_err(|e| format!("cannot read {}: {e}", script.display()))?,
        ),
        None => None,
    };
    // A daemon started for this run logs warnings only, unless the user asked for more.
    if std::env::var_os("PHYSICS_LOG").is_none() {
        std::env::set_var("PHYSICS_LOG", "warn");
    }
    let session =
        connect(args, Duration::from_secs_f64(args.request_timeout)).map_err(|e| e.to_string())?;
    if let Some(daemon) = &session.daemon {
        signals
            .shared
            .daemon_pid
            .store(daemon.pid(), Ordering::SeqCst);
    }
    let viewer = match args.view {
        true => Some(viewer::start(args)?),
        false => None,
    };
    signals.set_phase(RUNNING);
    let lua = Lua::new();
    let lua_err = |e: mlua::Error| e.to_string();
    install_print(&lua).map_err(lua_err)?;
    let host = lua_client::install(&lua, session.client.clone()).map_err(lua_err)?;
    if let Some(remote) = remote_options(args) {
        lua_client::set_cluster(&lua, remote);
    }
    asset_roots(args).install(&lua);
    if let Some(file) = &args.snapshot {
        lua_client::start_from_snapshot(&lua, file)?;
    }
    if let Some(file) = &args.replay {
        replay::run(&lua, &session.client, file, args.until)?;
    }
    // Every global is in place: from here on scripts cannot change builtins or the API.
    lua.sandbox(true).map_err(lua_err)?;
    host.set_stop_flag(signals.shared.stop.clone());
    let max_run = (args.max_run_ms > 0).then(|| Duration::from_millis(args.max_run_ms));
    host.set_max_run_time(max_run);
    let max_memory = (args.max_memory_mb > 0).then_some((args.max_memory_mb as usize) << 20);
    host.set_memory_limit(max_memory).map_err(lua_err)?;
    let chunk = match (&args.script, source) {
        (Some(script), Some(source)) => Some(
            lua.load(source)
                .set_name(format!("@{}", script.display()))
                .into_function()
                .map_err(lua_err)?,
        ),
        _ => None,
    };
    let started = Instant::now();
    let deadline = args.seconds.map(|s| started + Duration::from_secs_f64(s));
    host.set_deadline(deadline);
    let mut ended = match chunk {
        Some(chunk) => frames(&host, chunk, args.fps, deadline, signals)
            .or_else(|e| failed(args, &host, signals, e)),
        // `--replay` without a script: the replay was the run.
        None => Ok(Ended::Finished),
    };
    if let (Some(v), Ok(Ended::Finished)) = (&viewer, &ended) {
        // The script is done; its planes stay (and keep ticking) for the viewer.
        ended = Ok(viewer::linger(v, &host, args.fps, deadline, signals));
    }
    drop(host);
    drop(lua);
    signals.set_phase(CLEANING_UP);
    // The viewer is a client too: it goes before the daemon this run may have started.
    drop(viewer);
    drop(session);
    ended
}

/// `--replay FILE [--until TICK]`: the recording replayed into a new plane of the run's
/// client, which becomes the script's start plane.
mod replay {
    use std::path::Path;
    use std::sync::Arc;

    use client_sdk::{Advanced, Client, Replay};
    use mlua::Lua;

    /// Loads `file` (a damaged one is refused naming the byte offset), restores its start
    /// into a new manual plane, re-applies its batches tick by tick up to `until` (or its
    /// end) checking each tick's state hash, says on stderr what it replayed and hands the
    /// plane to the script. A divergence, or a file that cannot be replayed, is the error.
    pub fn run(lua: &Lua, client: &Client, file: &Path, until: Option<u64>) -> Result<(), String> {
        let shown = file.display();
        let recording =
            client_sdk::load_recording(file).map_err(|e| format!("--replay {shown}: {e}"))?;
        let (first, last) = (recording.first_tick(), recording.last_tick());
        if let Some(u) = until.filter(|u| *u < first) {
            return Err(format!(
                "--until {u}: the recording {shown} starts at tick {first} (it holds ticks \
                 {first}..{last})"
            ));
        }
        let kind = recording.start.kind;
        let complete = recording.end.is_some();
        let mut replay = Replay::start(client, Arc::new(recording))
            .map_err(|e| format!("--replay {shown}: cannot restore its start keyframe: {e}"))?;
        let target = until.map(|u| u.min(last));
        let mut checked = 0u64;
        loop {
            if target.is_some_and(|t| replay.tick() >= t) {
                break;
            }
            match replay.advance() {
                Ok(Advanced::Tick(_)) => checked += 1,
                Ok(Advanced::End) => break,
                Ok(Advanced::Diverged(d)) => {
                    return Err(format!(
                        "--replay {shown}: {d} ({checked} tick(s) before it agreed)"
                    ))
                }
                Err(e) => {
                    return Err(format!(
                        "--replay {shown}: the replay stopped after tick {}: {e}",
                        replay.tick()
                    ))
                }
            }
        }
        let at = replay.tick();
        let mut line = format!(
            "physics-lua: replayed ticks {first}..{at} of {shown}: every state hash equal \
             ({checked} ticks)"
        );
        if let Some(u) = until.filter(|u| *u > last) {
            line.push_str(&format!(
                "; --until {u} is past its last tick {last}: replayed to its end"
            ));
        }
        if !complete && replay.at_end() {
            line.push_str("; the file has no end entry (its daemon stopped while recording)");
        }
        eprintln!("{line}");
        lua_client::start_from_plane(lua, replay.into_plane(), kind)
            .map_err(|e| format!("--replay {shown}: {e}"))
    }
}

/// `--view`: the `physics-view` process next to this runner.
mod viewer {
    use std::io::BufRead;
    use std::path::PathBuf;
    use std::process::{Child, Command, Stdio};
    use std::time::{Duration, Instant};

    use super::{Args, Ended, Signals};
    use lua_client::Host;

    /// A viewer this run started; stopped (SIGINT, then waited for) when dropped.
    pub struct Viewer {
        child: Child,
    }

    impl Drop for Viewer {
        fn drop(&mut self) {
            // SIGINT lets it say goodbye to the daemon.
            client_sdk::interrupt_child(&mut self.child);
        }
    }

    /// `$PHYSICS_VIEW_BIN`, else `physics-view` next to this executable, else from `PATH`.
    fn executable() -> PathBuf {
        client_sdk::sibling_executable("physics-view", "PHYSICS_VIEW_BIN")
    }

    /// Starts the viewer on the run's domain and prints its URL (on stderr, next to the
    /// runner's other messages; stdout is the script's).
    pub fn start(args: &Args) -> Result<Viewer, String> {
        let exe = executable();
        let mut command = Command::new(&exe);
        command
            .args(["--domain", &args.domain])
            .args(["--port", &args.view_port.to_string()])
            .args(["--exit-with", &std::process::id().to_string()])
            .stdin(Stdio::null())
            .stdout(Stdio::piped());
        if args.view_allow_control {
            command.arg("--allow-control");
        }
        let mut child = command.spawn().map_err(|e| {
            format!(
                "--view: cannot start {} ({e}); build it with cargo build --workspace --bins",
                exe.display()
            )
        })?;
        let out = child.stdout.take().expect("piped stdout");
        let (tx, rx) = std::sync::mpsc::channel();
        std::thread::spawn(move || {
            let mut line = String::new();
            let _ = std::io::BufReader::new(out).read_line(&mut line);
            let _ = tx.send(line);
        });
        let viewer = Viewer { child };
        match rx.recv_timeout(Duration::from_secs(10)) {
            Ok(line) if line.contains("http://") => {
                let url = line
                    .split_whitespace()
                    .find(|w| w.starts_with("http://"))
                    .unwrap_or_default();
                eprintln!("physics-lua: viewer at {url}");
                Ok(viewer)
            }
            _ => Err(format!(
                "--view: {} did not start (port {} taken? --view-port 0 picks a free one)",
                exe.display(),
                args.view_port
            )),
        }
    }

    /// After the script's work is done: keeps the run (and its planes) up for the viewer
    /// until a signal or the deadline, running frames so planes that tick keep going.
    pub fn linger(
        _viewer: &Viewer,
        host: &Host,
        fps: f64,
        deadline: Option<Instant>,
        signals: &Signals,
    ) -> Ended {
        eprintln!("physics-lua: the script is done; the viewer stays up until Ctrl-C");
        let frame = Duration::from_secs_f64(1.0 / fps);
        loop {
            let next = Instant::now() + frame;
            if deadline.is_some_and(|d| next > d) {
                return Ended::Finished;
            }
            signals.sleep_until(next);
            if signals.stop_requested() {
                // Ctrl-C is how a viewed run is meant to end.
                return Ended::Finished;
            }
            let _ = host.flush();
        }
    }
}

/// Runs the script, then frames while there is work, until the deadline or a signal.
fn frames(
    host: &Host,
    chunk: mlua::Function,
    fps: f64,
    deadline: Option<Instant>,
    signals: &Signals,
) -> mlua::Result<Ended> {
    host.spawn(chunk)?;
    host.flush()?;
    let frame = Duration::from_secs_f64(1.0 / fps);
    let mut last = Instant::now();
    while host.busy() {
        if signals.stop_requested() {
            return Ok(Ended::Signalled);
        }
        let mut next = last + frame;
        // With only waits pending, sleep until the earliest is due rather than spinning frames.
        if let (Some(wake_in), false) = (host.next_wake_in(), host.busy_every_frame()) {
            // A wait of years still wakes the loop hourly (a Duration or Instant that far
            // ahead could overflow).
            let wake_in = Duration::from_secs_f64(wake_in.min(3600.0));
            next = next.max(Instant::now() + wake_in);
            if host.watching_daemon() {
                // Stalled / Resumed must fire within a second of the daemon stopping.
                next = next.min(Instant::now() + lua_client::WATCH_PERIOD);
            }
        }
        if deadline.is_some_and(|d| next > d) {
            break;
        }
        // Frames skipped while only waits were pending are frames nobody needed, not one long
        // frame: the frame that ends the quiet stretch is as long as the one it replaces (the
        // frames before it ran, in the script's view, at `fps`), so `Heart` never sees the
        // whole stretch as its dt.
        let quiet_from = next.checked_sub(frame).unwrap_or(last).max(last);
        signals.sleep_until(next);
        if signals.stop_requested() {
            return Ok(Ended::Signalled);
        }
        let now = Instant::now();
        let dt = (now - quiet_from).as_secs_f64();
        last = now;
        host.frame(dt)?;
    }
    for refused in host.client().take_refused(None) {
        eprintln!(
            "physics-lua: warning: the daemon refused a write that no later call reported: {}",
            refused.message
        );
    }
    Ok(Ended::Finished)
}

/// A Lua error of the run: what the watchdog stopped, a memory limit hit, or the script's
/// own error, said with the flag that set the limit.
fn failed(args: &Args, host: &Host, signals: &Signals, e: mlua::Error) -> Result<Ended, String> {
    if signals.stop_requested() {
        // Whatever failed then (a script stopped mid-way, a call cut short) failed because of
        // the signal.
        return Ok(Ended::Signalled);
    }
    match host.stopped() {
        Some(Stop::Requested) => Ok(Ended::Signalled),
        Some(Stop::Deadline) => Ok(Ended::StoppedAtDeadline(e.to_string())),
        Some(Stop::RunTime { .. }) => Err(format!(
            "{e}\n(the limit is --max-run-ms {}; 0 turns it off)",
            args.max_run_ms
        )),
        None if out_of_memory(&e) => Err(format!(
            "script ran out of memory (limit --max-memory-mb {}; 0 turns it off)\n{e}",
            args.max_memory_mb
        )),
        None => match lua_client::colon_hint(&e) {
            Some(hint) => Err(format!("{hint}\n{e}")),
            None => Err(e.to_string()),
        },
    }
}

fn main() -> ExitCode {
    let args = Args::parse();
    // A run prints what the script prints and the runner's own warnings.
    client_sdk::quiet_transport_logs();
    let signals = Signals::install();
    let code = match run(&args, &signals) {
        Ok(Ended::Finished) => ExitCode::SUCCESS,
        Ok(Ended::StoppedAtDeadline(at)) => {
            eprintln!(
                "physics-lua: --seconds {} was up while the script was still running; stopped \
                 it\n{at}",
                args.seconds.unwrap_or_default()
            );
            ExitCode::SUCCESS
        }
        Ok(Ended::Signalled) => {
            eprintln!("physics-lua: stopped by a signal");
            ExitCode::from(SIGNALLED)
        }
        Err(message) => {
            eprintln!("physics-lua: {message}");
            ExitCode::FAILURE
        }
    };
    signals.set_phase(CLEANING_UP);
    code
}

//! `physics-view`: a live browser viewer of every plane of a running physics daemon.
//!
//! It attaches to the daemon's domain as an ordinary client (zero-copy reads of each
//! plane's newest tick, read-only requests for shapes and properties) and serves one page:
//! the plane list, a three.js 3D view of the chosen plane (a canvas in pixel space for GUI
//! planes), contact and controller overlays, plots of the tick header's figures, and the
//! properties of a clicked body. It samples at display rate and never slows the daemon:
//! the daemon's publishers overwrite what the viewer has not read. Controls that change a
//! plane (pause, step, resume) are refused unless `--allow-control` is given; it binds to
//! 127.0.0.1 unless `--bind` says otherwise.
//!
//! `--replay FILE` plays a recording (`physics-daemon --record`, `plane:StartRecording`)
//! into a plane of the viewer's own, on the domain's daemon (started when none runs), with
//! a timeline in the page: play, pause, step, jump to a tick, speed.

mod describe;
mod joints;
mod replay;
mod sampler;
mod server;

use std::io::Write;
use std::net::IpAddr;
use std::process::ExitCode;
use std::sync::{mpsc, Arc, Mutex};

use clap::Parser;

#[derive(Parser, Debug)]
#[command(
    version,
    about = "Live browser viewer of every plane of a physics daemon",
    after_help = "Prints `physics-view: http://ADDRESS:PORT/ ...` on stdout once it listens."
)]
struct Args {
    /// Domain of the daemon to watch (it is looked for again every second while none runs).
    #[arg(long, env = "PHYSICS_DOMAIN", default_value = "physics")]
    domain: String,
    /// Address to listen on. The default serves this machine only; the page and its API
    /// show every plane of the domain to whoever can reach the address.
    #[arg(long, default_value = "127.0.0.1")]
    bind: IpAddr,
    /// Port to listen on; 0 picks a free one (the URL is printed).
    #[arg(long, default_value_t = 8080)]
    port: u16,
    /// Allow the page's pause / step / resume buttons (they change planes; the daemon
    /// still refuses them on planes of other clients that are not Shared).
    #[arg(long)]
    allow_control: bool,
    /// Seconds of tick-header history kept per plane for the plots (sampled 10 times a
    /// second).
    #[arg(long, default_value_t = 300.0)]
    history_seconds: f64,
    /// Exit (saying goodbye to the daemon) once the process PID is gone: what
    /// `physics-lua --view` passes, so a runner that is killed leaves no viewer behind.
    #[arg(long, value_name = "PID")]
    exit_with: Option<u32>,
    /// Play this recording (a `.physrec` file) into a plane of the viewer's own, with a
    /// timeline in the page; starts a daemon for --domain when none runs.
    #[arg(long, value_name = "FILE")]
    replay: Option<std::path::PathBuf>,
}

fn main() -> ExitCode {
    tracing_subscriber::fmt()
        .with_env_filter(
            tracing_subscriber::EnvFilter::try_from_env("PHYSICS_LOG")
                .unwrap_or_else(|_| tracing_subscriber::EnvFilter::new("warn")),
        )
        .with_writer(std::io::stderr)
        .init();
    let args = Args::parse();
    if !(args.history_seconds.is_finite() && args.history_seconds > 0.0) {
        eprintln!(
            "physics-view: --history-seconds must be a positive number, got {}",
            args.history_seconds
        );
        return ExitCode::from(2);
    }
    // A recording is read and checked before anything starts: a damaged one is refused
    // naming the byte offset.
    let (replay, started) = match &args.replay {
        None => (None, None),
        Some(path) => match client_sdk::load_recording(path) {
            Ok(recording) => {
                let (ready, started) = mpsc::channel();
                let start = sampler::ReplayStart {
                    path: path.display().to_string(),
                    recording: Arc::new(recording),
                    ready,
                };
                (Some(start), Some(started))
            }
            Err(e) => {
                eprintln!("physics-view: {e}");
                return ExitCode::FAILURE;
            }
        },
    };
    let overview = Arc::new(Mutex::new(sampler::Overview::default()));
    let (jobs, rx) = mpsc::channel();
    {
        let (domain, overview) = (args.domain.clone(), overview.clone());
        let history = args.history_seconds;
        std::thread::Builder::new()
            .name("sampler".into())
            .spawn(move || sampler::run(domain, overview, rx, history, replay))
            .expect("spawn the sampler thread");
    }
    if let Some(started) = started {
        match started.recv() {
            Ok(Ok(plane)) => tracing::info!(plane, "replaying"),
            Ok(Err(e)) => {
                let file = args.replay.as_deref().unwrap_or(std::path::Path::new(""));
                eprintln!("physics-view: cannot replay {}: {e}", file.display());
                return ExitCode::FAILURE;
            }
            Err(_) => {
                eprintln!("physics-view: the sampler stopped before the replay started");
                return ExitCode::FAILURE;
            }
        }
    }
    {
        let jobs = jobs.clone();
        if let Err(e) = ctrlc::set_handler(move || {
            // The sampler says goodbye to the daemon, then exits the process.
            let _ = jobs.send(sampler::Job::Shutdown);
        }) {
            eprintln!("physics-view: cannot install the signal handler: {e}");
            return ExitCode::FAILURE;
        }
    }
    if let Some(pid) = args.exit_with {
        let jobs = jobs.clone();
        std::thread::spawn(move || {
            while std::path::Path::new(&format!("/proc/{pid}")).exists() {
                std::thread::sleep(std::time::Duration::from_millis(250));
            }
            let _ = jobs.send(sampler::Job::Shutdown);
        });
    }
    let state = server::AppState {
        overview,
        jobs,
        allow_control: args.allow_control,
        domain: args.domain.clone(),
    };
    let runtime = match tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
    {
        Ok(r) => r,
        Err(e) => {
            eprintln!("physics-view: cannot start the runtime: {e}");
            return ExitCode::FAILURE;
        }
    };
    let result: std::io::Result<()> = runtime.block_on(async {
        let listener = tokio::net::TcpListener::bind((args.bind, args.port))
            .await
            .map_err(|e| {
                std::io::Error::new(
                    e.kind(),
                    format!("cannot listen on {}:{}: {e}", args.bind, args.port),
                )
            })?;
        let addr = listener.local_addr()?;
        let host = match addr.ip() {
            IpAddr::V6(ip) => format!("[{ip}]"),
            IpAddr::V4(ip) => ip.to_string(),
        };
        println!(
            "physics-view: http://{host}:{}/ (domain {}, {})",
            addr.port(),
            args.domain,
            if args.allow_control {
                "controls allowed"
            } else {
                "read-only"
            }
        );
        let _ = std::io::stdout().flush();
        axum::serve(listener, server::router(state)).await
    });
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("physics-view: {e}");
            ExitCode::FAILURE
        }
    }
}

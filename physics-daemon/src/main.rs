//! `physics-daemon [--domain NAME]`: serves every physics plane of one domain.

use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

use clap::Parser;
use shm_layout::names;

#[derive(Parser)]
#[command(
    version,
    about = "Physics daemon: simulates planes and publishes them in shared memory"
)]
struct Args {
    /// Deployment domain; every process of one deployment uses the same one.
    #[arg(long, env = names::DOMAIN_ENV, default_value = names::DEFAULT_DOMAIN)]
    domain: String,
    /// Started on demand by this process: exit once it is gone and no client is left.
    #[arg(long)]
    starter_pid: Option<u32>,
    #[command(flatten)]
    limits: physics_daemon::server::Limits,
}

fn main() -> ExitCode {
    let args = Args::parse();
    tracing_subscriber::fmt()
        .with_env_filter(
            tracing_subscriber::EnvFilter::try_from_env("PHYSICS_LOG")
                .unwrap_or_else(|_| "info".into()),
        )
        .with_writer(std::io::stderr)
        .init();

    let shutdown = Arc::new(AtomicBool::new(false));
    let flag = shutdown.clone();
    let domain = args.domain.clone();
    let on_signal = move || {
        flag.store(true, Ordering::Relaxed);
        // The loop sleeps until an event: give it one.
        if let Err(e) = physics_daemon::wake(&domain) {
            tracing::debug!("cannot wake the loop for shutdown (it may have stopped already): {e}");
        }
    };
    if let Err(e) = ctrlc::set_handler(on_signal) {
        tracing::error!("cannot install the SIGINT/SIGTERM handler: {e}");
        return ExitCode::FAILURE;
    }
    // Each plane steps on its own worker (a one-thread pool of its own, or the pool its
    // Threads asks for); the global pool is for anything else: keep it at one worker so
    // nothing spreads over the machine's cores uninvited.
    let _ = rapier3d::rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build_global();

    let options = physics_daemon::server::Options {
        limits: args.limits,
        starter_pid: args.starter_pid,
        // Fault injection for tests: a Step with this exact dt panics inside its plane.
        panic_on_step_dt: std::env::var("PHYSICS_FAULT_PANIC_DT")
            .ok()
            .and_then(|v| v.parse().ok()),
    };
    match physics_daemon::server::run_with(&args.domain, &shutdown, options) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            tracing::error!("{e}");
            ExitCode::FAILURE
        }
    }
}

//! `physics-daemon [--domain NAME]`: serves every physics plane of one domain.
//! `physics-daemon --cluster NAME --name DAEMON [--listen ...] [--connect ...]`: the same, as
//! a member of a physics cluster (docs/cluster.md).
//! `physics-daemon --cleanup [--domain NAME]`: removes what dead processes of the domain
//! left behind (a killed daemon's or client's shared memory and files), then exits.

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
    #[command(flatten)]
    persist: physics_daemon::server::persist::PersistArgs,
    #[command(flatten)]
    cluster: physics_daemon::cluster::ClusterArgs,
    #[command(flatten)]
    record: physics_daemon::record::RecordArgs,
    /// Remove what dead processes of the domain left behind (shared memory, node records),
    /// print what was removed, and exit. Live processes keep everything of theirs.
    #[arg(long)]
    cleanup: bool,
}

fn main() -> ExitCode {
    // Before any thread exists: see `trim` for why one arena.
    physics_daemon::server::trim::limit_arenas();
    let args = Args::parse();
    tracing_subscriber::fmt()
        .with_env_filter(
            tracing_subscriber::EnvFilter::try_from_env("PHYSICS_LOG")
                .unwrap_or_else(|_| "info".into()),
        )
        .with_writer(std::io::stderr)
        .init();

    if args.cleanup {
        return cleanup(&args.domain);
    }
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

    // A cluster member joins before serving: a refused name or flag stops the daemon here.
    let gauge = Arc::new(physics_daemon::cluster::load::Gauge::default());
    let cluster = match physics_daemon::cluster::Cluster::join(&args.cluster, gauge.clone()) {
        Ok(cluster) => cluster,
        Err(e) => {
            tracing::error!("{e}");
            // Nothing of the domain exists yet. Zenoh's exit handlers can wait on a session
            // still closing, so leave without running them.
            // SAFETY: _exit ends the process; no state of ours needs flushing (the log
            // writer is unbuffered stderr).
            unsafe { libc::_exit(1) }
        }
    };
    let mut cluster = cluster;
    if let (Some(n), None) = (args.persist.replicate_every, cluster.as_ref()) {
        tracing::error!(
            "--replicate-every {n} replicates persistent planes to the other members of a \
             cluster: it needs --cluster NAME --name DAEMON"
        );
        return ExitCode::FAILURE;
    }
    let persistence = args.persist.persistence();
    let mut adopt = None;
    let mut migrate = None;
    if let Some(c) = cluster.as_mut() {
        if let Err(e) = c.serve_remote(&args.domain, args.limits.max_clients) {
            tracing::error!("{e}");
            return ExitCode::FAILURE;
        }
        // With a state folder, this member's persistent planes fail over to the others.
        if let Some(p) = &persistence {
            let queue = Arc::new(physics_daemon::server::persist::Adoptions::default());
            let dir = physics_daemon::server::persist::domain_dir(&p.dir, &args.domain);
            if let Err(e) = c.start_failover(dir, queue.clone(), &args.domain) {
                tracing::error!("{e}");
                return ExitCode::FAILURE;
            }
            adopt = Some(queue);
        }
        match c.start_migration(&args.domain) {
            Ok(m) => migrate = Some(m),
            Err(e) => {
                tracing::error!("{e}");
                return ExitCode::FAILURE;
            }
        }
        if let (Some(share), Some(m)) = (args.cluster.rebalance, migrate.clone()) {
            if let Err(e) = c.start_rebalance(share, m, &args.domain) {
                tracing::error!("{e}");
                return ExitCode::FAILURE;
            }
        }
    }
    let options = physics_daemon::server::Options {
        limits: args.limits,
        starter_pid: args.starter_pid,
        // Fault injection for tests: a Step with this exact dt panics inside its plane.
        panic_on_step_dt: std::env::var("PHYSICS_FAULT_PANIC_DT")
            .ok()
            .and_then(|v| v.parse().ok()),
        persistence,
        load: cluster.as_ref().map(|_| gauge),
        adopt,
        migrate,
        record: physics_daemon::record::RecordSettings::new(
            &args.record,
            args.cluster.name.as_deref().unwrap_or(&args.domain),
        ),
    };
    let served = physics_daemon::server::run_with(&args.domain, &shutdown, options);
    if let Some(cluster) = cluster {
        cluster.leave();
    }
    match served {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            tracing::error!("{e}");
            ExitCode::FAILURE
        }
    }
}

/// `--cleanup`: removes a dead deployment's leftovers and says what is left.
fn cleanup(domain: &str) -> ExitCode {
    let files = physics_daemon::server::files::domain_files;
    let before = files(domain).len();
    if let Err(e) = physics_daemon::cleanup_domain(domain) {
        tracing::error!("{e}");
        return ExitCode::FAILURE;
    }
    let left = files(domain).len();
    println!(
        "domain {domain}: removed {} files of dead processes; {left} left (held by live \
         processes)",
        before.saturating_sub(left)
    );
    ExitCode::SUCCESS
}

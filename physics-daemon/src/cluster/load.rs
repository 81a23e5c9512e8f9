//! The load report: once a second each daemon of a cluster puts a
//! [`LoadReport`] on `physics/<cluster>/load/<name>` (planes, bodies, the share of its tick
//! budget used, CPU) and answers queries on that key with the latest one, so a newcomer (a
//! client choosing where to place a plane) reads every member's load at once.
//!
//! Its inputs come through two hooks of the server (`server::quotas::gauge`) and cost nothing
//! without a cluster: the server loop hands the [`Gauge`] its planes' usage records when the
//! set of planes changes, and every step's duration is added to one counter.

use std::sync::mpsc::{self, RecvTimeoutError, Sender};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use shm_layout::cluster::{self as keys, LoadReport};
use zenoh::Wait;

use super::error::ClusterError;
use crate::server::quotas::gauge::stepped_nanos;
pub use crate::server::quotas::gauge::Gauge;

/// CPU time this process used so far (user + system).
fn process_cpu() -> Duration {
    // SAFETY: getrusage only writes the struct it is given.
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    if unsafe { libc::getrusage(libc::RUSAGE_SELF, &mut usage) } != 0 {
        return Duration::ZERO;
    }
    let tv = |t: libc::timeval| {
        Duration::from_secs(t.tv_sec.max(0) as u64) + Duration::from_micros(t.tv_usec.max(0) as u64)
    };
    tv(usage.ru_utime) + tv(usage.ru_stime)
}

/// Cores this process may run on (its affinity: `taskset` narrows it).
fn cores() -> u32 {
    std::thread::available_parallelism().map_or(1, |n| n.get() as u32)
}

/// The thread that puts the report each second and the queryable that answers with it.
pub struct Reporter {
    stop: Sender<()>,
    thread: Option<JoinHandle<()>>,
    _queryable: zenoh::query::Queryable<()>,
}

impl Reporter {
    /// Starts reporting daemon `name`'s load in `cluster`.
    pub fn start(
        session: &zenoh::Session,
        cluster: &str,
        name: &str,
        gauge: Arc<Gauge>,
    ) -> Result<Reporter, ClusterError> {
        let key = keys::load_key(cluster, name);
        let publisher = session
            .declare_publisher(key.clone())
            .wait()
            .map_err(|e| ClusterError::Zenoh(format!("cannot declare the publisher {key}: {e}")))?;
        let latest = Arc::new(Mutex::new(Vec::new()));
        let mut sampler = Sampler::new(name, gauge);
        *latest.lock().unwrap_or_else(|p| p.into_inner()) = sampler.sample().encode();
        let answer = latest.clone();
        let reply_key = key.clone();
        let queryable = session
            .declare_queryable(key.clone())
            .callback(move |query| {
                let bytes = answer.lock().unwrap_or_else(|p| p.into_inner()).clone();
                if let Err(e) = query.reply(reply_key.clone(), bytes).wait() {
                    tracing::debug!("load query reply: {e}");
                }
            })
            .wait()
            .map_err(|e| ClusterError::Zenoh(format!("cannot declare the queryable {key}: {e}")))?;
        let (stop, stopped) = mpsc::channel::<()>();
        let thread = std::thread::Builder::new()
            .name("cluster-load".into())
            .spawn(move || {
                let period = Duration::from_millis(keys::LOAD_PERIOD_MS);
                let mut next = Instant::now();
                loop {
                    let report = sampler.sample().encode();
                    *latest.lock().unwrap_or_else(|p| p.into_inner()) = report.clone();
                    if let Err(e) = publisher.put(report).wait() {
                        tracing::debug!("load report: {e}");
                    }
                    next += period;
                    match stopped.recv_timeout(next.saturating_duration_since(Instant::now())) {
                        Err(RecvTimeoutError::Timeout) => {}
                        _ => return,
                    }
                }
            })
            .map_err(|e| ClusterError::Zenoh(format!("cannot start the load reporter: {e}")))?;
        Ok(Reporter {
            stop,
            thread: Some(thread),
            _queryable: queryable,
        })
    }

    /// Stops the reports.
    pub fn stop(mut self) {
        let _ = self.stop.send(());
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

/// Turns counters into rates over the time since the last sample.
struct Sampler {
    name: String,
    gauge: Arc<Gauge>,
    at: Instant,
    cpu: Duration,
    stepped: u64,
    sequence: u64,
}

impl Sampler {
    fn new(name: &str, gauge: Arc<Gauge>) -> Sampler {
        Sampler {
            name: name.to_string(),
            gauge,
            at: Instant::now(),
            cpu: process_cpu(),
            stepped: stepped_nanos(),
            sequence: 0,
        }
    }

    fn sample(&mut self) -> LoadReport {
        let now = Instant::now();
        let cpu = process_cpu();
        let stepped = stepped_nanos();
        let wall = (now - self.at).as_secs_f64().max(1e-3);
        let cores = cores();
        let (planes, bodies) = self.gauge.counts();
        let report = LoadReport {
            name: self.name.clone(),
            planes,
            bodies,
            budget_used: (stepped.saturating_sub(self.stepped) as f64
                / 1e9
                / (wall * f64::from(cores.max(1)))) as f32,
            cpu: (cpu.saturating_sub(self.cpu).as_secs_f64() / wall) as f32,
            cores,
            pid: std::process::id(),
            sequence: self.sequence,
        };
        self.at = now;
        self.cpu = cpu;
        self.stepped = stepped;
        self.sequence += 1;
        report
    }
}

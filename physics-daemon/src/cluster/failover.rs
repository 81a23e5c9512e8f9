//! Failover of persistent planes (docs/cluster.md, "Failover"): a member started with
//! `--state-dir` replicates its persistent planes' files to every other such member, and
//! when a member's liveliness token ends (its process or host died), one survivor restores
//! its planes and serves them, orphaned until opened, with `Recovered(lostTicks)` as after a
//! restart.
//!
//! - **Replication**: a thread looks at the daemon's state folder every [`SCAN_PERIOD`] and
//!   puts each plane file that changed (`<name>.physnap`, written atomically every
//!   `--snapshot-every` by the persistence writer) on `physics/<c>/replica/<daemon>/<name>`,
//!   and each tick record (`<name>.tick`, every 100 ms while the plane moves) on
//!   `physics/<c>/replica-tick/<daemon>/<name>`; a file removed (its plane destroyed) is a
//!   delete of the key.
//! - **Holding**: every member with `--state-dir` declares `physics/<c>/holder/<daemon>` and
//!   keeps the newest replica of every other member's planes in memory.
//! - **Taking over**: when a daemon's token ends, the holder alive with the smallest name
//!   (each computes the same one) hands that daemon's replicas to its server loop
//!   ([`crate::server::persist::Adoptions`]), which restores them as it restores its own
//!   files at start; its own replication then carries them on.

use std::collections::HashMap;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, SystemTime};

use zenoh::liveliness::LivelinessToken;
use zenoh::sample::{Sample, SampleKind};
use zenoh::{Session, Wait};

use super::error::ClusterError;
use crate::server::persist::{Adoptions, Loaded, EXTENSION};

/// How often the state folder is looked at for changed files.
pub const SCAN_PERIOD: Duration = Duration::from_millis(100);

/// The newest replica of one plane of another member.
#[derive(Default)]
struct Replica {
    bytes: Vec<u8>,
    recorded: Option<u64>,
}

/// Replicas by (owner daemon, plane name).
type Store = Arc<Mutex<HashMap<(String, String), Replica>>>;

/// Replication and takeover for one member; stops when dropped.
pub struct Failover {
    stop: Arc<AtomicBool>,
    _holder: LivelinessToken,
    _replicas: zenoh::pubsub::Subscriber<()>,
    _ticks: zenoh::pubsub::Subscriber<()>,
    _members: zenoh::pubsub::Subscriber<()>,
}

fn key(cluster: &str, what: &str, daemon: &str, name: &str) -> String {
    format!(
        "{}/{cluster}/{what}/{daemon}/{name}",
        shm_layout::cluster::ROOT
    )
}

/// (owner, plane name) of a replica key.
fn owner_and_name(key: &str) -> Option<(String, String)> {
    let mut parts = key.rsplit('/');
    let name = parts.next()?.to_string();
    let owner = parts.next()?.to_string();
    Some((owner, name))
}

impl Failover {
    /// Starts replicating `dir` (this daemon's state folder of its domain) and holding the
    /// other members' replicas; `adopt` and `domain` reach this daemon's server loop.
    pub fn start(
        session: &Session,
        cluster: &str,
        me: &str,
        dir: PathBuf,
        adopt: Arc<Adoptions>,
        domain: &str,
    ) -> Result<Failover, ClusterError> {
        let zerr = |e: zenoh::Error| ClusterError::Zenoh(format!("failover: {e}"));
        let store: Store = Arc::default();
        let root = shm_layout::cluster::ROOT;
        let holder = session
            .liveliness()
            .declare_token(format!("{root}/{cluster}/holder/{me}"))
            .wait()
            .map_err(zerr)?;
        let (s1, me1) = (store.clone(), me.to_string());
        let replicas = session
            .declare_subscriber(format!("{root}/{cluster}/replica/*/*"))
            .callback(move |sample: Sample| {
                let Some(id) = owner_and_name(sample.key_expr().as_str()) else {
                    return;
                };
                if id.0 == me1 {
                    return;
                }
                let mut store = s1.lock().unwrap_or_else(|p| p.into_inner());
                match sample.kind() {
                    SampleKind::Put => {
                        store.entry(id).or_default().bytes =
                            sample.payload().to_bytes().into_owned()
                    }
                    SampleKind::Delete => {
                        store.remove(&id);
                    }
                }
            })
            .wait()
            .map_err(zerr)?;
        let (s2, me2) = (store.clone(), me.to_string());
        let ticks = session
            .declare_subscriber(format!("{root}/{cluster}/replica-tick/*/*"))
            .callback(move |sample: Sample| {
                let Some(id) = owner_and_name(sample.key_expr().as_str()) else {
                    return;
                };
                let bytes = sample.payload().to_bytes();
                let Some(tick) = bytes
                    .get(..8)
                    .and_then(|b| b.try_into().ok())
                    .map(u64::from_le_bytes)
                else {
                    return;
                };
                if id.0 == me2 {
                    return;
                }
                let mut store = s2.lock().unwrap_or_else(|p| p.into_inner());
                store.entry(id).or_default().recorded = Some(tick);
            })
            .wait()
            .map_err(zerr)?;
        let (s3, session3, cluster3, me3, domain3) = (
            store.clone(),
            session.clone(),
            cluster.to_string(),
            me.to_string(),
            domain.to_string(),
        );
        let members = session
            .liveliness()
            .declare_subscriber(shm_layout::cluster::daemons_key(cluster))
            .callback(move |sample: Sample| {
                if sample.kind() != SampleKind::Delete {
                    return;
                }
                let gone =
                    shm_layout::cluster::last_segment(sample.key_expr().as_str()).to_string();
                let (store, session, cluster, me, domain, adopt) = (
                    s3.clone(),
                    session3.clone(),
                    cluster3.clone(),
                    me3.clone(),
                    domain3.clone(),
                    adopt.clone(),
                );
                // Not on zenoh's callback thread: the choice asks the cluster.
                std::thread::spawn(move || {
                    take_over(&session, &cluster, &me, &gone, &store, &adopt, &domain)
                });
            })
            .wait()
            .map_err(zerr)?;
        let stop = Arc::new(AtomicBool::new(false));
        let (stop2, session4, cluster4, me4) = (
            stop.clone(),
            session.clone(),
            cluster.to_string(),
            me.to_string(),
        );
        std::thread::Builder::new()
            .name("replicate".into())
            .spawn(move || replicate(&session4, &cluster4, &me4, &dir, &stop2))
            .map_err(|e| ClusterError::Zenoh(format!("failover: cannot start a thread: {e}")))?;
        Ok(Failover {
            stop,
            _holder: holder,
            _replicas: replicas,
            _ticks: ticks,
            _members: members,
        })
    }
}

impl Drop for Failover {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::SeqCst);
    }
}

/// When `gone`'s token ended: the holder alive with the smallest name restores its planes.
fn take_over(
    session: &Session,
    cluster: &str,
    me: &str,
    gone: &str,
    store: &Store,
    adopt: &Adoptions,
    domain: &str,
) {
    let holders = session
        .liveliness()
        .get(format!("{}/{cluster}/holder/*", shm_layout::cluster::ROOT))
        .timeout(Duration::from_secs(1))
        .wait();
    let mut alive: Vec<String> = vec![me.to_string()];
    if let Ok(replies) = holders {
        while let Ok(reply) = replies.recv() {
            if let Ok(sample) = reply.result() {
                alive.push(
                    shm_layout::cluster::last_segment(sample.key_expr().as_str()).to_string(),
                );
            }
        }
    }
    alive.retain(|n| n != gone);
    alive.sort();
    let planes: Vec<(String, Replica)> = {
        let mut store = store.lock().unwrap_or_else(|p| p.into_inner());
        let keys: Vec<_> = store.keys().filter(|(o, _)| o == gone).cloned().collect();
        keys.into_iter()
            .filter_map(|k| store.remove(&k).map(|r| (k.1, r)))
            // A tick record without its plane file: nothing to restore.
            .filter(|(_, r)| !r.bytes.is_empty())
            .collect()
    };
    if alive.first().map(String::as_str) != Some(me) || planes.is_empty() {
        return;
    }
    for (name, replica) in planes {
        match Loaded::from_bytes(&name, replica.bytes, replica.recorded) {
            Ok(loaded) => {
                tracing::warn!(
                    plane = name,
                    from = gone,
                    tick = loaded.tick,
                    lost_ticks = loaded.lost_ticks,
                    "taking over a persistent plane of a member that left"
                );
                adopt.push(loaded);
            }
            Err(e) => tracing::error!(plane = name, from = gone, "cannot take over: {e}"),
        }
    }
    if let Err(e) = crate::wake(domain) {
        tracing::error!("cannot wake the server loop for adopted planes: {e}");
    }
}

/// Puts every plane file and tick record of `dir` that changed, until `stop`.
fn replicate(session: &Session, cluster: &str, me: &str, dir: &std::path::Path, stop: &AtomicBool) {
    let mut seen: HashMap<PathBuf, (u64, SystemTime)> = HashMap::new();
    while !stop.load(Ordering::SeqCst) {
        let mut present = Vec::new();
        for entry in std::fs::read_dir(dir).into_iter().flatten().flatten() {
            let path = entry.path();
            let Some(file) = path
                .file_name()
                .and_then(|f| f.to_str())
                .map(str::to_string)
            else {
                continue;
            };
            let (stem, what) = if let Some(s) = file.strip_suffix(&format!(".{EXTENSION}")) {
                (s.to_string(), "replica")
            } else if let Some(s) = file.strip_suffix(".tick") {
                (s.to_string(), "replica-tick")
            } else {
                continue;
            };
            present.push(path.clone());
            let Ok(meta) = entry.metadata() else { continue };
            let stamp = (
                meta.len(),
                meta.modified().unwrap_or(SystemTime::UNIX_EPOCH),
            );
            if seen.get(&path) == Some(&stamp) {
                continue;
            }
            let Ok(bytes) = std::fs::read(&path) else {
                continue;
            };
            let put = session.put(key(cluster, what, me, &stem), bytes).wait();
            if let Err(e) = put {
                tracing::debug!(file, "replicate: {e}");
                continue;
            }
            seen.insert(path, stamp);
        }
        // A plane file removed: its plane was destroyed; the replicas go too.
        let gone: Vec<PathBuf> = seen
            .keys()
            .filter(|p| !present.contains(p))
            .cloned()
            .collect();
        for path in gone {
            seen.remove(&path);
            if let Some(stem) = path
                .file_name()
                .and_then(|f| f.to_str())
                .and_then(|f| f.strip_suffix(&format!(".{EXTENSION}")))
            {
                let _ = session.delete(key(cluster, "replica", me, stem)).wait();
            }
        }
        std::thread::sleep(SCAN_PERIOD);
    }
}

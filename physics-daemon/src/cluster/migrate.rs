//! Migration over Zenoh (docs/cluster.md "Migration"): the [`Courier`] the request loop
//! hands a moving plane to (a query on the target's `physics/<c>/migrate/<daemon>`, whose
//! payload is the [`MovingPlane`] and whose reply the target's [`MoveAnswer`]), and the
//! queryable that takes planes arriving here to this daemon's loop
//! ([`crate::server::moves::migration::Migration::arrive`]) and answers once the loop restored them.

use std::sync::Arc;
use std::time::Duration;

use shm_layout::migrate::{migrate_key, MoveAnswer, MovingPlane};
use zenoh::query::Query;
use zenoh::{Session, Wait};

use super::error::ClusterError;
use crate::server::moves::migration::{Courier, Migration, RESTORE_WAIT};

/// How long a liveliness question about the target waits.
const ASK_TIMEOUT: Duration = Duration::from_secs(1);

/// The largest moving plane accepted (a snapshot of some 10⁶ bodies).
pub const MAX_MOVING_BYTES: usize = 512 << 20;

/// Reaches the other members for migrations.
pub struct ZenohCourier {
    session: Session,
    cluster: String,
}

impl Courier for ZenohCourier {
    fn check_target(&self, daemon: &str) -> Result<(), String> {
        let replies = self
            .session
            .liveliness()
            .get(shm_layout::cluster::daemons_key(&self.cluster))
            .timeout(ASK_TIMEOUT)
            .wait()
            .map_err(|e| format!("cannot ask the cluster: {e}"))?;
        let mut live = Vec::new();
        while let Ok(reply) = replies.recv() {
            if let Ok(sample) = reply.result() {
                live.push(
                    shm_layout::cluster::last_segment(sample.key_expr().as_str()).to_string(),
                );
            }
        }
        if live.iter().any(|d| d == daemon) {
            return Ok(());
        }
        live.sort();
        Err(format!(
            "no live daemon is named {daemon:?} in cluster {:?} (live: {})",
            self.cluster,
            live.join(", ")
        ))
    }

    fn deliver(&self, daemon: &str, plane: &MovingPlane) -> MoveAnswer {
        let bytes = postcard::to_allocvec(plane).map_err(|e| format!("cannot encode: {e}"))?;
        let replies = self
            .session
            .get(migrate_key(&self.cluster, daemon))
            .payload(bytes)
            .timeout(RESTORE_WAIT * 2 + ASK_TIMEOUT)
            .wait()
            .map_err(|e| format!("cannot reach {daemon:?}: {e}"))?;
        let reply = replies
            .recv()
            .map_err(|_| format!("{daemon:?} did not answer"))?;
        match reply.into_result() {
            Ok(sample) => postcard::from_bytes::<MoveAnswer>(&sample.payload().to_bytes())
                .map_err(|e| format!("{daemon:?} answered something unreadable: {e}"))?,
            Err(e) => Err(String::from_utf8_lossy(&e.payload().to_bytes()).into_owned()),
        }
    }
}

/// Takes planes arriving here; stops when dropped.
pub struct Arrivals {
    _queryable: zenoh::query::Queryable<()>,
}

/// The migration hook of daemon `me` (its loop takes arrivals after `crate::wake(domain)`)
/// and the queryable that feeds it.
pub fn start(
    session: &Session,
    cluster: &str,
    me: &str,
    endpoint: &str,
    domain: &str,
) -> Result<(Arc<Migration>, Arrivals), ClusterError> {
    let courier = ZenohCourier {
        session: session.clone(),
        cluster: cluster.to_string(),
    };
    let migration = Arc::new(Migration::new(me, cluster, endpoint, Box::new(courier)));
    let (m, domain) = (migration.clone(), domain.to_string());
    let queryable = session
        .declare_queryable(migrate_key(cluster, me))
        .callback(move |query: Query| {
            let (m, domain) = (m.clone(), domain.clone());
            // The restore takes a while: not on Zenoh's callback thread.
            let spawned = std::thread::Builder::new()
                .name("arrival".into())
                .spawn(move || arrive(&m, &domain, query));
            if let Err(e) = spawned {
                tracing::error!("cannot take an arriving plane: {e}");
            }
        })
        .wait()
        .map_err(|e| ClusterError::Zenoh(format!("migration: {e}")))?;
    Ok((
        migration,
        Arrivals {
            _queryable: queryable,
        },
    ))
}

/// Hands one arriving plane to the loop and answers the query with the loop's verdict.
fn arrive(migration: &Migration, domain: &str, query: Query) {
    let answer = (|| {
        let payload = query
            .payload()
            .map(|p| p.to_bytes().into_owned())
            .ok_or("no plane in the query")?;
        if payload.len() > MAX_MOVING_BYTES {
            return Err(format!(
                "a moving plane of {} bytes is over the limit of {MAX_MOVING_BYTES}",
                payload.len()
            ));
        }
        let plane: MovingPlane =
            postcard::from_bytes(&payload).map_err(|e| format!("not a moving plane: {e}"))?;
        let answer = migration.arrive(plane);
        crate::wake(domain).map_err(|e| format!("cannot wake the loop: {e}"))?;
        answer
            .recv_timeout(RESTORE_WAIT * 2)
            .map_err(|_| format!("not restored within {:?}", RESTORE_WAIT * 2))?
    })();
    let bytes = postcard::to_allocvec(&answer).unwrap_or_default();
    if let Err(e) = query.reply(query.key_expr().clone(), bytes).wait() {
        tracing::warn!("cannot answer a migration: {e}");
    }
}

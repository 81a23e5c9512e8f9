//! A view of a physics cluster (docs/cluster.md): which daemons are alive and how loaded
//! each is. [`Cluster::connect`] opens a Zenoh session in client mode to one or more member
//! endpoints; the member routes for it, so one endpoint reaches the whole cluster.
//!
//! Membership comes from the daemons' liveliness tokens (`physics/<cluster>/daemon/<name>`);
//! load from their reports (`physics/<cluster>/load/<name>`), which each daemon also answers
//! to a query, so [`Cluster::daemons`] needs no wait for the next report.

use std::path::PathBuf;
use std::time::Duration;

pub use shm_layout::cluster::LoadReport;
use shm_layout::cluster::{self as keys, Endpoint};
use zenoh::Wait;

use crate::error::Error;

/// How long a question to the cluster waits for its members' answers.
pub const QUERY_TIMEOUT: Duration = Duration::from_millis(1000);

/// How to reach a cluster.
#[derive(Debug, Clone, Default)]
pub struct ClusterOptions {
    /// The cluster's name (`--cluster` of its daemons).
    pub cluster: String,
    /// Member endpoints (`tcp/127.0.0.1:7447`); plain TCP only on loopback, `tls/…` beyond.
    pub endpoints: Vec<String>,
    /// For `tls/` endpoints: the authority that signed the members' certificates.
    pub tls_ca: Option<PathBuf>,
    /// For `tls/` endpoints: this client's certificate (members use mutual TLS).
    pub tls_cert: Option<PathBuf>,
    /// Its key.
    pub tls_key: Option<PathBuf>,
}

/// One live daemon of the cluster.
#[derive(Debug, Clone, PartialEq)]
pub struct DaemonInfo {
    /// Its name (`--name`).
    pub name: String,
    /// Its latest load report, when it answered in time.
    pub load: Option<LoadReport>,
}

/// A session with a physics cluster.
pub struct Cluster {
    session: zenoh::Session,
    name: String,
}

impl Cluster {
    /// Connects to `cluster` through `endpoints` (loopback TCP, or see
    /// [`Cluster::connect_with`] for TLS).
    pub fn connect(cluster: &str, endpoints: &[&str]) -> Result<Cluster, Error> {
        Cluster::connect_with(&ClusterOptions {
            cluster: cluster.to_string(),
            endpoints: endpoints.iter().map(|e| e.to_string()).collect(),
            ..Default::default()
        })
    }

    /// Connects with explicit options.
    pub fn connect_with(options: &ClusterOptions) -> Result<Cluster, Error> {
        let config = client_config(options)?;
        let session = zenoh::open(config).wait().map_err(|e| {
            Error::Cluster(format!(
                "cannot reach cluster {:?} at {:?}: {e}",
                options.cluster, options.endpoints
            ))
        })?;
        Ok(Cluster {
            session,
            name: options.cluster.clone(),
        })
    }

    /// The cluster's name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The daemons alive now, by name, each with its latest load.
    pub fn daemons(&self) -> Result<Vec<DaemonInfo>, Error> {
        let asked = |e: zenoh::Error| Error::Cluster(format!("cannot ask the cluster: {e}"));
        let tokens = self
            .session
            .liveliness()
            .get(keys::daemons_key(&self.name))
            .timeout(QUERY_TIMEOUT)
            .wait()
            .map_err(asked)?;
        let loads = self
            .session
            .get(keys::loads_key(&self.name))
            .timeout(QUERY_TIMEOUT)
            .wait()
            .map_err(asked)?;
        let mut daemons: Vec<DaemonInfo> = Vec::new();
        while let Ok(reply) = tokens.recv() {
            if let Ok(sample) = reply.result() {
                let name = keys::last_segment(sample.key_expr().as_str()).to_string();
                if !daemons.iter().any(|d| d.name == name) {
                    daemons.push(DaemonInfo { name, load: None });
                }
            }
        }
        while let Ok(reply) = loads.recv() {
            let Ok(sample) = reply.result() else { continue };
            let name = keys::last_segment(sample.key_expr().as_str());
            // A report counts only under its own name (no daemon speaks for another).
            let Some(report) =
                LoadReport::decode(&sample.payload().to_bytes()).filter(|r| r.name == name)
            else {
                continue;
            };
            if let Some(d) = daemons.iter_mut().find(|d| d.name == name) {
                d.load = Some(report);
            }
        }
        daemons.sort_by(|a, b| a.name.cmp(&b.name));
        Ok(daemons)
    }

    /// The Zenoh session (for the parts of the SDK built on it).
    pub fn session(&self) -> &zenoh::Session {
        &self.session
    }

    /// The session itself (a remote client keeps it).
    pub(crate) fn into_session(self) -> zenoh::Session {
        self.session
    }
}

/// The client-mode configuration of `options`, after the same checks the daemons make:
/// plain TCP only to loopback; TLS needs the authority, a certificate and its key.
fn client_config(options: &ClusterOptions) -> Result<zenoh::Config, Error> {
    keys::check_name("cluster", &options.cluster).map_err(|e| Error::Cluster(e.to_string()))?;
    if options.endpoints.is_empty() {
        return Err(Error::Cluster(
            "no endpoint given: name at least one member (tcp/127.0.0.1:7447)".into(),
        ));
    }
    let mut tls = false;
    for value in &options.endpoints {
        let endpoint =
            Endpoint::parse("endpoint", value).map_err(|e| Error::Cluster(e.to_string()))?;
        if endpoint.transport == "tcp" && !endpoint.is_loopback() {
            return Err(Error::Cluster(format!(
                "endpoint {value} reaches beyond loopback: use tls/HOST:PORT with tls_ca, \
                 tls_cert and tls_key"
            )));
        }
        tls |= endpoint.transport == "tls";
    }
    let mut c = zenoh::Config::default();
    let json = |v: &[String]| serde_json::to_string(v).unwrap_or_else(|_| "[]".into());
    let mut set = |key: &str, value: String| {
        c.insert_json5(key, &value)
            .map_err(|e| Error::Cluster(format!("config {key} = {value}: {e}")))
    };
    set("mode", "\"client\"".into())?;
    set("scouting/multicast/enabled", "false".into())?;
    set("connect/endpoints", json(&options.endpoints))?;
    set("listen/endpoints", "[]".into())?;
    set("transport/link/tx/lease", keys::LEASE_MS.to_string())?;
    set("transport/shared_memory/enabled", "false".into())?;
    set("adminspace/enabled", "false".into())?;
    if tls {
        let (Some(ca), Some(cert), Some(key)) =
            (&options.tls_ca, &options.tls_cert, &options.tls_key)
        else {
            return Err(Error::Cluster(
                "a tls endpoint needs tls_ca, tls_cert and tls_key (members use mutual TLS)".into(),
            ));
        };
        let path =
            |p: &PathBuf| serde_json::to_string(&p.display().to_string()).unwrap_or_default();
        set("transport/link/tls/root_ca_certificate", path(ca))?;
        set("transport/link/tls/connect_certificate", path(cert))?;
        set("transport/link/tls/connect_private_key", path(key))?;
        // Zenoh presents the client certificate only with mTLS on.
        set("transport/link/tls/enable_mtls", "true".into())?;
    }
    Ok(c)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn plain_tcp_beyond_loopback_is_refused() {
        let options = ClusterOptions {
            cluster: "c".into(),
            endpoints: vec!["tcp/10.0.0.1:7447".into()],
            ..Default::default()
        };
        let e = client_config(&options).unwrap_err().to_string();
        assert!(e.contains("tcp/10.0.0.1:7447") && e.contains("tls"), "{e}");
        let options = ClusterOptions {
            endpoints: vec!["tls/10.0.0.1:7447".into()],
            ..options
        };
        let e = client_config(&options).unwrap_err().to_string();
        assert!(e.contains("tls_ca"), "{e}");
        let none = ClusterOptions {
            cluster: "c".into(),
            ..Default::default()
        };
        assert!(client_config(&none)
            .unwrap_err()
            .to_string()
            .contains("endpoint"));
        let bad = ClusterOptions {
            cluster: "a/b".into(),
            endpoints: vec!["tcp/127.0.0.1:1".into()],
            ..Default::default()
        };
        assert!(client_config(&bad).unwrap_err().to_string().contains("a/b"));
    }
}

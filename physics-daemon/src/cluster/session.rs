//! The cluster flags, their checks, and the Zenoh session they open.
//!
//! Security: a cluster listens on 127.0.0.1 unless told otherwise. Any endpoint beyond
//! loopback (to listen on or to connect to) must use Zenoh's TLS transport with mutual
//! authentication: `--tls-cert`/`--tls-key` (this daemon's certificate and key), `--tls-ca`
//! (the authority that signed every member's certificate) and at least one `--allow-peer`
//! (the certificate common names admitted; Zenoh's access control denies everyone else on
//! every message). Plain TCP is refused beyond loopback with an error naming the flags.

use std::path::PathBuf;

use shm_layout::cluster::{self as keys, Endpoint};
use zenoh::Wait;

use super::error::ClusterError;

/// Where a cluster listens when `--listen` is not given.
pub const DEFAULT_LISTEN: &str = "tcp/127.0.0.1:7447";

/// `--cluster` and the flags that go with it.
#[derive(clap::Args, Debug, Clone, Default)]
pub struct ClusterArgs {
    /// Join the physics cluster of this name (no cluster transport exists without it).
    #[arg(long)]
    pub cluster: Option<String>,
    /// This daemon's name in the cluster (unique among its live daemons).
    #[arg(long, requires = "cluster")]
    pub name: Option<String>,
    /// Endpoint to listen on for other members and remote clients (repeatable); default
    /// tcp/127.0.0.1:7447. Beyond loopback: tls/HOST:PORT with --tls-cert, --tls-key,
    /// --tls-ca and --allow-peer.
    #[arg(long, requires = "cluster")]
    pub listen: Vec<String>,
    /// Endpoint of another member to connect to (repeatable); members learn the rest of the
    /// cluster from it.
    #[arg(long, requires = "cluster")]
    pub connect: Vec<String>,
    /// PEM certificate of this daemon (TLS endpoints).
    #[arg(long, requires = "cluster")]
    pub tls_cert: Option<PathBuf>,
    /// PEM private key of --tls-cert.
    #[arg(long, requires = "cluster")]
    pub tls_key: Option<PathBuf>,
    /// PEM certificate of the authority that signed every member's certificate.
    #[arg(long, requires = "cluster")]
    pub tls_ca: Option<PathBuf>,
    /// Certificate common name of a peer allowed in (repeatable); required with TLS.
    #[arg(long, requires = "cluster")]
    pub allow_peer: Vec<String>,
    /// Move planes to less loaded members while this daemon uses more than this share of
    /// its tick budget (0 < SHARE <= 1; the flag alone: 0.8). Off without the flag.
    #[arg(long, requires = "cluster", num_args = 0..=1, default_missing_value = "0.8", value_name = "SHARE")]
    pub rebalance: Option<f32>,
}

/// The checked flags.
#[derive(Debug, Clone)]
pub struct Plan {
    /// The cluster.
    pub cluster: String,
    /// This daemon's name.
    pub name: String,
    /// Endpoints to listen on.
    pub listen: Vec<String>,
    /// Endpoints to connect to.
    pub connect: Vec<String>,
    /// Certificate, key and authority, when any endpoint uses TLS.
    pub tls: Option<Tls>,
    /// Common names admitted (TLS only).
    pub allow: Vec<String>,
}

/// The TLS material.
#[derive(Debug, Clone)]
pub struct Tls {
    /// This daemon's certificate.
    pub cert: PathBuf,
    /// Its key.
    pub key: PathBuf,
    /// The authority.
    pub ca: PathBuf,
}

impl Plan {
    /// Checks the flags; `None` without `--cluster`.
    pub fn from_args(args: &ClusterArgs) -> Result<Option<Plan>, ClusterError> {
        let Some(cluster) = args.cluster.clone() else {
            return Ok(None);
        };
        keys::check_name("--cluster", &cluster)?;
        let name = args.name.clone().ok_or_else(|| {
            ClusterError::Flags("--cluster needs --name DAEMON (this daemon's name in it)".into())
        })?;
        keys::check_name("--name", &name)?;
        let listen = if args.listen.is_empty() {
            vec![DEFAULT_LISTEN.to_string()]
        } else {
            args.listen.clone()
        };
        let mut needs_tls = Vec::new();
        let mut uses_tls = false;
        for (flag, list) in [("--listen", &listen), ("--connect", &args.connect)] {
            for value in list {
                let endpoint = Endpoint::parse(flag, value)?;
                uses_tls |= endpoint.transport == "tls";
                if endpoint.transport != "tls" && !endpoint.is_loopback() {
                    needs_tls.push(format!("{flag} {value}"));
                }
            }
        }
        if !needs_tls.is_empty() {
            return Err(ClusterError::Flags(format!(
                "{} reaches beyond loopback: use a tls/HOST:PORT endpoint with --tls-cert, \
                 --tls-key, --tls-ca and --allow-peer (plain tcp is for 127.0.0.1 only)",
                needs_tls.join(", ")
            )));
        }
        let tls = if uses_tls {
            let missing: Vec<&str> = [
                ("--tls-cert", args.tls_cert.is_none()),
                ("--tls-key", args.tls_key.is_none()),
                ("--tls-ca", args.tls_ca.is_none()),
                ("--allow-peer", args.allow_peer.is_empty()),
            ]
            .into_iter()
            .filter_map(|(flag, missing)| missing.then_some(flag))
            .collect();
            if !missing.is_empty() {
                return Err(ClusterError::Flags(format!(
                    "a tls endpoint needs {} (mutual TLS and an allow-list of peers)",
                    missing.join(", ")
                )));
            }
            for cn in &args.allow_peer {
                if cn.is_empty() || cn.len() > 253 || cn.chars().any(|c| c.is_control()) {
                    return Err(ClusterError::Flags(format!(
                        "--allow-peer {cn:?}: expected a certificate common name"
                    )));
                }
            }
            Some(Tls {
                cert: args.tls_cert.clone().unwrap_or_default(),
                key: args.tls_key.clone().unwrap_or_default(),
                ca: args.tls_ca.clone().unwrap_or_default(),
            })
        } else {
            None
        };
        Ok(Some(Plan {
            cluster,
            name,
            listen,
            connect: args.connect.clone(),
            tls,
            allow: args.allow_peer.clone(),
        }))
    }

    /// The Zenoh configuration of this plan.
    pub fn config(&self) -> Result<zenoh::Config, ClusterError> {
        let mut c = zenoh::Config::default();
        let mut set = |key: &str, value: String| {
            c.insert_json5(key, &value)
                .map_err(|e| ClusterError::Zenoh(format!("config {key} = {value}: {e}")))
        };
        let json = json_list;
        set("mode", "\"peer\"".into())?;
        set("scouting/multicast/enabled", "false".into())?;
        set("listen/endpoints", json(&self.listen))?;
        set("connect/endpoints", json(&self.connect))?;
        // A lost host is noticed within the lease (a dead process: at once, its sockets close).
        set("transport/link/tx/lease", keys::LEASE_MS.to_string())?;
        set("transport/shared_memory/enabled", "false".into())?;
        set("adminspace/enabled", "false".into())?;
        if let Some(tls) = &self.tls {
            let path = |p: &PathBuf| json_string(&p.display().to_string());
            set("transport/link/tls/root_ca_certificate", path(&tls.ca))?;
            set("transport/link/tls/listen_certificate", path(&tls.cert))?;
            set("transport/link/tls/listen_private_key", path(&tls.key))?;
            set("transport/link/tls/connect_certificate", path(&tls.cert))?;
            set("transport/link/tls/connect_private_key", path(&tls.key))?;
            set("transport/link/tls/enable_mtls", "true".into())?;
            let acl = format!(
                r#"{{ enabled: true, default_permission: "deny",
                   rules: [{{ id: "cluster", permission: "allow", flows: ["egress", "ingress"],
                     messages: ["put", "delete", "declare_subscriber", "query", "reply",
                       "declare_queryable", "liveliness_token", "liveliness_query",
                       "declare_liveliness_subscriber"],
                     key_exprs: [{keys}] }}],
                   subjects: [{{ id: "allowed", cert_common_names: {cns} }}],
                   policies: [{{ rules: ["cluster"], subjects: ["allowed"] }}] }}"#,
                keys = json_string(&keys::cluster_keys(&self.cluster)),
                cns = json(&self.allow),
            );
            set("access_control", acl)?;
        }
        Ok(c)
    }
}

fn json_string(s: &str) -> String {
    serde_json::to_string(s).unwrap_or_else(|_| "\"\"".into())
}

fn json_list(v: &[String]) -> String {
    serde_json::to_string(v).unwrap_or_else(|_| "[]".into())
}

/// Opens the session of `plan`.
pub fn open(plan: &Plan) -> Result<zenoh::Session, ClusterError> {
    let config = plan.config()?;
    zenoh::open(config).wait().map_err(|e| {
        ClusterError::Zenoh(format!(
            "cannot open the session (listen {:?}, connect {:?}): {e}",
            plan.listen, plan.connect
        ))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn args(listen: &[&str]) -> ClusterArgs {
        ClusterArgs {
            cluster: Some("c".into()),
            name: Some("a".into()),
            listen: listen.iter().map(|s| s.to_string()).collect(),
            ..Default::default()
        }
    }

    #[test]
    fn loopback_is_the_default_and_needs_nothing() {
        let plan = Plan::from_args(&args(&[])).unwrap().unwrap();
        assert_eq!(plan.listen, vec![DEFAULT_LISTEN.to_string()]);
        assert!(plan.tls.is_none());
        assert!(Plan::from_args(&ClusterArgs::default()).unwrap().is_none());
    }

    #[test]
    fn beyond_loopback_needs_tls_and_an_allow_list() {
        let e = Plan::from_args(&args(&["tcp/0.0.0.0:7447"]))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("--listen tcp/0.0.0.0:7447") && e.contains("--tls-cert"),
            "{e}"
        );
        let e = Plan::from_args(&args(&["tls/10.1.2.3:7447"]))
            .unwrap_err()
            .to_string();
        for flag in ["--tls-cert", "--tls-key", "--tls-ca", "--allow-peer"] {
            assert!(e.contains(flag), "{e}");
        }
        let mut a = args(&["tls/10.1.2.3:7447"]);
        a.tls_cert = Some("c.pem".into());
        a.tls_key = Some("k.pem".into());
        a.tls_ca = Some("ca.pem".into());
        a.allow_peer = vec!["b.example".into()];
        let plan = Plan::from_args(&a).unwrap().unwrap();
        assert!(plan.tls.is_some());
        plan.config()
            .expect("a valid zenoh configuration with access control");
        let mut c = args(&[]);
        c.connect = vec!["tcp/192.168.1.4:7447".into()];
        let e = Plan::from_args(&c).unwrap_err().to_string();
        assert!(e.contains("--connect tcp/192.168.1.4:7447"), "{e}");
    }

    #[test]
    fn bad_names_are_named() {
        let mut a = args(&[]);
        a.name = Some("x/y".into());
        let e = Plan::from_args(&a).unwrap_err().to_string();
        assert!(e.contains("--name") && e.contains("x/y"), "{e}");
        a.name = None;
        let e = Plan::from_args(&a).unwrap_err().to_string();
        assert!(e.contains("--name"), "{e}");
    }
}

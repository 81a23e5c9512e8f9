//! The cluster's wire: the names daemons and clients meet under on Zenoh, the checks on
//! cluster and daemon names and on endpoints, and the load report each daemon puts once a
//! second. Shared by the daemon (`physics-daemon --cluster`) and the SDK
//! (`client_sdk::cluster`) so both sides spell every key the same way. No I/O.
//!
//! Keys (one cluster is one prefix, so several clusters share a network without seeing each
//! other):
//! - `physics/<cluster>/daemon/<name>`: the liveliness token of a daemon; it exists exactly
//!   while the daemon's session is alive.
//! - `physics/<cluster>/load/<name>`: the daemon's [`LoadReport`], put each second and also
//!   answered to a query (a newcomer need not wait a second).

use serde::{Deserialize, Serialize};

/// Longest cluster or daemon name, in bytes.
pub const MAX_CLUSTER_NAME_LEN: usize = 64;

/// The first segment of every cluster key.
pub const ROOT: &str = "physics";

/// The load report period.
pub const LOAD_PERIOD_MS: u64 = 1000;

/// How long a silent link to a peer is kept before its daemon counts as gone (zenoh's link
/// lease). A process that dies has its sockets closed by the kernel, which ends the link at
/// once; the lease bounds the case where a host or its network vanishes without a word.
pub const LEASE_MS: u64 = 3000;

/// A cluster or daemon name that cannot be used.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error(
    "{field} {value:?} is not a valid name: use 1 to {MAX_CLUSTER_NAME_LEN} ASCII letters, \
     digits, '_' or '-'"
)]
pub struct NameError {
    /// Which name (`--cluster`, `--name`).
    pub field: &'static str,
    /// The name as given.
    pub value: String,
}

/// Checks a cluster or daemon name: it becomes one segment of a key expression, so it may
/// hold none of zenoh's special characters (`/ * $ ? # @`).
pub fn check_name(field: &'static str, value: &str) -> Result<(), NameError> {
    let ok = !value.is_empty()
        && value.len() <= MAX_CLUSTER_NAME_LEN
        && value
            .bytes()
            .all(|b| b.is_ascii_alphanumeric() || b == b'_' || b == b'-');
    if ok {
        Ok(())
    } else {
        Err(NameError {
            field,
            value: value.chars().take(80).collect(),
        })
    }
}

/// The liveliness key of daemon `name` in `cluster`.
pub fn daemon_key(cluster: &str, name: &str) -> String {
    format!("{ROOT}/{cluster}/daemon/{name}")
}

/// The key expression matching every daemon token of `cluster`.
pub fn daemons_key(cluster: &str) -> String {
    format!("{ROOT}/{cluster}/daemon/*")
}

/// The key daemon `name` puts its load on.
pub fn load_key(cluster: &str, name: &str) -> String {
    format!("{ROOT}/{cluster}/load/{name}")
}

/// The key expression matching every load report of `cluster`.
pub fn loads_key(cluster: &str) -> String {
    format!("{ROOT}/{cluster}/load/*")
}

/// Everything of `cluster` (the access-control rule of a TLS cluster allows this only).
pub fn cluster_keys(cluster: &str) -> String {
    format!("{ROOT}/{cluster}/**")
}

/// The last segment of a key (the daemon name of a token or load key).
pub fn last_segment(key: &str) -> &str {
    key.rsplit('/').next().unwrap_or(key)
}

/// What a daemon reports about itself each second.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LoadReport {
    /// The daemon's name in the cluster.
    pub name: String,
    /// Planes it hosts.
    pub planes: u32,
    /// Objects in those planes.
    pub bodies: u64,
    /// Share of its tick budget used over the last period: time spent stepping planes
    /// divided by (period × the cores the daemon may run on). 1.0 means every core did
    /// nothing but step.
    pub budget_used: f32,
    /// CPU the daemon process used over the last period, in cores (1.0 = one core busy).
    pub cpu: f32,
    /// Cores the daemon may run on (its CPU affinity).
    pub cores: u32,
    /// Its process id (on its own host).
    pub pid: u32,
    /// Reports sent before this one (tells a reader the report is fresh).
    pub sequence: u64,
}

impl LoadReport {
    /// The report's bytes (postcard).
    pub fn encode(&self) -> Vec<u8> {
        postcard::to_stdvec(self).unwrap_or_default()
    }

    /// Reads a report; `None` for bytes that are no report (a forged or foreign put).
    pub fn decode(bytes: &[u8]) -> Option<LoadReport> {
        let report: LoadReport = postcard::from_bytes(bytes).ok()?;
        let finite = report.budget_used.is_finite() && report.cpu.is_finite();
        (finite && check_name("name", &report.name).is_ok()).then_some(report)
    }
}

/// Why an endpoint cannot be used.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum EndpointError {
    /// Not `tcp/HOST:PORT` or `tls/HOST:PORT`.
    #[error(
        "{flag} {value:?}: expected tcp/HOST:PORT or tls/HOST:PORT (other zenoh transports \
         are not built in)"
    )]
    Malformed {
        /// The flag (`--listen`, `--connect`).
        flag: &'static str,
        /// The endpoint as given.
        value: String,
    },
}

/// An endpoint split into its transport and host.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Endpoint {
    /// `tcp` or `tls`.
    pub transport: String,
    /// The host part (an address or a name, brackets kept off IPv6).
    pub host: String,
    /// The port.
    pub port: u16,
}

impl Endpoint {
    /// Parses `tcp/HOST:PORT` or `tls/HOST:PORT` (zenoh's `?…` and `#…` suffixes allowed).
    pub fn parse(flag: &'static str, value: &str) -> Result<Endpoint, EndpointError> {
        let bad = || EndpointError::Malformed {
            flag,
            value: value.chars().take(120).collect(),
        };
        let (transport, rest) = value.split_once('/').ok_or_else(bad)?;
        if transport != "tcp" && transport != "tls" {
            return Err(bad());
        }
        let address = rest.split(['?', '#']).next().unwrap_or(rest);
        let (host, port) = address.rsplit_once(':').ok_or_else(bad)?;
        let port: u16 = port.parse().map_err(|_| bad())?;
        let host = host.trim_start_matches('[').trim_end_matches(']');
        if host.is_empty() {
            return Err(bad());
        }
        Ok(Endpoint {
            transport: transport.to_string(),
            host: host.to_string(),
            port,
        })
    }

    /// Whether the host is this machine's loopback (127.0.0.0/8, ::1 or `localhost`).
    /// Anything else, the unspecified address 0.0.0.0 included, reaches beyond the host.
    pub fn is_loopback(&self) -> bool {
        if self.host.eq_ignore_ascii_case("localhost") {
            return true;
        }
        self.host
            .parse::<std::net::IpAddr>()
            .is_ok_and(|ip| ip.is_loopback())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_refuse_key_characters() {
        assert!(check_name("--name", "alpha-1_b").is_ok());
        for bad in ["", "a/b", "a*", "$x", "a b", "é", &"x".repeat(65)] {
            let e = check_name("--name", bad).unwrap_err();
            assert!(e.to_string().contains("--name"), "{e}");
        }
    }

    #[test]
    fn endpoints_parse_and_classify() {
        let e = Endpoint::parse("--listen", "tcp/127.0.0.1:7447").unwrap();
        assert!(e.is_loopback());
        assert_eq!(e.port, 7447);
        assert!(Endpoint::parse("--listen", "tcp/[::1]:1#iface=lo")
            .unwrap()
            .is_loopback());
        assert!(!Endpoint::parse("--listen", "tcp/0.0.0.0:7447")
            .unwrap()
            .is_loopback());
        assert!(!Endpoint::parse("--listen", "tls/10.0.0.2:7447")
            .unwrap()
            .is_loopback());
        for bad in ["udp/127.0.0.1:1", "tcp/127.0.0.1", "tcp/:1", "127.0.0.1:1"] {
            let e = Endpoint::parse("--connect", bad).unwrap_err();
            assert!(e.to_string().contains("--connect"), "{e}");
        }
    }

    #[test]
    fn load_reports_round_trip_and_refuse_forgeries() {
        let r = LoadReport {
            name: "a".into(),
            planes: 2,
            bodies: 10,
            budget_used: 0.25,
            cpu: 0.5,
            cores: 2,
            pid: 7,
            sequence: 3,
        };
        assert_eq!(LoadReport::decode(&r.encode()), Some(r.clone()));
        assert_eq!(LoadReport::decode(&[0xff, 0xff, 0xff]), None);
        let nan = LoadReport {
            cpu: f32::NAN,
            ..r.clone()
        };
        assert_eq!(LoadReport::decode(&nan.encode()), None);
        let slash = LoadReport {
            name: "a/b".into(),
            ..r
        };
        assert_eq!(LoadReport::decode(&slash.encode()), None);
    }
}

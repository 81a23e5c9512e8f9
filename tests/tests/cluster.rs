//! A physics cluster on one machine: three daemons, each in a domain of its own (as if on
//! three hosts) and each listening on a loopback port the OS handed out, join one cluster;
//! every member's liveliness and load are seen through one endpoint; a duplicate name and
//! an unsafe listen address are refused with errors naming what to change; a SIGKILLed
//! daemon drops out within a bound set by the transport's lease.

use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use client_sdk::cluster::{Cluster, DaemonInfo};
use client_sdk::PlaneOptions;
use integration_tests::cluster::{endpoint, free_port, member, unique_cluster};
use integration_tests::{eventually, unique_domain, TestDaemon};

/// Runs a daemon expected to refuse its flags: its exit status and stderr. A daemon that
/// has not exited within 15 s fails the test (and is killed).
fn refused(args: &[&str]) -> (bool, String) {
    let mut child = Command::new(client_sdk::daemon_executable())
        .args(["--domain", &unique_domain("cl-refused")])
        .args(args)
        .env("PHYSICS_LOG", "warn")
        .stdin(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("run physics-daemon");
    let deadline = Instant::now() + Duration::from_secs(15);
    let status = loop {
        if let Some(status) = child.try_wait().expect("wait physics-daemon") {
            break status;
        }
        if Instant::now() > deadline {
            let _ = child.kill();
            let _ = child.wait();
            let mut err = String::new();
            use std::io::Read;
            let _ = child
                .stderr
                .take()
                .expect("stderr")
                .read_to_string(&mut err);
            panic!("physics-daemon {args:?} did not exit within 15 s of refusing: {err}");
        }
        std::thread::sleep(Duration::from_millis(10));
    };
    let mut err = String::new();
    use std::io::Read;
    let _ = child
        .stderr
        .take()
        .expect("stderr")
        .read_to_string(&mut err);
    (status.success(), err)
}

fn names(daemons: &[DaemonInfo]) -> Vec<&str> {
    daemons.iter().map(|d| d.name.as_str()).collect()
}

#[test]
fn three_daemons_see_each_other_and_a_killed_one_leaves() {
    let cluster = unique_cluster("three");
    let (pa, pb, pc) = (free_port(), free_port(), free_port());
    let a = member(&cluster, "a", pa, &[], &[]);
    let b = member(&cluster, "b", pb, &[pa], &[]);
    let mut c = member(&cluster, "c", pc, &[pa, pb], &[]);

    // Through b's endpoint only: the member routes for its client, so all three are seen.
    let view = Cluster::connect(&cluster, &[&endpoint(pb)]).expect("connect to the cluster");
    let all = eventually(Duration::from_secs(10), || {
        let d = view.daemons().ok()?;
        (names(&d) == ["a", "b", "c"] && d.iter().all(|d| d.load.is_some())).then_some(d)
    })
    .expect("a, b and c alive, each with a load report");
    for d in &all {
        let load = d.load.as_ref().unwrap();
        assert_eq!(load.name, d.name);
        assert_eq!((load.planes, load.bodies), (0, 0), "{load:?}");
        assert!(load.cores >= 1, "{load:?}");
    }
    // Each report names its own process: three daemons, three pids.
    let pids: Vec<u32> = all.iter().map(|d| d.load.as_ref().unwrap().pid).collect();
    assert_eq!(pids, [a.pid(), b.pid(), c.pid()]);

    // Load follows what b hosts: one automatic 60 Hz plane with 1 anchored floor and 40
    // falling boxes (41 objects). Only b steps, so only b spends tick budget.
    let client = b.client();
    let plane = client
        .create_plane(&PlaneOptions::default())
        .expect("a plane on b");
    // `pile` adds its own floor: 40 cubes and 1 slab.
    physics_scenes::pile(&mut &plane, 40).expect("pile on b");
    client.flush().expect("flush");
    let loaded = eventually(Duration::from_secs(6), || {
        let d = view.daemons().ok()?;
        let b = d.iter().find(|d| d.name == "b")?.load.clone()?;
        (b.planes == 1 && b.bodies == 41 && b.budget_used > 0.0).then_some(d)
    })
    .expect("b reports 1 plane, 41 bodies and some tick budget used");
    for d in &loaded {
        let load = d.load.as_ref().unwrap();
        assert!(
            load.budget_used.is_finite() && load.budget_used <= 1.0,
            "{load:?}"
        );
        assert!(load.cpu.is_finite() && load.cpu >= 0.0, "{load:?}");
        if d.name != "b" {
            // No plane, no step: exactly nothing of the budget.
            assert_eq!(
                (load.planes, load.bodies, load.budget_used),
                (0, 0, 0.0),
                "{load:?}"
            );
        } else {
            assert!(load.cpu > 0.0, "b steps a plane yet used no CPU: {load:?}");
        }
    }

    // SIGKILL c: the kernel closes its sockets, so its links (and token) end at once; the
    // bound is the lease (a host that vanishes without closing anything) plus one query.
    let bound = Duration::from_millis(shm_layout::cluster::LEASE_MS)
        + client_sdk::cluster::QUERY_TIMEOUT
        + Duration::from_millis(500);
    c.kill9();
    let killed = Instant::now();
    let gone = eventually(bound, || {
        let d = view.daemons().ok()?;
        (names(&d) == ["a", "b"]).then(|| killed.elapsed())
    })
    .unwrap_or_else(|| panic!("c still listed {bound:?} after SIGKILL"));
    eprintln!("SIGKILLed daemon left the cluster view after {gone:?} (bound {bound:?})");
    drop((a, b, plane, client));
}

#[test]
fn a_name_alive_is_refused() {
    let cluster = unique_cluster("dup");
    let (pa, pb, pc) = (free_port(), free_port(), free_port());
    let _a = member(&cluster, "a", pa, &[], &[]);
    let _b = member(&cluster, "b", pb, &[pa], &[]);
    let _c = member(&cluster, "c", pc, &[pa, pb], &[]);
    // The newcomer connects to a only: it must learn of b through gossip before it checks.
    // A name alive in the cluster is refused, naming it.
    let (ok, err) = refused(&[
        "--cluster",
        &cluster,
        "--name",
        "b",
        "--listen",
        "tcp/127.0.0.1:0",
        "--connect",
        &endpoint(pa),
    ]);
    assert!(!ok && err.contains("\"b\" is already alive"), "{err}");
}

#[test]
fn unsafe_or_malformed_cluster_flags_are_refused_by_name() {
    let port = free_port().to_string();
    let any = format!("tcp/0.0.0.0:{port}");
    let (ok, err) = refused(&["--cluster", "x", "--name", "a", "--listen", &any]);
    assert!(
        !ok,
        "listening on every interface in plain tcp must be refused"
    );
    for flag in [
        "--listen",
        "--tls-cert",
        "--tls-key",
        "--tls-ca",
        "--allow-peer",
    ] {
        assert!(err.contains(flag), "{flag} not named in: {err}");
    }
    let tls = format!("tls/10.9.9.9:{port}");
    let (ok, err) = refused(&["--cluster", "x", "--name", "a", "--listen", &tls]);
    assert!(
        !ok && err.contains("--tls-cert") && err.contains("--allow-peer"),
        "{err}"
    );
    let (ok, err) = refused(&["--cluster", "x/y", "--name", "a"]);
    assert!(
        !ok && err.contains("--cluster") && err.contains("x/y"),
        "{err}"
    );
    let (ok, err) = refused(&["--cluster", "x"]);
    assert!(!ok && err.contains("--name"), "{err}");
    let (ok, err) = refused(&["--name", "a"]);
    assert!(!ok && err.contains("--cluster"), "{err}");
    let (ok, err) = refused(&[
        "--cluster",
        "x",
        "--name",
        "a",
        "--listen",
        "udp/127.0.0.1:1",
    ]);
    assert!(!ok && err.contains("udp/127.0.0.1:1"), "{err}");
    // Replication needs a cluster, and a count of ticks.
    let (ok, err) = refused(&["--replicate-every", "10"]);
    assert!(
        !ok && err.contains("--replicate-every") && err.contains("--cluster"),
        "{err}"
    );
    let (ok, err) = refused(&["--cluster", "x", "--name", "a", "--replicate-every", "0"]);
    assert!(!ok && err.contains("--replicate-every"), "{err}");
}

/// Certificates for a TLS cluster on loopback, made with the `openssl` tool: one authority
/// and, per common name, a certificate for 127.0.0.1 usable on both ends of a link (mTLS).
struct Certs {
    dir: std::path::PathBuf,
}

impl Certs {
    fn new(tag: &str) -> Certs {
        let dir = std::env::temp_dir().join(unique_domain(tag));
        std::fs::create_dir_all(&dir).expect("cert dir");
        let certs = Certs { dir };
        certs.openssl(&[
            "req",
            "-x509",
            "-newkey",
            "ec",
            "-pkeyopt",
            "ec_paramgen_curve:prime256v1",
            "-nodes",
            "-keyout",
            "ca.key",
            "-out",
            "ca.pem",
            "-days",
            "2",
            "-subj",
            "/CN=physics-test-ca",
            "-addext",
            "basicConstraints=critical,CA:TRUE",
            "-addext",
            "keyUsage=critical,keyCertSign,cRLSign",
        ]);
        std::fs::write(
            certs.dir.join("leaf.ext"),
            "subjectAltName=IP:127.0.0.1,DNS:localhost\nbasicConstraints=CA:FALSE\n\
             keyUsage=critical,digitalSignature\nextendedKeyUsage=serverAuth,clientAuth\n",
        )
        .expect("extensions file");
        certs
    }

    fn openssl(&self, args: &[&str]) {
        let out = Command::new("openssl")
            .args(args)
            .current_dir(&self.dir)
            .output()
            .expect("the openssl tool makes the test certificates: install openssl");
        assert!(
            out.status.success(),
            "openssl {args:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
    }

    /// A certificate and key for common name `cn`: (cert, key) paths.
    fn leaf(&self, cn: &str) -> (String, String) {
        let (key, csr, pem) = (
            format!("{cn}.key"),
            format!("{cn}.csr"),
            format!("{cn}.pem"),
        );
        self.openssl(&[
            "req",
            "-newkey",
            "ec",
            "-pkeyopt",
            "ec_paramgen_curve:prime256v1",
            "-nodes",
            "-keyout",
            &key,
            "-out",
            &csr,
            "-subj",
            &format!("/CN={cn}"),
        ]);
        self.openssl(&[
            "x509",
            "-req",
            "-in",
            &csr,
            "-CA",
            "ca.pem",
            "-CAkey",
            "ca.key",
            "-CAcreateserial",
            "-out",
            &pem,
            "-days",
            "2",
            "-extfile",
            "leaf.ext",
        ]);
        (self.path(&pem), self.path(&key))
    }

    fn path(&self, file: &str) -> String {
        self.dir.join(file).display().to_string()
    }
}

impl Drop for Certs {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.dir);
    }
}

/// A member on a TLS endpoint with its own certificate and an allow-list.
fn tls_member(
    certs: &Certs,
    cluster: &str,
    name: &str,
    listen: u16,
    connect: Option<u16>,
    allow: &[&str],
) -> TestDaemon {
    let (cert, key) = certs.leaf(name);
    let mut args = vec![
        "--cluster".to_string(),
        cluster.into(),
        "--name".into(),
        name.into(),
        "--listen".into(),
        format!("tls/127.0.0.1:{listen}"),
        "--tls-cert".into(),
        cert,
        "--tls-key".into(),
        key,
        "--tls-ca".into(),
        certs.path("ca.pem"),
    ];
    if let Some(port) = connect {
        args.push("--connect".into());
        args.push(format!("tls/127.0.0.1:{port}"));
    }
    for cn in allow {
        args.push("--allow-peer".into());
        args.push(cn.to_string());
    }
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    TestDaemon::start_with(&format!("cl-tls-{name}"), &args, &[])
}

#[test]
fn a_tls_cluster_admits_only_its_allow_list() {
    let certs = Certs::new("cl-certs");
    let cluster = unique_cluster("tls");
    let (pa, pb, px) = (free_port(), free_port(), free_port());
    // a and b admit each other and the viewer; nobody admits "intruder", although its
    // certificate is signed by the same authority.
    let _a = tls_member(&certs, &cluster, "a", pa, None, &["b", "viewer"]);
    let _b = tls_member(&certs, &cluster, "b", pb, Some(pa), &["a", "viewer"]);
    let _x = tls_member(&certs, &cluster, "intruder", px, Some(pa), &["a", "b"]);
    let (cert, key) = certs.leaf("viewer");
    let view = Cluster::connect_with(&client_sdk::cluster::ClusterOptions {
        cluster: cluster.clone(),
        endpoints: vec![format!("tls/127.0.0.1:{pa}")],
        tls_ca: Some(certs.path("ca.pem").into()),
        tls_cert: Some(cert.into()),
        tls_key: Some(key.into()),
    })
    .expect("connect over TLS");
    let seen = eventually(Duration::from_secs(10), || {
        let d = view.daemons().ok()?;
        (names(&d) == ["a", "b"] && d.iter().all(|d| d.load.is_some())).then_some(d)
    });
    assert!(seen.is_some(), "a and b not both seen over TLS");
    // Long enough for the intruder's token to have arrived had it been let in (b's came
    // within the same window above).
    std::thread::sleep(Duration::from_millis(1500));
    let d = view.daemons().expect("daemons");
    assert_eq!(names(&d), ["a", "b"], "the intruder must not be seen");

    // A viewer off the allow-list sees nothing either.
    let (cert, key) = certs.leaf("stranger");
    let stranger = Cluster::connect_with(&client_sdk::cluster::ClusterOptions {
        cluster: cluster.clone(),
        endpoints: vec![format!("tls/127.0.0.1:{pa}")],
        tls_ca: Some(certs.path("ca.pem").into()),
        tls_cert: Some(cert.into()),
        tls_key: Some(key.into()),
    });
    if let Ok(stranger) = stranger {
        assert_eq!(stranger.daemons().expect("daemons"), vec![]);
    }
}

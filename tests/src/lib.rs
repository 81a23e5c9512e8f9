//! Harness of the multi-process suite: each test starts a real `physics-daemon` process in a
//! domain of its own, so tests run in parallel without seeing each other.

use std::path::PathBuf;
use std::process::{Child, Command, ExitStatus, Stdio};
use std::sync::atomic::{AtomicU32, Ordering};
use std::time::{Duration, Instant};

use client_sdk::{Client, Error};

/// A daemon process owned by one test; killed when dropped.
pub struct TestDaemon {
    pub domain: String,
    child: Option<Child>,
}

/// A domain no other test (or earlier run) uses.
pub fn unique_domain(tag: &str) -> String {
    static COUNTER: AtomicU32 = AtomicU32::new(0);
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    let t = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .unwrap()
        .subsec_nanos();
    let suffix = format!("-{}-{n}-{}", std::process::id(), t % 100_000);
    // Domains are at most 32 characters: the tag gives way (the suffix keeps it unique).
    let keep = tag.len().min(32usize.saturating_sub(suffix.len()));
    let tag = tag.get(..keep).unwrap_or("t");
    format!("{tag}{suffix}")
}

fn daemon_bin() -> PathBuf {
    let bin = client_sdk::daemon_executable();
    assert!(
        bin.is_file(),
        "physics-daemon binary not found at {} (build it first: cargo build --workspace)",
        bin.display()
    );
    bin
}

impl TestDaemon {
    pub fn start(tag: &str) -> TestDaemon {
        Self::start_in(&unique_domain(tag))
    }

    /// Starts a daemon in an existing domain (e.g. after the previous one crashed).
    pub fn start_in(domain: &str) -> TestDaemon {
        Self::start_with_in(domain, &[], &[])
    }

    /// Starts a daemon with extra flags and environment (quotas, fault injection).
    pub fn start_with(tag: &str, args: &[&str], env: &[(&str, &str)]) -> TestDaemon {
        Self::start_with_in(&unique_domain(tag), args, env)
    }

    /// Starts a daemon with extra flags in an existing domain (e.g. a restart with the same
    /// `--state-dir` after the previous daemon was killed).
    pub fn start_with_in(domain: &str, args: &[&str], env: &[(&str, &str)]) -> TestDaemon {
        Self::spawn_in(domain, args, env, Stdio::inherit())
    }

    /// [`TestDaemon::start_with_in`] with the daemon's log (stderr, level `info`) written to
    /// `log`.
    pub fn start_logged_in(domain: &str, args: &[&str], log: &std::path::Path) -> TestDaemon {
        let file = std::fs::File::create(log).expect("create the daemon log");
        Self::spawn_in(domain, args, &[("PHYSICS_LOG", "info")], Stdio::from(file))
    }

    fn spawn_in(domain: &str, args: &[&str], env: &[(&str, &str)], stderr: Stdio) -> TestDaemon {
        let domain = domain.to_string();
        let child = Command::new(daemon_bin())
            .args(["--domain", &domain])
            .args(args)
            .env("PHYSICS_LOG", "warn")
            .envs(env.iter().copied())
            .stdin(Stdio::null())
            .stderr(stderr)
            .spawn()
            .expect("spawn physics-daemon");
        let daemon = TestDaemon {
            domain,
            child: Some(child),
        };
        let deadline = Instant::now() + Duration::from_secs(10);
        loop {
            match Client::connect(&daemon.domain) {
                Ok(_) => return daemon,
                Err(Error::NoDaemon { .. }) if Instant::now() < deadline => {
                    std::thread::sleep(Duration::from_millis(20))
                }
                Err(e) => panic!("daemon of {} did not come up: {e}", daemon.domain),
            }
        }
    }

    /// Whether the daemon process still runs.
    pub fn is_running(&mut self) -> bool {
        self.child
            .as_mut()
            .is_some_and(|c| matches!(c.try_wait(), Ok(None)))
    }

    pub fn client(&self) -> Client {
        Client::connect(&self.domain).expect("connect to test daemon")
    }

    pub fn pid(&self) -> u32 {
        self.child.as_ref().expect("daemon running").id()
    }

    /// Sends `sig` to the daemon.
    pub fn signal(&self, sig: i32) {
        // SAFETY: kill(2) on our own child.
        unsafe { libc::kill(self.pid() as i32, sig) };
    }

    /// SIGKILL, then reap the process.
    pub fn kill9(&mut self) {
        self.signal(libc::SIGKILL);
        let _ = self.child.take().expect("daemon running").wait();
    }

    /// Sends `sig` and waits up to `timeout` for the exit. Returns the status and the time.
    pub fn stop_with(&mut self, sig: i32, timeout: Duration) -> (ExitStatus, Duration) {
        let started = Instant::now();
        self.signal(sig);
        let mut child = self.child.take().expect("daemon running");
        loop {
            if let Some(status) = child.try_wait().expect("wait daemon") {
                return (status, started.elapsed());
            }
            if started.elapsed() > timeout {
                let _ = child.kill();
                panic!("daemon did not exit within {timeout:?} of signal {sig}");
            }
            std::thread::sleep(Duration::from_millis(5));
        }
    }
}

impl Drop for TestDaemon {
    /// Stops the daemon cleanly (SIGINT, SIGKILL after 2 s), then removes whatever killed
    /// processes of the test left in the domain.
    fn drop(&mut self) {
        if let Some(mut child) = self.child.take() {
            // SAFETY: kill(2) on our own child.
            unsafe { libc::kill(child.id() as i32, libc::SIGINT) };
            let deadline = Instant::now() + Duration::from_secs(2);
            while Instant::now() < deadline && matches!(child.try_wait(), Ok(None)) {
                std::thread::sleep(Duration::from_millis(5));
            }
            let _ = child.kill();
            let _ = child.wait();
        }
        let _ = physics_daemon::cleanup_domain(&self.domain);
    }
}

/// Every file of `domain` under /dev/shm and the iceoryx2 root (sockets, node records).
pub fn domain_files(domain: &str) -> Vec<PathBuf> {
    physics_daemon::server::files::domain_files(domain)
}

/// How often the threads of process `pid` have gone to sleep and woken (the sum of their
/// voluntary context switches).
pub fn wake_ups(pid: u32) -> u64 {
    let tasks = std::fs::read_dir(format!("/proc/{pid}/task")).expect("the process's threads");
    tasks
        .filter_map(|t| std::fs::read_to_string(t.ok()?.path().join("status")).ok())
        .filter_map(|status| {
            status
                .lines()
                .find_map(|l| l.strip_prefix("voluntary_ctxt_switches:"))
                .and_then(|v| v.trim().parse::<u64>().ok())
        })
        .sum()
}

/// Polls `f` until it returns `Some` or `timeout` passes.
pub fn eventually<T>(timeout: Duration, mut f: impl FnMut() -> Option<T>) -> Option<T> {
    let deadline = Instant::now() + timeout;
    loop {
        if let Some(v) = f() {
            return Some(v);
        }
        if Instant::now() > deadline {
            return None;
        }
        std::thread::sleep(Duration::from_millis(10));
    }
}

/// One manual plane on a daemon of its own: what the physics tests start from.
/// Fields drop in order, so the client says goodbye before its daemon stops.
pub struct Scene {
    pub plane: client_sdk::Plane,
    pub client: Client,
    pub daemon: TestDaemon,
}

impl Scene {
    /// A manual plane (TickRate 0) with `options` on top.
    pub fn new(tag: &str, options: client_sdk::PlaneOptions) -> Scene {
        let daemon = TestDaemon::start(tag);
        let client = daemon.client();
        let plane = client
            .create_plane(&client_sdk::PlaneOptions {
                tick_rate: Some(0.0),
                ..options
            })
            .expect("create plane");
        Scene {
            plane,
            client,
            daemon,
        }
    }

    /// An anchored 200 × 1 × 200 slab whose top face is y = 0.
    pub fn floor(&self) -> client_sdk::Object {
        physics_scenes::floor(&mut &self.plane, 200.0, &[]).expect("add floor")
    }

    pub fn anchored_box(&self, size: [f32; 3], pose: client_sdk::Pose) -> client_sdk::Object {
        physics_scenes::anchored_box(&mut &self.plane, size, pose, &[]).expect("add anchored box")
    }

    /// Steps `n` times by `dt`.
    pub fn run(&self, dt: f32, n: u32) {
        for _ in 0..n {
            self.plane.step(dt).expect("step");
        }
    }
}

/// Unit quaternion `[x, y, z, w]` for `angle` radians about a unit `axis`.
pub fn quat(axis: [f32; 3], angle: f32) -> [f32; 4] {
    let (s, c) = (angle / 2.0).sin_cos();
    [axis[0] * s, axis[1] * s, axis[2] * s, c]
}

/// Angle in radians between two unit quaternions.
pub fn angle_between(a: [f32; 4], b: [f32; 4]) -> f32 {
    let dot: f32 = a.iter().zip(b).map(|(x, y)| x * y).sum();
    2.0 * dot.abs().min(1.0).acos()
}

/// Plane options without damping: for closed forms that have none.
pub fn no_damping() -> client_sdk::PlaneOptions {
    client_sdk::PlaneOptions {
        linear_damping: Some(0.0),
        angular_damping: Some(0.0),
        ..Default::default()
    }
}

/// No damping and no gravity.
pub fn zero_gravity() -> client_sdk::PlaneOptions {
    client_sdk::PlaneOptions {
        gravity: Some([0.0; 3]),
        ..no_damping()
    }
}

/// `physics-lua SCRIPT --domain DOMAIN EXTRA…` (SCRIPT relative to the repository root),
/// with the runner built next to this test's executable by `cargo build --workspace --bins`,
/// quiet logs, no stdin and piped output.
pub fn physics_lua(domain: &str, script: &str, extra: &[&str]) -> Command {
    let exe = std::env::current_exe().expect("test executable");
    let runner = exe
        .ancestors()
        .skip(1)
        .take(3)
        .map(|dir| dir.join("physics-lua"))
        .find(|p| p.is_file())
        .unwrap_or_else(|| {
            panic!(
                "physics-lua not found near {} (run cargo build --workspace --bins first)",
                exe.display()
            )
        });
    let mut command = Command::new(runner);
    // Scripts name files (maps, props) from the repository root, as the examples do.
    command
        .current_dir(std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(".."))
        .arg(
            std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("..")
                .join(script),
        )
        .args(["--domain", domain])
        .args(extra)
        .env("PHYSICS_LOG", "warn")
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    command
}

pub mod structure;

/// Walking a recording file's entries (`shm_layout::recording`), to damage or forge one in
/// a test.
pub mod recording_file {
    use shm_layout::recording::{push_tick, EntryTag, ENTRY_OVERHEAD, PREAMBLE_LEN};

    /// (byte offset, tag, whole length) of every entry, asserting that they tile the file.
    pub fn entries(bytes: &[u8]) -> Vec<(usize, u8, usize)> {
        let mut at = PREAMBLE_LEN;
        let mut out = Vec::new();
        while at + ENTRY_OVERHEAD <= bytes.len() {
            let len = u32::from_le_bytes(bytes[at + 1..at + 5].try_into().unwrap()) as usize;
            out.push((at, bytes[at], len + ENTRY_OVERHEAD));
            at += len + ENTRY_OVERHEAD;
        }
        assert_eq!(at, bytes.len(), "the entries tile the file");
        out
    }

    /// The byte offset of the `Tick` entry of `tick`.
    pub fn tick_entry(bytes: &[u8], tick: u64) -> usize {
        entries(bytes)
            .into_iter()
            .find(|&(at, tag, _)| {
                tag == EntryTag::Tick as u8
                    && u64::from_le_bytes(bytes[at + 5..at + 13].try_into().unwrap()) == tick
            })
            .map(|(at, _, _)| at)
            .unwrap_or_else(|| panic!("no tick entry of tick {tick}"))
    }

    /// `bytes` with the `Tick` entry of `tick` holding another state hash (and the checksum
    /// that goes with it, so the file still reads), and that hash.
    pub fn forge_tick_hash(bytes: &[u8], tick: u64) -> (Vec<u8>, u64) {
        let at = tick_entry(bytes, tick);
        // Payload: tick u64 | dt f32 | state hash u64.
        let dt = f32::from_le_bytes(bytes[at + 13..at + 17].try_into().unwrap());
        let hash = u64::from_le_bytes(bytes[at + 17..at + 25].try_into().unwrap());
        let forged = hash ^ 0x0100_0000_0000_0001;
        let mut out = bytes[..at].to_vec();
        push_tick(&mut out, tick, dt, forged);
        out.extend_from_slice(&bytes[at + ENTRY_OVERHEAD + 20..]);
        assert_eq!(out.len(), bytes.len());
        (out, forged)
    }
}

/// The .glb files the examples and Luau tests load (`examples/assets/`), generated here with
/// the SDK's glTF writer; `tests/tests/maps.rs` checks the shipped files are exactly these
/// (`PHYSICS_WRITE_ASSETS=1` rewrites them).
pub mod assets {
    use client_sdk::map::MapMesh;

    /// `examples/assets/terrain.glb`: a 24 × 24 unit heightfield of 12 × 12 quads (two
    /// triangles each, shared vertices), height `0.5·sin(x/3)·cos(z/4)`, wound
    /// counter-clockwise seen from above.
    pub fn terrain() -> Vec<MapMesh> {
        let n = 12;
        let step = 2.0f32;
        let half = n as f32 * step / 2.0;
        let mut m = MapMesh::default();
        for i in 0..=n {
            for j in 0..=n {
                let (x, z) = (i as f32 * step - half, j as f32 * step - half);
                m.vertices.push([x, terrain_height(x, z), z]);
            }
        }
        let at = |i: u32, j: u32| i * (n + 1) + j;
        for i in 0..n {
            for j in 0..n {
                let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
                m.triangles.push([a, c, b]);
                m.triangles.push([a, d, c]);
            }
        }
        vec![m]
    }

    /// The terrain's height at (x, z) on its vertices (linear in between).
    pub fn terrain_height(x: f32, z: f32) -> f32 {
        0.5 * (x / 3.0).sin() * (z / 4.0).cos()
    }

    /// An axis-aligned box mesh of `size` centred on `centre` (8 vertices, 12 triangles,
    /// outward counter-clockwise).
    pub fn box_mesh(centre: [f32; 3], size: [f32; 3]) -> MapMesh {
        let h = size.map(|s| s / 2.0);
        let vertices = (0..8)
            .map(|k| {
                let s = |bit: u32| if k & (1 << bit) != 0 { 1.0 } else { -1.0 };
                [
                    centre[0] + s(0) * h[0],
                    centre[1] + s(1) * h[1],
                    centre[2] + s(2) * h[2],
                ]
            })
            .collect();
        // Corner index = x + 2y + 4z (bits).
        let triangles = vec![
            [0, 2, 3],
            [0, 3, 1], // -Z
            [4, 5, 7],
            [4, 7, 6], // +Z
            [0, 4, 6],
            [0, 6, 2], // -X
            [1, 3, 7],
            [1, 7, 5], // +X
            [0, 1, 5],
            [0, 5, 4], // -Y
            [2, 6, 7],
            [2, 7, 3], // +Y
        ];
        MapMesh {
            vertices,
            triangles,
        }
    }

    /// `examples/assets/dumbbell.glb`: two 1-unit cubes centred at x = ±1.5 (two meshes, so
    /// `Decompose` makes two welded parts) — a 4 × 1 × 1 box overall.
    pub fn dumbbell() -> Vec<MapMesh> {
        vec![
            box_mesh([-1.5, 0.0, 0.0], [1.0; 3]),
            box_mesh([1.5, 0.0, 0.0], [1.0; 3]),
        ]
    }

    /// `examples/scenarios/assets/road.glb`: a road 12 wide (x in [−6, 6]) running from
    /// z = 10 toward −Z to z = −150, flat, then a ramp up 3 over 30 (slope 0.1), a plateau,
    /// a ramp down and flat again (`road_height`), one mesh, wound counter-clockwise seen
    /// from above.
    pub fn road() -> Vec<MapMesh> {
        let mut m = MapMesh::default();
        let mut z = 10.0f32;
        let mut k = 0u32;
        while z >= -150.0 {
            let h = road_height(z);
            m.vertices.push([-6.0, h, z]);
            m.vertices.push([6.0, h, z]);
            if k > 0 {
                let (l0, r0, l1, r1) = (2 * k - 2, 2 * k - 1, 2 * k, 2 * k + 1);
                m.triangles.push([l0, r0, r1]);
                m.triangles.push([l0, r1, l1]);
            }
            k += 1;
            z -= 10.0;
        }
        vec![m]
    }

    /// The road's surface height at z: 0 down to z = −40, up by 0.1 per unit to 3 at
    /// z = −70, 3 to z = −100, down to 0 at z = −130, then 0.
    pub fn road_height(z: f32) -> f32 {
        let d = -z;
        if d <= 40.0 {
            0.0
        } else if d <= 70.0 {
            (d - 40.0) * 0.1
        } else if d <= 100.0 {
            3.0
        } else if d <= 130.0 {
            3.0 - (d - 100.0) * 0.1
        } else {
            0.0
        }
    }

    /// Every shipped asset: (path from the repository root, meshes).
    pub fn all() -> Vec<(&'static str, Vec<MapMesh>)> {
        vec![
            ("examples/assets/terrain.glb", terrain()),
            ("examples/assets/dumbbell.glb", dumbbell()),
            ("examples/scenarios/assets/road.glb", road()),
        ]
    }
}

/// Daemons of a physics cluster on loopback, each in a domain of its own (as if on its own
/// host) and on a port the OS handed out (`tests/tests/cluster*.rs`).
pub mod cluster {
    use super::TestDaemon;

    /// A loopback port nobody listens on now (the OS picks it; closed again at once).
    pub fn free_port() -> u16 {
        std::net::TcpListener::bind("127.0.0.1:0")
            .and_then(|l| l.local_addr())
            .expect("a free loopback port")
            .port()
    }

    /// `tcp/127.0.0.1:PORT`.
    pub fn endpoint(port: u16) -> String {
        format!("tcp/127.0.0.1:{port}")
    }

    /// A cluster name of this test run only (clusters with other names share nothing).
    pub fn unique_cluster(tag: &str) -> String {
        super::unique_domain(tag).replace('.', "-")
    }

    /// A remote client of daemon `daemon` of `cluster`, through the member listening on
    /// `port`.
    pub fn remote_client(cluster: &str, port: u16, daemon: &str) -> client_sdk::Client {
        client_sdk::Client::connect_cluster(&client_sdk::remote::RemoteOptions {
            cluster: client_sdk::cluster::ClusterOptions {
                cluster: cluster.to_string(),
                endpoints: vec![endpoint(port)],
                ..Default::default()
            },
            daemon: Some(daemon.to_string()),
        })
        .expect("remote client")
    }

    /// `physics-lua SCRIPT --cluster CLUSTER --connect tcp/127.0.0.1:PORT --daemon DAEMON`.
    pub fn cluster_lua(
        cluster: &str,
        port: u16,
        daemon: &str,
        script: &std::path::Path,
    ) -> std::process::Command {
        super::physics_lua(
            "unused-domain",
            script.to_str().expect("a UTF-8 script path"),
            &[
                "--cluster",
                cluster,
                "--connect",
                &endpoint(port),
                "--daemon",
                daemon,
            ],
        )
    }

    /// Daemon `name` of `cluster`, listening on `listen`, connecting to `connect`, with
    /// `extra` flags.
    pub fn member(
        cluster: &str,
        name: &str,
        listen: u16,
        connect: &[u16],
        extra: &[&str],
    ) -> TestDaemon {
        let mut args: Vec<String> = extra.iter().map(|s| s.to_string()).collect();
        args.extend([
            "--cluster".to_string(),
            cluster.to_string(),
            "--name".into(),
            name.into(),
            "--listen".into(),
            endpoint(listen),
        ]);
        for port in connect {
            args.push("--connect".into());
            args.push(endpoint(*port));
        }
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        TestDaemon::start_with(&format!("cl-{name}"), &args, &[])
    }
}

/// Runs `physics-lua script --domain domain extra...` to its end and returns its output and
/// how long it ran; kills it and panics with what it printed once it runs past `limit`.
pub fn run_lua(
    domain: &str,
    script: &str,
    extra: &[&str],
    limit: Duration,
) -> (std::process::Output, Duration) {
    let started = Instant::now();
    let mut child = physics_lua(domain, script, extra)
        .spawn()
        .expect("spawn physics-lua");
    while child.try_wait().expect("wait physics-lua").is_none() {
        if started.elapsed() > limit {
            let _ = child.kill();
            let out = child.wait_with_output().expect("collect output");
            panic!(
                "{script} still running after {limit:?}\nstdout:\n{}\nstderr:\n{}",
                String::from_utf8_lossy(&out.stdout),
                String::from_utf8_lossy(&out.stderr)
            );
        }
        std::thread::sleep(Duration::from_millis(10));
    }
    let output = child.wait_with_output().expect("collect output");
    (output, started.elapsed())
}

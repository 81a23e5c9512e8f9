//! `physics-view` in a real browser: a daemon with a known scene (anchored parts of every
//! primitive shape at known poses and a ball resting on the floor, plus a GUI plane), the
//! viewer as its own process on a free port, and headless Chromium loading the page. The
//! page writes what it shows into data- attributes of `#view`; the test reads them from the
//! DOM Chromium dumps and compares them with the poses the SDK reads from shared memory.
//! It also saves a screenshot (`viewer.png` in the test's output folder).
//!
//! Chromium is required: without it the test fails and says how to install it.

// The viewer's other subjects: joints drawn (live and replayed) and `--replay`.
mod browser;
mod joints;
mod replay;

use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::mpsc;
use std::time::Duration;

use browser::{chromium, chromium_run, view_attributes, viewer_bin};
use client_sdk::{Client, GuiPlaneOptions, GuiShape, Plane, PlaneOptions, Pose, Shape};
use integration_tests::{eventually, physics_lua, quat, unique_domain, TestDaemon};
use serde_json::Value;
use shm_layout::{GuiObjectProp, ObjectProp, FLAG_ANCHORED};

/// A running viewer; killed when dropped.
struct Viewer {
    child: Child,
    base: String,
}

impl Viewer {
    fn start(domain: &str, extra: &[&str]) -> Viewer {
        let mut child = Command::new(viewer_bin())
            .args(["--domain", domain, "--port", "0"])
            .args(extra)
            .env("PHYSICS_LOG", "warn")
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .spawn()
            .expect("spawn physics-view");
        let out = child.stdout.take().expect("stdout");
        let (tx, rx) = mpsc::channel();
        std::thread::spawn(move || {
            for line in BufReader::new(out).lines().map_while(Result::ok) {
                let _ = tx.send(line);
            }
        });
        let line = rx
            .recv_timeout(Duration::from_secs(20))
            .expect("physics-view printed no URL within 20 s");
        let url = line
            .split_whitespace()
            .find(|w| w.starts_with("http://"))
            .unwrap_or_else(|| panic!("no URL in {line:?}"));
        assert!(
            url.starts_with("http://127.0.0.1:"),
            "binds to 127.0.0.1 by default: {line}"
        );
        Viewer {
            child,
            base: url.trim_end_matches('/').to_string(),
        }
    }

    fn request(&self, method: &str, path: &str) -> (u16, String) {
        http(&self.base, method, path)
    }

    fn json(&self, path: &str) -> Value {
        let (status, body) = self.request("GET", path);
        assert_eq!(status, 200, "GET {path}: {body}");
        serde_json::from_str(&body).unwrap_or_else(|e| panic!("GET {path}: {e}: {body}"))
    }
}

impl Drop for Viewer {
    fn drop(&mut self) {
        // SAFETY: kill(2) on our own child: SIGINT lets it say goodbye to the daemon.
        unsafe { libc::kill(self.child.id() as i32, libc::SIGINT) };
        for _ in 0..100 {
            if let Ok(Some(_)) = self.child.try_wait() {
                return;
            }
            std::thread::sleep(Duration::from_millis(20));
        }
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// `METHOD path` over plain HTTP/1.1 to `base` (`http://HOST:PORT`): (status, body).
fn http(base: &str, method: &str, path: &str) -> (u16, String) {
    try_http(base, method, path).unwrap_or_else(|e| panic!("{method} {base}{path}: {e}"))
}

fn try_http(base: &str, method: &str, path: &str) -> std::io::Result<(u16, String)> {
    let host = base.trim_start_matches("http://");
    let mut s = TcpStream::connect(host)?;
    s.set_read_timeout(Some(Duration::from_secs(20)))?;
    write!(
        s,
        "{method} {path} HTTP/1.1\r\nHost: {host}\r\nContent-Length: 0\r\nConnection: close\r\n\r\n"
    )?;
    let mut raw = String::new();
    s.read_to_string(&mut raw)?;
    let (head, body) = raw.split_once("\r\n\r\n").expect("HTTP reply");
    let status = head
        .split_whitespace()
        .nth(1)
        .and_then(|c| c.parse().ok())
        .expect("status code");
    Ok((status, body.to_string()))
}

/// Loads `url` until the page has drawn a snapshot (`data-ready="1"`); returns #view's
/// attributes.
fn load_view(profile: &Path, url: &str) -> std::collections::HashMap<String, String> {
    let mut last = String::new();
    for _ in 0..3 {
        let dom = chromium_run(profile, &["--dump-dom".to_string()], url);
        let attrs = view_attributes(&dom);
        if attrs.get("data-ready").map(String::as_str) == Some("1") {
            return attrs;
        }
        last = format!("{attrs:?}");
    }
    panic!("the page never drew a snapshot of {url}: #view = {last}");
}

fn vec3(v: &Value) -> [f64; 3] {
    let a = v.as_array().expect("array");
    [0, 1, 2].map(|i| a[i].as_f64().expect("number"))
}

/// The three.js view shows every body of a 3D plane with its shape at the pose shared
/// memory holds, a GUI plane's bodies in pixels, the list and JSON API agree, controls are
/// refused when read-only, and a screenshot is taken.
#[test]
fn the_page_shows_every_body_at_its_pose() {
    let browser = chromium();
    let daemon = TestDaemon::start("viewer");
    let client: Client = daemon.client();

    // A manual 3D plane: nothing moves unless the test steps it.
    let plane: Plane = client.create_plane(&PlaneOptions::manual()).unwrap();
    let anchored = [ObjectProp::Anchored(true)];
    let tilt = quat([0.0, 1.0, 0.0], 0.6);
    let parts: Vec<(&str, Shape, Pose)> = vec![
        (
            "Cube",
            Shape::Cube {
                size: [40.0, 1.0, 40.0],
            },
            Pose::at([0.0, -0.5, 0.0]),
        ),
        (
            "Cube",
            Shape::Cube {
                size: [2.0, 2.0, 2.0],
            },
            Pose {
                position: [6.0, 1.0, 0.0],
                rotation: tilt,
            },
        ),
        (
            "Wedge",
            Shape::Wedge {
                size: [2.0, 2.0, 3.0],
            },
            Pose::at([-6.0, 1.0, 0.0]),
        ),
        (
            "Cylinder",
            Shape::Cylinder {
                size: [2.0, 3.0, 2.0],
            },
            Pose::at([0.0, 1.5, -6.0]),
        ),
        (
            "Capsule",
            Shape::Capsule {
                size: [1.0, 3.0, 1.0],
            },
            Pose::at([4.0, 1.5, -5.0]),
        ),
    ];
    let mut objects = Vec::new();
    for (name, shape, pose) in &parts {
        objects.push((
            *name,
            plane.add(shape.clone(), *pose, &anchored).unwrap(),
            *pose,
        ));
    }
    // A ball of radius 1 dropped from 0.5 above the floor, settled for 3 s.
    let ball = plane
        .add(
            Shape::Sphere { radius: 1.0 },
            Pose::at([0.0, 1.5, 2.0]),
            &[],
        )
        .unwrap();
    for _ in 0..180 {
        plane.step(1.0 / 60.0).unwrap();
    }

    // A manual GUI plane with no gravity: two anchored squares and a circle, in pixels.
    let gui = client
        .create_gui_plane(&GuiPlaneOptions {
            gravity: Some([0.0, 0.0]),
            ..GuiPlaneOptions::manual()
        })
        .unwrap();
    let gui_parts = [
        (GuiShape::Square, [400.0, 40.0], [320.0, 460.0]),
        (GuiShape::Square, [60.0, 60.0], [120.0, 200.0]),
        (GuiShape::Circle, [50.0, 50.0], [500.0, 150.0]),
    ];
    for (shape, size, position) in gui_parts {
        gui.add(shape, size, position, &[GuiObjectProp::Anchored(true)])
            .unwrap();
    }
    gui.step(1.0 / 60.0).unwrap();

    let viewer = Viewer::start(&daemon.domain, &[]);

    // The JSON API: both planes listed with their kind, body count and tick rate.
    let planes = eventually(Duration::from_secs(10), || {
        let v = viewer.json("/api/planes");
        (v.as_array().unwrap().len() == 2).then_some(v)
    })
    .expect("/api/planes never listed both planes");
    let row = |id: u32| {
        planes
            .as_array()
            .unwrap()
            .iter()
            .find(|p| p["id"] == id)
            .unwrap_or_else(|| panic!("plane {id} not listed: {planes}"))
            .clone()
    };
    let (p3, p2) = (row(plane.id()), row(gui.plane().id()));
    assert_eq!(p3["kind"], "Rapier3d");
    assert_eq!(p3["body_count"], 6);
    assert_eq!(p3["tick_rate"], 0.0);
    assert_eq!(p3["tick"], 180);
    assert_eq!(p2["kind"], "Gui2d");
    assert_eq!(p2["body_count"], 3);
    assert!(p3["step_time_us"].as_f64().unwrap() > 0.0, "{p3}");

    // Controls change planes: refused unless the viewer was started with --allow-control.
    let (status, body) = viewer.request("POST", &format!("/api/plane/{}/step", plane.id()));
    assert_eq!(status, 403, "{body}");
    assert!(body.contains("--allow-control"), "{body}");
    assert_eq!(
        plane.snapshot().unwrap().tick(),
        180,
        "the refused step ran"
    );

    // The page, in headless Chromium.
    let tmp = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(format!(
        "viewer-{}",
        daemon
            .domain
            .replace(|c: char| !c.is_ascii_alphanumeric(), "-")
    ));
    std::fs::create_dir_all(&tmp).unwrap();
    let url = format!("{}/?plane={}", viewer.base, plane.id());
    let attrs = load_view(&tmp.join("profile"), &url);
    assert_eq!(attrs["data-plane"], plane.id().to_string());
    assert_eq!(attrs["data-kind"], "Rapier3d");
    assert_eq!(attrs["data-tick"], "180");
    assert_eq!(attrs["data-body-count"], "6");
    assert_eq!(attrs["data-plane-count"], "2");
    // three.js made one mesh per body and rendered with WebGL.
    assert_eq!(attrs["data-meshes"], "6", "{attrs:?}");
    assert_eq!(attrs["data-renderer"], "webgl", "{attrs:?}");

    let shown: Vec<Value> = serde_json::from_str(&attrs["data-bodies"]).unwrap();
    assert_eq!(shown.len(), 6);
    let snap = plane.snapshot().unwrap();
    let by_slot = |slot: u32| {
        shown
            .iter()
            .find(|b| b["slot"] == slot)
            .unwrap_or_else(|| panic!("slot {slot} not shown: {shown:?}"))
    };
    // Positions travel f32 → JSON (shortest round-trip decimal) → JS double → JSON: exact
    // to f32 precision, so 1e-5 relative to the coordinate (or 1e-5 absolute) is ample.
    let close = |a: f64, b: f64| (a - b).abs() <= 1e-5 * b.abs().max(1.0);
    for (name, object, pose) in &objects {
        let b = by_slot(object.handle().slot);
        assert_eq!(b["shape"], *name, "{b}");
        assert_eq!(b["anchored"], true, "{b}");
        let p = vec3(&b["position"]);
        for i in 0..3 {
            assert!(
                close(p[i], pose.position[i] as f64),
                "{name}: {p:?} vs {pose:?}"
            );
        }
        let q = b["rotation"].as_array().unwrap();
        for i in 0..4 {
            assert!(
                close(q[i].as_f64().unwrap(), pose.rotation[i] as f64),
                "{name}: rotation {q:?} vs {:?}",
                pose.rotation
            );
        }
    }
    // The ball: exactly where shared memory has it (the plane is manual, so the page and
    // the SDK read the same tick), and resting on the floor: its centre one radius above
    // y = 0, within 0.05 (rapier keeps resting contacts a few hundredths apart or inside).
    let b = by_slot(ball.handle().slot);
    assert_eq!(b["shape"], "Sphere");
    let state = snap.get(ball.handle()).unwrap();
    assert_eq!(state.flags & FLAG_ANCHORED, 0);
    let p = vec3(&b["position"]);
    for (i, v) in p.iter().enumerate() {
        assert!(
            close(*v, state.position[i] as f64),
            "ball {p:?} vs {state:?}"
        );
    }
    assert!(
        (p[1] - 1.0).abs() < 0.05,
        "ball not resting on the floor: {p:?}"
    );
    assert!(
        (p[0] - 0.0).abs() < 0.05 && (p[2] - 2.0).abs() < 0.05,
        "ball moved: {p:?}"
    );
    assert_eq!(b["sleeping"], state.is_sleeping(), "{b}");
    assert_eq!(vec3(&b["size"]), [2.0, 2.0, 2.0], "{b}");

    // The screenshot, kept in the test's output folder.
    let png = tmp.join("viewer.png");
    let _ = std::fs::remove_file(&png);
    chromium_run(
        &tmp.join("profile"),
        &[format!("--screenshot={}", png.display())],
        &url,
    );
    let bytes = std::fs::read(&png).unwrap_or_else(|e| panic!("no screenshot at {png:?}: {e}"));
    assert!(bytes.starts_with(b"\x89PNG\r\n\x1a\n"), "not a PNG");
    // A blank 1280 × 800 page compresses to a few KiB; the drawn scene is far larger.
    assert!(bytes.len() > 20_000, "screenshot is {} bytes", bytes.len());
    eprintln!("screenshot: {}", png.display());

    // The GUI plane: drawn on a 2D canvas, every body at its pixel position.
    let url = format!("{}/?plane={}", viewer.base, gui.plane().id());
    let attrs = load_view(&tmp.join("profile"), &url);
    assert_eq!(attrs["data-kind"], "Gui2d");
    assert_eq!(attrs["data-body-count"], "3");
    assert_eq!(attrs["data-meshes"], "3");
    let shown: Vec<Value> = serde_json::from_str(&attrs["data-bodies"]).unwrap();
    for (shape, size, position) in gui_parts {
        let b = shown
            .iter()
            .find(|b| {
                let p = vec3(&b["position"]);
                (p[0] - position[0] as f64).abs() < 1e-3 && (p[1] - position[1] as f64).abs() < 1e-3
            })
            .unwrap_or_else(|| panic!("no body at {position:?}: {shown:?}"));
        assert_eq!(b["shape"], shape.name(), "{b}");
        let s = vec3(&b["size"]);
        assert_eq!([s[0], s[1]], [size[0] as f64, size[1] as f64], "{b}");
    }
    drop(viewer);
    drop(browser);
}

/// With `--allow-control` the page's controls act on planes the viewer may change: a step
/// of a shared manual plane advances it by one tick, pause and resume flip `Enabled`; a
/// plane of another client that is not shared still refuses them (the daemon's rule).
#[test]
fn controls_need_allow_control_and_the_daemons_consent() {
    let daemon = TestDaemon::start("viewer-ctl");
    let client = daemon.client();
    let shared = client
        .create_plane(&PlaneOptions {
            shared: Some(true),
            ..PlaneOptions::manual()
        })
        .unwrap();
    let private = client.create_plane(&PlaneOptions::manual()).unwrap();
    let viewer = Viewer::start(&daemon.domain, &["--allow-control"]);
    eventually(Duration::from_secs(10), || {
        (viewer.json("/api/planes").as_array().unwrap().len() == 2).then_some(())
    })
    .expect("planes listed");

    let (status, body) = viewer.request("POST", &format!("/api/plane/{}/step", shared.id()));
    assert_eq!(status, 200, "{body}");
    assert_eq!(shared.snapshot().unwrap().tick(), 1);
    let (status, body) = viewer.request("POST", &format!("/api/plane/{}/pause", shared.id()));
    assert_eq!(status, 200, "{body}");
    assert!(!shared.info().unwrap().enabled);
    let (status, _) = viewer.request("POST", &format!("/api/plane/{}/resume", shared.id()));
    assert_eq!(status, 200);
    assert!(shared.info().unwrap().enabled);

    let (status, body) = viewer.request("POST", &format!("/api/plane/{}/step", private.id()));
    assert_eq!(status, 409, "{body}");
    assert!(body.contains("belongs to another client"), "{body}");
    assert_eq!(private.snapshot().unwrap().tick(), 0);
    let (status, body) = viewer.request("POST", &format!("/api/plane/{}/explode", shared.id()));
    assert_eq!(status, 404, "{body}");

    // A body's properties, as a click on it shows them.
    let ball = shared
        .add(
            Shape::Sphere { radius: 0.5 },
            Pose::at([1.0, 2.0, 3.0]),
            &[],
        )
        .unwrap();
    shared.step(1.0 / 60.0).unwrap();
    let v = viewer.json(&format!(
        "/api/plane/{}/body/{}",
        shared.id(),
        ball.handle().slot
    ));
    assert_eq!(v["info"]["shape"], "Sphere", "{v}");
    assert!(
        (v["info"]["mass"].as_f64().unwrap() - 1.0).abs() < 1e-6,
        "{v}"
    );
    let (status, body) = viewer.request("GET", &format!("/api/plane/{}/body/999", shared.id()));
    assert_eq!(status, 404, "{body}");
    let (status, _) = viewer.request("GET", "/api/plane/4242");
    assert_eq!(status, 404);
}

/// `physics-lua SCRIPT --view` starts the viewer on the script's domain, prints its URL, keeps
/// the script's planes up after the script is done (until `--seconds` here), and stops the
/// viewer when the run ends.
#[test]
fn physics_lua_view_shows_the_scripts_planes() {
    let domain = unique_domain("viewer-lua");
    let mut child = physics_lua(
        &domain,
        "examples/falling_ball.luau",
        &["--view", "--view-port", "0", "--seconds", "6"],
    )
    .spawn()
    .expect("spawn physics-lua");
    let err = child.stderr.take().expect("stderr");
    let (tx, rx) = mpsc::channel();
    std::thread::spawn(move || {
        for line in BufReader::new(err).lines().map_while(Result::ok) {
            let _ = tx.send(line);
        }
    });
    let mut seen = Vec::new();
    let base = loop {
        let line = rx
            .recv_timeout(Duration::from_secs(20))
            .unwrap_or_else(|_| panic!("no viewer URL on stderr: {seen:?}"));
        if let Some(url) = line.split_whitespace().find(|w| w.starts_with("http://")) {
            break url.trim_end_matches('/').to_string();
        }
        seen.push(line);
    };
    assert!(base.starts_with("http://127.0.0.1:"), "{base}");
    // The script's plane: a ball and a floor.
    let planes = eventually(Duration::from_secs(10), || {
        let (status, body) = try_http(&base, "GET", "/api/planes").ok()?;
        let v: Value = serde_json::from_str(&body).ok()?;
        (status == 200 && v.as_array()?.len() == 1 && v[0]["body_count"] == 2).then_some(v)
    })
    .expect("the viewer never listed the script's plane");
    let (status, body) = http(&base, "GET", &format!("/api/plane/{}", planes[0]["id"]));
    assert_eq!(status, 200, "{body}");
    let snap: Value = serde_json::from_str(&body).unwrap();
    let mut shapes: Vec<&str> = snap["bodies"]
        .as_array()
        .unwrap()
        .iter()
        .map(|b| b["shape"].as_str().unwrap())
        .collect();
    shapes.sort();
    assert_eq!(shapes, ["Cube", "Sphere"], "{snap}");

    let status = eventually(Duration::from_secs(20), || child.try_wait().ok().flatten())
        .expect("physics-lua did not end after --seconds 6");
    assert!(status.success(), "physics-lua: {status}");
    // The viewer went with the run.
    eventually(Duration::from_secs(5), || {
        try_http(&base, "GET", "/api/info").is_err().then_some(())
    })
    .expect("the viewer still answers after the run ended");
}

/// `physics-lua --help` and `physics-view --help` document every flag.
#[test]
fn help_documents_every_flag() {
    let lua = physics_lua("unused", "examples/falling_ball.luau", &[])
        .get_program()
        .to_owned();
    for (exe, flags) in [
        (
            PathBuf::from(lua),
            &[
                "--domain",
                "--seconds",
                "--fps",
                "--max-run-ms",
                "--max-memory-mb",
                "--request-timeout",
                "--view",
                "--view-port",
                "--view-allow-control",
            ][..],
        ),
        (
            viewer_bin(),
            &[
                "--domain",
                "--bind",
                "--port",
                "--allow-control",
                "--history-seconds",
                "--exit-with",
            ][..],
        ),
    ] {
        let out = Command::new(&exe).arg("--help").output().unwrap();
        assert!(out.status.success());
        let help = String::from_utf8_lossy(&out.stdout);
        let lines: Vec<&str> = help.lines().collect();
        for flag in flags {
            // Each flag has its own line, its description on the next one.
            let i = lines
                .iter()
                .position(|l| l.trim_start().starts_with(&format!("{flag} ")) || l.trim() == *flag)
                .unwrap_or_else(|| panic!("{} --help lacks {flag}:\n{help}", exe.display()));
            let described = lines
                .get(i + 1)
                .is_some_and(|d| d.trim().len() > 10 && !d.trim_start().starts_with("--"));
            assert!(described, "{flag} has no description:\n{help}");
        }
    }
}

/// The viewer outlives its daemon: it reports the daemon gone within a few seconds and
/// shows the planes of the next daemon of the domain.
#[test]
fn the_viewer_follows_a_restarted_daemon() {
    let daemon = TestDaemon::start("viewer-restart");
    let domain = daemon.domain.clone();
    let viewer = Viewer::start(&domain, &[]);
    let first_pid = eventually(Duration::from_secs(10), || {
        let info = viewer.json("/api/info");
        (info["connected"] == true).then(|| info["daemon_pid"].as_u64().unwrap())
    })
    .expect("the viewer never connected");
    assert_eq!(first_pid, daemon.pid() as u64);
    drop(daemon);
    let info = eventually(Duration::from_secs(10), || {
        let info = viewer.json("/api/info");
        (info["connected"] == false).then_some(info)
    })
    .expect("the viewer never noticed that the daemon was gone");
    assert!(info["error"].as_str().unwrap().contains(&domain), "{info}");

    let daemon = TestDaemon::start_in(&domain);
    let client = daemon.client();
    let plane = client.create_plane(&PlaneOptions::manual()).unwrap();
    plane
        .add(
            Shape::Sphere { radius: 1.0 },
            Pose::at([0.0, 5.0, 0.0]),
            &[],
        )
        .unwrap();
    plane.step(1.0 / 60.0).unwrap();
    let planes = eventually(Duration::from_secs(10), || {
        let v = viewer.json("/api/planes");
        (v.as_array().unwrap().len() == 1 && v[0]["body_count"] == 1).then_some(v)
    })
    .expect("the viewer never showed the new daemon's plane");
    assert_eq!(planes[0]["id"], plane.id());
    assert_eq!(
        viewer.json("/api/info")["daemon_pid"].as_u64().unwrap(),
        daemon.pid() as u64
    );
}

/// `GET /api/plane/{id}/snapshot` over plain HTTP: (status, head, body bytes).
fn http_bytes(base: &str, path: &str) -> (u16, String, Vec<u8>) {
    let host = base.trim_start_matches("http://");
    let mut s = TcpStream::connect(host).expect("connect to the viewer");
    s.set_read_timeout(Some(Duration::from_secs(20))).unwrap();
    write!(
        s,
        "GET {path} HTTP/1.1\r\nHost: {host}\r\nConnection: close\r\n\r\n"
    )
    .unwrap();
    let mut raw = Vec::new();
    s.read_to_end(&mut raw).unwrap();
    let split = raw
        .windows(4)
        .position(|w| w == b"\r\n\r\n")
        .expect("HTTP reply");
    let head = String::from_utf8_lossy(&raw[..split]).into_owned();
    let status = head
        .split_whitespace()
        .nth(1)
        .and_then(|c| c.parse().ok())
        .expect("status code");
    (status, head, raw[split + 4..].to_vec())
}

/// "Download snapshot": the page links the selected plane's snapshot; the link gives the
/// plane's whole state as a `.physnap` file (its tick and state hash are the plane's), for
/// a read-only viewer too; an unknown plane is a 404 naming it.
#[test]
fn the_page_offers_a_planes_snapshot_for_download() {
    // Fails with how to install it when there is no browser.
    chromium();
    let daemon = TestDaemon::start("viewer-dl");
    let client = daemon.client();
    let plane = client.create_plane(&PlaneOptions::manual()).unwrap();
    plane
        .add(
            Shape::Cube {
                size: [20.0, 1.0, 20.0],
            },
            Pose::at([0.0, -0.5, 0.0]),
            &[ObjectProp::Anchored(true)],
        )
        .unwrap();
    plane
        .add(
            Shape::Sphere { radius: 0.5 },
            Pose::at([0.0, 5.0, 0.0]),
            &[],
        )
        .unwrap();
    for _ in 0..7 {
        plane.step(1.0 / 60.0).unwrap();
    }
    let viewer = Viewer::start(&daemon.domain, &[]);
    let id = plane.id();
    let (status, head, body) = http_bytes(&viewer.base, &format!("/api/plane/{id}/snapshot"));
    assert_eq!(status, 200, "{head}");
    assert!(
        head.contains(&format!("plane-{id}-tick-7.physnap")),
        "{head}"
    );
    let snapshot = client_sdk::PlaneSnapshot::from_bytes(body).unwrap();
    assert_eq!(snapshot.tick(), 7);
    assert_eq!(snapshot.state_hash(), plane.state_hash().unwrap());
    // It is a file FromSnapshot takes: a plane in the same state.
    let copy = client.plane_from_snapshot(&snapshot, &[]).unwrap();
    assert_eq!(copy.state_hash().unwrap(), snapshot.state_hash());

    let (status, body) = viewer.request("GET", "/api/plane/9999/snapshot");
    assert_eq!(status, 404, "{body}");
    assert!(body.contains("9999"), "{body}");

    // The page's link points at the selected plane's snapshot.
    let profile = std::env::temp_dir().join(unique_domain("viewer-dl-profile"));
    let url = format!("{}/?plane={id}", viewer.base);
    let want = format!("href=\"/api/plane/{id}/snapshot\"");
    let mut link = String::new();
    // The page sets the link once it has the plane list (retried like load_view).
    for _ in 0..3 {
        let dom = chromium_run(&profile, &["--dump-dom".to_string()], &url);
        link = dom
            .find("id=\"download\"")
            .and_then(|i| {
                let start = dom[..i].rfind('<')?;
                Some(dom[start..i + dom[i..].find('>')?].to_string())
            })
            .unwrap_or_else(|| panic!("no download link in the page"));
        if link.contains(&want) {
            break;
        }
    }
    let _ = std::fs::remove_dir_all(&profile);
    assert!(link.contains(&want), "{link}");
}

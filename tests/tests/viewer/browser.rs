//! What the viewer's browser tests share: the browser and a run of it, the viewer binary
//! and a running viewer, a temporary folder, an HTTP request and the attributes the page
//! writes into `#view`.

use std::collections::HashMap;
use std::ffi::OsStr;
use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::{mpsc, Arc, Mutex};
use std::time::Duration;

use integration_tests::unique_domain;
use serde_json::Value;

/// The browser: `$CHROMIUM`, else the first of the usual names on `PATH`.
pub fn chromium() -> PathBuf {
    if let Some(p) = std::env::var_os("CHROMIUM") {
        return PathBuf::from(p);
    }
    for name in ["chromium", "chromium-browser", "google-chrome", "chrome"] {
        if let Some(dir) = std::env::var_os("PATH") {
            for d in std::env::split_paths(&dir) {
                let p = d.join(name);
                if p.is_file() {
                    return p;
                }
            }
        }
    }
    panic!(
        "Chromium not found (looked for $CHROMIUM, chromium, chromium-browser, google-chrome \
         on PATH): the viewer test needs a real browser. Install it, e.g. \
         `apt-get install chromium` (.ci/run does)."
    );
}

/// The `physics-view` binary built next to this test by `cargo build --workspace --bins`.
pub fn viewer_bin() -> PathBuf {
    let exe = std::env::current_exe().expect("test executable");
    exe.ancestors()
        .skip(1)
        .take(3)
        .map(|dir| dir.join("physics-view"))
        .find(|p| p.is_file())
        .unwrap_or_else(|| {
            panic!(
                "physics-view not found near {} (run cargo build --workspace --bins first)",
                exe.display()
            )
        })
}

/// A folder of its own under the temporary folder, removed when dropped.
pub struct TempDir(pub PathBuf);

impl TempDir {
    pub fn new(tag: &str) -> TempDir {
        let path = std::env::temp_dir().join(unique_domain(tag));
        std::fs::create_dir_all(&path).expect("create a temporary folder");
        TempDir(path)
    }

    pub fn join(&self, name: impl AsRef<Path>) -> PathBuf {
        self.0.join(name)
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// `METHOD path` with a JSON `body` over plain HTTP/1.1 to `base`: (status, body).
pub fn http(base: &str, method: &str, path: &str, body: &str) -> (u16, String) {
    let host = base.trim_start_matches("http://");
    let mut s = TcpStream::connect(host).unwrap_or_else(|e| panic!("{base}: {e}"));
    s.set_read_timeout(Some(Duration::from_secs(60))).unwrap();
    write!(
        s,
        "{method} {path} HTTP/1.1\r\nHost: {host}\r\nContent-Type: application/json\r\n\
         Content-Length: {}\r\nConnection: close\r\n\r\n{body}",
        body.len()
    )
    .unwrap();
    let mut raw = String::new();
    s.read_to_string(&mut raw).unwrap();
    let (head, body) = raw.split_once("\r\n\r\n").expect("HTTP reply");
    let status = head
        .split_whitespace()
        .nth(1)
        .and_then(|c| c.parse().ok())
        .expect("status code");
    (status, body.to_string())
}

/// The attributes of the element with `id="view"` in a serialized DOM, entities decoded.
pub fn view_attributes(dom: &str) -> HashMap<String, String> {
    let start = dom
        .find("id=\"view\"")
        .and_then(|i| dom[..i].rfind('<'))
        .unwrap_or_else(|| panic!("no #view in the page: {}", &dom[..dom.len().min(2000)]));
    let tag = &dom[start..start + dom[start..].find('>').expect("end of the tag")];
    let mut attrs = HashMap::new();
    let mut rest = tag.split_once(char::is_whitespace).map_or("", |(_, r)| r);
    while let Some(eq) = rest.find("=\"") {
        let name = rest[..eq].trim().to_string();
        let after = &rest[eq + 2..];
        let end = after.find('"').expect("closing quote");
        let value = after[..end]
            .replace("&quot;", "\"")
            .replace("&lt;", "<")
            .replace("&gt;", ">")
            .replace("&#39;", "'")
            .replace("&nbsp;", "\u{a0}")
            .replace("&amp;", "&");
        attrs.insert(name, value);
        rest = &after[end + 1..];
    }
    attrs
}

/// A running viewer; interrupted (then killed) when dropped.
pub struct Viewer {
    child: Child,
    pub base: String,
    /// What it wrote on stderr so far.
    pub stderr: Arc<Mutex<Vec<String>>>,
}

/// Lines of a pipe, collected by a thread of their own.
fn collect_lines(
    pipe: impl Read + Send + 'static,
) -> (mpsc::Receiver<String>, Arc<Mutex<Vec<String>>>) {
    let (tx, rx) = mpsc::channel();
    let all = Arc::new(Mutex::new(Vec::new()));
    let keep = all.clone();
    std::thread::spawn(move || {
        for line in BufReader::new(pipe).lines().map_while(Result::ok) {
            keep.lock().unwrap().push(line.clone());
            let _ = tx.send(line);
        }
    });
    (rx, all)
}

impl Viewer {
    /// `physics-view --domain DOMAIN --port 0 --replay FILE EXTRA...`, once it listens.
    pub fn replay(domain: &str, file: &Path, extra: &[&str]) -> Viewer {
        let mut args = vec![OsStr::new("--replay"), file.as_os_str()];
        args.extend(extra.iter().map(OsStr::new));
        Viewer::start(domain, &args)
    }

    /// `physics-view --domain DOMAIN --port 0 ARGS...`, once it listens.
    pub fn start<A: AsRef<OsStr>>(domain: &str, args: &[A]) -> Viewer {
        let mut child = Command::new(viewer_bin())
            .args(["--domain", domain, "--port", "0"])
            .args(args)
            .env("PHYSICS_LOG", "warn")
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .expect("spawn physics-view");
        let (lines, _) = collect_lines(child.stdout.take().expect("stdout"));
        let (_, stderr) = collect_lines(child.stderr.take().expect("stderr"));
        let line = lines
            .recv_timeout(Duration::from_secs(60))
            .unwrap_or_else(|_| {
                panic!(
                    "physics-view printed no URL within 60 s; stderr: {:?}",
                    stderr.lock().unwrap()
                )
            });
        let url = line
            .split_whitespace()
            .find(|w| w.starts_with("http://"))
            .unwrap_or_else(|| panic!("no URL in {line:?}"));
        Viewer {
            child,
            base: url.trim_end_matches('/').to_string(),
            stderr,
        }
    }

    pub fn get(&self, path: &str) -> Value {
        let (status, body) = http(&self.base, "GET", path, "");
        assert_eq!(status, 200, "GET {path}: {body}");
        serde_json::from_str(&body).unwrap_or_else(|e| panic!("GET {path}: {e}: {body}"))
    }

    /// `POST /api/replay` with `body`: (status, answer).
    pub fn act(&self, body: Value) -> (u16, Value) {
        let (status, text) = http(&self.base, "POST", "/api/replay", &body.to_string());
        let v = serde_json::from_str(&text).unwrap_or_else(|e| panic!("{body}: {e}: {text}"));
        (status, v)
    }

    /// `POST /api/replay` that must succeed: the timeline's state after it.
    pub fn ok(&self, body: Value) -> Value {
        let (status, v) = self.act(body.clone());
        assert_eq!(status, 200, "POST /api/replay {body}: {v}");
        v
    }
}

impl Drop for Viewer {
    fn drop(&mut self) {
        // SAFETY: kill(2) on our own child: SIGINT lets it say goodbye to the daemon.
        unsafe { libc::kill(self.child.id() as i32, libc::SIGINT) };
        for _ in 0..300 {
            if let Ok(Some(_)) = self.child.try_wait() {
                return;
            }
            std::thread::sleep(Duration::from_millis(20));
        }
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// Headless Chromium with a software WebGL (SwiftShader), a profile of its own, and
/// `extra` (e.g. `--dump-dom`) on `url`. Returns stdout.
pub fn chromium_run(profile: &Path, extra: &[String], url: &str) -> String {
    let out = Command::new(chromium())
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--use-gl=swiftshader",
            "--enable-unsafe-swiftshader",
            "--no-first-run",
            "--hide-scrollbars",
            "--window-size=1280,800",
            "--virtual-time-budget=3000",
        ])
        .arg(format!("--user-data-dir={}", profile.display()))
        .args(extra)
        .arg(url)
        .stdin(Stdio::null())
        .output()
        .expect("run chromium");
    assert!(
        out.status.success(),
        "chromium failed ({}): {}",
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

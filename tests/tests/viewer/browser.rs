//! What the viewer's browser tests share: the browser, the viewer binary, a temporary
//! folder, an HTTP request and the attributes the page writes into `#view`.

use std::collections::HashMap;
use std::io::{Read, Write};
use std::net::TcpStream;
use std::path::{Path, PathBuf};
use std::time::Duration;

use integration_tests::unique_domain;

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

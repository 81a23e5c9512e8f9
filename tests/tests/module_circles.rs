//! The layers of the crates that change most stay free of import circles: in `physics-daemon`,
//! `client-sdk` and `lua-client`, no top-level module imports (directly or through others) a
//! module that imports it back. A circle means two concepts cannot be understood, tested or
//! changed apart (a seam that imports its implementations, rows that import their types).
//!
//! Edges are read from the sources: `crate::m` paths, `crate::{A, B}` lists (names the crate
//! root re-exports from `m` count as `m`) and, in top-level files, `super::m`; a file's unit
//! tests (its trailing `#[cfg(test)] mod tests`) are left out.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

use integration_tests::structure::{circles, rust_files};

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .unwrap()
        .to_path_buf()
}

/// The top-level modules of a crate: `src/m.rs` and `src/m/` (the binaries aside).
fn top_modules(src: &Path) -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    for entry in std::fs::read_dir(src).unwrap() {
        let path = entry.unwrap().path();
        let name = path.file_name().unwrap().to_string_lossy().to_string();
        if path.is_dir() && name != "bin" {
            out.insert(name);
        } else if let Some(m) = name.strip_suffix(".rs") {
            if m != "lib" && m != "main" {
                out.insert(m.to_string());
            }
        }
    }
    out
}

/// Names the crate root re-exports (`pub use m::{A, B}` / `pub use m::A`), by name.
fn reexports(src: &Path, top: &BTreeSet<String>) -> BTreeMap<String, String> {
    let mut out = BTreeMap::new();
    let Ok(lib) = std::fs::read_to_string(src.join("lib.rs")) else {
        return out;
    };
    let flat = lib.split_whitespace().collect::<Vec<_>>().join(" ");
    for part in flat.split("pub use ").skip(1) {
        let Some((module, rest)) = part.split_once("::") else {
            continue;
        };
        if !top.contains(module) {
            continue;
        }
        let names = match rest.strip_prefix('{') {
            Some(list) => list.split('}').next().unwrap_or(""),
            None => rest.split(';').next().unwrap_or(""),
        };
        for name in names.split(|c: char| !c.is_alphanumeric() && c != '_') {
            if !name.is_empty() {
                out.insert(name.to_string(), module.to_string());
            }
        }
    }
    out
}

fn words(s: &str) -> impl Iterator<Item = &str> {
    s.split(|c: char| !c.is_alphanumeric() && c != '_')
        .filter(|w| !w.is_empty())
}

/// module → the modules it imports.
fn edges(krate: &str) -> BTreeMap<String, BTreeSet<String>> {
    let src = repo().join(krate).join("src");
    let top = top_modules(&src);
    let names = reexports(&src, &top);
    let mut graph: BTreeMap<String, BTreeSet<String>> =
        top.iter().map(|m| (m.clone(), BTreeSet::new())).collect();
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    for file in files {
        let rel = file.strip_prefix(&src).unwrap();
        let first = rel
            .components()
            .next()
            .unwrap()
            .as_os_str()
            .to_string_lossy();
        let me = first.trim_end_matches(".rs").to_string();
        if !top.contains(&me) {
            continue;
        }
        let whole = std::fs::read_to_string(&file).unwrap();
        // A file's unit tests (its trailing `mod tests`) may use any layer.
        let code = whole.split("#[cfg(test)]\nmod tests").next().unwrap_or("");
        let text: String = code
            .lines()
            .map(|l| l.split("//").next().unwrap_or(""))
            .collect::<Vec<_>>()
            .join("\n");
        let mut add = |m: &str| {
            if m != me && top.contains(m) {
                graph.get_mut(&me).unwrap().insert(m.to_string());
            }
        };
        for part in text.split("crate::").skip(1) {
            if let Some(list) = part.strip_prefix('{') {
                for w in words(list.split('}').next().unwrap_or("")) {
                    add(names.get(w).map_or(w, String::as_str));
                }
            } else if let Some(w) = words(part).next() {
                add(names.get(w).map_or(w, String::as_str));
            }
        }
        if rel.components().count() == 1 {
            for part in text.split("super::").skip(1) {
                if let Some(w) = words(part).next() {
                    add(w);
                }
            }
        }
    }
    graph
}

#[test]
fn the_checker_finds_a_circle() {
    let graph: BTreeMap<String, BTreeSet<String>> = [
        ("a", vec!["b"]),
        ("b", vec!["c"]),
        ("c", vec!["a"]),
        ("d", vec!["a"]),
    ]
    .into_iter()
    .map(|(k, v)| (k.into(), v.into_iter().map(String::from).collect()))
    .collect();
    assert_eq!(circles(&graph), vec![vec!["a", "b", "c"]]);
}

#[test]
fn the_main_crates_have_no_import_circles() {
    let mut found = Vec::new();
    for krate in ["physics-daemon", "client-sdk", "lua-client"] {
        let graph = edges(krate);
        assert!(
            graph.values().map(BTreeSet::len).sum::<usize>() > 5,
            "{krate}: the scan found almost no imports: {graph:?}"
        );
        for c in circles(&graph) {
            found.push(format!("{krate}: {}", c.join(" <-> ")));
        }
    }
    assert!(found.is_empty(), "import circles:\n{}", found.join("\n"));
}

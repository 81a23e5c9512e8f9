//! The structure stays one room per concern: no import circle between the files of any crate,
//! no source file over 900 lines, the daemon free of client, bench and plotting crates, and
//! the README's "to add" table naming files that exist. The file graph is read from the
//! sources (see `integration_tests::structure`).

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use integration_tests::structure::{code_of, paths_in, rust_files, FileGraph};

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .unwrap()
        .to_path_buf()
}

/// The workspace's member crates, as the root Cargo.toml lists them.
fn members() -> Vec<String> {
    let manifest = std::fs::read_to_string(repo().join("Cargo.toml")).unwrap();
    let list = manifest
        .split("members = [")
        .nth(1)
        .and_then(|s| s.split(']').next())
        .expect("the root Cargo.toml lists members");
    let out: Vec<String> = list
        .split(',')
        .map(|s| s.trim().trim_matches('"').to_string())
        .filter(|s| !s.is_empty())
        .collect();
    assert!(out.len() >= 8, "members read from Cargo.toml: {out:?}");
    out
}

/// A crate in a temporary folder: `files` as (path under src/, text).
fn scratch_crate(tag: &str, files: &[(&str, &str)]) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("structure-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    for (path, text) in files {
        let p = dir.join(path);
        std::fs::create_dir_all(p.parent().unwrap()).unwrap();
        std::fs::write(p, text).unwrap();
    }
    dir
}

#[test]
fn the_reader_expands_use_trees_and_skips_comments_and_strings() {
    let code = code_of(
        "use crate::{a::{B, c::D}, e};\n// use crate::hidden;\nlet s = \"crate::f::G\";\n\
         pub(in crate::k) fn x() { super::h::I::new(); }\n#[cfg(test)]\nmod tests { use crate::z; }\n",
    );
    let paths: Vec<String> = paths_in(&code).iter().map(|p| p.join("::")).collect();
    assert_eq!(
        paths,
        [
            "crate::a::B",
            "crate::a::c::D",
            "crate::e",
            "super::h::I::new"
        ]
    );
}

#[test]
fn the_checker_finds_file_circles_through_re_exports() {
    // lib re-exports Plane from plane.rs; joints.rs reaches it through the root and plane.rs
    // stores a joints::Joints: a circle of the three files.
    let src = scratch_crate(
        "circle",
        &[
            ("lib.rs", "mod joints;\nmod plane;\npub use plane::Plane;\n"),
            (
                "plane.rs",
                "pub struct Plane { j: crate::joints::Joints }\n",
            ),
            (
                "joints.rs",
                "use crate::Plane;\npub struct Joints;\nimpl Plane { fn f(&self) {} }\n",
            ),
        ],
    );
    let graph = FileGraph::of(&src);
    assert_eq!(
        graph.circles(),
        vec![vec!["(crate root)", "joints", "plane"]]
    );
    // The same crate layered: the glue that knows both lives in a file nobody imports.
    let src = scratch_crate(
        "layered",
        &[
            (
                "lib.rs",
                "mod joints;\nmod plane;\nmod ops;\npub use plane::Plane;\n",
            ),
            (
                "plane.rs",
                "pub struct Plane { j: crate::joints::Joints }\n",
            ),
            ("joints.rs", "pub struct Joints;\n"),
            (
                "ops.rs",
                "use crate::Plane;\nuse super::joints::Joints;\nimpl Plane { fn f(&self) {} }\n",
            ),
        ],
    );
    let graph = FileGraph::of(&src);
    assert!(graph.circles().is_empty(), "{:?}", graph.edges);
    assert_eq!(
        graph.edges[&vec!["ops".to_string()]].len(),
        2,
        "ops imports plane and joints: {:?}",
        graph.edges
    );
    // A parent that uses what its child defines while the child uses the parent's type.
    let src = scratch_crate(
        "parent",
        &[
            ("lib.rs", "mod api;\n"),
            (
                "api/mod.rs",
                "mod part;\npub struct State;\nfn register() { part::register(); }\n",
            ),
            ("api/part.rs", "use super::State;\npub fn register() {}\n"),
        ],
    );
    assert_eq!(FileGraph::of(&src).circles(), vec![vec!["api", "api/part"]]);
}

#[test]
fn no_crate_has_an_import_circle_between_its_files() {
    let mut found = Vec::new();
    for krate in members() {
        let src = repo().join(&krate).join("src");
        let graph = FileGraph::of(&src);
        let edges: usize = graph.edges.values().map(BTreeSet::len).sum();
        assert!(
            graph.files.len() < 3 || edges > 0,
            "{krate}: the scan found no imports among {} files",
            graph.files.len()
        );
        for c in graph.circles() {
            found.push(format!("{krate}: {}", c.join(" <-> ")));
        }
    }
    assert!(
        found.is_empty(),
        "import circles between files:\n{}",
        found.join("\n")
    );
}

/// Test code: the tests crate, `tests.rs` / `*_tests.rs` unit-test files, test folders.
fn is_test_code(rel: &Path) -> bool {
    let s = rel.to_string_lossy();
    s.starts_with("tests/") || s.contains("/tests/") || s.ends_with("tests.rs")
}

#[test]
fn no_source_file_is_over_900_lines() {
    const MAX: usize = 900;
    let mut long = Vec::new();
    let mut seen = 0;
    for krate in members() {
        let mut files = Vec::new();
        rust_files(&repo().join(&krate), &mut files);
        for dir in ["static", "types"] {
            let Ok(entries) = std::fs::read_dir(repo().join(&krate).join(dir)) else {
                continue;
            };
            files.extend(entries.flatten().map(|e| e.path()));
        }
        for file in files {
            let rel = file.strip_prefix(repo()).unwrap().to_path_buf();
            let name = rel.file_name().unwrap().to_string_lossy().to_string();
            // Generated or third-party code: minified bundles.
            if is_test_code(&rel) || name.ends_with(".min.js") || !file.is_file() {
                continue;
            }
            let Ok(text) = std::fs::read_to_string(&file) else {
                continue;
            };
            seen += 1;
            let lines = text.lines().count();
            if lines > MAX {
                long.push(format!("{} ({lines} lines)", rel.display()));
            }
        }
    }
    assert!(seen > 100, "only {seen} source files found");
    assert!(
        long.is_empty(),
        "files over {MAX} lines:\n{}",
        long.join("\n")
    );
}

/// The packages `package` depends on for its normal and build dependencies (transitively,
/// for this machine's target), from `cargo tree`.
fn normal_dependencies(package: &str) -> BTreeSet<String> {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let out = std::process::Command::new(cargo)
        .args(["tree", "--offline", "-p", package, "-e", "normal,build"])
        .args(["--prefix", "none", "-f", "{p}"])
        .current_dir(repo())
        .output()
        .expect("run cargo tree");
    assert!(
        out.status.success(),
        "cargo tree: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout)
        .lines()
        .filter_map(|l| l.split_whitespace().next())
        .filter(|name| *name != package)
        .map(String::from)
        .collect()
}

#[test]
fn the_daemon_depends_on_no_client_bench_or_plotting_crate() {
    let deps = normal_dependencies("physics-daemon");
    assert!(
        deps.contains("rapier3d") && deps.contains("shm-layout"),
        "{deps:?}"
    );
    let forbidden = [
        "client-sdk",
        "lua-client",
        "physics-bench",
        "physics-view",
        "physics-scenes",
        "physics-fuzz",
        "physics-envelope",
        "mlua",
        "plotters",
        "indicatif",
    ];
    let found: Vec<&str> = forbidden
        .into_iter()
        .filter(|f| deps.contains(*f))
        .collect();
    assert!(found.is_empty(), "physics-daemon depends on {found:?}");
}

/// The file paths in backticks on the README's "to add" table rows (placeholders such as
/// `KIND` or `NAME` aside).
fn to_add_paths() -> Vec<String> {
    let readme = std::fs::read_to_string(repo().join("README.md")).unwrap();
    let table = readme
        .split("To add")
        .nth(1)
        .expect("README has the 'To add' table");
    let mut out = Vec::new();
    for line in table.lines().skip(1) {
        if !line.starts_with('|') && !line.trim().is_empty() {
            break;
        }
        for (i, piece) in line.split('`').enumerate() {
            let path = piece.trim();
            let looks_like_path = i % 2 == 1
                && !path.contains(' ')
                && (path.contains('/') || path.ends_with(".rs") || path.ends_with(".luau"));
            let placeholder = path
                .split(|c: char| !c.is_alphanumeric())
                .any(|w| w.len() >= 3 && w.chars().all(|c| c.is_ascii_uppercase()));
            if looks_like_path && !placeholder {
                out.push(path.to_string());
            }
        }
    }
    out
}

#[test]
fn the_readme_to_add_table_names_files_that_exist() {
    let paths = to_add_paths();
    assert!(paths.len() >= 10, "paths read from the table: {paths:?}");
    let mut roots = vec![repo()];
    for krate in members() {
        roots.push(repo().join(&krate));
        roots.push(repo().join(&krate).join("src"));
    }
    let missing: Vec<&String> = paths
        .iter()
        .filter(|p| !roots.iter().any(|r| r.join(p).exists()))
        .collect();
    assert!(
        missing.is_empty(),
        "README's to-add table names missing files: {missing:?}"
    );
}

/// The paths docs/architecture.md's map names: the first fenced block under `## Map`; a line
/// starting in the first column names a path from the repository's root (its first word),
/// indented lines continue its description.
fn map_paths() -> Vec<String> {
    let doc = std::fs::read_to_string(repo().join("docs/architecture.md")).unwrap();
    let section = doc
        .split("\n## Map")
        .nth(1)
        .expect("docs/architecture.md has a '## Map' section");
    let block = section
        .split("```")
        .nth(1)
        .expect("the map is a fenced block");
    block
        .lines()
        .skip(1)
        .filter(|line| !line.starts_with(' '))
        .filter_map(|line| line.split_whitespace().next())
        .map(String::from)
        .collect()
}

#[test]
fn the_architecture_map_names_every_crate_and_folder_and_nothing_else() {
    let named = map_paths();
    assert!(named.len() >= 12, "paths read from the map: {named:?}");
    let missing: Vec<&String> = named.iter().filter(|p| !repo().join(p).exists()).collect();
    assert!(
        missing.is_empty(),
        "the map names paths that do not exist: {missing:?}"
    );
    let mut unnamed = Vec::new();
    for entry in std::fs::read_dir(repo()).unwrap().flatten() {
        let name = entry.file_name().to_string_lossy().to_string();
        if entry.path().is_dir() && !name.starts_with('.') && name != "target" {
            let top = format!("{name}/");
            if !named.contains(&top) {
                unnamed.push(top);
            }
        }
    }
    for krate in members() {
        let src = repo().join(&krate).join("src");
        for entry in std::fs::read_dir(&src).unwrap().flatten() {
            if entry.path().is_dir() {
                let path = format!("{krate}/src/{}/", entry.file_name().to_string_lossy());
                if !named.contains(&path) {
                    unnamed.push(path);
                }
            }
        }
    }
    assert!(
        unnamed.is_empty(),
        "folders docs/architecture.md's map does not name: {unnamed:?}"
    );
}

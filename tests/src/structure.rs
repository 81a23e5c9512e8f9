//! Reading the sources' structure: which file imports which, and the circles among them.
//!
//! A file's imports are the paths it writes (`use` trees with their braces expanded, and paths
//! in code such as `super::Plane::new`): `crate::`, `super::`, `self::` and paths through a
//! child module. Each is an edge to the file of the deepest module the path names: an item
//! reached through a re-export (`crate::Error`, `super::Plane`) imports the file that
//! re-exports it, whose own `pub use` lines are edges in turn; so a file that imports through
//! the crate root or its parent is in a circle whenever that file re-exports something of its
//! own. A `mod x;` declaration is not an import, nor is the path of a `pub(in ...)`; a file's
//! trailing unit tests (`#[cfg(test)] mod tests`) and test-only module files are left out.
//! Paths into other crates are not edges.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// A module path inside a crate (`[]` is the crate root).
pub type ModPath = Vec<String>;

/// The files of one crate and the file-to-file imports among them.
pub struct FileGraph {
    /// Module path -> file.
    pub files: BTreeMap<ModPath, PathBuf>,
    /// Module path -> the module paths (files) it imports.
    pub edges: BTreeMap<ModPath, BTreeSet<ModPath>>,
}

/// Every `.rs` file under `dir`.
pub fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let path = entry.path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// The code of a file without comments, string contents and its trailing unit tests.
pub fn code_of(text: &str) -> String {
    let text = text.split("#[cfg(test)]\nmod tests").next().unwrap_or("");
    let b = text.as_bytes();
    let mut out = String::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        match b[i] {
            b'/' if b.get(i + 1) == Some(&b'/') => {
                while i < b.len() && b[i] != b'\n' {
                    i += 1;
                }
            }
            b'/' if b.get(i + 1) == Some(&b'*') => {
                let mut depth = 0;
                while i < b.len() {
                    if b[i] == b'/' && b.get(i + 1) == Some(&b'*') {
                        depth += 1;
                        i += 2;
                    } else if b[i] == b'*' && b.get(i + 1) == Some(&b'/') {
                        depth -= 1;
                        i += 2;
                        if depth == 0 {
                            break;
                        }
                    } else {
                        i += 1;
                    }
                }
            }
            b'r' if matches!(b.get(i + 1), Some(b'"') | Some(b'#'))
                && (i == 0 || !(b[i - 1].is_ascii_alphanumeric() || b[i - 1] == b'_')) =>
            {
                let mut j = i + 1;
                let mut hashes = 0;
                while b.get(j) == Some(&b'#') {
                    hashes += 1;
                    j += 1;
                }
                if b.get(j) != Some(&b'"') {
                    out.push('r');
                    i += 1;
                    continue;
                }
                j += 1;
                let close: Vec<u8> = std::iter::once(b'"')
                    .chain(std::iter::repeat_n(b'#', hashes))
                    .collect();
                while j < b.len() && !b[j..].starts_with(&close) {
                    j += 1;
                }
                out.push_str("\"\"");
                i = j + close.len();
            }
            b'"' => {
                i += 1;
                while i < b.len() && b[i] != b'"' {
                    i += if b[i] == b'\\' { 2 } else { 1 };
                }
                out.push_str("\"\"");
                i += 1;
            }
            b'\'' if b.get(i + 2) == Some(&b'\'') || b.get(i + 1) == Some(&b'\\') => {
                // A char literal ('{', '\n', '\''): dropped, so its bracket counts for nothing.
                i += 1;
                while i < b.len() && b[i] != b'\'' {
                    i += if b[i] == b'\\' { 2 } else { 1 };
                }
                out.push_str("' '");
                i += 1;
            }
            c => {
                out.push(c as char);
                i += 1;
            }
        }
    }
    out
}

fn is_ident(t: &str) -> bool {
    t.chars()
        .next()
        .is_some_and(|c| c.is_alphabetic() || c == '_')
}

fn tokens(code: &str) -> Vec<String> {
    let mut out = Vec::new();
    let chars: Vec<char> = code.chars().collect();
    let mut i = 0;
    while i < chars.len() {
        let c = chars[i];
        if c.is_alphanumeric() || c == '_' {
            let start = i;
            while i < chars.len() && (chars[i].is_alphanumeric() || chars[i] == '_') {
                i += 1;
            }
            out.push(chars[start..i].iter().collect());
        } else if c == ':' && chars.get(i + 1) == Some(&':') {
            out.push("::".into());
            i += 2;
        } else {
            if !c.is_whitespace() {
                out.push(c.to_string());
            }
            i += 1;
        }
    }
    out
}

/// Every path the code writes, `use` trees expanded (`a::{b, c::d}` gives `a::b`, `a::c::d`).
pub fn paths_in(code: &str) -> Vec<Vec<String>> {
    fn tree(t: &[String], mut i: usize, prefix: Vec<String>, out: &mut Vec<Vec<String>>) -> usize {
        match t.get(i).map(String::as_str) {
            Some("{") => {
                i += 1;
                while i < t.len() && t[i] != "}" {
                    if t[i] == "," {
                        i += 1;
                    } else {
                        i = tree(t, i, prefix.clone(), out);
                    }
                }
                i + 1
            }
            Some("*") => {
                let mut p = prefix;
                p.push("*".into());
                out.push(p);
                i + 1
            }
            Some(w) if is_ident(w) => {
                let mut p = prefix;
                p.push(w.to_string());
                i += 1;
                if t.get(i).map(String::as_str) == Some("::") {
                    let next = t.get(i + 1).map(String::as_str).unwrap_or("");
                    if next == "{" || next == "*" || is_ident(next) {
                        return tree(t, i + 1, p, out);
                    }
                    out.push(p);
                    return i + 1;
                }
                out.push(p);
                if t.get(i).map(String::as_str) == Some("as") {
                    i += 2;
                }
                i
            }
            _ => i + 1,
        }
    }
    let t = tokens(code);
    let mut out = Vec::new();
    let mut i = 0;
    while i < t.len() {
        let starts = is_ident(&t[i])
            && t.get(i + 1).map(String::as_str) == Some("::")
            && (i == 0 || t[i - 1] != "::");
        // `pub(in crate::a)` names where an item is visible, not what the file imports.
        let visibility = i >= 2 && t[i - 1] == "in" && t[i - 2] == "(";
        if starts && visibility {
            let mut ignored = Vec::new();
            i = tree(&t, i, Vec::new(), &mut ignored).max(i + 1);
        } else if starts {
            let mut found = Vec::new();
            let j = tree(&t, i, Vec::new(), &mut found);
            out.extend(found.into_iter().filter(|p| p.len() > 1));
            i = j.max(i + 1);
        } else {
            i += 1;
        }
    }
    out
}

impl FileGraph {
    /// The files of `src` (a crate's `src/`; its `bin/` aside) and their imports.
    pub fn of(src: &Path) -> FileGraph {
        let mut all = Vec::new();
        rust_files(src, &mut all);
        let mut files = BTreeMap::new();
        for file in all {
            let rel = file.strip_prefix(src).unwrap().with_extension("");
            let mut module: ModPath = rel
                .components()
                .map(|c| c.as_os_str().to_string_lossy().to_string())
                .collect();
            if module.first().is_some_and(|m| m == "bin") {
                continue;
            }
            if module
                .last()
                .is_some_and(|m| m == "mod" || m == "lib" || m == "main")
            {
                module.pop();
            }
            files.insert(module, file);
        }
        let code: BTreeMap<ModPath, String> = files
            .iter()
            .map(|(m, f)| (m.clone(), code_of(&std::fs::read_to_string(f).unwrap())))
            .collect();
        // Module files declared under #[cfg(test)] (and everything below them).
        let mut tests = BTreeSet::new();
        for (m, c) in &code {
            let t = tokens(c);
            for (k, w) in t.windows(3).enumerate() {
                if w[0] == "test" && w[1] == ")" && w[2] == "]" {
                    let rest = &t[k + 3..];
                    let rest = match rest.first().map(String::as_str) {
                        Some("pub") => &rest[1..],
                        _ => rest,
                    };
                    if rest.len() >= 3 && rest[0] == "mod" && rest[2] == ";" {
                        let mut child = m.clone();
                        child.push(rest[1].clone());
                        tests.insert(child);
                    }
                }
            }
        }
        files.retain(|m, _| !tests.iter().any(|t| m.starts_with(t)));
        let paths: BTreeMap<ModPath, Vec<Vec<String>>> = files
            .keys()
            .map(|m| (m.clone(), paths_in(&code[m])))
            .collect();
        let graph = Resolver { files: &files };
        let mut edges = BTreeMap::new();
        for m in files.keys() {
            let mut to = BTreeSet::new();
            for p in &paths[m] {
                if let Some(target) = graph.resolve(m, p) {
                    if &target != m {
                        to.insert(target);
                    }
                }
            }
            edges.insert(m.clone(), to);
        }
        FileGraph { files, edges }
    }

    /// The circles: sets of more than one file that import each other (directly or not).
    pub fn circles(&self) -> Vec<Vec<String>> {
        let names = |m: &ModPath| {
            if m.is_empty() {
                "(crate root)".to_string()
            } else {
                m.join("/")
            }
        };
        let graph: BTreeMap<String, BTreeSet<String>> = self
            .edges
            .iter()
            .map(|(k, v)| (names(k), v.iter().map(names).collect()))
            .collect();
        circles(&graph)
    }
}

struct Resolver<'a> {
    files: &'a BTreeMap<ModPath, PathBuf>,
}

impl Resolver<'_> {
    /// The file a path written in `me` leads to (None: another crate, a local name or a type's
    /// associated item).
    fn resolve(&self, me: &ModPath, path: &[String]) -> Option<ModPath> {
        if path.is_empty() {
            return None;
        }
        let (mut cur, rest): (ModPath, &[String]) = match path[0].as_str() {
            "crate" => (Vec::new(), &path[1..]),
            "self" => (me.clone(), &path[1..]),
            "super" => {
                let mut base = me.clone();
                let mut rest = path;
                while rest.first().is_some_and(|s| s == "super") {
                    base.pop();
                    rest = &rest[1..];
                }
                (base, rest)
            }
            first => {
                let mut child = me.clone();
                child.push(first.to_string());
                if !self.files.contains_key(&child) {
                    return None;
                }
                (me.clone(), path)
            }
        };
        let mut k = 0;
        while k < rest.len() {
            let mut next = cur.clone();
            next.push(rest[k].clone());
            if !self.files.contains_key(&next) {
                break;
            }
            cur = next;
            k += 1;
        }
        if !self.files.contains_key(&cur) {
            return None;
        }
        Some(cur)
    }
}

/// The strongly connected components with more than one node (Tarjan), each sorted.
pub fn circles(graph: &BTreeMap<String, BTreeSet<String>>) -> Vec<Vec<String>> {
    struct State<'a> {
        graph: &'a BTreeMap<String, BTreeSet<String>>,
        index: BTreeMap<&'a str, usize>,
        low: BTreeMap<&'a str, usize>,
        stack: Vec<&'a str>,
        on: BTreeSet<&'a str>,
        out: Vec<Vec<String>>,
    }
    fn visit<'a>(s: &mut State<'a>, n: &'a str) {
        let i = s.index.len();
        s.index.insert(n, i);
        s.low.insert(n, i);
        s.stack.push(n);
        s.on.insert(n);
        for w in s.graph.get(n).into_iter().flatten() {
            let w = w.as_str();
            if !s.index.contains_key(w) {
                visit(s, w);
                let lw = s.low[w];
                let ln = s.low.get_mut(n).unwrap();
                *ln = (*ln).min(lw);
            } else if s.on.contains(w) {
                let iw = s.index[w];
                let ln = s.low.get_mut(n).unwrap();
                *ln = (*ln).min(iw);
            }
        }
        if s.low[n] == s.index[n] {
            let mut comp = Vec::new();
            while let Some(w) = s.stack.pop() {
                s.on.remove(w);
                comp.push(w.to_string());
                if w == n {
                    break;
                }
            }
            if comp.len() > 1 {
                comp.sort();
                s.out.push(comp);
            }
        }
    }
    let mut s = State {
        graph,
        index: BTreeMap::new(),
        low: BTreeMap::new(),
        stack: Vec::new(),
        on: BTreeSet::new(),
        out: Vec::new(),
    };
    for n in graph.keys() {
        if !s.index.contains_key(n.as_str()) {
            visit(&mut s, n);
        }
    }
    s.out
}

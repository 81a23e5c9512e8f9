//! `lua-client/types/physics.d.luau` (the luau-lsp definitions) against the runtime, so a
//! member cannot exist on one side only:
//!
//! - every property row of the runtime (`lua_client::property_rows`, the tables `props/`
//!   reads and writes through) is declared on its class, and every declared property of a
//!   class with a row table is a row (or a Signal, which are not rows);
//! - every method name the runtime registers (`add_method("X"`, method tables built with
//!   `t.set("X", lua.create_function`) in `lua-client/src/api/`) is declared;
//! - every declared member exists at run time: a generated Luau script indexes each member
//!   of each declared class (and each module field) on a real instance through physics-lua
//!   against a real daemon (members documented as "not supported yet" must say so);
//! - every member the example and test scripts use (`x.Name`, `x:Name(`) is declared.
//!
//! The types themselves (and every script against them, in strict mode) are checked by Luau's
//! own type checker in `.ci/luau-tools`: see docs/lua.md, "Luau tooling".

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

use integration_tests::{physics_lua, TestDaemon};

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// One member of a declared class.
#[derive(Debug, Clone)]
struct Member {
    name: String,
    function: bool,
    /// The declared type (after the colon), for properties.
    ty: String,
}

/// What physics.d.luau declares.
#[derive(Debug, Default)]
struct Definitions {
    /// `declare class NAME` → members.
    classes: BTreeMap<String, Vec<Member>>,
    /// `[export] type NAME = { ... }` → its field names (nested tables' too, three levels deep).
    tables: BTreeMap<String, Vec<String>>,
    /// `type NAME = { ... }` → its own field names.
    own_fields: BTreeMap<String, Vec<String>>,
    /// `declare NAME` / `declare function NAME`.
    globals: BTreeSet<String>,
}

impl Definitions {
    fn load() -> Definitions {
        let path = repo().join("lua-client/types/physics.d.luau");
        let text = std::fs::read_to_string(&path).expect("read physics.d.luau");
        // Comments out.
        let text: String = text
            .lines()
            .map(|l| l.split_once("--").map_or(l, |(code, _)| code))
            .collect::<Vec<_>>()
            .join("\n");
        let mut d = Definitions::default();
        let mut lines = text.lines().peekable();
        while let Some(line) = lines.next() {
            if let Some(rest) = line.strip_prefix("declare class ") {
                let name = rest.split_whitespace().next().unwrap().to_string();
                let mut members = Vec::new();
                for l in lines.by_ref() {
                    let l = l.trim();
                    if l == "end" {
                        break;
                    }
                    if let Some(f) = l.strip_prefix("function ") {
                        let n = f.split('(').next().unwrap().trim();
                        members.push(Member {
                            name: n.to_string(),
                            function: true,
                            ty: String::new(),
                        });
                    } else if let Some((n, ty)) = l.split_once(':') {
                        members.push(Member {
                            name: n.trim().to_string(),
                            function: false,
                            ty: ty.trim().to_string(),
                        });
                    }
                }
                d.classes.insert(name, members);
            } else if let Some(rest) = line
                .strip_prefix("export type ")
                .or_else(|| line.strip_prefix("type "))
            {
                // `type Signal<T... = ...any> = {` declares `Signal`: its generic
                // parameters (and their defaults) go first.
                let rest = match (rest.find('<'), rest.find('>'), rest.find('=')) {
                    (Some(lt), Some(gt), Some(eq)) if lt < eq => {
                        format!("{}{}", &rest[..lt], &rest[gt + 1..])
                    }
                    _ => rest.to_string(),
                };
                let Some((name, body)) = rest.split_once('=') else {
                    continue;
                };
                let mut body = body.to_string();
                let depth = |s: &str| {
                    s.chars().fold(0i32, |d, c| match c {
                        '{' | '(' => d + 1,
                        '}' | ')' => d - 1,
                        _ => d,
                    })
                };
                while depth(&body) > 0 {
                    body.push('\n');
                    body.push_str(lines.next().expect("unterminated type"));
                }
                if body.trim_start().starts_with('{') {
                    d.tables
                        .insert(name.trim().to_string(), top_level_fields(&body));
                    d.own_fields
                        .insert(name.trim().to_string(), fields_to_depth(&body, 1));
                }
            } else if let Some(rest) = line.strip_prefix("declare ") {
                let rest = rest.strip_prefix("function ").unwrap_or(rest);
                let name: String = rest
                    .chars()
                    .take_while(|c| c.is_alphanumeric() || *c == '_')
                    .collect();
                d.globals.insert(name);
            }
        }
        d
    }

    /// Every name a script may use after `.` or `:`.
    fn all_names(&self) -> BTreeSet<String> {
        let mut all: BTreeSet<String> = self.globals.clone();
        for members in self.classes.values() {
            all.extend(members.iter().map(|m| m.name.clone()));
        }
        for fields in self.tables.values() {
            all.extend(fields.iter().cloned());
        }
        all
    }
}

/// Field names at the first nesting level of a `{ ... }` type body (nested tables'
/// fields too, one level deeper, since scripts reach them as `GUI.Basic.Square`).
fn top_level_fields(body: &str) -> Vec<String> {
    fields_to_depth(body, 3)
}

/// Field names of a `{ ... }` type body down to nesting level `max_depth` (1: its own).
fn fields_to_depth(body: &str, max_depth: i32) -> Vec<String> {
    let mut fields = Vec::new();
    let mut depth = 0;
    let chars: Vec<char> = body.chars().collect();
    let mut i = 0;
    while i < chars.len() {
        let c = chars[i];
        match c {
            '{' | '(' => depth += 1,
            '}' | ')' => depth -= 1,
            _ if (c.is_alphabetic() || c == '_') && (1..=max_depth).contains(&depth) => {
                let start = i;
                while i < chars.len() && (chars[i].is_alphanumeric() || chars[i] == '_') {
                    i += 1;
                }
                let word: String = chars[start..i].iter().collect();
                let mut j = i;
                while j < chars.len() && chars[j] == ' ' {
                    j += 1;
                }
                // `name:` (a field), not `name::` and not a type after a colon.
                let prev = chars[..start].iter().rev().find(|c| !c.is_whitespace());
                if j < chars.len()
                    && chars[j] == ':'
                    && matches!(prev, Some('{') | Some(',') | None)
                {
                    fields.push(word);
                }
                continue;
            }
            _ => {}
        }
        i += 1;
    }
    fields
}

#[test]
fn property_rows_match_the_declared_properties() {
    let d = Definitions::load();
    let mut problems = Vec::new();
    // The GUI types' row tables hold their writable options; their read-only figures
    // (ObjectCount, Sleeping, ...) are read outside the rows, so only the run-time check
    // below covers those.
    let all_rows = [
        "BasePart",
        "PhysicsObject",
        "PhysicsPlane",
        "Controller",
        "Map",
    ];
    for (owner, rows) in lua_client::property_rows() {
        let Some(members) = d.classes.get(owner) else {
            problems.push(format!("class {owner} (a property table) is not declared"));
            continue;
        };
        for row in &rows {
            if !members.iter().any(|m| m.name == *row && !m.function) {
                problems.push(format!("{owner}.{row} is a row but not declared"));
            }
        }
        for m in members.iter().filter(|_| all_rows.contains(&owner)) {
            // Signals are members of their own kind, not property rows.
            let ty = m.ty.trim_end_matches('?');
            let signal = ty == "Signal" || ty.starts_with("Signal<");
            if !m.function && !signal && !rows.contains(&m.name.as_str()) {
                problems.push(format!(
                    "{owner}.{} is declared but the runtime has no row for it",
                    m.name
                ));
            }
        }
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

/// Names the runtime registers as methods or module functions, from the sources of
/// `lua-client/src/api/` and `values/`: `add_method("X"`, `add_function("X"`,
/// `add_method_mut("X"` and `.set("X", lua.create_function` / `create_async_function`.
fn registered_names() -> BTreeMap<String, String> {
    let mut names = BTreeMap::new();
    let mut files = Vec::new();
    let mut dirs = vec![
        repo().join("lua-client/src/api"),
        repo().join("lua-client/src/values"),
    ];
    // A type with its rows beside it is a folder (`api/plane/{mod.rs, props.rs}`).
    while let Some(dir) = dirs.pop() {
        for entry in std::fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                dirs.push(path);
            } else {
                files.push(path);
            }
        }
    }
    for path in files {
        let text = std::fs::read_to_string(&path).unwrap();
        let file = path.display().to_string();
        // Join lines so `t.set(\n "X",\n lua.create_function(` reads as one.
        let flat: String = text.split_whitespace().collect::<Vec<_>>().join(" ");
        for pat in [
            "add_method(\"",
            "add_method_mut(\"",
            "add_function(\"",
            "add_function_mut(\"",
            ".set( \"",
            ".set(\"",
        ] {
            let mut rest = flat.as_str();
            while let Some(i) = rest.find(pat) {
                rest = &rest[i + pat.len()..];
                let Some(end) = rest.find('"') else { break };
                let name = &rest[..end];
                let after = rest[end + 1..].trim_start_matches([',', ' ']);
                let is_function = !pat.starts_with(".set")
                    || after.starts_with("lua.create_function")
                    || after.starts_with("lua.create_async_function");
                let word = !name.is_empty()
                    && name.chars().all(|c| c.is_alphanumeric() || c == '_')
                    && name.chars().next().unwrap().is_uppercase();
                if is_function && word {
                    names.entry(name.to_string()).or_insert(file.clone());
                }
            }
        }
    }
    names
}

#[test]
fn registered_methods_are_declared() {
    let d = Definitions::load();
    let all = d.all_names();
    let registered = registered_names();
    assert!(
        registered.len() > 50,
        "the scan found only {} method names: {registered:?}",
        registered.len()
    );
    let missing: Vec<String> = registered
        .iter()
        .filter(|(name, _)| !all.contains(*name))
        .map(|(name, file)| format!("{name} (registered in {file})"))
        .collect();
    assert!(
        missing.is_empty(),
        "registered by the runtime but not declared in physics.d.luau:\n{}",
        missing.join("\n")
    );
}

/// Every declared member of every class, and every field of every module, exists at run
/// time on a real instance (through physics-lua, against a real daemon).
#[test]
fn every_declared_member_exists_at_run_time() {
    let d = Definitions::load();
    let mut decl = String::from("local DECL = {\n");
    for (class, members) in &d.classes {
        decl.push_str(&format!("\t{class} = {{"));
        for m in members {
            decl.push_str(&format!(
                " {{ {:?}, {}, {} }},",
                m.name,
                m.function,
                m.ty.ends_with('?')
            ));
        }
        decl.push_str(" },\n");
    }
    // Host objects declared as (generic) table types rather than classes: their fields
    // are methods.
    for table in ["Signal"] {
        let fields = d
            .own_fields
            .get(table)
            .unwrap_or_else(|| panic!("type {table} not declared"));
        decl.push_str(&format!("\t{table} = {{"));
        for f in fields {
            decl.push_str(&format!(" {{ {f:?}, true, false }},"));
        }
        decl.push_str(" },\n");
    }
    decl.push_str("}\nlocal MODULES = {\n");
    for (table, module) in [
        ("PhysicsServiceModule", "PhysicsService"),
        ("RenderableModule", "Renderable"),
        ("PrimitivesModule", "Primitives"),
        ("GUIModule", "GUI"),
    ] {
        let fields = d
            .own_fields
            .get(table)
            .unwrap_or_else(|| panic!("type {table} not declared"));
        let top: Vec<String> = fields.iter().map(|f| format!("{f:?}")).collect();
        decl.push_str(&format!("\t{module} = {{ {} }},\n", top.join(", ")));
    }
    decl.push_str("}\n");
    // The script declares both tables empty on marked lines (so it type-checks on its own);
    // the generated ones take the place of the first.
    let body = std::fs::read_to_string(repo().join("tests/lua/definitions.luau")).unwrap();
    let marker = "-- filled in by lua_definitions.rs";
    let mut replaced = 0;
    let body: Vec<&str> = body
        .lines()
        .map(|l| {
            if l.ends_with(marker) {
                replaced += 1;
                if replaced == 1 {
                    return decl.as_str();
                }
                return "";
            }
            l
        })
        .collect();
    assert_eq!(replaced, 2, "definitions.luau must mark DECL and MODULES");
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR"));
    let script = dir.join(format!("definitions-{}.luau", std::process::id()));
    std::fs::write(&script, body.join("\n")).unwrap();

    let daemon = TestDaemon::start("lua-defs");
    let out = physics_lua(&daemon.domain, script.to_str().unwrap(), &[])
        .output()
        .expect("run physics-lua");
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stdout}\n{stderr}");
    let checked: usize = stdout
        .lines()
        .find_map(|l| l.strip_prefix("definitions ok "))
        .unwrap_or_else(|| panic!("no verdict: {stdout}\n{stderr}"))
        .trim()
        .parse()
        .unwrap();
    let declared: usize = d.classes.values().map(Vec::len).sum();
    assert!(
        checked >= declared * 9 / 10,
        "checked {checked} of {declared}"
    );
}

/// Members a script uses: `.Name` or `:Name` after an identifier, `)` or `]`, outside
/// strings and comments.
fn used_members(source: &str) -> BTreeSet<String> {
    let mut used = BTreeSet::new();
    for line in source.lines() {
        let code = line.split_once("--").map_or(line, |(c, _)| c);
        // Strings out (the scripts use "..." and '...'; error-message checks hold names).
        let mut clean = String::new();
        let mut quote = None;
        for c in code.chars() {
            match (quote, c) {
                (None, '"' | '\'') => quote = Some(c),
                (Some(q), c) if c == q => quote = None,
                (None, c) => clean.push(c),
                _ => {}
            }
        }
        let chars: Vec<char> = clean.chars().collect();
        for i in 1..chars.len() {
            if (chars[i] == '.' || chars[i] == ':')
                && (chars[i - 1].is_alphanumeric() || matches!(chars[i - 1], ')' | ']' | '_'))
                && chars.get(i + 1).is_some_and(|c| c.is_ascii_uppercase())
            {
                let name: String = chars[i + 1..]
                    .iter()
                    .take_while(|c| c.is_alphanumeric() || **c == '_')
                    .collect();
                used.insert(name);
            }
        }
    }
    used
}

/// Names given as fields in the script's own table constructors (`{ Foo = 1 }`, `, Foo = `)
/// and functions it defines on its own tables (`function t.Foo(`, `function t:Foo(`).
fn constructor_fields(source: &str) -> BTreeSet<String> {
    let chars: Vec<char> = source.chars().collect();
    let mut out = BTreeSet::new();
    for part in source.split("function ").skip(1) {
        let head: String = part
            .chars()
            .take_while(|c| c.is_alphanumeric() || matches!(c, '_' | '.' | ':'))
            .collect();
        if let Some(i) = head.rfind(['.', ':']) {
            out.insert(head[i + 1..].to_string());
        }
    }
    let mut i = 0;
    while i < chars.len() {
        if chars[i].is_alphabetic() || chars[i] == '_' {
            let start = i;
            while i < chars.len() && (chars[i].is_alphanumeric() || chars[i] == '_') {
                i += 1;
            }
            let prev = chars[..start].iter().rev().find(|c| !c.is_whitespace());
            let mut j = i;
            while j < chars.len() && chars[j].is_whitespace() {
                j += 1;
            }
            if matches!(prev, Some('{') | Some(','))
                && chars.get(j) == Some(&'=')
                && chars.get(j + 1) != Some(&'=')
            {
                out.insert(chars[start..i].iter().collect());
            }
            continue;
        }
        i += 1;
    }
    out
}

#[test]
fn scripts_use_only_declared_members() {
    let d = Definitions::load();
    let all = d.all_names();
    // Scripts that use undeclared members on purpose (to check the runtime's errors) list
    // them on a line `-- undeclared: A, B`.
    let mut problems = Vec::new();
    let mut scripts = 0;
    for dir in ["examples", "tests/lua", "examples/scenarios"] {
        for entry in std::fs::read_dir(repo().join(dir)).unwrap() {
            let path = entry.unwrap().path();
            if path.extension().is_none_or(|e| e != "luau") {
                continue;
            }
            scripts += 1;
            let text = std::fs::read_to_string(&path).unwrap();
            let allowed: BTreeSet<String> = text
                .lines()
                .filter_map(|l| l.trim().strip_prefix("-- undeclared:"))
                .flat_map(|l| {
                    l.split(|c: char| !(c.is_alphanumeric() || c == '_'))
                        .filter(|w| !w.is_empty())
                        .map(str::to_string)
                        .collect::<Vec<_>>()
                })
                .collect();
            // Fields of tables the script builds itself (`local t = { Foo = 1 }`, `t.Foo`).
            let own = constructor_fields(&text);
            for name in used_members(&text) {
                if !all.contains(&name) && !allowed.contains(&name) && !own.contains(&name) {
                    problems.push(format!("{}: {name}", path.display()));
                }
            }
        }
    }
    assert!(scripts > 20, "only {scripts} scripts found");
    assert!(
        problems.is_empty(),
        "members used by scripts but not declared in physics.d.luau:\n{}",
        problems.join("\n")
    );
}

/// The settings tables' Lua rows (rows flagged `lua`) are declared with the Luau type of
/// their kind: the declaration and the table cannot disagree on what a property holds.
#[test]
fn settings_table_rows_declare_their_kind() {
    use client_sdk::settings::table::{PropKind, PropRow};
    let d = Definitions::load();
    let mut problems = Vec::new();
    let tables: [(&str, &[PropRow]); 4] = [
        ("Controller", client_sdk::ControllerProp::ROWS),
        ("PhysicsObject", client_sdk::ObjectProp::ROWS),
        ("PhysicsPlane", client_sdk::PlaneProp::ROWS),
        ("PhysicsGuiObject", client_sdk::GuiObjectProp::ROWS),
    ];
    let mut checked = 0;
    for (owner, rows) in tables {
        let members = &d.classes[owner];
        for row in rows.iter().filter(|r| r.lua) {
            let want = match row.kind {
                PropKind::Bool => "boolean",
                PropKind::Float | PropKind::Integer { .. } => "number",
                // Declared as the class Vector (Luau's `vector` at run time; see physics.d.luau).
                PropKind::Vector => "Vector",
                PropKind::Vector2 => "Dim",
                PropKind::Pose => "CFrame",
                PropKind::Other => "(no Luau type)",
            };
            match members.iter().find(|m| m.name == row.name && !m.function) {
                Some(m) if m.ty == want => checked += 1,
                Some(m) => problems.push(format!(
                    "{owner}.{} is declared {} but its row holds a {want}",
                    row.name, m.ty
                )),
                None => problems.push(format!("{owner}.{} is not declared", row.name)),
            }
        }
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
    // Objects: Weight, Bounciness, Friction, ... ; planes: every option.
    assert!(checked >= 25, "only {checked} rows checked");
}

//! `docs/lua-api.md` is generated: the Luau API reference comes from the two places that
//! define it, the settings tables (`shm-layout/src/settings/{plane,object}.rs`: name, default,
//! accepted values, doc of each plane option and object property) and the definitions file
//! (`lua-client/types/physics.d.luau`: every class, member, type and their comments). This
//! test renders the page and fails when the committed page differs, so the reference cannot
//! drift from the code. Regenerate with
//!
//! ```text
//! PHYSICS_UPDATE_DOCS=1 cargo test -p integration-tests --test lua api_doc
//! ```

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use shm_layout::settings::table::{PropKind, PropRow, Range};
use shm_layout::settings::{ObjectProp, PlaneProp};

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// One block of the definitions file: a class, a type or a global, with its comment.
#[derive(Debug)]
struct Block {
    /// `class`, `type` or `global`.
    what: &'static str,
    name: String,
    doc: String,
    /// Members of a class: (declaration, comment).
    members: Vec<(String, String)>,
    /// The declaration's text (types and globals).
    text: String,
}

/// Splits `code -- comment` (a `--` inside a string literal is not expected in the file).
fn split_comment(line: &str) -> (&str, &str) {
    match line.split_once("--") {
        Some((code, comment)) => (code.trim_end(), comment.trim()),
        None => (line.trim_end(), ""),
    }
}

fn join_doc(lines: &mut Vec<String>) -> String {
    let doc = lines.join(" ");
    lines.clear();
    doc
}

fn parse_definitions(text: &str) -> Vec<Block> {
    let mut blocks = Vec::new();
    let mut pending: Vec<String> = Vec::new();
    let mut lines = text.lines().skip_while(|l| !l.trim().is_empty()).peekable();
    while let Some(line) = lines.next() {
        let trimmed = line.trim();
        if trimmed.is_empty() {
            pending.clear();
            continue;
        }
        if let Some(comment) = trimmed.strip_prefix("--") {
            pending.push(comment.trim().to_string());
            continue;
        }
        if let Some(name) = trimmed.strip_prefix("declare class ") {
            let doc = join_doc(&mut pending);
            let mut members = Vec::new();
            for member in lines.by_ref() {
                let m = member.trim();
                if m == "end" {
                    break;
                }
                if let Some(comment) = m.strip_prefix("--") {
                    pending.push(comment.trim().to_string());
                    continue;
                }
                let (code, comment) = split_comment(m);
                if !comment.is_empty() {
                    pending.push(comment.to_string());
                }
                members.push((code.to_string(), join_doc(&mut pending)));
            }
            blocks.push(Block {
                what: "class",
                name: name.trim().to_string(),
                doc,
                members,
                text: String::new(),
            });
            continue;
        }
        let (what, rest) = if let Some(r) = trimmed.strip_prefix("export type ") {
            ("type", r)
        } else if let Some(r) = trimmed.strip_prefix("type ") {
            ("type", r)
        } else if let Some(r) = trimmed.strip_prefix("declare function ") {
            ("global", r)
        } else if let Some(r) = trimmed.strip_prefix("declare ") {
            ("global", r)
        } else {
            continue;
        };
        let name: String = rest
            .chars()
            .take_while(|c| c.is_alphanumeric() || *c == '_')
            .collect();
        let mut text = line.to_string();
        // A table type spans lines until its braces close.
        let mut depth = line.matches('{').count() as i64 - line.matches('}').count() as i64;
        while depth > 0 {
            let Some(next) = lines.next() else { break };
            depth += next.matches('{').count() as i64 - next.matches('}').count() as i64;
            text.push('\n');
            text.push_str(next);
        }
        blocks.push(Block {
            what,
            name,
            doc: join_doc(&mut pending),
            members: Vec::new(),
            text,
        });
    }
    blocks
}

/// Text for one table cell: on one line, pipes escaped.
fn cell(s: &str) -> String {
    s.split_whitespace()
        .collect::<Vec<_>>()
        .join(" ")
        .replace('|', "\\|")
}

/// A default as users write it: vectors as `(x, y, z)` without trailing `.0`s.
fn value_text(text: String) -> String {
    if text.starts_with("Pose {") {
        return "identity".into();
    }
    let Some(inner) = text.strip_prefix('[').and_then(|t| t.strip_suffix(']')) else {
        return text;
    };
    let parts: Vec<String> = inner
        .split(", ")
        .map(|p| p.trim_end_matches(".0").to_string())
        .collect();
    format!("({})", parts.join(", "))
}

fn range_text(kind: PropKind, range: Range) -> String {
    match kind {
        PropKind::Bool => return "true / false".into(),
        PropKind::Other => return "see notes".into(),
        PropKind::Pose => return "a CFrame".into(),
        PropKind::Integer { min, max } if range == Range::Any => return format!("[{min}, {max}]"),
        _ => {}
    }
    match range {
        Range::Any => "any finite value".into(),
        Range::NonNegative => "≥ 0".into(),
        Range::Positive => "> 0".into(),
        Range::AtLeast(x) => format!("≥ {}", x as f32),
        Range::Within(lo, hi) => format!("[{lo}, {hi}]"),
        Range::Clamped(lo, hi) => format!("clamped to [{lo}, {hi}]"),
        Range::Bounded(max) => format!("components within ±{max}"),
        Range::UnitAxes(a, b) => format!("{a} and {b} within [-1, 1]"),
        Range::Extent => format!(
            "components within [{}, {}]",
            shm_layout::validate::MIN_SIZE,
            shm_layout::validate::MAX_SIZE
        ),
    }
}

/// A settings table as a markdown table: name, default, accepted values, notes.
fn rows_table(out: &mut String, rows: &[PropRow], defaults: &[String]) {
    out.push_str("| Name | Default | Accepts | Notes |\n|---|---|---|---|\n");
    for (row, default) in rows.iter().zip(defaults) {
        // Rustdoc links read as code here.
        let mut notes = row.doc.trim().replace("[`", "`").replace("`]", "`");
        if row.creation_only {
            notes.push_str(" *Creation only.*");
        }
        if row.cpu_only {
            notes.push_str(" *CPU planes only (a DeferGpu plane refuses other values).*");
        }
        let _ = writeln!(
            out,
            "| `{}` | `{}` | {} | {} |",
            row.name,
            cell(default),
            cell(&range_text(row.kind, row.range)),
            cell(&notes)
        );
    }
    out.push('\n');
}

fn render() -> String {
    let definitions = std::fs::read_to_string(repo().join("lua-client/types/physics.d.luau"))
        .expect("read physics.d.luau");
    let blocks = parse_definitions(&definitions);
    let mut out = String::new();
    out.push_str(
        "# Luau API reference\n\n\
         <!-- Generated by tests/tests/lua/api_doc.rs; do not edit. Regenerate with\n\
         PHYSICS_UPDATE_DOCS=1 cargo test -p integration-tests --test lua api_doc -->\n\n\
         Generated from the settings tables (`shm-layout/src/settings/plane.rs`, `object.rs`) and\n\
         the definitions file `lua-client/types/physics.d.luau`; a test fails when this page\n\
         differs from them. How the API behaves, with examples: [lua.md](lua.md),\n\
         [api-3d.md](api-3d.md), [controllers.md](controllers.md), [gui.md](gui.md),\n\
         [snapshots.md](snapshots.md).\n\n",
    );
    out.push_str("## Contents\n\n- [Plane options](#plane-options)\n- [Object properties](#object-properties)\n");
    for b in &blocks {
        if b.what == "class" {
            let _ = writeln!(
                out,
                "- class [`{}`](#class-{})",
                b.name,
                b.name.to_lowercase()
            );
        }
    }
    out.push_str("- [Types](#types)\n- [Globals](#globals)\n\n");

    out.push_str(
        "## Plane options\n\n`PhysicsService.New{ … }` takes them; each is also a property of \
         the plane (`plane.Gravity = …`) unless marked creation only. Rust: `PlaneProp`.\n\n",
    );
    let defaults: Vec<String> = PlaneProp::DEFAULTS
        .iter()
        .map(|p| value_text(p.value_text()))
        .collect();
    rows_table(&mut out, PlaneProp::ROWS, &defaults);
    out.push_str(
        "## Object properties\n\nProperties of a `PhysicsObject` (and of its `BasePart` where \
         the class declares them). Rust: `ObjectProp`.\n\n",
    );
    let defaults: Vec<String> = ObjectProp::DEFAULTS
        .iter()
        .map(|p| value_text(p.value_text()))
        .collect();
    rows_table(&mut out, ObjectProp::ROWS, &defaults);

    for b in blocks.iter().filter(|b| b.what == "class") {
        let _ = writeln!(out, "## class {}\n", b.name);
        if !b.doc.is_empty() {
            let _ = writeln!(out, "{}\n", b.doc);
        }
        out.push_str("| Member | Notes |\n|---|---|\n");
        // A property without a comment of its own takes its settings row's doc.
        let rows: &[PropRow] = match b.name.as_str() {
            "PhysicsPlane" => PlaneProp::ROWS,
            "PhysicsObject" | "BasePart" => ObjectProp::ROWS,
            _ => &[],
        };
        for (decl, doc) in &b.members {
            let name = decl.split([':', '(']).next().unwrap_or("").trim();
            let row_doc = rows.iter().find(|r| r.name == name).map(|r| r.doc.trim());
            let doc = match row_doc {
                Some(row_doc) if doc.is_empty() => row_doc.replace("[`", "`").replace("`]", "`"),
                _ => doc.clone(),
            };
            let _ = writeln!(out, "| `{}` | {} |", cell(decl), cell(&doc));
        }
        out.push('\n');
    }
    out.push_str("## Types\n\n");
    for b in blocks.iter().filter(|b| b.what == "type") {
        let _ = writeln!(out, "### {}\n", b.name);
        if !b.doc.is_empty() {
            let _ = writeln!(out, "{}\n", b.doc);
        }
        let _ = writeln!(out, "```luau\n{}\n```\n", b.text.trim_end());
    }
    out.push_str("## Globals\n\n");
    for b in blocks.iter().filter(|b| b.what == "global") {
        let _ = writeln!(out, "```luau\n{}\n```\n", b.text.trim_end());
        if !b.doc.is_empty() {
            let _ = writeln!(out, "{}\n", b.doc);
        }
    }
    out.trim_end().to_string() + "\n"
}

#[test]
fn lua_api_page_is_generated_from_the_tables_and_definitions() {
    let page = render();
    let path = repo().join("docs/lua-api.md");
    if std::env::var_os("PHYSICS_UPDATE_DOCS").is_some() {
        std::fs::write(&path, &page).expect("write docs/lua-api.md");
        return;
    }
    let committed = std::fs::read_to_string(&path).unwrap_or_default();
    if committed != page {
        let line = committed
            .lines()
            .zip(page.lines())
            .position(|(a, b)| a != b)
            .map_or(committed.lines().count().min(page.lines().count()), |i| i)
            + 1;
        panic!(
            "docs/lua-api.md differs from the settings tables and physics.d.luau (first at line \
             {line}); regenerate it with\n  PHYSICS_UPDATE_DOCS=1 cargo test -p \
             integration-tests --test lua api_doc"
        );
    }
}

#[test]
fn every_row_and_class_is_on_the_page() {
    let page = render();
    for row in PlaneProp::ROWS.iter().chain(ObjectProp::ROWS) {
        assert!(
            page.contains(&format!("| `{}` |", row.name)),
            "{} missing",
            row.name
        );
    }
    for class in [
        "PhysicsPlane",
        "PhysicsObject",
        "BasePart",
        "Controller",
        "Joint",
        "Map",
    ] {
        assert!(
            page.contains(&format!("## class {class}\n")),
            "{class} missing"
        );
    }
    // A member's comment follows it into the page.
    assert!(page.contains("| `Unit: Vector` | zero for the zero vector |"));
}

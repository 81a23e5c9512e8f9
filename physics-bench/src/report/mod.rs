//! Writing reports: `NAME.json` (machine-readable) and `NAME.md` (for people) in one folder.
//!
//! The JSON holds the bench's fields, `run` (the machine, the date, the build and the command
//! line: [`run::Run`]) and `body_md` (the bench's tables and notes, rendered by the bench
//! from the same fields). The page is rendered from that JSON alone ([`page::render`]), so
//! `physics-bench render` can render it again, into docs/reports/, without a rerun.
//!
//! - [`table`]: markdown tables and figures.
//! - [`goal`]: goals and their table.
//! - [`run`]: where and how a report was made.
//! - [`page`]: the page and the index of a folder of reports.

pub mod goal;
pub mod page;
pub mod run;
pub mod table;

use std::path::{Path, PathBuf};

pub use goal::{goals_table, Goal};
pub use table::{mib, num, Table};

use super::error::{BenchError, BenchResult};

/// A report as stored: the bench's fields, then where it ran and its page's body.
#[derive(serde::Serialize)]
struct Stored<'a, T: serde::Serialize> {
    #[serde(flatten)]
    report: &'a T,
    run: run::Run,
    body_md: &'a str,
}

/// Writes `dir/name.json` and `dir/name.md`, creating `dir`. `json` serialises to a JSON
/// object (its fields stay at the top level); `body` is the bench's markdown, a `# ` title
/// first. Returns both paths.
pub fn write(
    dir: &Path,
    name: &str,
    json: &impl serde::Serialize,
    body: &str,
) -> BenchResult<(PathBuf, PathBuf)> {
    std::fs::create_dir_all(dir).map_err(BenchError::io(format!(
        "create the output folder --out {}",
        dir.display()
    )))?;
    let json_path = dir.join(format!("{name}.json"));
    let stored = Stored {
        report: json,
        run: run::Run::here(name),
        body_md: body,
    };
    let failed = |e: String| BenchError::Failed(format!("encode {}: {e}", json_path.display()));
    let value = serde_json::to_value(&stored).map_err(|e| failed(e.to_string()))?;
    let markdown = page::render(&value).map_err(failed)?;
    let text = serde_json::to_string_pretty(&stored).map_err(|e| failed(e.to_string()))?;
    std::fs::write(&json_path, text + "\n")
        .map_err(BenchError::io(format!("write {}", json_path.display())))?;
    let md_path = dir.join(format!("{name}.md"));
    std::fs::write(&md_path, markdown)
        .map_err(BenchError::io(format!("write {}", md_path.display())))?;
    Ok((json_path, md_path))
}

/// Prints the page at `md_path` (written by [`write()`]) to stdout.
pub fn print(md_path: &Path) {
    match std::fs::read_to_string(md_path) {
        Ok(page) => println!("{page}"),
        Err(e) => eprintln!("read {}: {e}", md_path.display()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(serde::Serialize)]
    struct Small {
        bodies: usize,
        goals: Vec<Goal>,
    }

    #[test]
    fn write_keeps_the_fields_and_renders_the_page_from_the_json() {
        let dir = std::env::temp_dir().join(format!("report-write-{}", std::process::id()));
        let small = Small {
            bodies: 3,
            goals: vec![Goal::new("three bodies", "3", Some(true))],
        };
        let (json, md) = write(&dir, "small", &small, "# Small\n\nA table.\n").unwrap();
        let value: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
        assert_eq!(value["bodies"], 3);
        assert_eq!(value["run"]["bench"], "small");
        assert!(value["run"]["machine"]["cores"].as_u64().unwrap() >= 1);
        let page = std::fs::read_to_string(&md).unwrap();
        assert_eq!(page, page::render(&value).unwrap());
        assert!(page.contains("| three bodies | 3 | met |"), "{page}");
        let _ = std::fs::remove_dir_all(&dir);
    }
}

//! Writing reports: `NAME.json` (machine-readable) and `NAME.md` (for people) in one folder.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use super::error::{BenchError, BenchResult};

/// A goal of a report, what was measured, and whether it was met (`None`: not judged).
#[derive(Debug, Clone, serde::Serialize)]
pub struct Goal {
    pub goal: String,
    pub value: String,
    pub met: Option<bool>,
}

impl Goal {
    pub fn new(goal: impl Into<String>, value: impl Into<String>, met: Option<bool>) -> Goal {
        Goal {
            goal: goal.into(),
            value: value.into(),
            met,
        }
    }
}

/// The markdown table of `goals`.
pub fn goals_table(goals: &[Goal]) -> String {
    let mut t = Table::new(&["goal", "measured", "verdict"]);
    for g in goals {
        t.row(&[g.goal.clone(), g.value.clone(), verdict(g.met).into()]);
    }
    t.finish()
}

/// Bytes as MiB with sensible digits.
pub fn mib(bytes: f64) -> String {
    num(Some(bytes / (1024.0 * 1024.0)))
}

/// Writes `dir/name.json` and `dir/name.md`, creating `dir`. Returns both paths.
pub fn write(
    dir: &Path,
    name: &str,
    json: &impl serde::Serialize,
    markdown: &str,
) -> BenchResult<(PathBuf, PathBuf)> {
    std::fs::create_dir_all(dir).map_err(BenchError::io(format!(
        "create the output folder --out {}",
        dir.display()
    )))?;
    let json_path = dir.join(format!("{name}.json"));
    let text = serde_json::to_string_pretty(json)
        .map_err(|e| BenchError::Failed(format!("encode {}: {e}", json_path.display())))?;
    std::fs::write(&json_path, text + "\n")
        .map_err(BenchError::io(format!("write {}", json_path.display())))?;
    let md_path = dir.join(format!("{name}.md"));
    std::fs::write(&md_path, markdown)
        .map_err(BenchError::io(format!("write {}", md_path.display())))?;
    Ok((json_path, md_path))
}

/// A markdown table built row by row.
pub struct Table {
    text: String,
}

impl Table {
    pub fn new(headers: &[&str]) -> Table {
        let mut text = format!("| {} |\n", headers.join(" | "));
        let _ = writeln!(text, "|{}", "---|".repeat(headers.len()));
        Table { text }
    }

    pub fn row(&mut self, cells: &[String]) {
        let _ = writeln!(self.text, "| {} |", cells.join(" | "));
    }

    pub fn finish(self) -> String {
        self.text
    }
}

/// A figure with a sensible number of digits for a table ("—" when missing).
pub fn num(v: Option<f64>) -> String {
    match v {
        None => "—".into(),
        Some(v) if !v.is_finite() => "—".into(),
        Some(v) if v.abs() >= 100.0 => format!("{v:.0}"),
        Some(v) if v.abs() >= 10.0 => format!("{v:.1}"),
        Some(v) => format!("{v:.2}"),
    }
}

/// "met" / "not met" / "n/a" for a goal.
pub fn verdict(met: Option<bool>) -> &'static str {
    match met {
        Some(true) => "met",
        Some(false) => "**not met**",
        None => "n/a",
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_and_tables() {
        assert_eq!(num(Some(1234.56)), "1235");
        assert_eq!(num(Some(12.345)), "12.3");
        assert_eq!(num(Some(1.2345)), "1.23");
        assert_eq!(num(None), "—");
        assert_eq!(num(Some(f64::NAN)), "—");
        let mut t = Table::new(&["a", "b"]);
        t.row(&["1".into(), "2".into()]);
        assert_eq!(t.finish(), "| a | b |\n|---|---|\n| 1 | 2 |\n");
    }
}

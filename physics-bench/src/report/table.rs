//! Markdown tables and the figures in their cells.

use std::fmt::Write as _;

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

/// Bytes as MiB with sensible digits.
pub fn mib(bytes: f64) -> String {
    num(Some(bytes / (1024.0 * 1024.0)))
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

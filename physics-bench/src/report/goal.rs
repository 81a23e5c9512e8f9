//! A report's goals: what each bench promises, what it measured, and the verdict.

use super::table::{verdict, Table};

/// A goal of a report, what was measured, and whether it was met (`None`: not judged).
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
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

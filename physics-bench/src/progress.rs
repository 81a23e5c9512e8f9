//! Progress of a long bench run: one bar counting phases, plus result lines above it.

use std::time::Duration;

use indicatif::{ProgressBar, ProgressStyle};

pub struct Progress {
    bar: ProgressBar,
}

impl Progress {
    pub fn new(phases: u64) -> Progress {
        let bar = ProgressBar::new(phases);
        bar.set_style(
            ProgressStyle::with_template("{elapsed:>4} [{bar:30}] {pos}/{len} {msg}")
                .unwrap_or_else(|_| ProgressStyle::default_bar())
                .progress_chars("=> "),
        );
        bar.enable_steady_tick(Duration::from_millis(200));
        Progress { bar }
    }

    /// Names the phase now running.
    pub fn phase(&self, what: impl Into<String>) {
        self.bar.set_message(what.into());
    }

    /// Marks one phase done.
    pub fn done(&self) {
        self.bar.inc(1);
    }

    /// Prints a line above the bar (plainly on stderr when the bar is hidden, e.g. in CI).
    pub fn note(&self, line: impl AsRef<str>) {
        if self.bar.is_hidden() {
            eprintln!("{}", line.as_ref());
        } else {
            self.bar.println(line.as_ref());
        }
    }

    pub fn finish(&self) {
        self.bar.finish_and_clear();
    }
}

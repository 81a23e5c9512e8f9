//! Where and how a report was made: the machine, the date, the build and the command line.
//! Recorded in every report's JSON (`run`) and shown in its page's header.

use std::time::{SystemTime, UNIX_EPOCH};

/// The machine a report was measured on.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Machine {
    /// The CPU model (`model name` of /proc/cpuinfo).
    pub cpu: String,
    /// Cores this process may run on.
    pub cores: usize,
    /// Total memory, GiB (/proc/meminfo).
    pub memory_gib: f64,
    /// The distribution (/etc/os-release) and the kernel release.
    pub os: String,
}

/// How and where one report was made.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Run {
    /// The report's name: the page is `NAME.md`, the JSON `NAME.json`.
    pub bench: String,
    /// When the report was written, UTC (`YYYY-MM-DDTHH:MM:SSZ`).
    pub date_utc: String,
    /// `debug` or `release`: the profile physics-bench was built with.
    pub profile: String,
    /// The command line, program name first.
    pub command: String,
    pub machine: Machine,
    /// The 1, 5 and 15 minute load averages when the report was written (/proc/loadavg):
    /// above the core count, other work ran beside the bench.
    pub load_average: [f64; 3],
}

impl Run {
    /// This process's run of `bench`, now.
    pub fn here(bench: &str) -> Run {
        let secs = SystemTime::now()
            .duration_since(UNIX_EPOCH)
            .map_or(0, |d| d.as_secs());
        Run {
            bench: bench.into(),
            date_utc: utc_date(secs),
            profile: if cfg!(debug_assertions) {
                "debug"
            } else {
                "release"
            }
            .into(),
            command: command_line(std::env::args()),
            machine: Machine::here(),
            load_average: load_average(),
        }
    }
}

impl Machine {
    /// The machine this process runs on; "unknown" for what cannot be read.
    pub fn here() -> Machine {
        let read = |path: &str| std::fs::read_to_string(path).unwrap_or_default();
        let cpuinfo = read("/proc/cpuinfo");
        let cpu = field(&cpuinfo, "model name")
            .or_else(|| field(&cpuinfo, "Model"))
            .or_else(|| field(&cpuinfo, "Hardware"))
            .unwrap_or_else(|| "unknown CPU".into());
        let memory_kib: f64 = field(&read("/proc/meminfo"), "MemTotal")
            .and_then(|v| v.split_whitespace().next()?.parse().ok())
            .unwrap_or(0.0);
        let distribution = read("/etc/os-release")
            .lines()
            .find_map(|l| l.strip_prefix("PRETTY_NAME="))
            .map(|v| v.trim_matches('"').to_string())
            .unwrap_or_else(|| std::env::consts::OS.into());
        let kernel = read("/proc/sys/kernel/osrelease").trim().to_string();
        Machine {
            cpu,
            cores: std::thread::available_parallelism().map_or(1, |n| n.get()),
            memory_gib: (memory_kib / (1024.0 * 1024.0) * 10.0).round() / 10.0,
            os: if kernel.is_empty() {
                distribution
            } else {
                format!("{distribution}, kernel {kernel}")
            },
        }
    }
}

/// The value of `key: value` in a /proc text (the first such line).
fn field(text: &str, key: &str) -> Option<String> {
    text.lines().find_map(|l| {
        let (k, v) = l.split_once(':')?;
        (k.trim() == key).then(|| v.trim().to_string())
    })
}

fn load_average() -> [f64; 3] {
    let text = std::fs::read_to_string("/proc/loadavg").unwrap_or_default();
    let mut v = text.split_whitespace().map(|x| x.parse().unwrap_or(0.0));
    [
        v.next().unwrap_or(0.0),
        v.next().unwrap_or(0.0),
        v.next().unwrap_or(0.0),
    ]
}

/// `args` as one line: the program by its file name, arguments with spaces or quotes
/// single-quoted.
pub fn command_line(args: impl IntoIterator<Item = String>) -> String {
    let mut args = args.into_iter();
    let program = args.next().map_or_else(
        || "physics-bench".to_string(),
        |p| {
            std::path::Path::new(&p)
                .file_name()
                .map_or(p.clone(), |n| n.to_string_lossy().into_owned())
        },
    );
    std::iter::once(program)
        .chain(args.map(|a| {
            if a.is_empty() || a.contains(|c: char| c.is_whitespace() || "'\"$`\\".contains(c)) {
                format!("'{}'", a.replace('\'', r"'\''"))
            } else {
                a
            }
        }))
        .collect::<Vec<_>>()
        .join(" ")
}

/// Seconds since the Unix epoch as `YYYY-MM-DDTHH:MM:SSZ` (the proleptic Gregorian
/// calendar, days to civil date after Howard Hinnant's algorithm).
pub fn utc_date(secs: u64) -> String {
    let days = (secs / 86_400) as i64;
    let rem = secs % 86_400;
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1_460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let day = doy - (153 * mp + 2) / 5 + 1;
    let month = if mp < 10 { mp + 3 } else { mp - 9 };
    let year = yoe + era * 400 + i64::from(month <= 2);
    format!(
        "{year:04}-{month:02}-{day:02}T{:02}:{:02}:{:02}Z",
        rem / 3_600,
        rem % 3_600 / 60,
        rem % 60
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dates_and_command_lines() {
        assert_eq!(utc_date(0), "1970-01-01T00:00:00Z");
        assert_eq!(utc_date(951_782_400), "2000-02-29T00:00:00Z");
        assert_eq!(utc_date(1_798_761_599), "2026-12-31T23:59:59Z");
        let args = ["/x/target/debug/physics-bench", "fuzz", "--out", "a b"];
        assert_eq!(
            command_line(args.map(String::from)),
            "physics-bench fuzz --out 'a b'"
        );
    }

    #[test]
    fn the_machine_is_read_from_proc() {
        let m = Machine::here();
        assert!(m.cores >= 1);
        assert!(!m.cpu.is_empty() && !m.os.is_empty());
    }
}

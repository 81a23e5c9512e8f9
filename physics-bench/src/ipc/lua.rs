//! What reads cost a Luau script: 1,000 `part.CFrame` reads per frame
//! (`examples/cframe_cost.luau`) and one `obj.Weight` / `plane.LinearDamping` read
//! (`examples/property_cost.luau`), each run by the `physics-lua` next to this executable
//! against a daemon of its own.

use std::path::PathBuf;
use std::process::Command;

use crate::daemon::DaemonProcess;
use crate::error::{BenchError, BenchResult};
use crate::estimator::Estimator;

const CFRAME_COST: &str = include_str!("../../../examples/cframe_cost.luau");
const PROPERTY_COST: &str = include_str!("../../../examples/property_cost.luau");

#[derive(Debug, Clone, serde::Serialize)]
pub struct LuaReads {
    /// [`Estimator::WallMedianOfSamples`]: the medians the scripts print.
    pub estimator: Estimator,
    /// Median per frame, µs.
    pub cframe_x1000_us: f64,
    pub cframe_x1000_second_read_us: f64,
    pub table_x1000_us: f64,
    /// Median per read, µs.
    pub weight_read_us: f64,
    pub linear_damping_read_us: f64,
    /// Values the daemon derives each tick: the tick header's count, a body's flags.
    pub object_count_read_us: f64,
    pub sleeping_read_us: f64,
}

fn physics_lua() -> BenchResult<PathBuf> {
    let exe = std::env::current_exe().map_err(BenchError::io("current exe"))?;
    let lua = exe.with_file_name("physics-lua");
    if lua.is_file() {
        Ok(lua)
    } else {
        Err(BenchError::Failed(format!(
            "{} not found: build it with the bench (cargo build --release --workspace --bins)",
            lua.display()
        )))
    }
}

/// Runs `script` and returns its stdout.
fn run(name: &str, script: &str) -> BenchResult<String> {
    let daemon = DaemonProcess::start("lua")?;
    let path = std::env::temp_dir().join(format!("{}-{name}", daemon.domain));
    std::fs::write(&path, script).map_err(BenchError::io(format!("write {}", path.display())))?;
    let out = Command::new(physics_lua()?)
        .arg(&path)
        .args(["--domain", &daemon.domain, "--seconds", "30"])
        .env("PHYSICS_LOG", "warn")
        .output()
        .map_err(BenchError::io("run physics-lua"));
    let _ = std::fs::remove_file(&path);
    let out = out?;
    if !out.status.success() {
        return Err(BenchError::Failed(format!(
            "physics-lua {name} failed: {}",
            String::from_utf8_lossy(&out.stderr)
        )));
    }
    Ok(String::from_utf8_lossy(&out.stdout).into_owned())
}

/// The median (µs) printed on the line starting with `label`.
fn median(text: &str, label: &str) -> BenchResult<f64> {
    text.lines()
        .find(|l| l.trim_start().starts_with(label))
        .and_then(|l| l.split("median").nth(1))
        .and_then(|rest| rest.split_whitespace().next())
        .and_then(|v| v.parse().ok())
        .ok_or_else(|| BenchError::Failed(format!("no \"{label}\" median in:\n{text}")))
}

pub fn measure() -> BenchResult<LuaReads> {
    let cframe = run("cframe_cost.luau", CFRAME_COST)?;
    let props = run("property_cost.luau", PROPERTY_COST)?;
    Ok(LuaReads {
        estimator: Estimator::WallMedianOfSamples,
        cframe_x1000_us: median(&cframe, "part.CFrame x1000 ")?,
        cframe_x1000_second_read_us: median(&cframe, "part.CFrame x1000 (2nd")?,
        table_x1000_us: median(&cframe, "table.field x1000")?,
        weight_read_us: median(&props, "obj.Weight x1000")? / 1000.0,
        linear_damping_read_us: median(&props, "plane.LinearDamping x1000")? / 1000.0,
        object_count_read_us: median(&props, "plane.ObjectCount x1000")? / 1000.0,
        sleeping_read_us: median(&props, "obj.Sleeping x1000")? / 1000.0,
    })
}

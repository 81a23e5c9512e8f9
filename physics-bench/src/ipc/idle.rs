//! What an idle daemon costs: CPU over a window with no client, then with one client holding
//! an idle manual plane.

use std::time::Duration;

use client_sdk::{PlaneOptions, Pose, Shape};

use crate::daemon::DaemonProcess;
use crate::error::BenchResult;
use crate::estimator::Estimator;
use crate::procfs::cpu_percent_over;
use crate::progress::Progress;

#[derive(Debug, Clone, serde::Serialize)]
pub struct IdleCpu {
    /// [`Estimator::CpuOverWindow`].
    pub estimator: Estimator,
    pub no_clients: f64,
    pub idle_manual_plane: f64,
    pub window_s: f64,
}

pub fn run(window: Duration, progress: &Progress) -> BenchResult<IdleCpu> {
    let daemon = DaemonProcess::start("idle")?;
    // Let the start-up (and the readiness check's connection) finish before the window.
    std::thread::sleep(Duration::from_secs(2));
    progress.phase(format!("idle CPU, no clients ({} s)", window.as_secs()));
    let no_clients = cpu_percent_over(daemon.pid(), window)?;
    progress.done();

    progress.phase(format!(
        "idle CPU, one manual plane ({} s)",
        window.as_secs()
    ));
    let client = daemon.connect()?;
    let plane = client.create_plane(&PlaneOptions::manual())?;
    plane.add(
        Shape::Sphere { radius: 0.5 },
        Pose::at([0.0, 1.0, 0.0]),
        &[],
    )?;
    std::thread::sleep(Duration::from_secs(1));
    let idle_manual_plane = cpu_percent_over(daemon.pid(), window)?;
    progress.done();
    Ok(IdleCpu {
        estimator: Estimator::CpuOverWindow,
        no_clients,
        idle_manual_plane,
        window_s: window.as_secs_f64(),
    })
}

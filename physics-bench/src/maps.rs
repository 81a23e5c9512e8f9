//! `physics-bench maps`: a generated heightfield of about 1,000,000 triangles loaded as a
//! triangle-mesh map into a real daemon (upload and build time, daemon memory before and
//! after), then 1,000 boxes dropped on it and, once they rest (kept awake: NeverSleep), the
//! daemon's step cost (the tick header's step time) next to the same boxes on a flat box
//! floor.

use std::path::PathBuf;
use std::time::{Duration, Instant};

use client_sdk::map::MapMesh;
use client_sdk::{MapOptions, Plane, PlaneOptions, Pose, Shape};

use super::daemon::DaemonProcess;
use super::error::{BenchError, BenchResult};
use super::procfs;
use super::report::{self, mib, num, Table};

/// Options of the `maps` subcommand.
#[derive(Debug, Clone, clap::Args)]
pub struct MapsArgs {
    /// Triangles of the generated map (a square grid of quads, two triangles each).
    #[arg(long, default_value_t = 1_000_000)]
    pub triangles: usize,
    /// Boxes dropped on it.
    #[arg(long, default_value_t = 1_000)]
    pub boxes: usize,
    /// Ticks measured once the boxes rest.
    #[arg(long, default_value_t = 120)]
    pub ticks: usize,
    /// Folder receiving maps.json and maps.md.
    #[arg(long, default_value = "bench-out")]
    pub out: PathBuf,
}

#[derive(Debug, Clone, serde::Serialize)]
pub struct MapsReport {
    pub triangles: usize,
    pub vertices: usize,
    /// Bytes of vertex and index data sent.
    pub upload_bytes: u64,
    /// Upload and build, seen by the client (`load_map_meshes`).
    pub load_s: f64,
    pub daemon_rss_before_bytes: u64,
    pub daemon_rss_after_bytes: u64,
    pub boxes: usize,
    /// Mean and worst step time (daemon's own figure) with the boxes resting on the map.
    pub step_mean_us_map: f64,
    pub step_max_us_map: f64,
    /// The same on an anchored box floor.
    pub step_mean_us_floor: f64,
    /// Boxes resting on the map (|v| < 0.5, awake) at the end.
    pub resting_on_map: usize,
}

/// `n × n` quads over `n` units with gentle hills, shared vertices.
fn heightfield(n: usize) -> MapMesh {
    let half = n as f32 / 2.0;
    let mut m = MapMesh::default();
    for i in 0..=n {
        for j in 0..=n {
            let (x, z) = (i as f32 - half, j as f32 - half);
            m.vertices
                .push([x, 0.5 * (x / 7.0).sin() * (z / 9.0).cos(), z]);
        }
    }
    let at = |i: usize, j: usize| (i * (n + 1) + j) as u32;
    for i in 0..n {
        for j in 0..n {
            let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
            m.triangles.push([a, c, b]);
            m.triangles.push([a, d, c]);
        }
    }
    m
}

/// Drops `count` unit boxes in a grid over the middle of the ground, lets them settle,
/// then returns the daemon's step times (µs) over `ticks` ticks and the boxes at rest.
fn boxes_on(plane: &Plane, count: usize, ticks: usize) -> BenchResult<(Vec<f64>, usize)> {
    let side = (count as f64).sqrt().ceil() as usize;
    let mut objects = Vec::with_capacity(count);
    for k in 0..count {
        let (i, j) = (k / side, k % side);
        let at = [
            (i as f32 - side as f32 / 2.0) * 2.0,
            3.0,
            (j as f32 - side as f32 / 2.0) * 2.0,
        ];
        objects.push(plane.add(Shape::Cube { size: [1.0; 3] }, Pose::at(at), &[])?);
    }
    // Two seconds to land and settle.
    for _ in 0..120 {
        plane.step(1.0 / 60.0)?;
    }
    let mut times = Vec::with_capacity(ticks);
    for _ in 0..ticks {
        plane.step(1.0 / 60.0)?;
        times.push(plane.snapshot()?.header().step_time_us as f64);
    }
    let mut resting = 0;
    for o in &objects {
        let v = o.velocity()?;
        if v.iter().map(|c| c * c).sum::<f32>().sqrt() < 0.5 {
            resting += 1;
        }
    }
    Ok((times, resting))
}

fn mean(v: &[f64]) -> f64 {
    v.iter().sum::<f64>() / v.len().max(1) as f64
}

pub fn run(args: &MapsArgs) -> BenchResult<()> {
    let n = ((args.triangles as f64 / 2.0).sqrt().round() as usize).max(1);
    let mesh = heightfield(n);
    let (nv, nt) = (mesh.vertices.len(), mesh.triangles.len());
    // The map counts its vertices and triangles against the client's mesh quota while it
    // uploads: raise it for this run.
    let quota = ((nv + nt) as u64 * 2).max(1_000_000).to_string();
    let daemon = DaemonProcess::start_with(
        "maps",
        &["--max-mesh-vertices-per-client".to_string(), quota],
        None,
    )?;
    let client = daemon.connect()?;
    // NeverSleep: resting boxes would otherwise fall asleep and cost nothing per step; the
    // figure wanted is the contact work of 1,000 boxes on the map.
    let options = PlaneOptions {
        tick_rate: Some(0.0),
        never_sleep: Some(true),
        ..PlaneOptions::default()
    };
    let plane = client.create_plane(&options)?;
    std::thread::sleep(Duration::from_millis(200));
    let rss_before = procfs::rss_bytes(daemon.pid())?;
    let started = Instant::now();
    let map = plane.load_map_meshes(std::slice::from_ref(&mesh), &MapOptions::default())?;
    let load_s = started.elapsed().as_secs_f64();
    let rss_after = procfs::rss_bytes(daemon.pid())?;
    if map.report.triangles as usize != nt {
        return Err(BenchError::Failed(format!(
            "the map holds {} triangles, {nt} were sent",
            map.report.triangles
        )));
    }
    let (map_times, resting) = boxes_on(&plane, args.boxes, args.ticks)?;

    let flat = client.create_plane(&options)?;
    let floor = flat.add(
        Shape::Cube {
            size: [n as f32 + 10.0, 1.0, n as f32 + 10.0],
        },
        Pose::at([0.0, -0.5, 0.0]),
        &[],
    )?;
    floor.set_anchored(true)?;
    let (floor_times, _) = boxes_on(&flat, args.boxes, args.ticks)?;

    let report = MapsReport {
        triangles: nt,
        vertices: nv,
        upload_bytes: (nv * 12 + nt * 12) as u64,
        load_s,
        daemon_rss_before_bytes: rss_before,
        daemon_rss_after_bytes: rss_after,
        boxes: args.boxes,
        step_mean_us_map: mean(&map_times),
        step_max_us_map: map_times.iter().copied().fold(0.0, f64::max),
        step_mean_us_floor: mean(&floor_times),
        resting_on_map: resting,
    };
    let md = markdown(&report);
    let (json, md_path) = report::write(&args.out, "maps", &report, &md)?;
    report::print(&md_path);
    println!("wrote {} and {}", json.display(), md_path.display());
    Ok(())
}

fn markdown(r: &MapsReport) -> String {
    let mut t = Table::new(&["figure", "value"]);
    let rows = [
        (
            "triangles / vertices",
            format!("{} / {}", r.triangles, r.vertices),
        ),
        ("vertex + index data (MiB)", mib(r.upload_bytes as f64)),
        ("load (upload + build), s", num(Some(r.load_s))),
        (
            "daemon RSS before (MiB)",
            mib(r.daemon_rss_before_bytes as f64),
        ),
        (
            "daemon RSS after (MiB)",
            mib(r.daemon_rss_after_bytes as f64),
        ),
        (
            "map memory (RSS growth, MiB)",
            mib(r
                .daemon_rss_after_bytes
                .saturating_sub(r.daemon_rss_before_bytes) as f64),
        ),
        (
            "boxes resting on the map",
            format!("{} of {}", r.resting_on_map, r.boxes),
        ),
        (
            "step, boxes on the map: mean µs",
            num(Some(r.step_mean_us_map)),
        ),
        (
            "step, boxes on the map: worst µs",
            num(Some(r.step_max_us_map)),
        ),
        (
            "step, boxes on a box floor: mean µs",
            num(Some(r.step_mean_us_floor)),
        ),
    ];
    for (k, v) in rows {
        t.row(&[k.to_string(), v]);
    }
    format!(
        "# Triangle-mesh map: {} triangles, {} boxes\n\n{}",
        r.triangles,
        r.boxes,
        t.finish()
    )
}

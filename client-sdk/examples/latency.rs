//! Measures the figures of the foundation: daemon idle CPU, one request round trip, and the
//! time from a tick's end to this process holding its poses.
//!
//! cargo build --release --workspace && target/release/examples/latency [DOMAIN]

use std::time::{Duration, Instant};

use client_sdk::{connect_or_start, PlaneOptions, Pose, Shape};
use shm_layout::monotonic_ns;

fn cpu_ticks(pid: u32) -> u64 {
    let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).unwrap_or_default();
    let after_name = stat.rsplit(')').next().unwrap_or("");
    let f: Vec<&str> = after_name.split_whitespace().collect();
    // utime and stime are fields 14 and 15 of the line, 12 and 13 after the name.
    f.get(11).and_then(|v| v.parse::<u64>().ok()).unwrap_or(0)
        + f.get(12).and_then(|v| v.parse::<u64>().ok()).unwrap_or(0)
}

fn idle_cpu_percent(pid: u32, seconds: u64) -> f64 {
    let hz = 100.0; // USER_HZ on Linux
    let before = cpu_ticks(pid);
    std::thread::sleep(Duration::from_secs(seconds));
    (cpu_ticks(pid) - before) as f64 / hz / seconds as f64 * 100.0
}

fn percentiles(mut v: Vec<f64>) -> (f64, f64, f64) {
    v.sort_by(|a, b| a.partial_cmp(b).unwrap());
    let p = |q: f64| v[((v.len() - 1) as f64 * q).round() as usize];
    (p(0.5), p(0.99), *v.last().unwrap())
}

fn main() -> Result<(), client_sdk::Error> {
    let domain = std::env::args()
        .nth(1)
        .unwrap_or_else(|| format!("latency-{}", std::process::id()));
    let session = connect_or_start(&domain)?;
    let pid = session.daemon_pid();

    println!(
        "daemon idle CPU, 10 s, no planes:        {:.3} %",
        idle_cpu_percent(pid, 10)
    );
    let manual = session.create_plane(&PlaneOptions::manual())?;
    let ball = manual.add(
        Shape::Sphere { radius: 0.5 },
        Pose::at([0.0, 1.0, 0.0]),
        &[],
    )?;
    println!(
        "daemon idle CPU, 10 s, one manual plane: {:.3} %",
        idle_cpu_percent(pid, 10)
    );

    let mut rtt = Vec::new();
    for i in 0..5000 {
        ball.set_velocity([i as f32 * 1e-3, 0.0, 0.0])?;
        let t = Instant::now();
        session.flush()?;
        rtt.push(t.elapsed().as_secs_f64() * 1e6);
    }
    let (p50, p99, max) = percentiles(rtt);
    println!("request round trip (1 SetVelocity):      p50 {p50:.1} us  p99 {p99:.1} us  max {max:.1} us");

    for n in [1_000usize, 10_000] {
        let plane = session.create_plane(&PlaneOptions {
            gravity: Some([0.0; 3]),
            tick_rate: Some(60.0),
            ..Default::default()
        })?;
        let side = (n as f64).cbrt().ceil() as usize;
        for i in 0..n {
            let (x, y, z) = (i % side, (i / side) % side, i / (side * side));
            plane.add(
                Shape::Cube { size: [0.5; 3] },
                Pose::at([x as f32, y as f32, z as f32]),
                &[client_sdk::ObjectProp::Velocity([0.1, 0.0, 0.0])],
            )?;
        }
        let mut delivery = Vec::new();
        let mut steps = Vec::new();
        for _ in 0..240 {
            plane.wait_tick(Duration::from_secs(2))?;
            let snap = plane.snapshot()?;
            let seen = monotonic_ns();
            // Touch every pose, as a reader would.
            let sum: f32 = snap.bodies().iter().map(|b| b.position[0]).sum();
            std::hint::black_box(sum);
            delivery.push((seen - snap.header().tick_end_ns) as f64 / 1e3);
            steps.push(snap.header().step_time_us as f64);
        }
        let (d50, d99, dmax) = percentiles(delivery);
        let (s50, _, _) = percentiles(steps);
        println!(
            "{n:>6} bodies: tick end -> client holds poses p50 {d50:.1} us  p99 {d99:.1} us  max {dmax:.1} us   (step p50 {s50:.0} us)"
        );
        plane.destroy()?;
    }
    Ok(())
}

//! A ball falls onto an anchored floor and bounces. Starts a daemon if none runs.
//!
//! cargo run --example falling_ball [-- DOMAIN]

use client_sdk::{connect_or_start, PlaneOptions, Pose, Shape};

fn main() -> Result<(), client_sdk::Error> {
    let domain = std::env::args().nth(1).unwrap_or_else(|| "physics".into());
    let client = connect_or_start(&domain)?;
    let plane = client.create_plane(&PlaneOptions::manual())?;
    let floor = plane.add(
        Shape::Cube {
            size: [20.0, 1.0, 20.0],
        },
        Pose::at([0.0, -0.5, 0.0]),
        &[],
    )?;
    floor.set_anchored(true)?;
    let ball = plane.add(
        Shape::Sphere { radius: 0.5 },
        Pose::at([0.0, 10.0, 0.0]),
        &[],
    )?;
    for frame in 0..=90 {
        plane.step(1.0 / 60.0)?;
        if frame % 10 == 0 {
            let p = ball.position()?;
            let v = ball.velocity()?;
            let h = plane.snapshot()?.header().to_owned();
            println!(
                "t={:5.3}s  y={:7.3}  vy={:8.3}  step={:6.1}us  penetration={:.4}",
                h.sim_time, p[1], v[1], h.step_time_us, h.max_penetration
            );
        }
    }
    plane.destroy()?;
    Ok(())
}

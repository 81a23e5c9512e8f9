//! A timer-driven plane moves its ticks to just after its game's frames (`server/frame_phase.rs`
//! in the daemon): a game that flushes its writes at a steady point of every frame gets the
//! plane's next tick right after that flush (the step runs while the game sleeps, and takes
//! the frame's writes with no wait), and the plane keeps its tick rate.

use std::time::Duration;

use client_sdk::{Client, ConnectOptions, ObjectProp, PlaneOptions, PlaneProp, Pose, Shape};
use integration_tests::TestDaemon;
use shm_layout::monotonic_ns;

const PERIOD_NS: u64 = 16_666_667;

fn sleep_until(at_ns: u64) {
    let now = monotonic_ns();
    if at_ns > now {
        std::thread::sleep(Duration::from_nanos(at_ns - now));
    }
}

/// One attempt: a 60 Hz plane and a 60 fps "game" that flushes a velocity write half a
/// period after the plane's ticks. Returns the median delay from sending the write to the
/// end of the first tick that carries it over the last 60 frames, and the ticks the plane
/// made over the last 120.
fn attempt(daemon: &TestDaemon) -> (f64, u64) {
    let mut options = ConnectOptions::new(&daemon.domain);
    options.refusals_at_next_call = true;
    let client = Client::connect_with(options).unwrap();
    let plane = client
        .create_plane(&PlaneOptions::manual().with(PlaneProp::Gravity([0.0, 0.0, 0.0])))
        .unwrap();
    let ball = plane
        .add(
            Shape::Sphere { radius: 0.5 },
            Pose::at([0.0, 5.0, 0.0]),
            &[],
        )
        .unwrap();
    client.flush().unwrap();
    plane.set_now(PlaneProp::TickRate(60.0)).unwrap();
    plane.wait_tick(Duration::from_secs(10)).unwrap();
    let t0 = plane.snapshot().unwrap().header().tick_end_ns;
    let frames = 300u64;
    let mut delays = Vec::new();
    let mut ticks = Vec::new();
    let slot = ball.handle().slot as usize;
    for k in 1..=frames {
        // Mid-period after the plane's ticks as they were at the start.
        sleep_until(t0 + k * PERIOD_NS + PERIOD_NS / 2);
        let v = (k % 7) as f32 * 0.01;
        let sent = monotonic_ns();
        ball.set(ObjectProp::Velocity([v, 0.0, 0.0])).unwrap();
        client.flush().unwrap();
        // The first tick that carries the write (consecutive frames' velocities differ by
        // 0.01): its end, from when the write was sent. Looked for in the newest sample
        // first (on a busy machine the tick can end before this thread runs again).
        let mut waited = 0;
        let header = loop {
            let snapshot = plane.snapshot().unwrap();
            let vx = snapshot.bodies()[slot].linear_velocity[0];
            // Damping may take a little off: the others are 0.01 away.
            if snapshot.header().tick_end_ns > sent && (vx - v).abs() < 0.004 {
                break *snapshot.header();
            }
            waited += 1;
            assert!(
                waited < 30,
                "frame {k}: no tick carried velocity {v} (last {vx})"
            );
            plane.wait_tick(Duration::from_secs(10)).unwrap();
        };
        if k > frames - 60 {
            delays.push(header.tick_end_ns.saturating_sub(sent) as f64 / 1e6);
        }
        if k > frames - 120 {
            ticks.push(header.tick);
        }
    }
    delays.sort_by(f64::total_cmp);
    let made = ticks.last().unwrap() - ticks.first().unwrap();
    (delays[delays.len() / 2], made)
}

#[test]
fn ticks_move_to_just_after_a_steady_frame_end_and_keep_their_rate() {
    let daemon = TestDaemon::start("frame-phase");
    // Without the phase following, the tick ends half a period (8.3 ms) after each write.
    // A loaded machine can scatter the frames past what is followed: up to three attempts.
    let mut seen = Vec::new();
    for _ in 0..3 {
        let (median_ms, made) = attempt(&daemon);
        // 119 intervals of frames at 60 fps: the plane's own rate (± scheduling slips).
        assert!(
            (114..=124).contains(&made),
            "the plane made {made} ticks over 119 frame intervals"
        );
        if median_ms < 3.0 {
            return;
        }
        seen.push(median_ms);
    }
    panic!("the ticks did not follow the frames: median write → tick end {seen:?} ms");
}

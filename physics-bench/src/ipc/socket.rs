//! The baseline users would write without shared memory: poses gathered from the world into
//! a Vec, serialised with serde (postcard), sent over a Unix socket to another thread, which
//! reads and deserialises them.

use std::io::{Read, Write};
use std::os::unix::net::UnixStream;
use std::time::Duration;

use physics_scenes::LocalPlane;
use shm_layout::monotonic_ns;

use crate::error::{BenchError, BenchResult};

/// What a typical state message carries per body.
#[derive(Debug, Clone, Copy, serde::Serialize, serde::Deserialize)]
struct WireBody {
    position: [f32; 3],
    rotation: [f32; 4],
    linear_velocity: [f32; 3],
    angular_velocity: [f32; 3],
    flags: u32,
    generation: u32,
}

/// Time from "tick end" (just before gathering) until the receiving thread holds every pose,
/// in microseconds, for `ticks` messages. Messages go at 60 Hz, the zero-copy side's tick
/// rate, so the receiver waits for each like the zero-copy client waits for a tick: blocked
/// in `read`, or, with `poll`, spinning on a non-blocking socket (as the zero-copy client
/// spins on its shared-memory queue).
pub fn delivery_us(plane: &LocalPlane, ticks: usize, poll: bool) -> BenchResult<Vec<f64>> {
    let (mut tx, rx) = UnixStream::pair().map_err(BenchError::io("create a socket pair"))?;
    rx.set_nonblocking(poll)
        .map_err(BenchError::io("set the receiver's blocking mode"))?;
    let receiver = std::thread::spawn(move || receive(rx, ticks));
    let mut wire: Vec<WireBody> = Vec::new();
    let mut ack = [0u8; 1];
    for _ in 0..ticks {
        std::thread::sleep(Duration::from_micros(16_667));
        let tick_end = monotonic_ns();
        wire.clear();
        wire.extend((0..plane.slot_count()).map(|i| {
            let b = plane.body_state(i);
            WireBody {
                position: b.position,
                rotation: b.rotation,
                linear_velocity: b.linear_velocity,
                angular_velocity: b.angular_velocity,
                flags: b.flags,
                generation: b.generation,
            }
        }));
        let bytes = postcard::to_stdvec(&wire)
            .map_err(|e| BenchError::Failed(format!("serialise poses: {e}")))?;
        let sent = tx
            .write_all(&(bytes.len() as u64).to_le_bytes())
            .and_then(|_| tx.write_all(&tick_end.to_le_bytes()))
            .and_then(|_| tx.write_all(&bytes))
            .and_then(|_| tx.read_exact(&mut ack));
        if let Err(e) = sent {
            // The receiver's own error says more than a broken pipe.
            drop(tx);
            return match receiver.join() {
                Ok(Err(inner)) => Err(inner),
                _ => Err(BenchError::io("send poses over the socket")(e)),
            };
        }
    }
    receiver
        .join()
        .map_err(|_| BenchError::Failed("the socket receiver thread panicked".into()))?
}

fn receive(mut rx: UnixStream, ticks: usize) -> BenchResult<Vec<f64>> {
    let mut latencies = Vec::with_capacity(ticks);
    let mut buf = Vec::new();
    let mut header = [0u8; 16];
    for _ in 0..ticks {
        read_full(&mut rx, &mut header).map_err(BenchError::io("read a pose message header"))?;
        let len = u64::from_le_bytes(header[..8].try_into().unwrap_or_default()) as usize;
        let tick_end = u64::from_le_bytes(header[8..].try_into().unwrap_or_default());
        buf.resize(len, 0);
        read_full(&mut rx, &mut buf).map_err(BenchError::io("read a pose message"))?;
        let poses: Vec<WireBody> = postcard::from_bytes(&buf)
            .map_err(|e| BenchError::Failed(format!("deserialise poses: {e}")))?;
        // Decoded: the poses are held.
        latencies.push(monotonic_ns().saturating_sub(tick_end) as f64 / 1e3);
        let sum: f32 = poses
            .iter()
            .map(|b| b.position[0] + b.position[1] + b.position[2] + b.rotation[3])
            .sum();
        std::hint::black_box(sum);
        rx.write_all(&[1])
            .map_err(BenchError::io("acknowledge a pose message"))?;
    }
    Ok(latencies)
}

/// `read_exact` that also works on a non-blocking socket, spinning while nothing is there.
fn read_full(rx: &mut UnixStream, mut buf: &mut [u8]) -> std::io::Result<()> {
    while !buf.is_empty() {
        match rx.read(buf) {
            Ok(0) => return Err(std::io::ErrorKind::UnexpectedEof.into()),
            Ok(n) => buf = &mut buf[n..],
            Err(e) if e.kind() == std::io::ErrorKind::WouldBlock => std::hint::spin_loop(),
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
    Ok(())
}

//! Ticks that land after the game's frame: a timer-driven plane moves the phase of its
//! schedule toward the moment its clients' frames end, without changing its rate.
//!
//! A game at 60 frames per second and a 60 Hz plane on the other core run side by side: on
//! a machine of two cores the step (milliseconds of the plane's worker) overlaps the game's
//! own frame work about half the time, and the game's frame is slower then (caches and
//! memory shared; `physics-bench frame`: 1.21 × the frame without physics). A game's frame
//! ends with one flush of its writes, then the game sleeps to its next frame. When those
//! flushes come at a steady phase of the plane's period, the worker moves its next tick
//! toward just after them, at most [`MAX_SHIFT_OF_PERIOD`] of a period per tick: the step
//! then runs while the game sleeps, and takes the frame's writes with no wait.
//!
//! Only a steady phase is followed: a "frame end" is a request followed by a quiet stretch
//! of at least a quarter period (continuous traffic has none), and the phase of those frame
//! ends must agree within [`STEADY`] (a game at a frame rate that is no multiple of the
//! plane's drifts through every phase and is not followed). The plane keeps its rate: each
//! shift is bounded, and once on the phase there is nothing left to shift. The shifts of one
//! schedule add up to at most half a period either way ([`MAX_TOTAL_OF_PERIOD`]): any phase
//! is at most that far, and a client whose frames follow the ticks themselves (it waits for
//! a tick, works, flushes) moves its frame ends with every shift, so following it would
//! chase it for ever and slow the plane; the bound stops that after half a period, once.

use std::time::{Duration, Instant};

/// Most a tick moves toward the frames' phase, as a share of the period (1/32: half a
/// millisecond at 60 Hz).
pub const MAX_SHIFT_OF_PERIOD: u32 = 32;
/// Frame ends whose phases scatter more than this (mean absolute deviation) are not followed.
pub const STEADY: Duration = Duration::from_millis(1);
/// Time from the frame's end to the tick that follows it: room for the request loop to
/// apply the frame's writes first on a busy machine (with 0.3 ms, two CPU hogs beside a
/// test made the write miss its tick most frames).
pub const MARGIN: Duration = Duration::from_millis(1);
/// The shifts of one schedule add up to at most 1/this of a period either way.
pub const MAX_TOTAL_OF_PERIOD: u32 = 2;
/// Frame ends seen before the phase is followed.
const WARM_UP: u32 = 8;
/// Weight of a new frame end in the running phase and deviation.
const WEIGHT: f64 = 1.0 / 8.0;

/// The phase of a plane's clients' frame ends, and how steady it is.
#[derive(Debug, Clone)]
pub struct FramePhase {
    /// Where phases are counted from.
    origin: Instant,
    /// The latest request not yet known to be a frame end (another may follow soon).
    last: Option<Instant>,
    /// Running phase of the frame ends in the period, ns (in `[0, period)`).
    phase_ns: f64,
    /// Running mean absolute deviation of the frame ends from `phase_ns`, ns.
    deviation_ns: f64,
    /// Frame ends seen (saturating).
    seen: u32,
    /// The period the phase is kept for.
    period: Duration,
    /// Sum of the shifts applied so far, ns (later positive).
    shifted_ns: f64,
}

impl FramePhase {
    /// A phase for a schedule of `period` starting at `origin`.
    pub fn new(origin: Instant, period: Duration) -> Self {
        FramePhase {
            origin,
            last: None,
            phase_ns: 0.0,
            deviation_ns: 0.0,
            seen: 0,
            period,
            shifted_ns: 0.0,
        }
    }

    fn period_ns(&self) -> f64 {
        self.period.as_nanos() as f64
    }

    /// `d` wrapped into `[-period/2, period/2)`.
    fn wrap(&self, d: f64) -> f64 {
        let p = self.period_ns();
        (d + p / 2.0).rem_euclid(p) - p / 2.0
    }

    fn phase_of(&self, at: Instant) -> f64 {
        let since = at.saturating_duration_since(self.origin).as_nanos() as f64;
        since.rem_euclid(self.period_ns())
    }

    /// A client's request reached the plane at `at`.
    pub fn request(&mut self, at: Instant) {
        if let Some(last) = self.last {
            if at.saturating_duration_since(last) >= self.period / 4 {
                self.frame_end(last);
            }
        }
        self.last = Some(at);
    }

    /// Records the pending request as a frame end once a quarter period passed without
    /// another (called at each tick).
    fn settle(&mut self, now: Instant) {
        if let Some(last) = self.last {
            if now.saturating_duration_since(last) >= self.period / 4 {
                self.frame_end(last);
                self.last = None;
            }
        }
    }

    fn frame_end(&mut self, at: Instant) {
        let phase = self.phase_of(at);
        if self.seen == 0 {
            self.phase_ns = phase;
            self.deviation_ns = 0.0;
        } else {
            let off = self.wrap(phase - self.phase_ns);
            self.phase_ns = (self.phase_ns + WEIGHT * off).rem_euclid(self.period_ns());
            self.deviation_ns += WEIGHT * (off.abs() - self.deviation_ns);
        }
        self.seen = self.seen.saturating_add(1);
    }

    /// Whether the frame ends are steady enough to follow.
    pub fn steady(&self) -> bool {
        self.seen >= WARM_UP && self.deviation_ns <= STEADY.as_nanos() as f64
    }

    /// The next tick, `next` as the schedule has it, moved at most
    /// 1/[`MAX_SHIFT_OF_PERIOD`] of a period toward [`MARGIN`] after the frames' phase when
    /// that phase is steady; `next` itself otherwise. `now`: the time of the call.
    pub fn next_tick(&mut self, next: Instant, now: Instant) -> Instant {
        self.settle(now);
        if !self.steady() {
            return next;
        }
        let target = self.phase_ns + MARGIN.as_nanos() as f64;
        let d = self.wrap(target - self.phase_of(next));
        let cap = self.period_ns() / MAX_SHIFT_OF_PERIOD as f64;
        let total = self.period_ns() / MAX_TOTAL_OF_PERIOD as f64;
        let shift = d
            .clamp(-cap, cap)
            .clamp(-total - self.shifted_ns, total - self.shifted_ns);
        let by = Duration::from_nanos(shift.abs() as u64);
        let moved = if shift >= 0.0 {
            next + by
        } else {
            // Never into the past: a tick is not brought forward before now.
            next.checked_sub(by).map_or(next, |t| t.max(now))
        };
        self.shifted_ns += if moved >= next {
            (moved - next).as_nanos() as f64
        } else {
            -((next - moved).as_nanos() as f64)
        };
        moved
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const P: Duration = Duration::from_micros(16_667);

    /// Runs `ticks` ticks of a 60 Hz schedule whose client ends a frame every
    /// `frame` at `offset` after the schedule's start; returns the tick times.
    fn run(frame: Duration, offset: Duration, ticks: usize, busy: bool) -> Vec<Instant> {
        let origin = Instant::now();
        let mut phase = FramePhase::new(origin, P);
        let mut next = origin + P;
        let mut frame_end = origin + offset;
        let mut out = Vec::new();
        let mut busy_at = origin;
        for _ in 0..ticks {
            if busy {
                // Continuous traffic: a request every millisecond.
                while busy_at <= next {
                    phase.request(busy_at);
                    busy_at += Duration::from_millis(1);
                }
            } else {
                while frame_end <= next {
                    phase.request(frame_end);
                    frame_end += frame;
                }
            }
            out.push(next);
            next = phase.next_tick(next + P, next);
        }
        out
    }

    fn phase_of(origin: Instant, t: Instant, period: Duration) -> f64 {
        (t - origin).as_nanos() as f64 % period.as_nanos() as f64
    }

    #[test]
    fn ticks_move_to_just_after_steady_frame_ends_and_keep_the_rate() {
        let offset = Duration::from_micros(5_000);
        let ticks = run(P, offset, 200, false);
        let origin = ticks[0] - P;
        // The last ticks land MARGIN after the frame ends' phase (within 10 µs).
        for &t in &ticks[150..] {
            let got = phase_of(origin, t, P);
            let want = (offset + MARGIN).as_nanos() as f64;
            assert!(
                (got - want).abs() < 10_000.0,
                "tick phase {got} ns, want {want}"
            );
        }
        // Every step between ticks stays within a period ± 1/32.
        for w in ticks.windows(2) {
            let gap = (w[1] - w[0]).as_nanos() as f64;
            let p = P.as_nanos() as f64;
            assert!((gap - p).abs() <= p / 32.0 + 1.0, "gap {gap}");
        }
        // The rate is kept: once locked, 50 ticks take 50 periods.
        let span = (ticks[199] - ticks[149]).as_nanos() as f64;
        assert!((span - 50.0 * P.as_nanos() as f64).abs() < 1_000.0);
    }

    #[test]
    fn a_game_at_half_the_rate_is_followed_too() {
        let offset = Duration::from_micros(9_000);
        let ticks = run(P * 2, offset, 200, false);
        let origin = ticks[0] - P;
        let got = phase_of(origin, ticks[199], P);
        let want = ((offset + MARGIN).as_nanos() as f64) % P.as_nanos() as f64;
        assert!(
            (got - want).abs() < 10_000.0,
            "tick phase {got} ns, want {want}"
        );
    }

    #[test]
    fn a_client_that_follows_the_ticks_moves_the_schedule_half_a_period_at_most() {
        // The client waits for each tick, works 11 ms and flushes: its frame ends move with
        // every shift of the ticks.
        let origin = Instant::now();
        let mut phase = FramePhase::new(origin, P);
        let mut next = origin + P;
        let mut ticks = Vec::new();
        for _ in 0..600 {
            ticks.push(next);
            phase.request(next + Duration::from_millis(11));
            let now = next + Duration::from_millis(12);
            next = phase.next_tick(next + P, now);
        }
        // 599 periods, give or take the half period the shifts may add up to.
        let span = (ticks[599] - ticks[0]).as_nanos() as f64;
        let p = P.as_nanos() as f64;
        assert!(
            (span - 599.0 * p).abs() <= p / 2.0 + 1.0,
            "600 ticks took {span} ns, {} periods",
            span / p
        );
        // And past that bound the schedule stays put.
        for w in ticks[300..].windows(2) {
            assert_eq!(w[1] - w[0], P);
        }
    }

    #[test]
    fn drifting_frames_and_continuous_traffic_leave_the_schedule_alone() {
        for (frame, busy) in [(Duration::from_micros(20_000), false), (P, true)] {
            let ticks = run(frame, Duration::from_micros(5_000), 200, busy);
            for w in ticks.windows(2) {
                assert_eq!(
                    w[1] - w[0],
                    P,
                    "frame {frame:?} busy {busy}: the schedule moved"
                );
            }
        }
    }
}

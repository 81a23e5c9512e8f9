//! Waiting without paying the scheduler: a reader that knows when its answer is due polls
//! shared memory for a bounded time around that moment instead of sleeping through it.
//!
//! A thread woken by an event pays the scheduler's wake-up latency (tens of microseconds on
//! a quiet machine, hundreds on a loaded one); on a small step that is most of what a tick
//! through the daemon costs over one in process. Two waits here know when their answer is
//! due: a `Step`'s reply (about the plane's last step time after the request) and the next
//! tick of a timer-driven plane (the last tick's end plus its dt). They sleep until shortly
//! before, poll (yielding the core between looks: on a machine with few cores the daemon's
//! threads that produce the answer may need it) until a bounded time after, and only then
//! sleep on the event. The polling is bounded so an idle reader costs nothing and a late
//! answer costs at most [`MAX_SPIN`] of one core.

use std::time::Duration;

use shm_layout::TickHeader;

/// How long before its polling window a tick wait stops sleeping on the tick event and
/// sleeps on a precise timer instead: the event's timed wait ends on the kernel's socket
/// timeout, which is rounded up to its tick (milliseconds; measured here: a reader dozing
/// on the event until the window held the sample 81 µs after the tick at the median, one
/// sleeping on a timer 22 µs). A tick that comes early within this last stretch is seen
/// when the window opens, at most this much late.
pub const COARSE: Duration = Duration::from_millis(9);

/// The most a wait polls before it sleeps on its event.
pub const MAX_SPIN: Duration = Duration::from_millis(2);

/// How much earlier than predicted the polling starts: the scheduler's late wake-up from a
/// timed sleep plus the jitter of the prediction.
pub const LEAD: Duration = Duration::from_micros(300);

/// How long after the predicted moment the polling goes on before the wait sleeps.
pub const TAIL: Duration = Duration::from_micros(700);

/// The spin budget of a `Step` request on a plane whose last tick is `last`: its step time,
/// half again for the variation between steps, plus [`LEAD`] for the request's own way to the
/// worker, at most [`MAX_SPIN`]. A plane that has not stepped yet gets [`LEAD`].
pub fn step_reply(last: Option<&TickHeader>) -> Duration {
    let step_us = last.map_or(0.0, |h| h.step_time_us.max(0.0) as f64);
    let spin = Duration::from_secs_f64(step_us * 1.5e-6) + LEAD;
    spin.min(MAX_SPIN)
}

/// When (CLOCK_MONOTONIC ns) the tick after `last` is due on a timer-driven plane: its end
/// plus its dt (the plane's period); `None` when nothing can be predicted (no dt).
pub fn next_tick_ns(last: &TickHeader) -> Option<u64> {
    let dt = last.dt;
    (dt.is_finite() && dt > 0.0).then(|| last.tick_end_ns + (f64::from(dt) * 1e9) as u64)
}

/// What a tick wait should do at `now_ns` for a tick due at `due_ns`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Phase {
    /// Too early: sleep on the event at most this long (then look again).
    Doze(Duration),
    /// Close to the moment: poll.
    Poll,
    /// The window passed without the tick: sleep on the event as usual.
    Sleep,
}

/// The phase of a wait at `now_ns` for a tick due at `due_ns`, polling in `window`.
pub fn phase_in(now_ns: u64, due_ns: u64, window: Window) -> Phase {
    let start = due_ns as i64 - window.lead_ns;
    let end = due_ns as i64 + window.tail_ns;
    let now = now_ns as i64;
    if now < start {
        Phase::Doze(Duration::from_nanos((start - now) as u64))
    } else if now <= end {
        Phase::Poll
    } else {
        Phase::Sleep
    }
}

/// When a wait polls, relative to the predicted moment: from `lead_ns` before it to
/// `tail_ns` after it (either may be negative: a window that lies wholly after or before
/// the prediction).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Window {
    /// Nanoseconds before the predicted moment that the polling starts.
    pub lead_ns: i64,
    /// Nanoseconds after the predicted moment that the polling ends.
    pub tail_ns: i64,
}

impl Default for Window {
    fn default() -> Self {
        Window {
            lead_ns: LEAD.as_nanos() as i64,
            tail_ns: TAIL.as_nanos() as i64,
        }
    }
}

/// What a reader learned of when its plane's ticks come.
///
/// The prediction: the daemon starts a timer-driven plane's ticks on a fixed cadence (each a
/// period after the last one was due, not after it ran), and its timer wakes late by the
/// machine's scheduling delay, a different amount each tick. Predicting from the last
/// tick's end (`end + dt`, [`next_tick_ns`]) carries that tick's delay into the next
/// prediction, so the error is the difference of two delays (on a loaded machine ±1.5 ms at
/// the quartiles). The reader therefore tracks the cadence itself: the earliest start seen,
/// advanced a period a tick (a start earlier than the estimate moves it there; a later one
/// only nudges it by 1/64 of the difference, so a drifting clock is followed), and predicts
/// the next tick's end as that plus a period plus the last step's time. The error is then
/// one tick's delay only (on the same loaded machine half the ticks within ±20 µs).
///
/// The window: the mean and the mean absolute deviation of the error, as running averages;
/// polling centred on the mean error, wide enough for [`SPREADS`] deviations either side
/// (never narrower than the fixed window) and never longer than [`MAX_SPIN`] — a reader
/// still polls at most that much of a core per tick.
#[derive(Debug, Default, Clone)]
pub struct Landing {
    mean_ns: f64,
    deviation_ns: f64,
    seen: u32,
    /// The cadence: the estimated scheduled start of tick `.0`, ns.
    cadence: Option<(u64, f64)>,
}

/// A timer-driven plane's period as its header tells it (its dt), ns.
pub fn period_ns(header: &TickHeader) -> Option<f64> {
    let dt = header.dt;
    (dt.is_finite() && dt > 0.0).then(|| f64::from(dt) * 1e9)
}

/// How many mean absolute deviations of the error either side of its mean the window covers
/// (2.5 of them are about two standard deviations of a normal error: ~95 % of the ticks).
pub const SPREADS: f64 = 2.5;

/// Weight of a new error in the running averages (about the last 16 ticks count).
const WEIGHT: f64 = 1.0 / 16.0;

impl Landing {
    /// Follows the cadence with the tick of `header` (a tick already followed changes
    /// nothing; a gap of more than a few ticks or a changed period starts over).
    pub fn follow(&mut self, header: &TickHeader) {
        let Some(period) = period_ns(header) else {
            self.cadence = None;
            return;
        };
        let start = header.tick_end_ns as f64 - f64::from(header.step_time_us.max(0.0)) * 1e3;
        self.cadence = Some(match self.cadence {
            Some((tick, _)) if tick == header.tick => return,
            Some((tick, due)) if header.tick > tick && header.tick - tick <= 4 => {
                let due = due + (header.tick - tick) as f64 * period;
                let late = start - due;
                if late < 0.0 || late > period / 2.0 {
                    // Earlier than the estimate, or so late the cadence restarted.
                    (header.tick, start)
                } else {
                    (header.tick, due + late / 64.0)
                }
            }
            _ => (header.tick, start),
        });
    }

    /// When (CLOCK_MONOTONIC ns) the tick after `header`'s is predicted to end: its
    /// scheduled start by the cadence plus a period plus `header`'s step time; without a
    /// cadence for that tick, [`next_tick_ns`].
    pub fn next_end_ns(&self, header: &TickHeader) -> Option<u64> {
        let period = period_ns(header)?;
        match self.cadence {
            Some((tick, due)) if tick == header.tick => {
                let step = f64::from(header.step_time_us.max(0.0)) * 1e3;
                Some((due + period + step) as u64)
            }
            _ => next_tick_ns(header),
        }
    }

    /// Notes that a tick predicted for `due_ns` ended at `end_ns`. An error of more than
    /// half of `period_ns` (a tick skipped, a paused daemon) says nothing of the timer's
    /// jitter and is ignored.
    pub fn observe(&mut self, due_ns: u64, end_ns: u64, period_ns: u64) {
        let err = end_ns as f64 - due_ns as f64;
        if !err.is_finite() || err.abs() > period_ns as f64 / 2.0 {
            return;
        }
        if self.seen == 0 {
            self.mean_ns = err;
            self.deviation_ns = 0.0;
        } else {
            let w = WEIGHT.max(1.0 / f64::from(self.seen + 1));
            self.deviation_ns += w * ((err - self.mean_ns).abs() - self.deviation_ns);
            self.mean_ns += w * (err - self.mean_ns);
        }
        self.seen = self.seen.saturating_add(1);
    }

    /// Where to poll for the next tick, relative to its prediction.
    pub fn window(&self) -> Window {
        let fixed = Window::default();
        if self.seen < 4 {
            return fixed;
        }
        let spread = SPREADS * self.deviation_ns;
        let lead = (spread - self.mean_ns).max(fixed.lead_ns as f64);
        let tail = (self.mean_ns + spread).max(fixed.tail_ns as f64);
        let max = MAX_SPIN.as_nanos() as f64;
        if lead + tail <= max {
            return Window {
                lead_ns: lead as i64,
                tail_ns: tail as i64,
            };
        }
        // Too wide to poll through: the part around the mean error.
        let lead = (max / 2.0 - self.mean_ns) as i64;
        Window {
            lead_ns: lead,
            tail_ns: max as i64 - lead,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn header(tick_end_ns: u64, dt: f32, step_time_us: f32) -> TickHeader {
        TickHeader {
            tick_end_ns,
            dt,
            step_time_us,
            ..TickHeader::default()
        }
    }

    #[test]
    fn a_step_spins_about_its_last_step_time_and_never_more_than_the_cap() {
        assert_eq!(step_reply(None), LEAD);
        let spin = step_reply(Some(&header(0, 1.0 / 60.0, 400.0)));
        assert_eq!(spin, Duration::from_micros(600) + LEAD);
        assert_eq!(step_reply(Some(&header(0, 1.0 / 60.0, 5_000.0))), MAX_SPIN);
        assert_eq!(step_reply(Some(&header(0, 0.0, f32::NAN))), LEAD);
    }

    #[test]
    fn a_tick_is_due_a_period_after_the_last_one_ended() {
        let due = next_tick_ns(&header(1_000_000_000, 1.0 / 60.0, 100.0)).unwrap();
        assert!((due as i64 - 1_016_666_666).abs() <= 1, "{due}");
        assert_eq!(next_tick_ns(&header(5, 0.0, 1.0)), None);
        assert_eq!(next_tick_ns(&header(5, f32::NAN, 1.0)), None);
    }

    #[test]
    fn the_window_follows_where_ticks_land_and_never_polls_past_the_cap() {
        let period = 16_666_667;
        let due = 1_000_000_000u64;
        // Too few ticks seen: the fixed window.
        let mut landing = Landing::default();
        landing.observe(due, due + 1_000_000, period);
        assert_eq!(landing.window(), Window::default());
        // Ticks that land 1.2 ms late, ±0.1 ms: the window moves after the prediction and
        // covers them; polling starts no later than 0.3 ms before the earliest of them.
        let mut landing = Landing::default();
        for k in 0..64u64 {
            let jitter: i64 = if k % 2 == 0 { 100_000 } else { -100_000 };
            landing.observe(due, (due as i64 + 1_200_000 + jitter) as u64, period);
        }
        let w = landing.window();
        let end = due as i64 + w.tail_ns;
        assert!(end >= due as i64 + 1_300_000, "{w:?}");
        assert!(w.lead_ns + w.tail_ns <= MAX_SPIN.as_nanos() as i64, "{w:?}");
        assert_eq!(
            phase_in(due + 1_250_000, due, w),
            Phase::Poll,
            "a tick 1.25 ms late is polled for: {w:?}"
        );
        // Widely scattered ticks (±5 ms): the window is capped at MAX_SPIN.
        let mut landing = Landing::default();
        for k in 0..64u64 {
            let end = if k % 2 == 0 {
                due + 5_000_000
            } else {
                due - 5_000_000
            };
            landing.observe(due, end, period);
        }
        let w = landing.window();
        assert_eq!(w.lead_ns + w.tail_ns, MAX_SPIN.as_nanos() as i64, "{w:?}");
        // A skipped tick (an error past half a period) teaches nothing.
        let before = landing.clone();
        landing.observe(due, due + 10_000_000, period);
        assert_eq!(landing.window(), before.window());
    }

    #[test]
    fn the_cadence_is_the_earliest_start_a_period_apart_not_the_last_end() {
        let period = 1.0 / 60.0;
        let p = 16_666_666.0;
        let t0 = 1_000_000_000.0;
        // Ticks due every period from t0, starting late by 0, 900, 50, 1,200, 0 µs; each
        // step 100 µs.
        let late = [0.0, 900_000.0, 50_000.0, 1_200_000.0, 0.0];
        let mut landing = Landing::default();
        for (k, l) in late.iter().enumerate() {
            let start = t0 + k as f64 * p + l;
            let h = TickHeader {
                tick: k as u64 + 1,
                tick_end_ns: (start + 100_000.0) as u64,
                step_time_us: 100.0,
                dt: period,
                ..TickHeader::default()
            };
            landing.follow(&h);
            landing.follow(&h); // the same tick again changes nothing
            let next = landing.next_end_ns(&h).unwrap() as f64;
            // The next tick is due at t0 + (k+1)·p and ends 100 µs after it starts: the
            // prediction is late by at most 1/64 of the delays seen, never a whole delay.
            let due_end = t0 + (k + 1) as f64 * p + 100_000.0;
            let nudged: f64 = late[..=k].iter().sum::<f64>() / 64.0;
            assert!(
                next >= due_end - 10.0 && next <= due_end + nudged + 10.0,
                "tick {}: predicted {next}, due {due_end}",
                k + 1
            );
            // The old prediction carries the delay: off by it.
            let old = next_tick_ns(&h).unwrap() as f64;
            assert!((old - due_end - l).abs() <= 2.0, "tick {}", k + 1);
        }
        // A gap of many ticks starts over from the tick seen.
        let h = TickHeader {
            tick: 50,
            tick_end_ns: 5_000_000_000,
            step_time_us: 100.0,
            dt: period,
            ..TickHeader::default()
        };
        landing.follow(&h);
        let (next, old) = (landing.next_end_ns(&h).unwrap(), next_tick_ns(&h).unwrap());
        assert!(next.abs_diff(old) <= 2, "{next} against {old}");
        // No dt: nothing to predict.
        let h = TickHeader::default();
        landing.follow(&h);
        assert_eq!(landing.next_end_ns(&h), None);
    }

    #[test]
    fn a_wait_dozes_then_polls_then_sleeps() {
        let due = 10_000_000;
        let lead = LEAD.as_nanos() as u64;
        let tail = TAIL.as_nanos() as u64;
        assert_eq!(
            phase_in(due - lead - 5_000, due, Window::default()),
            Phase::Doze(Duration::from_nanos(5_000))
        );
        let fixed = Window::default();
        assert_eq!(phase_in(due - lead, due, fixed), Phase::Poll);
        assert_eq!(phase_in(due + tail, due, fixed), Phase::Poll);
        assert_eq!(phase_in(due + tail + 1, due, fixed), Phase::Sleep);
    }
}

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

/// The phase of a wait at `now_ns` for a tick due at `due_ns`.
pub fn phase(now_ns: u64, due_ns: u64) -> Phase {
    let lead = LEAD.as_nanos() as u64;
    let tail = TAIL.as_nanos() as u64;
    if now_ns + lead < due_ns {
        Phase::Doze(Duration::from_nanos(due_ns - lead - now_ns))
    } else if now_ns <= due_ns + tail {
        Phase::Poll
    } else {
        Phase::Sleep
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
    fn a_wait_dozes_then_polls_then_sleeps() {
        let due = 10_000_000;
        let lead = LEAD.as_nanos() as u64;
        let tail = TAIL.as_nanos() as u64;
        assert_eq!(
            phase(due - lead - 5_000, due),
            Phase::Doze(Duration::from_nanos(5_000))
        );
        assert_eq!(phase(due - lead, due), Phase::Poll);
        assert_eq!(phase(due + tail, due), Phase::Poll);
        assert_eq!(phase(due + tail + 1, due), Phase::Sleep);
    }
}

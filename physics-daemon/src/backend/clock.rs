//! The tick clock and tick-header figures every plane kind keeps alike: the tick count,
//! simulated time, the last step's length and wall time, its deepest contact and touching
//! pairs, the checks a step's `dt` passes, and the [`TickHeader`] built from them. Kept once
//! here so the 3D and the GUI plane (and the GPU path) count ticks and fill headers the same
//! way.
//!
//! Its fields are part of each plane's snapshot state, in this order (a snapshot stores them
//! as it stored the planes' own fields before, byte for byte).

use std::time::Instant;

use shm_layout::validate::{self, MAX_DT};
use shm_layout::{CommandError, PlaneId, TickHeader, LAYOUT_VERSION};

/// A plane's tick clock and the figures of its last step.
#[derive(Debug, Default, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Clock {
    /// Ticks stepped so far.
    pub tick: u64,
    /// Simulated seconds so far.
    pub sim_time: f64,
    /// Wall time of the last step (µs).
    pub last_step_us: f32,
    /// Length of the last step (s).
    pub last_dt: f32,
    /// Deepest contact after the last step.
    pub max_penetration: f32,
    /// Touching pairs after the last step.
    pub contact_pairs: u32,
}

/// The shortest time step the engine is given (seconds): a step shorter than this is
/// simulated as this long ([`engine_dt`]), while the plane's clock advances by the step as
/// asked. A nanosecond is far below any game's time step, and the solver's rates are
/// 1 / dt: a step of 1e-38 s overflowed f32 in an articulation's motor bounds (NaN) and
/// panicked the solver. (Not zero: rapier's zero-length step skips its island bookkeeping,
/// and the next step then indexed past the islands' arrays.)
pub const MIN_DYNAMIC_DT: f32 = 1e-9;

/// The time step the engine is given for a step of `dt` (checked): at least
/// [`MIN_DYNAMIC_DT`].
pub fn engine_dt(dt: f32) -> f32 {
    dt.max(MIN_DYNAMIC_DT)
}

/// `dt` as every plane's step takes it: positive, finite and at most [`MAX_DT`] (errors
/// name `dt` and the value).
pub fn check_dt(dt: f32) -> Result<f32, CommandError> {
    let dt = validate::positive("dt", dt)?;
    if dt > MAX_DT {
        return Err(CommandError::invalid(format!(
            "dt must be at most {MAX_DT} s, got {dt}"
        )));
    }
    Ok(dt)
}

/// What a plane adds to its [`Clock`] in a tick header.
#[derive(Debug, Default, Clone, Copy, PartialEq)]
pub struct HeaderFigures {
    /// Length of the published body array.
    pub slot_count: u32,
    /// Live objects.
    pub body_count: u32,
    /// Largest joint error after the last step (0 without joints).
    pub max_joint_error: f32,
    /// Events produced so far (the running number of the next one).
    pub event_count: u64,
    /// [`shm_layout::StateHasher`] over every slot as the last step left it.
    pub state_hash: u64,
}

impl Clock {
    /// One step of `dt` done: the tick count and simulated time advance.
    pub fn advance(&mut self, dt: f32) {
        self.tick += 1;
        self.sim_time += dt as f64;
        self.last_dt = dt;
    }

    /// Records the wall time of a step begun at `started`.
    pub fn timed(&mut self, started: Instant) {
        self.last_step_us = started.elapsed().as_secs_f32() * 1e6;
    }

    /// The header of the newest tick of plane `plane_id`.
    pub fn header(&self, plane_id: PlaneId, f: HeaderFigures) -> TickHeader {
        TickHeader {
            layout_version: LAYOUT_VERSION,
            plane_id,
            tick: self.tick,
            sim_time: self.sim_time,
            tick_end_ns: 0,
            step_time_us: self.last_step_us,
            dt: self.last_dt,
            slot_count: f.slot_count,
            body_count: f.body_count,
            max_penetration: self.max_penetration,
            max_joint_error: f.max_joint_error,
            contact_pairs: self.contact_pairs,
            event_count: f.event_count as u32,
            state_hash: f.state_hash,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The clock stands where six fields of each plane's snapshot state stood: its encoding
    /// must be theirs, in the same order, or snapshots written before would not restore.
    #[test]
    fn encodes_as_the_six_fields_it_replaces() {
        let c = Clock {
            tick: 7,
            sim_time: 0.125,
            last_step_us: 3.5,
            last_dt: 1.0 / 60.0,
            max_penetration: 0.01,
            contact_pairs: 4,
        };
        let fields = (7u64, 0.125f64, 3.5f32, 1.0f32 / 60.0, 0.01f32, 4u32);
        assert_eq!(
            postcard::to_allocvec(&c).unwrap(),
            postcard::to_allocvec(&fields).unwrap()
        );
    }

    #[test]
    fn dt_is_checked_by_name() {
        for bad in [0.0, -1.0, f32::NAN, f32::INFINITY, MAX_DT * 2.0] {
            let e = check_dt(bad).unwrap_err();
            assert!(e.message.contains("dt"), "{bad}: {e}");
        }
        assert_eq!(check_dt(1.0 / 60.0).unwrap(), 1.0 / 60.0);
    }

    #[test]
    fn a_step_advances_tick_and_time() {
        let mut c = Clock::default();
        c.advance(0.5);
        c.advance(0.25);
        assert_eq!((c.tick, c.sim_time, c.last_dt), (2, 0.75, 0.25));
    }
}

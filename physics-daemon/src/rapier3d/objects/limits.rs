//! Speed limits of a plane: `MaxLinearSpeed` and `MaxAngularSpeed`.
//!
//! - MaxLinearSpeed is rapier's own linear cap (`normalized_max_linear_velocity`, which the
//!   solver applies after every substep, before positions move), set before every step.
//! - MaxAngularSpeed is enforced with [`capped`]. Rapier caps angular speed internally at a quarter
//!   turn per step (`MAX_ROTATION · inv_dt` in its staged island solver: 47 rad/s at 60 Hz) unless
//!   a body allows fast rotation; every body does (`Part::configure_body`), so that internal cap
//!   never applies and this one is the only limit. |ω| is scaled down to the limit for every body
//!   the step moves before it runs (in the per-body pass, `body_pass`, after the force pass, so
//!   RotateTo, SetPin and written AngularVelocity are capped before they turn anything) and for
//!   every awake body after it (`Scratch::cap_angular_speeds` in `body_pass`), so published angular
//!   velocities never exceed it. Within one step contacts may spin a body faster for that step's
//!   substeps only.

use rapier3d::prelude::*;

/// `w` scaled down to `max` rad/s (direction kept).
pub(crate) fn capped(w: Vector, max: f32) -> Vector {
    let speed = w.length();
    if speed > max {
        w * (max / speed)
    } else {
        w
    }
}

//! The force pass, run before every rapier step over the awake dynamic bodies (plus the ones
//! touched by commands since the last step). Rapier integrates gravity and contacts; this
//! pass adds what the API defines on top:
//!
//! - Buoyancy (acceleration), ConstantForce (plane + object, divided by mass),
//!   ImpulseDirection (acceleration): exact for constant forces.
//! - LinearDamping / AngularDamping: `v *= max(0, 1 - k·dt)`, as documented, applied to the
//!   velocity the tick starts with; the tick's accelerations (gravity included) come after.
//! - Drag `F = -Drag·|v|·v`: backward Euler over the whole tick, gravity and the other
//!   forces included: `v' = u - (Drag/m)·dt·|v'|·v'` with `u = keep·v + (g + a)·dt`, solved
//!   in closed form. It never overshoots or reverses a velocity at any dt, and its steady
//!   state is exact at any dt: `v' = v` gives `Drag·|v|·v = m·(g + a) - (k·m)·v`, the
//!   terminal velocity `√(m·g/Drag)` without damping. (Drag applied before gravity settled
//!   at `v_t + g·dt`.)
//! - RotateTo and SetPin: controllers that set the velocities they need, capped.
//!
//! The linear part becomes one force for the step, handed to rapier's force accumulator:
//! rapier spreads it over its substeps exactly like gravity, so Buoyancy = -Gravity.Y
//! cancels gravity in every substep (a velocity kick before the step would not, and the
//! body would drift). Angular changes are set directly: "direct rotation" must also turn
//! bodies whose rotation is locked against contacts.
//!
//! A plane with no forces and no driven objects skips the pass. The pass runs as part of the
//! per-body pass before the step (`body_pass`): [`drive`] only reads a body.

use rapier3d::prelude::*;
use shm_layout::{Pin, PlaneSettings, RotateTo};

use crate::rapier3d::objects::part::Part;

/// Plane-wide inputs of one pass.
pub(crate) struct Env {
    dt: f32,
    linear_keep: f32,
    angular_keep: f32,
    drag: f32,
    acceleration: Vector,
    force: Vector,
    gravity: Vector,
    /// The plane's `MaxLinearSpeed`.
    max_speed: f32,
}

impl Env {
    /// The pass's plane-wide inputs for a step of `dt`, or None when it would change no
    /// velocity (no damping, drag or plane-wide force, and no object with a drive of its
    /// own: `driven` counts those).
    pub(crate) fn new(s: &PlaneSettings, gravity: Vector, driven: u32, dt: f32) -> Option<Env> {
        let env = Env {
            dt,
            linear_keep: (1.0 - s.linear_damping * dt).max(0.0),
            angular_keep: (1.0 - s.angular_damping * dt).max(0.0),
            drag: s.drag,
            acceleration: Vector::new(0.0, s.buoyancy, 0.0),
            force: Vector::from(s.constant_force),
            gravity,
            max_speed: s.max_linear_speed,
        };
        let idle = env.linear_keep == 1.0
            && env.angular_keep == 1.0
            && env.drag == 0.0
            && env.acceleration == Vector::ZERO
            && env.force == Vector::ZERO
            && driven == 0;
        (!idle).then_some(env)
    }
}

/// What the force pass does to one body's linear motion.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Push {
    /// Nothing: the velocity stays.
    None,
    /// A force for the step, for rapier's force accumulator.
    Force(Vector),
    /// The velocity, set directly (waking the body): the force would not be finite.
    Velocity(Vector),
}

/// One body's forces for the step: its angular velocity after the pass, and its push. Reads
/// the body only (see `body_pass`, which writes the result).
pub(crate) fn drive(body: &RigidBody, part: &Part, env: &Env) -> (Vector, Push) {
    let dt = env.dt;
    let mass = body.mass();
    let inv_mass = if mass > 0.0 { 1.0 / mass } else { 0.0 };
    let (v0, w0) = (body.linvel(), body.angvel());
    let forces = env.force + Vector::from(part.constant_force);
    // The velocity this step should end at, before gravity and contacts: damping acts on
    // the velocity the tick starts with, the accelerations are added after it.
    let mut v = v0 * env.linear_keep
        + (env.acceleration + Vector::from(part.impulse_direction) + forces * inv_mass) * dt;
    let mut w = w0;
    let mut w_driven = false;
    if let Some(pin) = &part.pin {
        (v, w) = pin_drive(body, part, pin, v, w, env);
        w_driven = true;
    }
    if let Some(r) = &part.rotate_to {
        w = rotate_drive(body, r, dt);
        w_driven = true;
    }
    if env.drag > 0.0 {
        // Backward Euler with gravity inside: rapier adds `g·dt` after this pass.
        let g_dt = env.gravity * (body.gravity_scale() * dt);
        v = implicit_drag(v + g_dt, env.drag * inv_mass * dt) - g_dt;
    }
    if !w_driven {
        w *= env.angular_keep;
    }
    // Locked rotation axes keep their velocity (locked translations are skipped by rapier,
    // which applies forces through the effective inverse mass).
    for i in 0..3 {
        if part.locks[i + 3] {
            w[i] = w0[i];
        }
    }
    // A force so large on a light part that the velocity it asks for overflows f32: aim
    // at the fastest the plane allows along each axis instead (the speed limit caps the
    // step's end as it caps any other). A non-finite velocity made an articulated link's
    // joint coordinates NaN within the step, and the solver panicked on them.
    if !v.is_finite() {
        let cap = |x: f32| {
            if x.is_nan() {
                0.0
            } else {
                x.clamp(-env.max_speed, env.max_speed)
            }
        };
        v = Vector::new(cap(v.x), cap(v.y), cap(v.z));
    }
    let force = (v - v0) * (mass / dt);
    let push = if !force.is_finite() {
        // A dt so small that mass / dt overflows (1e-45 s): a non-finite force would make
        // rapier quarantine (disable) the body for good. Set the velocity the force would
        // have given instead.
        Push::Velocity(v)
    } else if force == Vector::ZERO {
        Push::None
    } else {
        Push::Force(force)
    };
    (w, push)
}

/// Backward Euler on `dv/dt = -c·|v|·v`: the new speed s' solves `s' + c·dt·s'² = s`.
/// `c_dt` is `Drag / mass · dt`. Written in the cancellation-free form of the root.
fn implicit_drag(v: Vector, c_dt: f32) -> Vector {
    let s = v.length();
    if s == 0.0 || c_dt == 0.0 {
        return v;
    }
    let s_new = 2.0 * s / (1.0 + (1.0 + 4.0 * c_dt * s).sqrt());
    v * (s_new / s)
}

/// The rotation from `q` to `target` as a scaled axis (shortest way round).
fn rotation_error(q: Rotation, target: Rotation) -> Vector {
    let mut d = target * q.inverse();
    if d.w < 0.0 {
        d = -d;
    }
    d.to_scaled_axis()
}

/// Angular velocity of a proportional controller; the gain is capped at 1/dt so one step
/// never rotates past the target.
fn rotate_drive(body: &RigidBody, r: &RotateTo, dt: f32) -> Vector {
    let err = rotation_error(body.position().rotation, Rotation::from_array(r.target));
    err * r.strength.min(1.0 / dt)
}

/// Speed toward a target `dist` away that a controller with acceleration `accel` can still
/// stop from at half that acceleration, and at most the whole way in one step.
fn approach_speed(dist: f32, accel: f32, dt: f32) -> f32 {
    (dist / dt).min((accel * dist).sqrt())
}

/// SetPin: the grab point's velocity is steered toward the target with an acceleration of
/// at most `force / mass` (gravity included: a force that cannot lift the body leaves it on
/// the ground); the orientation is turned toward the target's with a torque of at most
/// `force × lever`.
fn pin_drive(
    body: &RigidBody,
    part: &Part,
    pin: &Pin,
    v: Vector,
    w: Vector,
    env: &Env,
) -> (Vector, Vector) {
    let dt = env.dt;
    let mass = body.mass().max(f32::EPSILON);
    let pose = body.position();
    let relative = Vector::from(pin.relative);
    let grab = pose.translation + pose.rotation * relative;
    let com = body.center_of_mass();
    let accel = pin.force / mass;

    let err = Vector::from(pin.target.position) - grab;
    let dist = err.length();
    let wanted = if dist > 0.0 {
        err * (approach_speed(dist, accel, dt) / dist)
    } else {
        Vector::ZERO
    };
    let grab_velocity = v + w.cross(grab - com);
    // Rapier adds gravity after this pass: ask for it to be cancelled too.
    let needed = (wanted - grab_velocity) / dt - env.gravity;
    let v = v + needed.clamp_length_max(accel) * dt;

    let half_diagonal = 0.5 * Vector::from(part.size).length();
    let lever = relative.length().max(half_diagonal).max(1e-3);
    let alpha = pin.force / (mass * lever);
    let err = rotation_error(pose.rotation, Rotation::from_array(pin.target.rotation));
    let angle = err.length();
    let wanted = if angle > 0.0 {
        err * (approach_speed(angle, alpha, dt) / angle)
    } else {
        Vector::ZERO
    };
    let w = w + (wanted - w).clamp_length_max(alpha * dt);
    (v, w)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rapier3d::plane::Plane;

    #[test]
    fn implicit_drag_never_reverses_and_matches_small_steps() {
        // Huge drag and step: the speed shrinks but keeps its sign.
        let v = implicit_drag(Vector::new(0.0, -100.0, 0.0), 1e6);
        assert!(v.y < 0.0 && v.y > -0.1, "{v:?}");
        // Small c·dt: s' ≈ s - c·dt·s².
        let s = implicit_drag(Vector::new(10.0, 0.0, 0.0), 1e-4).x;
        assert!((s - (10.0 - 1e-4 * 100.0)).abs() < 1e-3, "{s}");
    }

    #[test]
    fn drag_with_gravity_inside_holds_the_terminal_velocity_at_any_dt() {
        // g = 50, Drag/m = 2: v_t = 5. The tick starts at -v_t; gravity adds g·dt, the
        // backward-Euler drag must bring it back to exactly -v_t.
        let g = Vector::new(0.0, -50.0, 0.0);
        for dt in [0.1f32, 1.0 / 60.0, 1.0 / 240.0] {
            let v = Vector::new(0.0, -5.0, 0.0);
            let next = implicit_drag(v + g * dt, 2.0 * dt);
            assert!((next.y + 5.0).abs() < 1e-5, "dt {dt}: {next:?}");
        }
    }

    #[test]
    fn rotation_error_takes_the_short_way() {
        let q = Rotation::from_rotation_y(0.1);
        let t = Rotation::from_rotation_y(-0.2);
        let e = rotation_error(q, t);
        assert!((e.y + 0.3).abs() < 1e-5, "{e:?}");
        let e = rotation_error(q, -t); // same orientation, other hemisphere
        assert!((e.y + 0.3).abs() < 1e-5, "{e:?}");
    }

    /// A ConstantForce of the largest f32 on a light part asks for a velocity past f32:
    /// the part flies at the plane's speed limit instead of going non-finite (which made
    /// rapier quarantine it for good, and panicked the solver on an articulated link).
    #[test]
    fn an_overflowing_force_drives_at_the_speed_limit() {
        use crate::backend::Backend;
        use shm_layout::{ObjectOp, ObjectProp, PlaneOp, PlaneProp, Pose, Shape};
        let mut p = Plane::new(1, &[PlaneProp::TickRate(0.0)]).unwrap();
        let h = p
            .add_object(
                &Shape::Sphere { radius: 0.25 },
                Pose::at([0.0, 0.0, 0.0]),
                &[ObjectProp::Weight(0.005)],
            )
            .unwrap();
        p.apply(PlaneOp::Object {
            handle: h,
            op: ObjectOp::Set(ObjectProp::ConstantForce([f32::MAX, 0.0, -f32::MAX])),
        })
        .unwrap();
        for _ in 0..3 {
            p.step(1.0 / 60.0).unwrap();
        }
        let body = &p.world.bodies[p.objects.get(h).unwrap().handle];
        assert!(body.is_enabled(), "quarantined");
        let (x, v) = (body.translation(), body.linvel());
        assert!(x.is_finite() && v.is_finite(), "{x:?} {v:?}");
        let limit = p.settings.max_linear_speed;
        assert!(v.length() <= limit * 1.001, "{} over {limit}", v.length());
        assert!(
            v.x > 0.5 * limit / 2f32.sqrt() && v.z < -0.5 * limit / 2f32.sqrt(),
            "{v:?}"
        );
    }
}

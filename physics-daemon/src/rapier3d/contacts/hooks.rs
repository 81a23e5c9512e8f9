//! The plane's contact hook: RestThreshold, bounce speed at the time of impact, and
//! controllers' sideways pushes.

use rapier3d::prelude::*;

/// The plane's contact hook, run only for pairs where a collider asks for it (Bounciness >
/// 0, or a character controller's capsule):
/// - RestThreshold: a contact whose normal approach speed is below the threshold does not
///   bounce.
/// - Bounce speed at the time of impact: rapier reflects the approach speed the tick starts
///   with (`e·v0`), but a body still `d` away from the surface hits it `τ` into the tick,
///   faster by what gravity added meanwhile: `v_imp² = v0² + 2·a·d` (`a` the closing
///   acceleration gravity gives the pair). The pair's restitution is scaled by `v_imp / v0`
///   so the bounce leaves at `e·v_imp` and reaches the exact apex `(e·v_imp)²/(2g)`; without
///   it the apex fell short by ≈ `2·g·dt/v` (5 % at 60 Hz for a 10-unit drop).
/// - A controller (the only kinematic bodies) pressing sideways on a dynamic body: the
///   solver does not push it (a kinematic body would push with infinite strength); the
///   controller pushes it itself with a force capped at its PushStrength. Contacts along
///   the vertical stay: a crate dropped on a character rests on its head.
pub(crate) struct RestThreshold {
    /// The plane's RestThreshold (units/s).
    pub threshold: f32,
    /// The plane's gravity.
    pub gravity: Vector,
}

/// Contacts more vertical than this (|normal.y|) between a controller and a dynamic body are
/// left to the solver.
const VERTICAL: f32 = 0.7;

impl PhysicsHooks for RestThreshold {
    fn modify_solver_contacts(&self, context: &mut ContactModificationContext) {
        let bodies = context.bodies;
        let (b1, b2) = (context.rigid_body1, context.rigid_body2);
        let kind = |h: Option<RigidBodyHandle>| {
            h.and_then(|h| bodies.get(h))
                .map(|b| (b.is_kinematic(), b.is_dynamic()))
        };
        let controller_push = matches!(
            (kind(b1), kind(b2)),
            (Some((true, _)), Some((_, true))) | (Some((_, true)), Some((true, _)))
        );
        let Some(manifold) = context.rigid_mut() else {
            return;
        };
        if controller_push && manifold.normal.y.abs() < VERTICAL {
            manifold.solver_contacts.clear();
            return;
        }
        if *manifold.restitution == 0.0 {
            return;
        }
        let velocity = |h: Option<RigidBodyHandle>, p: Vector| {
            h.and_then(|h| bodies.get(h))
                .map_or(Vector::ZERO, |b| b.velocity_at_point(p))
        };
        // The normal points from collider 1 toward collider 2.
        let normal = *manifold.normal;
        let approach = manifold
            .solver_contacts
            .iter()
            .map(|c| (velocity(b1, c.anchor1) - velocity(b2, c.anchor2)).dot(normal))
            .fold(0.0f32, f32::max);
        if approach < self.threshold {
            *manifold.restitution = 0.0;
            return;
        }
        // Closing acceleration from gravity (bodies that do not feel it add none).
        let pull = |h: Option<RigidBodyHandle>| {
            h.and_then(|h| bodies.get(h))
                .filter(|b| b.is_dynamic())
                .map_or(Vector::ZERO, |b| self.gravity * b.gravity_scale())
        };
        let closing = (pull(b1) - pull(b2)).dot(normal);
        let gap = manifold
            .solver_contacts
            .iter()
            .map(|c| c.dist)
            .fold(f32::MAX, f32::min);
        if closing > 0.0 && gap > 0.0 && gap < f32::MAX {
            let at_impact = (approach * approach + 2.0 * closing * gap).sqrt();
            let e = *manifold.restitution;
            let scaled = e * at_impact / approach;
            // Below 1 stays below 1 (rapier keeps contacts of restitution ≥ 1 bouncing).
            *manifold.restitution = if e < 1.0 { scaled.min(0.999) } else { scaled };
        }
    }
}

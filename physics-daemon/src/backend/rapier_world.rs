//! What both rapier planes do with their engine's world, written once for either engine:
//! [`RapierWorld`] is implemented from the same source for rapier3d's `PhysicsWorld` and,
//! with the `gui` feature, rapier2d's. Code generic over it (held bodies, the state copies of
//! snapshots and Rewind) serves both planes.

use std::hash::Hash;

use super::marks::Marks;

/// A rapier engine's world, as the planes built on it use it beyond the engine's own API.
pub trait RapierWorld: Sized {
    /// The engine's rigid-body handle.
    type BodyHandle: Copy + Eq + Hash;
    /// A body's pose, linear velocity and angular velocity.
    type Motion: Copy;

    /// A copy: the engine's sets cloned (shapes shared), its per-step workspaces fresh.
    fn copy(&self) -> Self;

    /// Brings the colliders of the bodies marked in `stale` up to date for queries (their
    /// poses and broad-phase boxes, which the engine refreshes only when it steps), and
    /// empties `stale`. Bodies removed since they were marked are skipped.
    fn refresh_colliders(&mut self, stale: &mut Marks<Self::BodyHandle>);

    /// The pose and velocities of body `h`; `None` when it is gone.
    fn motion(&self, h: Self::BodyHandle) -> Option<Self::Motion>;

    /// Gives body `h` the pose and velocities `m` without waking it; nothing when it is gone.
    fn set_motion(&mut self, h: Self::BodyHandle, m: Self::Motion);
}

/// Implements [`RapierWorld`] for the `PhysicsWorld` of the engine crate `$rapier`.
macro_rules! rapier_world {
    ($module:ident, $rapier:ident) => {
        mod $module {
            use $rapier::prelude::*;

            use $crate::backend::marks::Marks;
            use $crate::backend::rapier_world::RapierWorld;

            impl RapierWorld for PhysicsWorld {
                type BodyHandle = RigidBodyHandle;
                type Motion = (Pose, Vector, AngVector);

                fn copy(&self) -> PhysicsWorld {
                    PhysicsWorld {
                        gravity: self.gravity,
                        integration_parameters: self.integration_parameters,
                        physics_pipeline: PhysicsPipeline::new(),
                        collision_pipeline: CollisionPipeline::new(),
                        islands: self.islands.clone(),
                        broad_phase: self.broad_phase.clone(),
                        narrow_phase: self.narrow_phase.clone(),
                        bodies: self.bodies.clone(),
                        colliders: self.colliders.clone(),
                        impulse_joints: self.impulse_joints.clone(),
                        multibody_joints: self.multibody_joints.clone(),
                        soft_bodies: self.soft_bodies.clone(),
                        ccd_solver: CCDSolver::new(),
                    }
                }

                fn refresh_colliders(&mut self, stale: &mut Marks<RigidBodyHandle>) {
                    if stale.is_empty() {
                        return;
                    }
                    for h in std::mem::take(stale) {
                        let Some(body) = self.bodies.get(h) else {
                            continue; // removed since: its collider is gone from the set queries read
                        };
                        let pose = *body.position();
                        for c in body.colliders() {
                            let Some(co) = self.colliders.get_mut(*c) else {
                                continue;
                            };
                            let local = co.position_wrt_parent().copied().unwrap_or_default();
                            co.set_position(pose * local);
                            let aabb = co.compute_aabb();
                            self.broad_phase
                                .set_aabb(&self.integration_parameters, *c, aabb);
                        }
                    }
                }

                fn motion(&self, h: RigidBodyHandle) -> Option<(Pose, Vector, AngVector)> {
                    let body = self.bodies.get(h)?;
                    Some((*body.position(), body.linvel(), body.angvel()))
                }

                fn set_motion(
                    &mut self,
                    h: RigidBodyHandle,
                    (pose, v, w): (Pose, Vector, AngVector),
                ) {
                    if let Some(body) = self.bodies.get_mut(h) {
                        body.set_position(pose, false);
                        body.set_linvel(v, false);
                        body.set_angvel(w, false);
                    }
                }
            }
        }
    };
}

rapier_world!(world_3d, rapier3d);
#[cfg(feature = "gui")]
rapier_world!(world_2d, rapier2d);

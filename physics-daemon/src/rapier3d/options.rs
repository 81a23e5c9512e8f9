//! Creating a plane and setting its options: each option checked and stored in the plane's
//! settings, then mapped onto rapier where rapier needs it at set time.

use rapier3d::prelude::*;
use shm_layout::{CommandError, PlaneId, PlaneProp};

use super::offload::{no_other_engine, DeferHook};
use super::plane::Plane;

impl Plane {
    /// A plane with default options, then `props` applied in order (`DeferGpu = true` is
    /// refused: see [`Plane::new_with`]).
    pub fn new(id: PlaneId, props: &[PlaneProp]) -> Result<Plane, CommandError> {
        Plane::new_with(id, props, &mut no_other_engine)
    }

    /// Applies one option (`DeferGpu = true` is refused: see [`Plane::set_with`]).
    pub fn set(&mut self, prop: PlaneProp) -> Result<(), CommandError> {
        self.apply_prop(prop, false, &mut no_other_engine)
    }

    /// Applies one option; `creating` allows the construction-only ones; `defer` takes
    /// `DeferGpu`.
    pub(super) fn apply_prop(
        &mut self,
        prop: PlaneProp,
        creating: bool,
        defer: &mut DeferHook<'_>,
    ) -> Result<(), CommandError> {
        let before = self.settings;
        let prop = self.settings.apply(prop, creating)?;
        if let PlaneProp::DeferGpu(on) = prop {
            if let Err(mut e) = defer(self, on) {
                self.settings = before;
                e.message = match creating {
                    true => format!("{}; no plane was created", e.message),
                    false => format!("{}; plane {} stays on the CPU", e.message, self.id),
                };
                return Err(e);
            }
        }
        // Mapping onto rapier: options read at step time need nothing here.
        match prop {
            PlaneProp::Gravity(g) => self.world.gravity = Vector::from(g),
            PlaneProp::Threads(n) => self.set_threads(n)?,
            PlaneProp::NeverSleep(on) => self.set_never_sleep(on),
            _ => {}
        }
        // Forces changed: resting bodies must feel them (sleeping ones would ignore them).
        if prop.changes_forces() {
            self.world.wake_up_all(true);
        }
        self.objects.mark_all();
        Ok(())
    }

    fn set_never_sleep(&mut self, on: bool) {
        let template = if on {
            RigidBodyActivation::cannot_sleep()
        } else {
            RigidBodyActivation::active()
        };
        for (_, body) in self.world.bodies.iter_mut() {
            let activation = body.activation_mut();
            activation.normalized_linear_threshold = template.normalized_linear_threshold;
            activation.angular_threshold = template.angular_threshold;
            body.wake_up(true);
        }
    }

    pub(super) fn set_threads(&mut self, n: u32) -> Result<(), CommandError> {
        // Capped by the machine's cores; the plane reads back what it uses. Only a plane
        // that asks for parallelism pays for a pool, shared with the planes of its size.
        let used = crate::backend::pools::capped(n);
        self.settings.threads = used;
        let pool =
            if used > 1 {
                Some(crate::backend::pools::shared(used).map_err(|e| {
                    CommandError::new(shm_layout::ErrorKind::Internal, e.to_string())
                })?)
            } else {
                None
            };
        self.world.physics_pipeline.set_thread_pool(pool);
        Ok(())
    }
}
